//! What a figure shows: the kinds of figure, their series, marks and overlays, and the house
//! palette. Plain data; the sibling `draw` renders it.

use image::RgbImage;
use plotters::style::RGBColor;

/// Okabe–Ito: black, orange, sky blue, bluish green, blue, vermillion, reddish purple, yellow
/// (yellow last: it is hard to read as a thin line on white).
pub const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 0, 0),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 158, 115),
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(204, 121, 167),
    RGBColor(240, 228, 66),
];

pub fn color(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mark {
    Line,
    Points,
    LinePoints,
    Dashed,
    /// One-pixel points, faded (e.g. a laser's returns under a top view).
    Dots,
}

/// One named series.
#[derive(Debug, Clone)]
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    pub mark: Mark,
    /// `(x, low, high)`: a shaded band (e.g. ±3σ).
    pub band: Vec<(f64, f64, f64)>,
    pub color: usize,
}

impl Series {
    pub fn line(name: impl Into<String>, points: Vec<(f64, f64)>, color: usize) -> Series {
        Series {
            name: name.into(),
            points,
            mark: Mark::Line,
            band: Vec::new(),
            color,
        }
    }

    pub fn points(name: impl Into<String>, points: Vec<(f64, f64)>, color: usize) -> Series {
        Series {
            mark: Mark::Points,
            ..Series::line(name, points, color)
        }
    }

    pub fn with_mark(mut self, mark: Mark) -> Series {
        self.mark = mark;
        self
    }

    pub fn with_band(mut self, band: Vec<(f64, f64, f64)>) -> Series {
        self.band = band;
        self
    }
}

/// A vertical mark at `x` with a label (occlusion, reset, ...).
#[derive(Debug, Clone)]
pub struct Event {
    pub x: f64,
    pub label: String,
    pub color: usize,
}

#[derive(Debug, Clone, Default)]
pub struct LinePlot {
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    pub events: Vec<Event>,
    /// Fixed axis ranges; `None` fits the data.
    pub x_range: Option<(f64, f64)>,
    pub y_range: Option<(f64, f64)>,
}

#[derive(Debug, Clone, Default)]
pub struct ScatterPlot {
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    /// Text in the upper left (e.g. `r = 0.93`).
    pub annotation: String,
    /// Least-squares line through all points.
    pub fit_line: bool,
}

/// Something placed in a top view.
#[derive(Debug, Clone)]
pub struct Sensor {
    pub x: f64,
    pub y: f64,
    /// Heading (rad, counter-clockwise from +x); `None` draws no arrow.
    pub heading: Option<f64>,
    pub label: String,
}

#[derive(Debug, Clone)]
pub struct Circle {
    pub x: f64,
    pub y: f64,
    pub r: f64,
    pub color: usize,
}

#[derive(Debug, Clone, Default)]
pub struct TopView {
    /// Closed outline of the room or area (metres).
    pub outline: Vec<(f64, f64)>,
    /// Filled obstacles (desks, trees...), each a closed polygon.
    pub obstacles: Vec<Vec<(f64, f64)>>,
    pub sensors: Vec<Sensor>,
    pub trajectories: Vec<Series>,
    pub circles: Vec<Circle>,
}

#[derive(Debug, Clone)]
pub struct Bar {
    pub label: String,
    pub value: f64,
    /// Half-length of the error bar (std or CI half-width); 0 for none.
    pub error: f64,
}

/// `(bar i, bar j, label)` drawn as a bracket above the two bars.
#[derive(Debug, Clone)]
pub struct Significance {
    pub i: usize,
    pub j: usize,
    pub label: String,
}

#[derive(Debug, Clone, Default)]
pub struct BarPlot {
    pub y_label: String,
    pub bars: Vec<Bar>,
    pub significance: Vec<Significance>,
}

/// Shapes drawn over an image, in pixel coordinates.
#[derive(Debug, Clone)]
pub enum Overlay {
    Box {
        x0: f64,
        y0: f64,
        x1: f64,
        y1: f64,
        label: String,
        color: usize,
    },
    Ellipse {
        cx: f64,
        cy: f64,
        a: f64,
        b: f64,
        angle: f64,
        color: usize,
    },
    Polyline {
        points: Vec<(f64, f64)>,
        closed: bool,
        color: usize,
    },
    Point {
        x: f64,
        y: f64,
        color: usize,
    },
}

#[derive(Debug, Clone)]
pub struct ImageOverlay {
    pub image: RgbImage,
    pub shapes: Vec<Overlay>,
}

/// Bars in groups (e.g. one group per sequence, one bar per method), a legend of the series.
#[derive(Debug, Clone, Default)]
pub struct GroupedBars {
    pub y_label: String,
    /// The groups' names, left to right.
    pub groups: Vec<String>,
    /// `(name, value per group)`; `None` draws no bar.
    pub series: Vec<(String, Vec<Option<f64>>)>,
    /// Text at the end of each bar, `labels[series][group]` (missing or empty: none).
    pub labels: Vec<Vec<String>>,
    /// Text under a group's name (e.g. `SKIPPED`), by group (missing or empty: none).
    pub group_notes: Vec<String>,
}

/// Figures side by side in a grid, `columns` wide, each with its own title, under the
/// figure's title. Image overlays in a grid show their shapes only in SVG.
#[derive(Debug, Clone, Default)]
pub struct Panels {
    pub columns: usize,
    pub panels: Vec<Figure>,
}

#[derive(Debug, Clone)]
pub enum FigureKind {
    Lines(LinePlot),
    Scatter(ScatterPlot),
    TopView(TopView),
    Bars(BarPlot),
    Overlay(ImageOverlay),
    GroupedBars(GroupedBars),
    Panels(Panels),
}

/// A figure ready to render.
#[derive(Debug, Clone)]
pub struct Figure {
    /// File stem: `<name>.png`, `<name>.svg`.
    pub name: String,
    pub title: String,
    pub size: (u32, u32),
    pub kind: FigureKind,
}

impl Figure {
    pub fn new(name: impl Into<String>, title: impl Into<String>, kind: FigureKind) -> Figure {
        let size = match &kind {
            FigureKind::Overlay(o) => (o.image.width().max(64), o.image.height().max(64) + 30),
            FigureKind::TopView(_) => (720, 720),
            FigureKind::GroupedBars(g) => ((140 + 190 * g.groups.len() as u32).max(800), 500),
            FigureKind::Panels(p) => p.size(),
            _ => (800, 500),
        };
        Figure {
            name: name.into(),
            title: title.into(),
            size,
            kind,
        }
    }
}

impl Panels {
    /// The grid's cell is the largest panel's size; 30 px more for the title.
    pub fn size(&self) -> (u32, u32) {
        let columns = self.columns.clamp(1, self.panels.len().max(1));
        let rows = self.panels.len().div_ceil(columns).max(1);
        let w = self.panels.iter().map(|f| f.size.0).max().unwrap_or(400);
        let h = self.panels.iter().map(|f| f.size.1).max().unwrap_or(300);
        (w * columns as u32, h * rows as u32 + 30)
    }
}

//! Figures in one house style, rendered by `plotters` to PNG and SVG from the same drawing
//! code, with an embedded font (DejaVu Sans, `assets/fonts/`) so no system font library is
//! needed. Kinds, as the experiments need them:
//!
//! - [`LinePlot`]: series over x with optional ±kσ bands and event marks (time series, sweeps,
//!   ROC curves, rates over time);
//! - [`ScatterPlot`]: points per series with an annotation (e.g. Pearson r) and a fit line;
//! - [`TopView`]: room outline, obstacles, sensors, trajectories and cylinders, equal aspect;
//! - [`BarPlot`]: bars with error bars and significance marks;
//! - [`ImageOverlay`]: a camera image with boxes, ellipses and polylines (projected cylinders).
//!
//! Colours are the Okabe–Ito palette (distinguishable with colour-vision deficiency).

use std::sync::Once;

use image::RgbImage;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;

const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
static FONT_ONCE: Once = Once::new();

fn register_font() {
    FONT_ONCE.call_once(|| {
        // The bytes are a valid TrueType font checked into the repository.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
        let _ = plotters::style::register_font("sans-serif", FontStyle::Bold, FONT);
    });
}

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

#[derive(Debug, thiserror::Error)]
#[error("figure {name}: {reason}")]
pub struct FigureError {
    pub name: String,
    pub reason: String,
}

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mark {
    Line,
    Points,
    LinePoints,
    Dashed,
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

/// The legend corner of a top view that covers the fewest trajectory points, circles and
/// sensors (a corner is the outer 40 % × 25 % of the plotted area; ties go to the first of
/// upper right, lower right, upper left, lower left).
fn emptiest_corner(p: &TopView, (x0, x1, y0, y1): (f64, f64, f64, f64)) -> SeriesLabelPosition {
    let (w, h) = (x1 - x0, y1 - y0);
    let pts: Vec<(f64, f64)> = p
        .trajectories
        .iter()
        .flat_map(|t| t.points.iter().copied())
        .chain(p.circles.iter().map(|c| (c.x, c.y)))
        .chain(p.sensors.iter().map(|s| (s.x, s.y)))
        .collect();
    let corners = [
        (SeriesLabelPosition::UpperRight, true, true),
        (SeriesLabelPosition::LowerRight, true, false),
        (SeriesLabelPosition::UpperLeft, false, true),
        (SeriesLabelPosition::LowerLeft, false, false),
    ];
    let count = |right: bool, upper: bool| {
        pts.iter()
            .filter(|(x, y)| {
                let in_x = if right {
                    *x >= x1 - 0.4 * w
                } else {
                    *x <= x0 + 0.4 * w
                };
                let in_y = if upper {
                    *y >= y1 - 0.25 * h
                } else {
                    *y <= y0 + 0.25 * h
                };
                in_x && in_y
            })
            .count()
    };
    let mut best = (usize::MAX, SeriesLabelPosition::UpperRight);
    for (pos, right, upper) in corners {
        let n = count(right, upper);
        if n < best.0 {
            best = (n, pos);
        }
    }
    best.1
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

#[derive(Debug, Clone)]
pub enum FigureKind {
    Lines(LinePlot),
    Scatter(ScatterPlot),
    TopView(TopView),
    Bars(BarPlot),
    Overlay(ImageOverlay),
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

type DrawResult<DB> = Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

fn bounds(points: impl Iterator<Item = (f64, f64)>) -> Option<(f64, f64, f64, f64)> {
    let mut b: Option<(f64, f64, f64, f64)> = None;
    for (x, y) in points.filter(|(x, y)| x.is_finite() && y.is_finite()) {
        b = Some(match b {
            None => (x, x, y, y),
            Some((x0, x1, y0, y1)) => (x0.min(x), x1.max(x), y0.min(y), y1.max(y)),
        });
    }
    b
}

/// Pad a range by 5 % (and give a degenerate range some width).
fn pad(lo: f64, hi: f64) -> (f64, f64) {
    let span = hi - lo;
    let m = if span > 0.0 {
        span * 0.05
    } else {
        lo.abs().max(1.0) * 0.1
    };
    (lo - m, hi + m)
}

fn caption_style() -> TextStyle<'static> {
    ("sans-serif", 18).into_font().color(&BLACK)
}

impl Figure {
    pub fn new(name: impl Into<String>, title: impl Into<String>, kind: FigureKind) -> Figure {
        let size = match &kind {
            FigureKind::Overlay(o) => (o.image.width().max(64), o.image.height().max(64) + 30),
            FigureKind::TopView(_) => (720, 720),
            _ => (800, 500),
        };
        Figure {
            name: name.into(),
            title: title.into(),
            size,
            kind,
        }
    }

    fn err(&self, e: impl std::fmt::Display) -> FigureError {
        FigureError {
            name: self.name.clone(),
            reason: e.to_string(),
        }
    }

    /// PNG bytes.
    pub fn to_png(&self) -> Result<Vec<u8>, FigureError> {
        register_font();
        let (w, h) = self.size;
        let mut buf = vec![255u8; (w * h * 3) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
            self.draw(&root, true).map_err(|e| self.err(e))?;
            root.present().map_err(|e| self.err(e))?;
        }
        let img = RgbImage::from_raw(w, h, buf).ok_or_else(|| self.err("buffer size"))?;
        let mut out = Vec::new();
        img.write_to(&mut std::io::Cursor::new(&mut out), image::ImageFormat::Png)
            .map_err(|e| self.err(e))?;
        Ok(out)
    }

    /// SVG text. Image overlays embed the image as a PNG data URI under the vector shapes.
    pub fn to_svg(&self) -> Result<String, FigureError> {
        register_font();
        let mut s = String::new();
        {
            let root = SVGBackend::with_string(&mut s, self.size).into_drawing_area();
            self.draw(&root, false).map_err(|e| self.err(e))?;
            root.present().map_err(|e| self.err(e))?;
        }
        if let FigureKind::Overlay(o) = &self.kind {
            use base64::Engine;
            let mut png = Vec::new();
            o.image
                .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
                .map_err(|e| self.err(e))?;
            let data = base64::engine::general_purpose::STANDARD.encode(&png);
            let tag = format!(
                "<image x=\"0\" y=\"30\" width=\"{}\" height=\"{}\" href=\"data:image/png;base64,{data}\"/>",
                o.image.width(),
                o.image.height()
            );
            // insert right after the opening <svg ...> tag so shapes draw on top
            if let Some(end) = s.find('>') {
                s.insert_str(end + 1, &tag);
            }
        }
        Ok(s)
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        raster: bool,
    ) -> DrawResult<DB> {
        if !matches!(self.kind, FigureKind::Overlay(_)) || raster {
            root.fill(&WHITE)?;
        }
        match &self.kind {
            FigureKind::Lines(p) => self.draw_lines(root, p),
            FigureKind::Scatter(p) => self.draw_scatter(root, p),
            FigureKind::TopView(p) => self.draw_top(root, p),
            FigureKind::Bars(p) => self.draw_bars(root, p),
            FigureKind::Overlay(p) => self.draw_overlay(root, p, raster),
        }
    }

    fn draw_lines<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        p: &LinePlot,
    ) -> DrawResult<DB> {
        let all = p.series.iter().flat_map(|s| {
            s.points
                .iter()
                .copied()
                .chain(s.band.iter().flat_map(|(x, lo, hi)| [(*x, *lo), (*x, *hi)]))
        });
        let (x0, x1, y0, y1) = bounds(all).unwrap_or((0.0, 1.0, 0.0, 1.0));
        let (x0, x1) = p.x_range.unwrap_or_else(|| pad(x0, x1));
        let (y0, y1) = p.y_range.unwrap_or_else(|| pad(y0, y1));
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, caption_style())
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(62)
            .build_cartesian_2d(x0..x1, y0..y1)?;
        chart
            .configure_mesh()
            .x_desc(&p.x_label)
            .y_desc(&p.y_label)
            .light_line_style(RGBColor(235, 235, 235))
            .label_style(("sans-serif", 13))
            .draw()?;
        for s in &p.series {
            let c = color(s.color);
            if !s.band.is_empty() {
                let mut poly: Vec<(f64, f64)> = s.band.iter().map(|(x, _, hi)| (*x, *hi)).collect();
                poly.extend(s.band.iter().rev().map(|(x, lo, _)| (*x, *lo)));
                chart.draw_series(std::iter::once(Polygon::new(poly, c.mix(0.18).filled())))?;
            }
            draw_series(&mut chart, s)?;
        }
        for e in &p.events {
            let c = color(e.color);
            chart.draw_series(DashedLineSeries::new(
                vec![(e.x, y0), (e.x, y1)],
                4,
                4,
                c.stroke_width(1),
            ))?;
            chart.draw_series(std::iter::once(Text::new(
                e.label.clone(),
                (e.x, y1),
                ("sans-serif", 11).into_font().color(&c),
            )))?;
        }
        if p.series.iter().any(|s| !s.name.is_empty()) {
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(RGBColor(160, 160, 160))
                .label_font(("sans-serif", 13))
                .position(SeriesLabelPosition::UpperRight)
                .draw()?;
        }
        Ok(())
    }

    fn draw_scatter<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        p: &ScatterPlot,
    ) -> DrawResult<DB> {
        let (x0, x1, y0, y1) = bounds(p.series.iter().flat_map(|s| s.points.iter().copied()))
            .unwrap_or((0.0, 1.0, 0.0, 1.0));
        let ((x0, x1), (y0, y1)) = (pad(x0, x1), pad(y0, y1));
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, caption_style())
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(62)
            .build_cartesian_2d(x0..x1, y0..y1)?;
        chart
            .configure_mesh()
            .x_desc(&p.x_label)
            .y_desc(&p.y_label)
            .light_line_style(RGBColor(235, 235, 235))
            .label_style(("sans-serif", 13))
            .draw()?;
        for s in &p.series {
            draw_series(
                &mut chart,
                &Series {
                    mark: Mark::Points,
                    ..s.clone()
                },
            )?;
        }
        if p.fit_line {
            let pts: Vec<(f64, f64)> = p
                .series
                .iter()
                .flat_map(|s| s.points.iter().copied())
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .collect();
            if let Some((a, b)) = least_squares(&pts) {
                chart.draw_series(LineSeries::new(
                    vec![(x0, a + b * x0), (x1, a + b * x1)],
                    RGBColor(120, 120, 120).stroke_width(1),
                ))?;
            }
        }
        if !p.annotation.is_empty() {
            chart.draw_series(std::iter::once(Text::new(
                p.annotation.clone(),
                (x0 + (x1 - x0) * 0.03, y1 - (y1 - y0) * 0.04),
                ("sans-serif", 15).into_font().color(&BLACK),
            )))?;
        }
        if p.series.len() > 1 {
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(RGBColor(160, 160, 160))
                .label_font(("sans-serif", 13))
                .draw()?;
        }
        Ok(())
    }

    fn draw_top<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        p: &TopView,
    ) -> DrawResult<DB> {
        let pts = p
            .outline
            .iter()
            .copied()
            .chain(p.obstacles.iter().flatten().copied())
            .chain(p.sensors.iter().map(|s| (s.x, s.y)))
            .chain(p.trajectories.iter().flat_map(|t| t.points.iter().copied()))
            .chain(
                p.circles
                    .iter()
                    .flat_map(|c| [(c.x - c.r, c.y - c.r), (c.x + c.r, c.y + c.r)]),
            );
        let (x0, x1, y0, y1) = bounds(pts).unwrap_or((0.0, 1.0, 0.0, 1.0));
        // equal aspect: widen the narrower axis
        let span = (x1 - x0).max(y1 - y0).max(1e-3) * 1.08;
        let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
        let (x0, x1, y0, y1) = (
            cx - span / 2.0,
            cx + span / 2.0,
            cy - span / 2.0,
            cy + span / 2.0,
        );
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, caption_style())
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(50)
            .build_cartesian_2d(x0..x1, y0..y1)?;
        chart
            .configure_mesh()
            .x_desc("x (m)")
            .y_desc("y (m)")
            .light_line_style(RGBColor(240, 240, 240))
            .label_style(("sans-serif", 12))
            .draw()?;
        for o in &p.obstacles {
            chart.draw_series(std::iter::once(Polygon::new(
                o.clone(),
                RGBColor(200, 200, 200).filled(),
            )))?;
        }
        if !p.outline.is_empty() {
            let mut closed = p.outline.clone();
            closed.push(p.outline[0]);
            chart.draw_series(LineSeries::new(closed, BLACK.stroke_width(2)))?;
        }
        for t in &p.trajectories {
            draw_series(&mut chart, t)?;
        }
        for c in &p.circles {
            let poly: Vec<(f64, f64)> = (0..=32)
                .map(|k| {
                    let a = k as f64 / 32.0 * std::f64::consts::TAU;
                    (c.x + c.r * a.cos(), c.y + c.r * a.sin())
                })
                .collect();
            chart.draw_series(std::iter::once(Polygon::new(
                poly.clone(),
                color(c.color).mix(0.25).filled(),
            )))?;
            chart.draw_series(LineSeries::new(poly, color(c.color).stroke_width(1)))?;
        }
        for s in &p.sensors {
            let c = RGBColor(90, 90, 90);
            chart.draw_series(std::iter::once(TriangleMarker::new(
                (s.x, s.y),
                7,
                c.filled(),
            )))?;
            if let Some(h) = s.heading {
                let l = span * 0.05;
                chart.draw_series(LineSeries::new(
                    vec![(s.x, s.y), (s.x + l * h.cos(), s.y + l * h.sin())],
                    c.stroke_width(2),
                ))?;
            }
            chart.draw_series(std::iter::once(Text::new(
                s.label.clone(),
                (s.x + span * 0.01, s.y + span * 0.01),
                ("sans-serif", 12).into_font().color(&c),
            )))?;
        }
        if p.trajectories.iter().any(|t| !t.name.is_empty()) {
            chart
                .configure_series_labels()
                .position(emptiest_corner(p, (x0, x1, y0, y1)))
                .background_style(WHITE.mix(0.85))
                .border_style(RGBColor(160, 160, 160))
                .label_font(("sans-serif", 12))
                .draw()?;
        }
        Ok(())
    }

    fn draw_bars<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        p: &BarPlot,
    ) -> DrawResult<DB> {
        let n = p.bars.len().max(1);
        let top = p
            .bars
            .iter()
            .map(|b| b.value + b.error.max(0.0))
            .filter(|v| v.is_finite())
            .fold(0.0f64, f64::max);
        let bottom = p
            .bars
            .iter()
            .map(|b| b.value - b.error.max(0.0))
            .filter(|v| v.is_finite())
            .fold(0.0f64, f64::min);
        let headroom = (top - bottom).max(1e-9) * (0.12 + 0.1 * p.significance.len() as f64);
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, caption_style())
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(62)
            .build_cartesian_2d(-0.5..(n as f64 - 0.5), bottom..(top + headroom))?;
        let labels: Vec<String> = p.bars.iter().map(|b| b.label.clone()).collect();
        chart
            .configure_mesh()
            .disable_x_mesh()
            .y_desc(&p.y_label)
            .x_labels(n)
            .x_label_formatter(&|x| {
                let i = x.round();
                if (x - i).abs() < 1e-6 && i >= 0.0 {
                    labels.get(i as usize).cloned().unwrap_or_default()
                } else {
                    String::new()
                }
            })
            .label_style(("sans-serif", 13))
            .draw()?;
        for (i, b) in p.bars.iter().enumerate() {
            let x = i as f64;
            chart.draw_series(std::iter::once(Rectangle::new(
                [(x - 0.3, 0.0), (x + 0.3, b.value)],
                color(i + 1).mix(0.8).filled(),
            )))?;
            if b.error > 0.0 {
                chart.draw_series(std::iter::once(ErrorBar::new_vertical(
                    x,
                    b.value - b.error,
                    b.value,
                    b.value + b.error,
                    BLACK.stroke_width(1),
                    12,
                )))?;
            }
        }
        for (k, s) in p.significance.iter().enumerate() {
            let y = top + (top - bottom).max(1e-9) * (0.05 + 0.1 * k as f64);
            let (a, b) = (s.i as f64, s.j as f64);
            chart.draw_series(LineSeries::new(
                vec![(a, y * 0.98), (a, y), (b, y), (b, y * 0.98)],
                BLACK.stroke_width(1),
            ))?;
            chart.draw_series(std::iter::once(Text::new(
                s.label.clone(),
                ((a + b) / 2.0 - 0.2, y + (top - bottom).max(1e-9) * 0.06),
                ("sans-serif", 12).into_font().color(&BLACK),
            )))?;
        }
        Ok(())
    }

    fn draw_overlay<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        p: &ImageOverlay,
        raster: bool,
    ) -> DrawResult<DB> {
        let (title_area, img_area) = root.split_vertically(30);
        if raster {
            title_area.fill(&WHITE)?;
        }
        title_area.draw(&Text::new(self.title.clone(), (6, 6), caption_style()))?;
        if raster {
            // paint the image pixel by pixel (the bitmap backend has no image primitive without
            // plotters' old `image` dependency)
            for (x, y, px) in p.image.enumerate_pixels() {
                img_area.draw_pixel((x as i32, y as i32), &RGBColor(px[0], px[1], px[2]))?;
            }
        }
        let pt = |x: f64, y: f64| (x.round() as i32, y.round() as i32);
        for s in &p.shapes {
            match s {
                Overlay::Box {
                    x0,
                    y0,
                    x1,
                    y1,
                    label,
                    color: c,
                } => {
                    img_area.draw(&Rectangle::new(
                        [pt(*x0, *y0), pt(*x1, *y1)],
                        color(*c).stroke_width(2),
                    ))?;
                    if !label.is_empty() {
                        img_area.draw(&Text::new(
                            label.clone(),
                            pt(*x0, *y0 - 13.0),
                            ("sans-serif", 12).into_font().color(&color(*c)),
                        ))?;
                    }
                }
                Overlay::Ellipse {
                    cx,
                    cy,
                    a,
                    b,
                    angle,
                    color: c,
                } => {
                    let (ca, sa) = (angle.cos(), angle.sin());
                    let poly: Vec<(i32, i32)> = (0..=48)
                        .map(|k| {
                            let t = k as f64 / 48.0 * std::f64::consts::TAU;
                            let (u, v) = (a * t.cos(), b * t.sin());
                            pt(cx + u * ca - v * sa, cy + u * sa + v * ca)
                        })
                        .collect();
                    img_area.draw(&PathElement::new(poly, color(*c).stroke_width(2)))?;
                }
                Overlay::Polyline {
                    points,
                    closed,
                    color: c,
                } => {
                    let mut poly: Vec<(i32, i32)> =
                        points.iter().map(|(x, y)| pt(*x, *y)).collect();
                    if *closed && let Some(first) = poly.first().copied() {
                        poly.push(first);
                    }
                    img_area.draw(&PathElement::new(poly, color(*c).stroke_width(2)))?;
                }
                Overlay::Point { x, y, color: c } => {
                    img_area.draw(&plotters::element::Circle::new(
                        pt(*x, *y),
                        3,
                        color(*c).filled(),
                    ))?;
                }
            }
        }
        Ok(())
    }
}

fn draw_series<DB: DrawingBackend>(
    chart: &mut ChartContext<
        '_,
        DB,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    s: &Series,
) -> DrawResult<DB> {
    let c = color(s.color);
    let pts: Vec<(f64, f64)> = s
        .points
        .iter()
        .copied()
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .collect();
    let anno = match s.mark {
        Mark::Line | Mark::LinePoints => {
            chart.draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))?
        }
        Mark::Dashed => {
            chart.draw_series(DashedLineSeries::new(pts.clone(), 6, 4, c.stroke_width(2)))?
        }
        Mark::Points => chart.draw_series(
            pts.iter()
                .map(|p| plotters::element::Circle::new(*p, 3, c.filled())),
        )?,
    };
    if !s.name.is_empty() {
        anno.label(s.name.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], c.stroke_width(2)));
    }
    if s.mark == Mark::LinePoints {
        chart.draw_series(
            pts.iter()
                .map(|p| plotters::element::Circle::new(*p, 3, c.filled())),
        )?;
    }
    Ok(())
}

/// Intercept and slope of the least-squares line; `None` with fewer than two distinct x.
pub fn least_squares(pts: &[(f64, f64)]) -> Option<(f64, f64)> {
    let n = pts.len() as f64;
    if pts.len() < 2 {
        return None;
    }
    let (mx, my) = pts
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let sxx: f64 = pts.iter().map(|(x, _)| (x - mx) * (x - mx)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let sxy: f64 = pts.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    let b = sxy / sxx;
    Some((my - b * mx, b))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_top_view_legend_goes_to_the_emptiest_corner() {
        let area = (0.0, 10.0, 0.0, 10.0);
        let with = |pts: Vec<(f64, f64)>| TopView {
            trajectories: vec![Series::line("a", pts, 0)],
            ..TopView::default()
        };
        let pos = |v: &TopView| format!("{:?}", emptiest_corner(v, area));
        // nothing anywhere: the first corner
        assert_eq!(pos(&with(vec![])), "UpperRight");
        // a track through the upper right: the next empty corner
        assert_eq!(pos(&with(vec![(9.0, 9.0), (8.0, 9.5)])), "LowerRight");
        // every corner but the lower left is crossed
        let crossed = vec![
            (9.0, 9.0),
            (9.0, 1.0),
            (1.0, 9.0),
            (1.0, 1.0),
            (2.0, 1.5),
            (9.5, 0.5),
            (8.5, 9.2),
        ];
        assert_eq!(pos(&with(crossed[..3].to_vec())), "LowerLeft");
        // all crossed: the least crossed (upper left, one point; the others two)
        assert_eq!(pos(&with(crossed)), "UpperLeft");
    }

    /// Render, decode the PNG back, and count pixels that are not white.
    fn check(fig: &Figure) {
        let png = fig.to_png().expect("png renders");
        // Set PEOPLETRACK_FIGURE_DIR to look at the test figures.
        if let Some(dir) = std::env::var_os("PEOPLETRACK_FIGURE_DIR") {
            std::fs::write(
                std::path::Path::new(&dir).join(format!("{}.png", fig.name)),
                &png,
            )
            .expect("save");
        }
        let img = image::load_from_memory(&png).expect("valid png").to_rgb8();
        assert_eq!((img.width(), img.height()), fig.size, "{}", fig.name);
        let inked = img.pixels().filter(|p| p.0 != [255, 255, 255]).count();
        let total = (img.width() * img.height()) as usize;
        assert!(
            inked > total / 100,
            "{}: only {inked} of {total} pixels drawn",
            fig.name
        );
        let svg = fig.to_svg().expect("svg renders");
        assert!(
            svg.starts_with("<svg") && svg.contains("</svg>") && svg.len() > 1000,
            "{}",
            fig.name
        );
    }

    fn wave(phase: f64) -> Vec<(f64, f64)> {
        (0..50)
            .map(|i| (i as f64 * 0.2, (i as f64 * 0.2 + phase).sin()))
            .collect()
    }

    #[test]
    fn every_kind_renders_to_png_and_svg() {
        let lines = LinePlot {
            x_label: "time (s)".into(),
            y_label: "height (m)".into(),
            series: vec![
                Series::line("estimate", wave(0.0), 5).with_band(
                    wave(0.0)
                        .iter()
                        .map(|(x, y)| (*x, y - 0.3, y + 0.3))
                        .collect(),
                ),
                Series::line("truth", wave(0.2), 0).with_mark(Mark::Dashed),
            ],
            events: vec![Event {
                x: 4.0,
                label: "occlusion".into(),
                color: 6,
            }],
            ..Default::default()
        };
        check(&Figure::new(
            "lines",
            "Height over time (±3σ)",
            FigureKind::Lines(lines),
        ));
        let scatter = ScatterPlot {
            x_label: "true distance (m)".into(),
            y_label: "person width (px)".into(),
            series: vec![Series::points(
                "",
                (1..40)
                    .map(|i| (i as f64 * 0.1, 40.0 / (i as f64 * 0.1)))
                    .collect(),
                5,
            )],
            annotation: "r = -0.87".into(),
            fit_line: true,
        };
        check(&Figure::new(
            "scatter",
            "Width vs distance",
            FigureKind::Scatter(scatter),
        ));
        let top = TopView {
            outline: vec![(0.0, 0.0), (10.0, 0.0), (10.0, 5.0), (0.0, 5.0)],
            obstacles: vec![vec![(2.0, 1.0), (4.0, 1.0), (4.0, 1.8), (2.0, 1.8)]],
            sensors: vec![Sensor {
                x: 5.0,
                y: 0.0,
                heading: Some(std::f64::consts::FRAC_PI_2),
                label: "omnicam".into(),
            }],
            trajectories: vec![Series::line(
                "truth",
                (0..30)
                    .map(|i| (1.0 + i as f64 * 0.25, 2.5 + (i as f64 * 0.3).sin()))
                    .collect(),
                0,
            )],
            circles: vec![Circle {
                x: 7.0,
                y: 3.0,
                r: 0.3,
                color: 6,
            }],
        };
        check(&Figure::new(
            "top",
            "Tracked path",
            FigureKind::TopView(top),
        ));
        let bars = BarPlot {
            y_label: "error (m)".into(),
            bars: vec![
                Bar {
                    label: "general".into(),
                    value: 0.16,
                    error: 0.1,
                },
                Bar {
                    label: "specific".into(),
                    value: 0.12,
                    error: 0.08,
                },
            ],
            significance: vec![Significance {
                i: 0,
                j: 1,
                label: "p = 0.003".into(),
            }],
        };
        check(&Figure::new(
            "bars",
            "Person-specific models",
            FigureKind::Bars(bars),
        ));
        let roc = LinePlot {
            x_label: "false positives (%)".into(),
            y_label: "true positives (%)".into(),
            series: vec![Series::line(
                "adaptive",
                vec![(0.0, 0.0), (1.0, 60.0), (5.0, 90.0), (100.0, 100.0)],
                5,
            )],
            x_range: Some((0.0, 100.0)),
            y_range: Some((0.0, 100.0)),
            ..Default::default()
        };
        check(&Figure::new("roc", "ROC", FigureKind::Lines(roc)));
        let mut img = RgbImage::new(160, 120);
        for (x, y, p) in img.enumerate_pixels_mut() {
            *p = image::Rgb([(x % 256) as u8, (y * 2 % 256) as u8, 90]);
        }
        let overlay = ImageOverlay {
            image: img,
            shapes: vec![
                Overlay::Box {
                    x0: 20.0,
                    y0: 20.0,
                    x1: 60.0,
                    y1: 100.0,
                    label: "1".into(),
                    color: 1,
                },
                Overlay::Ellipse {
                    cx: 100.0,
                    cy: 60.0,
                    a: 20.0,
                    b: 10.0,
                    angle: 0.4,
                    color: 2,
                },
                Overlay::Polyline {
                    points: vec![(10.0, 10.0), (150.0, 110.0)],
                    closed: false,
                    color: 3,
                },
                Overlay::Point {
                    x: 80.0,
                    y: 30.0,
                    color: 4,
                },
            ],
        };
        check(&Figure::new(
            "overlay",
            "Camera 1",
            FigureKind::Overlay(overlay),
        ));
    }

    #[test]
    fn rendering_is_deterministic() {
        let fig = Figure::new(
            "d",
            "same",
            FigureKind::Lines(LinePlot {
                series: vec![Series::line("a", wave(0.0), 1)],
                ..Default::default()
            }),
        );
        assert_eq!(fig.to_png().expect("a"), fig.to_png().expect("b"));
        assert_eq!(fig.to_svg().expect("a"), fig.to_svg().expect("b"));
    }

    #[test]
    fn least_squares_known_answer() {
        let (a, b) = least_squares(&[(0.0, 1.0), (1.0, 3.0), (2.0, 5.0)]).expect("line");
        assert!((a - 1.0).abs() < 1e-12 && (b - 2.0).abs() < 1e-12);
        assert_eq!(least_squares(&[(1.0, 1.0), (1.0, 2.0)]), None);
    }
}

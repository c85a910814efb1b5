//! Drawing a [`Figure`] with `plotters` on any backend (bitmap or SVG): axes, series, bands,
//! legends, top views, bars and image overlays in the house style.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::spec::{
    BarPlot, Figure, FigureKind, ImageOverlay, LinePlot, Mark, Overlay, ScatterPlot, Series,
    TopView, color,
};

/// The legend corner of a top view that covers the fewest trajectory points, circles and
/// sensors (a corner is the outer 40 % × 25 % of the plotted area; ties go to the first of
/// upper right, lower right, upper left, lower left).
pub(super) fn emptiest_corner(
    p: &TopView,
    (x0, x1, y0, y1): (f64, f64, f64, f64),
) -> SeriesLabelPosition {
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

pub(super) type DrawResult<DB> =
    Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

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

pub(super) fn caption_style() -> TextStyle<'static> {
    ("sans-serif", 18).into_font().color(&BLACK)
}

impl Figure {
    pub(super) fn draw<DB: DrawingBackend>(
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
            FigureKind::GroupedBars(p) => self.draw_grouped(root, p),
            FigureKind::Panels(p) => self.draw_panels(root, p, raster),
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
            .x_label_formatter(&|x| label_at(&labels, *x))
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
        Mark::Dots => {
            // opaque: the colour at 45 % on white, so overlapping dots stay faint
            let faint = |v: u8| (f64::from(v) * 0.45 + 255.0 * 0.55) as u8;
            let f = RGBColor(faint(c.0), faint(c.1), faint(c.2));
            chart.draw_series(pts.iter().map(|p| Pixel::new(*p, f)))?
        }
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

/// The label of category `x` on a category axis (`0, 1, …`); empty between categories.
pub(super) fn label_at(labels: &[String], x: f64) -> String {
    let i = x.round();
    if (x - i).abs() < 1e-6 && i >= 0.0 {
        labels.get(i as usize).cloned().unwrap_or_default()
    } else {
        String::new()
    }
}

//! Figures: the bird's-eye view with trajectories and cylinders (paper fig. 5c/6c) and the
//! four camera views with the projected cylinders (fig. 5a/b/d/e).

use crate::names::sanitize;
use image::RgbImage;
use nalgebra::Point3;

use super::evaluate::{Scored, f64s, strs};
use super::session::{images_at, read_calibration};
use super::{Params, topics};
use crate::geometry::triangulate::CalibratedView;
use crate::log::SessionLog;
use crate::report::Figure;
use crate::report::figure::{
    Circle, FigureKind, ImageOverlay, Mark, Overlay, Sensor, Series, TopView,
};
use crate::time::Nanos;

fn rect(r: &[f64; 4]) -> Vec<(f64, f64)> {
    vec![(r[0], r[1]), (r[2], r[1]), (r[2], r[3]), (r[0], r[3])]
}

/// One bird's-eye view per session.
pub(super) fn birdseye(s: &Scored, p: &Params) -> Vec<Figure> {
    let mut out = Vec::new();
    for d in &s.data {
        let t = &d.tracks;
        let rows = t.rows(&s.main);
        let mut by_id: std::collections::BTreeMap<i64, Vec<usize>> = Default::default();
        for &i in &rows {
            by_id.entry(t.id[i]).or_default().push(i);
        }
        let mut trajectories = Vec::new();
        let mut circles = Vec::new();
        let g = &d.truth;
        let mut truth: std::collections::BTreeMap<i64, Vec<(f64, f64)>> = Default::default();
        for i in 0..g.id.len() {
            truth.entry(g.id[i]).or_default().push((g.x[i], g.y[i]));
        }
        for (k, (_, pts)) in truth.into_iter().enumerate() {
            trajectories.push(
                Series::line(if k == 0 { "ground truth" } else { "" }, pts, 0)
                    .with_mark(Mark::Dashed),
            );
        }
        for (k, (id, ix)) in by_id.iter().enumerate() {
            let color = (*id as usize % 7) + 1;
            trajectories.push(Series::line(
                if k == 0 {
                    "3-D tracks (cylinders at their last position)"
                } else {
                    ""
                },
                ix.iter().map(|&i| (t.x[i], t.y[i])).collect(),
                color,
            ));
            let last = ix[ix.len() - 1];
            if t.r[last].is_finite() && t.r[last] > 0.0 {
                circles.push(Circle {
                    x: t.x[last],
                    y: t.y[last],
                    r: t.r[last],
                    color,
                });
            }
        }
        let sensors = match (
            strs(&d.calibration, "camera"),
            f64s(&d.calibration, "x_m"),
            f64s(&d.calibration, "y_m"),
            f64s(&d.calibration, "heading_rad"),
        ) {
            (Ok(c), Ok(x), Ok(y), Ok(h)) => (0..c.len())
                .map(|i| Sensor {
                    x: x[i],
                    y: y[i],
                    heading: Some(h[i]),
                    label: c[i].clone(),
                })
                .collect(),
            _ => Vec::new(),
        };
        out.push(Figure::new(
            format!("birdseye_{}", sanitize(&d.name)),
            format!(
                "Bird's-eye view, {}/{}: 3-D tracks and cylinders",
                d.dataset, d.name
            ),
            FigureKind::TopView(TopView {
                outline: rect(&p.room_m),
                obstacles: p.figure_obstacles_m.iter().map(rect).collect(),
                sensors,
                trajectories,
                circles,
            }),
        ));
    }
    out
}

/// Outline of a vertical cylinder in one camera: top and bottom rims and two sides.
pub(super) fn cylinder_outline(
    view: &CalibratedView,
    x: f64,
    y: f64,
    h: f64,
    r: f64,
) -> Vec<Vec<(f64, f64)>> {
    let rim = |z: f64| -> Vec<(f64, f64)> {
        (0..=36)
            .filter_map(|k| {
                let a = f64::from(k) / 36.0 * std::f64::consts::TAU;
                view.project(&Point3::new(x + r * a.cos(), y + r * a.sin(), z))
                    .map(|p| (p.x, p.y))
            })
            .collect()
    };
    let c = view.center();
    let (vx, vy) = (x - c.x, y - c.y);
    let norm = vx.hypot(vy).max(1e-9);
    let mut out = vec![rim(0.0), rim(h)];
    for side in [1.0f64, -1.0] {
        // the rim points whose radius is perpendicular to the viewing direction
        let (dx, dy) = (-vy / norm * r * side, vx / norm * r * side);
        let line: Vec<(f64, f64)> = (0..=10)
            .filter_map(|k| {
                view.project(&Point3::new(x + dx, y + dy, h * f64::from(k) / 10.0))
                    .map(|p| (p.x, p.y))
            })
            .collect();
        out.push(line);
    }
    out
}

/// The cameras of the first session at the frame with the most tracks, cylinders projected.
pub(super) fn camera_views(s: &Scored, p: &Params) -> anyhow::Result<Option<Figure>> {
    let Some(d) = s.data.first() else {
        return Ok(None);
    };
    let t = &d.tracks;
    let rows = t.rows(&s.main);
    if rows.is_empty() {
        return Ok(None);
    }
    // frame with the most supported tracks; ties: the one nearest the middle of the session
    let mut count: std::collections::BTreeMap<i64, usize> = Default::default();
    for &i in &rows {
        if t.cameras[i] > 0 {
            *count.entry(t.frame[i]).or_default() += 1;
        }
    }
    let mid = d.frames / 2;
    let Some((&frame, _)) = count
        .iter()
        .max_by(|a, b| a.1.cmp(b.1).then((b.0 - mid).abs().cmp(&(a.0 - mid).abs())))
    else {
        return Ok(None);
    };
    let stamp = rows
        .iter()
        .find(|&&i| t.frame[i] == frame)
        .map(|&i| Nanos(t.stamp_ns[i] as u64))
        .unwrap_or(Nanos(0));
    let tp = topics(p, &Default::default());
    let log = SessionLog::open(&d.path)?;
    let calib = read_calibration(&log, p, &tp)?;
    let images = images_at(&d.path, p, &tp, stamp)?;
    let (w, h) = images
        .iter()
        .flatten()
        .map(|i| i.dimensions())
        .next()
        .unwrap_or((352, 288));
    let cols = 2u32;
    let n = images.len() as u32;
    let rows_n = n.div_ceil(cols);
    let mut canvas = RgbImage::from_pixel(w * cols, h * rows_n, image::Rgb([255, 255, 255]));
    let mut shapes = Vec::new();
    for (c, img) in images.iter().enumerate() {
        let (ox, oy) = ((c as u32 % cols) * w, (c as u32 / cols) * h);
        if let Some(img) = img {
            image::imageops::overlay(&mut canvas, img, i64::from(ox), i64::from(oy));
        }
        let Some(view) = calib.views.get(c) else {
            continue;
        };
        let (oxf, oyf) = (f64::from(ox), f64::from(oy));
        let inside =
            |q: &(f64, f64)| q.0 >= 0.0 && q.1 >= 0.0 && q.0 < f64::from(w) && q.1 < f64::from(h);
        for &i in rows.iter().filter(|&&i| t.frame[i] == frame) {
            let color = (t.id[i] as usize % 7) + 1;
            let r = if t.r[i].is_finite() { t.r[i] } else { 0.2 };
            for line in cylinder_outline(view, t.x[i], t.y[i], t.h[i], r) {
                let pts: Vec<(f64, f64)> = line
                    .into_iter()
                    .filter(inside)
                    .map(|(x, y)| (x + oxf, y + oyf))
                    .collect();
                if pts.len() >= 2 {
                    shapes.push(Overlay::Polyline {
                        points: pts,
                        closed: false,
                        color,
                    });
                }
            }
            if let Some(head) = view.project(&Point3::new(t.x[i], t.y[i], t.h[i]))
                && inside(&(head.x, head.y))
            {
                shapes.push(Overlay::Box {
                    x0: head.x + oxf - 2.0,
                    y0: head.y + oyf - 2.0,
                    x1: head.x + oxf + 2.0,
                    y1: head.y + oyf + 2.0,
                    label: format!("{}", t.id[i]),
                    color,
                });
            }
        }
    }
    let time = rows
        .iter()
        .find(|&&i| t.frame[i] == frame)
        .map_or(0.0, |&i| t.t_s[i]);
    Ok(Some(Figure::new(
        "camera_views",
        format!(
            "{}/{} at {time:.2} s: the cameras ({}) with the 3-D cylinders projected",
            d.dataset,
            d.name,
            p.cameras.join(", ")
        ),
        FigureKind::Overlay(ImageOverlay {
            image: canvas,
            shapes,
        }),
    )))
}

//! What the camera-view figure (paper fig. 5a/b/d/e) needs, made while the log is open: the
//! frame with the most supported tracks of the main run, the cameras' images at its stamp
//! side by side, and the cylinders projected into them. Cached with the session's tables, so
//! that aggregation never re-opens the log.

use std::collections::BTreeMap;

use image::RgbImage;
use nalgebra::Point3;
use polars::prelude::DataFrame;

use super::input::images_at;
use crate::geometry::triangulate::CalibratedView;
use crate::log::SessionLog;
use crate::pipelines::s004_mohedano_multicam::tables::{TrackRow, ViewFrameRow, ViewShapeRow};
use crate::report::columns::image_table;
use crate::report::figure::Overlay;
use crate::report::rows::Rows;
use crate::time::Nanos;

/// Images side by side in this many columns.
const COLUMNS: u32 = 2;
/// Canvas cell size when no camera has an image at the stamp.
const DEFAULT_SIZE: (u32, u32) = (352, 288);
/// Radius drawn for a track whose radius is unknown (m).
const DEFAULT_RADIUS_M: f64 = 0.2;
const POLYLINE: &str = "polyline";
const BOX: &str = "box";

/// The camera view of one session.
pub(crate) struct CameraView {
    pub frame: i64,
    pub t_s: f64,
    pub canvas: RgbImage,
    pub shapes: Vec<Overlay>,
}

/// The frame with the most supported tracks; ties: the one nearest the middle of the session
/// (`frames` frames); equally near: the later one.
pub(crate) fn view_frame(main: &[&TrackRow], frames: i64) -> Option<i64> {
    let mut count: BTreeMap<i64, usize> = BTreeMap::new();
    for r in main {
        if r.cameras > 0 {
            *count.entry(r.frame).or_default() += 1;
        }
    }
    let mid = frames / 2;
    count
        .iter()
        .max_by(|a, b| a.1.cmp(b.1).then((b.0 - mid).abs().cmp(&(a.0 - mid).abs())))
        .map(|(&f, _)| f)
}

/// The view of the main run's tracks (`main`, in frame order) of a session of `frames` frames.
pub(crate) fn camera_view(
    log: &SessionLog,
    image_topics: &[String],
    views: &[CalibratedView],
    main: &[&TrackRow],
    frames: i64,
    tol_ns: u64,
) -> anyhow::Result<Option<CameraView>> {
    let Some(frame) = view_frame(main, frames) else {
        return Ok(None);
    };
    let at: Vec<&TrackRow> = main.iter().copied().filter(|r| r.frame == frame).collect();
    let stamp = at.first().map_or(Nanos(0), |r| Nanos(r.stamp_ns as u64));
    let images = images_at(log, image_topics, stamp, tol_ns)?;
    let (w, h) = images
        .iter()
        .flatten()
        .map(|i| i.dimensions())
        .next()
        .unwrap_or(DEFAULT_SIZE);
    let rows_n = (images.len() as u32).div_ceil(COLUMNS);
    let mut canvas = RgbImage::from_pixel(w * COLUMNS, h * rows_n, image::Rgb([255, 255, 255]));
    let mut shapes = Vec::new();
    for (c, img) in images.iter().enumerate() {
        let offset = ((c as u32 % COLUMNS) * w, (c as u32 / COLUMNS) * h);
        if let Some(img) = img {
            image::imageops::overlay(&mut canvas, img, i64::from(offset.0), i64::from(offset.1));
        }
        if let Some(view) = views.get(c) {
            shapes.extend(projected(view, &at, offset, (w, h)));
        }
    }
    Ok(Some(CameraView {
        frame,
        t_s: at.first().map_or(0.0, |r| r.t_s),
        canvas,
        shapes,
    }))
}

/// The tracks `at` one frame drawn in one camera whose image lies at `offset` in the canvas.
fn projected(
    view: &CalibratedView,
    at: &[&TrackRow],
    offset: (u32, u32),
    (w, h): (u32, u32),
) -> Vec<Overlay> {
    let (oxf, oyf) = (f64::from(offset.0), f64::from(offset.1));
    let inside =
        |q: &(f64, f64)| q.0 >= 0.0 && q.1 >= 0.0 && q.0 < f64::from(w) && q.1 < f64::from(h);
    let mut shapes = Vec::new();
    for t in at {
        let color = (t.id as usize % 7) + 1;
        let r = if t.radius_m.is_finite() {
            t.radius_m
        } else {
            DEFAULT_RADIUS_M
        };
        for line in cylinder_outline(view, t.x_m, t.y_m, t.height_m, r) {
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
        if let Some(head) = view.project(&Point3::new(t.x_m, t.y_m, t.height_m))
            && inside(&(head.x, head.y))
        {
            shapes.push(Overlay::Box {
                x0: head.x + oxf - 2.0,
                y0: head.y + oyf - 2.0,
                x1: head.x + oxf + 2.0,
                y1: head.y + oyf + 2.0,
                label: format!("{}", t.id),
                color,
            });
        }
    }
    shapes
}

/// Outline of a vertical cylinder in one camera: top and bottom rims and two sides.
pub(crate) fn cylinder_outline(
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

/// The view as cached tables: its frame, its canvas and its shapes.
pub(crate) fn view_tables(v: &CameraView) -> anyhow::Result<[DataFrame; 3]> {
    let frame = ViewFrameRow::frame(&[ViewFrameRow {
        frame: v.frame,
        t_s: v.t_s,
        error: String::new(),
    }])?;
    Ok([
        frame,
        image_table(&v.canvas)?,
        ViewShapeRow::frame(&shape_rows(&v.shapes))?,
    ])
}

/// Shapes as rows (polylines and boxes; other overlays are not drawn here).
pub(crate) fn shape_rows(shapes: &[Overlay]) -> Vec<ViewShapeRow> {
    let mut rows = Vec::new();
    for (k, s) in shapes.iter().enumerate() {
        let row = |kind: &str, color: usize, label: &str, (x, y): (f64, f64)| ViewShapeRow {
            shape: k as i64,
            kind: kind.to_string(),
            color: color as i64,
            label: label.to_string(),
            x,
            y,
        };
        match s {
            Overlay::Polyline { points, color, .. } => {
                rows.extend(points.iter().map(|&q| row(POLYLINE, *color, "", q)));
            }
            Overlay::Box {
                x0,
                y0,
                x1,
                y1,
                label,
                color,
            } => {
                rows.push(row(BOX, *color, label, (*x0, *y0)));
                rows.push(row(BOX, *color, label, (*x1, *y1)));
            }
            _ => {}
        }
    }
    rows
}

/// Shapes back from their rows.
pub(crate) fn shapes_from_rows(rows: &[ViewShapeRow]) -> Vec<Overlay> {
    let mut out = Vec::new();
    let mut k = 0;
    while k < rows.len() {
        let first = &rows[k];
        let n = rows[k..]
            .iter()
            .take_while(|r| r.shape == first.shape)
            .count();
        let pts = &rows[k..k + n];
        let color = first.color.max(0) as usize;
        if first.kind == BOX && n == 2 {
            out.push(Overlay::Box {
                x0: pts[0].x,
                y0: pts[0].y,
                x1: pts[1].x,
                y1: pts[1].y,
                label: first.label.clone(),
                color,
            });
        } else {
            out.push(Overlay::Polyline {
                points: pts.iter().map(|r| (r.x, r.y)).collect(),
                closed: false,
                color,
            });
        }
        k += n;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn track(frame: i64, cameras: i64) -> TrackRow {
        TrackRow {
            detector: "templates".into(),
            selection: "E_c".into(),
            n_app: 5,
            frame,
            stamp_ns: 1_000 + frame,
            t_s: frame as f64 * 0.04,
            id: 1,
            x_m: 1.0,
            y_m: 2.0,
            vx_mps: 0.0,
            vy_mps: 0.0,
            height_m: 1.7,
            radius_m: 0.25,
            cameras,
            support: String::new(),
            e_m_px: None,
            meas_x_m: None,
            meas_y_m: None,
            meas_height_m: None,
            meas_radius_m: None,
        }
    }

    #[test]
    fn the_view_frame_has_the_most_supported_tracks_then_is_nearest_the_middle() {
        let rows = [
            track(2, 2),
            track(2, 3),
            track(5, 2),
            track(5, 0),
            track(8, 2),
            track(8, 2),
            track(9, 0),
            track(9, 0),
            track(9, 0),
        ];
        let refs: Vec<&TrackRow> = rows.iter().collect();
        // frames 2 and 8 have two supported tracks each; both are 3 frames from the middle
        // of 10 frames (5), so the later one
        assert_eq!(view_frame(&refs, 10), Some(8));
        // middle 4: frame 2 (2 away) beats frame 8 (4 away)
        assert_eq!(view_frame(&refs, 8), Some(2));
        assert_eq!(view_frame(&refs[6..], 10), None);
    }

    #[test]
    fn shapes_survive_their_rows() {
        let shapes = vec![
            Overlay::Polyline {
                points: vec![(1.0, 2.0), (3.0, 4.5), (5.0, 6.0)],
                closed: false,
                color: 3,
            },
            Overlay::Box {
                x0: 1.0,
                y0: 2.0,
                x1: 5.0,
                y1: 6.0,
                label: "7".into(),
                color: 1,
            },
            Overlay::Polyline {
                points: vec![(0.0, 0.0), (1.0, 1.0)],
                closed: false,
                color: 3,
            },
        ];
        let rows = shape_rows(&shapes);
        assert_eq!(rows.len(), 7);
        let back = ViewShapeRow::read(&ViewShapeRow::frame(&rows).expect("frame")).expect("read");
        assert_eq!(
            format!("{:?}", shapes_from_rows(&back)),
            format!("{shapes:?}")
        );
    }
}

//! Figures: the bird's-eye view with trajectories and cylinders (paper fig. 5c/6c) and the
//! four camera views with the projected cylinders (fig. 5a/b/d/e), drawn from the cached
//! per-session tables only (the camera view was made by `session::view` while the log was
//! open).

use std::collections::BTreeMap;

use crate::names::sanitize;

use super::Params;
use super::scored::{Scored, SessionData};
use super::session::shapes_from_rows;
use super::tables::{TrackRow, ViewShapeRow};
use crate::report::Figure;
use crate::report::columns::read_image_table;
use crate::report::figure::{Circle, FigureKind, ImageOverlay, Mark, Sensor, Series, TopView};
use crate::report::rows::Rows;

fn rect(r: &[f64; 4]) -> Vec<(f64, f64)> {
    vec![(r[0], r[1]), (r[2], r[1]), (r[2], r[3]), (r[0], r[3])]
}

/// One bird's-eye view per session.
pub(crate) fn birdseye(s: &Scored, p: &Params) -> Vec<Figure> {
    s.data.iter().map(|d| birdseye_of(d, s, p)).collect()
}

fn birdseye_of(d: &SessionData, s: &Scored, p: &Params) -> Figure {
    let mut by_id: BTreeMap<i64, Vec<&TrackRow>> = BTreeMap::new();
    for r in d.rows(&s.main) {
        by_id.entry(r.id).or_default().push(r);
    }
    let mut trajectories = Vec::new();
    let mut circles = Vec::new();
    let mut truth: BTreeMap<i64, Vec<(f64, f64)>> = BTreeMap::new();
    for g in &d.truth {
        truth.entry(g.id).or_default().push((g.x_m, g.y_m));
    }
    for (k, (_, pts)) in truth.into_iter().enumerate() {
        trajectories.push(
            Series::line(if k == 0 { "ground truth" } else { "" }, pts, 0).with_mark(Mark::Dashed),
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
            ix.iter().map(|r| (r.x_m, r.y_m)).collect(),
            color,
        ));
        if let Some(last) = ix.last()
            && last.radius_m.is_finite()
            && last.radius_m > 0.0
        {
            circles.push(Circle {
                x: last.x_m,
                y: last.y_m,
                r: last.radius_m,
                color,
            });
        }
    }
    let sensors = d
        .calibration
        .iter()
        .map(|c| Sensor {
            x: c.x_m,
            y: c.y_m,
            heading: Some(c.heading_rad),
            label: c.camera.clone(),
        })
        .collect();
    Figure::new(
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
    )
}

/// The cameras of the first session at the frame with the most supported tracks, cylinders
/// projected (as cached by the session).
pub(crate) fn camera_views(s: &Scored, p: &Params) -> anyhow::Result<Option<Figure>> {
    let Some(d) = s.data.first() else {
        return Ok(None);
    };
    let Some(view) = &d.view else {
        return Ok(None);
    };
    if !view.frame.error.is_empty() {
        anyhow::bail!("{}", view.frame.error);
    }
    let Some((image, shapes)) = &view.tables else {
        return Ok(None);
    };
    let canvas = read_image_table(image)?;
    let shapes = shapes_from_rows(&ViewShapeRow::read(shapes)?);
    Ok(Some(Figure::new(
        "camera_views",
        format!(
            "{}/{} at {:.2} s: the cameras ({}) with the 3-D cylinders projected",
            d.dataset,
            d.name,
            view.frame.t_s,
            p.cameras.join(", ")
        ),
        FigureKind::Overlay(ImageOverlay {
            image: canvas,
            shapes,
        }),
    )))
}

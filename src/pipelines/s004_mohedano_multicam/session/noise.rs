//! The detector-noise runs (issue 32, part 2): the exact boxes of every frame — the log's
//! detections with `detector = "log"` (WILDTRACK's annotated boxes), else the ground-truth
//! boxes — through the detector model of `log::import::detector_noise` at each level of
//! `detector_noise` (seed `noise_seed`), then through the same 2-D tracker as their source
//! and the 3-D stage with each association of `noise_associations`. The 3-D stage is told the
//! detector it gets: the configured `occupancy` model with each level's errors added
//! ([`told`]), as a user who has measured their detector would set it. Rows go to their own
//! tables (`noise_tracks`, `noise_boxes`), so the other tables do not change.

use rayon::prelude::*;

use super::super::{Detector, Params, Topics};
use super::boxes::{box_head, boxes_from_detections, boxes_from_truth, graph_params};
use super::pass::FrameRec;
use super::runs::{Run, cylinder_params, run_variant};
use crate::frames::multicam;
use crate::geometry::triangulate::CalibratedView;
use crate::groundtruth::PeopleFrame;
use crate::log::SessionLog;
use crate::log::import::detector_noise::{self, CameraFrame, DetectorNoise};
use crate::log::msgs::Detection2DArray;
use crate::pipelines::s004_mohedano_multicam::tables::{NoiseBoxRow, TrackRow};
use crate::track::cylinders::{Association, CylinderParams, Object2d, OccupancyParams};
use crate::track::graph_match::{Box2d, GraphTracker};

/// The label of an association in the noise tables.
pub(crate) fn association_label(a: Association) -> String {
    format!("{a:?}").to_lowercase()
}

/// The `occupancy` model of the boxes after `noise`: `P_D (1 − drop)`, the jitters added in
/// quadrature, the false boxes added.
pub(crate) fn told(base: &OccupancyParams, noise: &DetectorNoise) -> OccupancyParams {
    OccupancyParams {
        p_detect: base.p_detect * (1.0 - noise.drop),
        jitter: base.jitter.hypot(noise.jitter),
        false_per_frame: base.false_per_frame + noise.false_per_frame,
        ..*base
    }
}

/// Exact boxes per frame and camera, and the 2-D tracker period of their source.
struct Clean {
    boxes: Vec<Vec<Vec<[f64; 4]>>>,
    /// The log's detections go through the camera chain's 2-D tracker (built before the
    /// frame period is known: 0.04 s), the ground-truth boxes through the ground-truth-box
    /// run's (the measured period).
    tracker_dt_s: f64,
}

/// The log's detections of every frame of the main pass (grouped as the pass groups them).
fn log_boxes(
    log: &SessionLog,
    p: &Params,
    t: &Topics,
    views: &[CalibratedView],
    frames: &[FrameRec],
) -> anyhow::Result<Vec<Vec<Vec<[f64; 4]>>>> {
    let tol_ns = (p.sync_tolerance_s * 1e9) as u64;
    let mut out = vec![vec![Vec::new(); views.len()]; frames.len()];
    let mut k = 0;
    for f in multicam::group::<Detection2DArray>(log, &t.detections, tol_ns)? {
        let f = f?;
        // the pass made a frame of every group: the same order, the same stamps
        while k < frames.len() && frames[k].stamp < f.stamp {
            k += 1;
        }
        if k == frames.len() || frames[k].stamp != f.stamp {
            continue;
        }
        for (c, d) in f.cameras.iter().enumerate() {
            if let Some(d) = d {
                out[k][c] = boxes_from_detections(d, box_head(p, &views[c]))
                    .into_iter()
                    .map(|b| b.bbox)
                    .collect();
            }
        }
    }
    Ok(out)
}

fn clean_boxes(
    log: &SessionLog,
    p: &Params,
    t: &Topics,
    views: &[CalibratedView],
    frames: &[FrameRec],
    gt_for_frame: &[Option<&PeopleFrame>],
    dt_s: f64,
) -> anyhow::Result<Clean> {
    if p.detector == Detector::Log {
        return Ok(Clean {
            boxes: log_boxes(log, p, t, views, frames)?,
            tracker_dt_s: 0.04,
        });
    }
    let boxes = gt_for_frame
        .iter()
        .map(|gt| {
            (0..views.len())
                .map(|c| {
                    gt.map(|g| boxes_from_truth(g, &p.cameras[c], box_head(p, &views[c])))
                        .unwrap_or_default()
                        .into_iter()
                        .map(|(_, b)| b.bbox)
                        .collect()
                })
                .collect()
        })
        .collect();
    Ok(Clean {
        boxes,
        tracker_dt_s: dt_s,
    })
}

/// The 2-D objects of every frame, with the 2-D track's smoothed head point and with the box's
/// own (`session::box_head_for_3d`).
#[derive(Default)]
struct Objects {
    smoothed: Vec<Vec<Object2d>>,
    box_head: Vec<Vec<Object2d>>,
}

/// One level's boxes through the 2-D trackers: the 2-D objects of every frame, and the counts.
fn objects_at(
    p: &Params,
    views: &[CalibratedView],
    frames: &[FrameRec],
    clean: &Clean,
    noise: &DetectorNoise,
) -> (Objects, NoiseBoxRow) {
    let mut trackers: Vec<GraphTracker> = views
        .iter()
        .map(|_| GraphTracker::new(graph_params(p, clean.tracker_dt_s)))
        .collect();
    let mut counts = NoiseBoxRow {
        noise: noise.label(),
        clean: 0,
        noisy: 0,
    };
    let mut out = Objects::default();
    for (k, f) in frames.iter().enumerate() {
        let (mut smoothed, mut own_head) = (Vec::new(), Vec::new());
        for (c, tr) in trackers.iter_mut().enumerate() {
            let clean_boxes = &clean.boxes[k][c];
            let cf = CameraFrame {
                view: &views[c],
                camera: c,
                stamp_ns: f.stamp.0,
                room_m: p.room_m,
            };
            let noisy = detector_noise::apply(noise, p.noise_seed, &cf, clean_boxes);
            counts.clean += clean_boxes.len() as i64;
            counts.noisy += noisy.len() as i64;
            let head = box_head(p, &views[c]);
            let boxes: Vec<Box2d> = noisy
                .iter()
                .map(|&b| Box2d {
                    bbox: b,
                    head_px: head.of(b, None),
                    width_px: b[2] - b[0],
                    height_px: b[3] - b[1],
                })
                .collect();
            for o in tr.step(&boxes) {
                let obj = Object2d {
                    camera: c,
                    id: o.id,
                    head_px: o.head_px,
                    width_px: o.width_px,
                    foot_px: Some([(o.bbox[0] + o.bbox[2]) / 2.0, o.bbox[3]]),
                };
                smoothed.push(obj);
                own_head.push(Object2d {
                    head_px: boxes[o.detection].head_px,
                    ..obj
                });
            }
        }
        out.smoothed.push(smoothed);
        out.box_head.push(own_head);
    }
    (out, counts)
}

/// What the noise runs write.
#[derive(Default)]
pub(crate) struct NoiseOut {
    pub tracks: Vec<TrackRow>,
    pub boxes: Vec<NoiseBoxRow>,
}

/// Every level × association (levels in parallel), as rows in that order.
#[allow(clippy::too_many_arguments)]
pub(crate) fn noise_runs(
    log: &SessionLog,
    p: &Params,
    t: &Topics,
    views: &[CalibratedView],
    frames: &[FrameRec],
    gt_for_frame: &[Option<&PeopleFrame>],
    dt_s: f64,
) -> anyhow::Result<NoiseOut> {
    if p.detector_noise.is_empty() || frames.is_empty() {
        return Ok(NoiseOut::default());
    }
    let clean = clean_boxes(log, p, t, views, frames, gt_for_frame, dt_s)?;
    let per_level: Vec<anyhow::Result<(Vec<TrackRow>, NoiseBoxRow)>> = p
        .detector_noise
        .par_iter()
        .map(|noise| {
            let (objects, counts) = objects_at(p, views, frames, &clean, noise);
            let mut rows = Vec::new();
            for &a in &p.noise_associations {
                let params = CylinderParams {
                    association: a,
                    occupancy: told(&p.occupancy, noise),
                    ..cylinder_params(p, dt_s, p.selection, p.n_app)
                };
                let objs = if a == Association::Occupancy {
                    &objects.box_head
                } else {
                    &objects.smoothed
                };
                let r = run_variant(views, params, objs)?;
                let (label, assoc) = (noise.label(), association_label(a));
                let run = Run {
                    detector: &label,
                    selection: &assoc,
                    n_app: p.n_app,
                    cameras: &p.cameras,
                };
                for (k, cyls) in r.tracks.iter().enumerate() {
                    rows.extend(
                        cyls.iter()
                            .map(|c| run.row(k, frames[k].stamp, frames[0].stamp, c)),
                    );
                }
            }
            Ok((rows, counts))
        })
        .collect();
    let mut out = NoiseOut::default();
    for r in per_level {
        let (rows, counts) = r?;
        out.tracks.extend(rows);
        out.boxes.push(counts);
    }
    Ok(out)
}

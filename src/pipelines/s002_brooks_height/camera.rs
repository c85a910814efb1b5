//! Camera sensing of seed 002 §4 on one session: the skin histogram built off-line from the
//! skin-training logs' ground-truth skin masks (never an evaluated session), then per frame
//! background subtraction ([`crate::vision::jabri`]) → moving blobs → skin segmentation
//! ([`crate::vision::skin`]) → the top-fifth person test → bearing and elevation of the head
//! top in the map frame. Run once per plane configuration of §4's scaling claim, timed and
//! scored against the exact person masks; the pipeline's own configuration gives the
//! observations.

use std::path::Path;
use std::time::Instant;

use anyhow::Context;
use image::RgbImage;
use nalgebra::{Isometry3, Point2};

use super::params::{Params, plane_name};
use super::tables::{CameraObsRow, PlanesRow};
use crate::frames::camera::{self as camera_frames, CameraFrame, image_topic};
use crate::frames::truth::Stamped;
use crate::geometry::camera::CameraModel;
use crate::groundtruth::PeopleFrame;
use crate::log::SessionLog;
use crate::vision::jabri::{ColourPlanes, EdgePlanes, JabriBackground, Planes};
use crate::vision::skin::{self, SkinHistogram};

/// Topic of the exact person mask and of the skin mask of `camera`.
pub fn mask_topics(camera: &str) -> (String, String) {
    (
        format!("/{camera}/ground_truth_mask"),
        format!("/{camera}/ground_truth_skin"),
    )
}

/// The skin histogram from every `skin_training_every`-th frame of the training logs of the
/// session at `session`.
pub fn train_skin(p: &Params, session: &Path) -> anyhow::Result<(SkinHistogram, Vec<String>)> {
    let mut hist = SkinHistogram::new(p.skin_bins);
    let mut used = Vec::new();
    let (_, skin_topic) = mask_topics(&p.camera);
    {
        for path in p.training_logs(session) {
            let log = SessionLog::open(&path)?;
            let topic = image_topic(&log, &p.camera).with_context(|| {
                format!("{}: no image topic of camera {}", path.display(), p.camera)
            })?;
            if log.summary().channel(&skin_topic).is_none() {
                anyhow::bail!(
                    "{}: skin training needs {skin_topic} (set skin_mask = true on the camera)",
                    path.display()
                );
            }
            for (k, f) in camera_frames::frames(&log, &topic, Some(&skin_topic))?.enumerate() {
                let f = f?;
                if k % p.skin_training_every == 0
                    && let Some(mask) = &f.mask
                {
                    hist.add(&f.rgb, mask.as_raw());
                }
            }
            used.push(path.display().to_string());
        }
    }
    if hist.pixels == 0 {
        anyhow::bail!(
            "skin_training {:?}: no skin pixels found (no logs, or masks empty)",
            p.skin_training
        );
    }
    Ok((hist, used))
}

/// A frame as the camera stage reads it: image, exact person mask, the person's true head-top
/// pixel (when visible).
pub struct Frame {
    pub stamp_ns: i64,
    pub rgb: RgbImage,
    pub person_mask: Option<Vec<u8>>,
    pub head_px: Option<[f64; 2]>,
    /// The segmented skin mask (255 skin), independent of the background planes.
    pub skin: Vec<u8>,
}

/// Read the camera's frames with their person masks and the ground-truth head pixel.
pub fn read_frames(
    log: &SessionLog,
    p: &Params,
    hist: &SkinHistogram,
    truth: &Stamped<PeopleFrame>,
    tolerance_ns: u64,
) -> anyhow::Result<Vec<Frame>> {
    let topic = image_topic(log, &p.camera).with_context(|| {
        format!(
            "{}: no image topic of camera {}",
            log.path().display(),
            p.camera
        )
    })?;
    let (mask_topic, _) = mask_topics(&p.camera);
    let mask = log
        .summary()
        .channel(&mask_topic)
        .is_some()
        .then_some(mask_topic.as_str());
    let mut out = Vec::new();
    for f in camera_frames::frames(log, &topic, mask)? {
        let CameraFrame {
            stamp, rgb, mask, ..
        } = f?;
        let head_px = truth.nearest(stamp, tolerance_ns).and_then(|g| {
            g.people.first().and_then(|person| {
                person
                    .cameras
                    .iter()
                    .find(|v| v.camera == p.camera && v.visibility > 0.2)
                    .and_then(|v| v.head_px)
            })
        });
        let skin = skin::segment(&rgb, hist, &p.skin()).mask;
        out.push(Frame {
            stamp_ns: i64::try_from(stamp.0).unwrap_or(i64::MAX),
            skin,
            rgb,
            person_mask: mask.map(|m| m.into_raw()),
            head_px,
        });
    }
    Ok(out)
}

/// One detection on a frame (pixels).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Detection {
    pub rect: [u32; 4],
    pub head: [f64; 2],
    pub skin_fraction: f64,
}

/// Background subtraction and the person test on one frame (its skin mask already
/// segmented): the motion mask and the person detections.
pub fn detect(
    bg: &mut JabriBackground,
    p: &Params,
    f: &Frame,
) -> anyhow::Result<(Vec<u8>, Vec<Detection>)> {
    let (w, h) = (f.rgb.width() as usize, f.rgb.height() as usize);
    let motion = bg.apply(&f.rgb)?;
    let rects = bg.blobs(&motion, w, h)?;
    let detections = rects
        .into_iter()
        .filter_map(|rect| {
            let (fraction, top) = skin::head_top(rect, &f.skin, w, p.min_skin_fraction);
            top.map(|head| Detection {
                rect,
                head,
                skin_fraction: fraction,
            })
        })
        .collect();
    Ok((motion, detections))
}

/// Bearing and elevation (map frame, from the camera centre) of the ray through pixel `px`.
pub fn angles(
    model: &CameraModel,
    world_from_camera: &Isometry3<f64>,
    px: [f64; 2],
) -> Option<[f64; 2]> {
    let ray = model.ray(&Point2::new(px[0], px[1]))?;
    let d = world_from_camera.rotation * ray.dir;
    Some([d.y.atan2(d.x), d.z.atan2(d.x.hypot(d.y))])
}

/// The tracking run's observations: every person detection after warm-up, in frame order.
pub fn observations(
    frames: &[Frame],
    p: &Params,
    model: &CameraModel,
    world_from_camera: &Isometry3<f64>,
) -> anyhow::Result<Vec<CameraObsRow>> {
    let planes = Planes {
        colour: p.colour,
        edges: p.edges,
    };
    let mut bg = JabriBackground::new(planes, p.jabri());
    let c = world_from_camera.translation.vector;
    let mut out = Vec::new();
    for (k, f) in frames.iter().enumerate() {
        let (_, detections) = detect(&mut bg, p, f)?;
        if k < p.warmup_frames {
            continue;
        }
        for d in detections {
            let Some([b, e]) = angles(model, world_from_camera, d.head) else {
                continue;
            };
            out.push(CameraObsRow {
                frame_idx: k as i64,
                stamp_ns: f.stamp_ns,
                bearing_rad: b,
                elevation_rad: e,
                cam_x: c.x,
                cam_y: c.y,
                cam_z: c.z,
                u: d.head[0],
                v: d.head[1],
                x0: i64::from(d.rect[0]),
                y0: i64::from(d.rect[1]),
                x1: i64::from(d.rect[2]),
                y1: i64::from(d.rect[3]),
                skin_fraction: d.skin_fraction,
            });
        }
    }
    Ok(out)
}

/// Largest distance (px) of a detected head top from the true one that counts as the person.
pub const HEAD_MATCH_PX: f64 = 20.0;

/// §4's scaling claim on one session: each plane configuration's background-subtraction time
/// per frame (the Jabri update alone, one thread) and detection quality after warm-up.
pub fn plane_grid(frames: &[Frame], p: &Params) -> anyhow::Result<Vec<PlanesRow>> {
    let mut rows = Vec::new();
    for (colour, edges) in super::params::PLANE_GRID {
        rows.push(plane_row(frames, p, colour, edges)?);
    }
    Ok(rows)
}

fn plane_row(
    frames: &[Frame],
    p: &Params,
    colour: ColourPlanes,
    edges: EdgePlanes,
) -> anyhow::Result<PlanesRow> {
    let planes = Planes { colour, edges };
    let mut bg = JabriBackground::new(planes, p.jabri());
    let (mut tp, mut fp, mut fneg) = (0u64, 0u64, 0u64);
    let (mut person_frames, mut detected, mut false_det) = (0i64, 0i64, 0i64);
    let (mut err_sum, mut err_n) = (0.0f64, 0u64);
    let mut secs = 0.0f64;
    let mut timed = 0i64;
    for (k, f) in frames.iter().enumerate() {
        let start = Instant::now();
        let motion = bg.apply(&f.rgb)?;
        let dt = start.elapsed().as_secs_f64();
        if k < p.warmup_frames {
            continue;
        }
        secs += dt;
        timed += 1;
        if let Some(m) = &f.person_mask {
            for (a, b) in motion.iter().zip(m) {
                match (*a != 0, *b != 0) {
                    (true, true) => tp += 1,
                    (true, false) => fp += 1,
                    (false, true) => fneg += 1,
                    _ => {}
                }
            }
        }
        let (w, h) = (f.rgb.width() as usize, f.rgb.height() as usize);
        let heads: Vec<[f64; 2]> = bg
            .blobs(&motion, w, h)?
            .into_iter()
            .filter_map(|rect| skin::head_top(rect, &f.skin, w, p.min_skin_fraction).1)
            .collect();
        let dist = |a: &[f64; 2], b: &[f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
        match f.head_px {
            Some(truth) => {
                person_frames += 1;
                let best = heads
                    .iter()
                    .map(|h| dist(h, &truth))
                    .fold(f64::INFINITY, f64::min);
                if best <= HEAD_MATCH_PX {
                    detected += 1;
                    err_sum += best;
                    err_n += 1;
                }
                false_det += heads
                    .iter()
                    .filter(|h| dist(h, &truth) > HEAD_MATCH_PX)
                    .count() as i64;
            }
            None => false_det += heads.len() as i64,
        }
    }
    let ratio = |a: u64, b: u64| if b == 0 { 0.0 } else { a as f64 / b as f64 };
    let precision = ratio(tp, tp + fp);
    let recall = ratio(tp, tp + fneg);
    let f1 = if precision + recall > 0.0 {
        2.0 * precision * recall / (precision + recall)
    } else {
        0.0
    };
    Ok(PlanesRow {
        config: plane_name(colour, edges),
        planes: planes.count() as i64,
        frames: timed,
        ms_per_frame: if timed > 0 {
            1e3 * secs / timed as f64
        } else {
            0.0
        },
        precision,
        recall,
        f1,
        person_frames,
        detected_frames: detected,
        false_detections: false_det,
        head_err_px: (err_n > 0).then(|| err_sum / err_n as f64),
    })
}

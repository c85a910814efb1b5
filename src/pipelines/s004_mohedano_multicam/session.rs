//! One session: calibration, the per-camera image stages, the 3-D runs, and the per-session
//! tables the aggregation reads.

// Tables are built column by column in tuples of vectors, one per column.
#![allow(clippy::type_complexity)]

use crate::geometry::rect::iou;
use std::collections::BTreeMap;
use std::path::Path;

use crate::progress::Progress;
use anyhow::{Context, bail};
use image::RgbImage;
use nalgebra::{Point2, Point3};
use polars::prelude::*;
use rayon::prelude::*;

use super::{BackgroundUpdate, Detector, Params, Topics};
use crate::geometry::triangulate::{CalibratedView, triangulate_dlt};
use crate::groundtruth::PeopleFrame;
use crate::log::msgs::{CameraInfo, CompressedImage, Detection2DArray, Image};
use crate::log::{Decoders, Message, SessionLog, TfBuffer, read_topic};
use crate::run::{Session, SessionTables};
use crate::time::Nanos;
use crate::track::cylinders::{self, Cylinder, CylinderParams, CylinderTracker, Selection};
use crate::track::graph_match::{Box2d, GraphParams, GraphTracker};
use crate::vision::gabor::{GaborBackground, GaborBank, GaborParams, Mask, Update};
use crate::vision::template::{self, Detection, DetectorParams, Silhouette};

/// Label of each source of 2-D objects in the tables.
pub(crate) const TEMPLATES: &str = "templates";
pub(crate) const GT_BOXES: &str = "gt_boxes";
pub(crate) const LOG: &str = "log";

pub(crate) fn selection_label(s: Selection) -> &'static str {
    match s {
        Selection::Corrected => "E_c",
        Selection::Mean => "E_m",
    }
}

pub(crate) fn main_detector(p: &Params) -> &'static str {
    match p.detector {
        Detector::Templates => TEMPLATES,
        Detector::Log => LOG,
    }
}

/// The cameras of one session with their calibration.
#[derive(Debug, Clone)]
pub(crate) struct Calibration {
    pub views: Vec<CalibratedView>,
}

/// Read each camera's first `CameraInfo` and its pose in the world frame from TF.
pub(crate) fn read_calibration(
    log: &SessionLog,
    p: &Params,
    t: &Topics,
) -> anyhow::Result<Calibration> {
    let file = log.path().display().to_string();
    let tf = TfBuffer::from_log(log, 0.0)?;
    let mut views = Vec::new();
    for (cam, topic) in p.cameras.iter().zip(&t.info) {
        let (_, info) = read_topic::<CameraInfo>(log, topic)?
            .next()
            .with_context(|| format!("{file}: no CameraInfo on {topic}"))??;
        let model = info
            .model()
            .with_context(|| format!("{file}: {topic}: camera {cam}"))?;
        let frame = if info.header.frame_id.is_empty() {
            cam.clone()
        } else {
            info.header.frame_id.clone()
        };
        let at = info.header.stamp.nanos().unwrap_or(Nanos(0));
        let world_from_camera = tf.lookup(&p.world_frame, &frame, at).with_context(|| {
            format!(
                "{file}: no transform {} <- {frame} (camera {cam}) at {:.3} s",
                p.world_frame,
                at.0 as f64 * 1e-9
            )
        })?;
        views.push(CalibratedView::new(model, world_from_camera));
    }
    Ok(Calibration { views })
}

/// What one camera contributes to one frame.
enum Payload {
    Compressed(CompressedImage),
    Raw(Image),
    Detections(Detection2DArray),
}

fn decode_image(p: &Payload) -> Option<Result<RgbImage, String>> {
    match p {
        Payload::Compressed(c) => Some(
            crate::log::image::decode_compressed(c)
                .map(|i| i.to_rgb8())
                .map_err(|e| e.to_string()),
        ),
        Payload::Raw(r) => Some(
            crate::log::image::decode_raw(r)
                .map(|i| i.to_rgb8())
                .map_err(|e| e.to_string()),
        ),
        Payload::Detections(_) => None,
    }
}

/// Per-camera state of the paper's image chain.
struct CameraChain {
    background: GaborBackground,
    mask: Mask,
    templates: Vec<Silhouette>,
    /// The template tried at each head position (`templates_by_position`).
    map: Option<template::TemplateMap>,
    tracker: GraphTracker,
}

/// One camera's output for one frame.
#[derive(Default)]
struct CameraOut {
    threshold: f64,
    foreground_frac: f64,
    detections: Vec<Detection>,
    objects: Vec<cylinders::Object2d>,
    failed: Option<String>,
    present: bool,
}

/// Everything kept of one frame.
struct FrameRec {
    stamp: Nanos,
    /// 2-D objects per source (templates or log detections), all cameras.
    objects: Vec<cylinders::Object2d>,
    /// Template detections per camera (for head vs centroid).
    detections: Vec<Vec<Detection>>,
}

fn graph_params(p: &Params, dt_s: f64) -> GraphParams {
    GraphParams {
        min_iou: p.match_iou_2d,
        max_missed: p.max_missed_2d,
        dt_s,
        ..GraphParams::default()
    }
}

pub(crate) fn cylinder_params(
    p: &Params,
    dt_s: f64,
    selection: Selection,
    n_app: u32,
) -> CylinderParams {
    CylinderParams {
        p_th_px: p.p_th_px,
        n_app,
        // the paper: N_dis = N_app is a reasonable choice; the sweep keeps them equal
        n_dis: if n_app == p.n_app { p.n_dis } else { n_app },
        selection,
        head_height_m: (p.head_height_m[0], p.head_height_m[1]),
        room_m: p.room_m,
        room_margin_m: p.room_margin_m,
        gate_m: p.gate_m,
        max_combinations: p.max_combinations,
        dt_s,
        ..CylinderParams::default()
    }
}

fn stamp_of(m: &Message, header: Option<Nanos>) -> Nanos {
    header.filter(|s| s.0 > 0).unwrap_or(m.log_time)
}

/// Where the head point of a box comes from.
#[derive(Clone, Copy)]
enum BoxHead<'a> {
    /// The top centre of the box.
    TopCentre,
    /// [`cylinders::box_head_px`]: the top row on the image of the person's vertical.
    Axis(&'a CalibratedView, f64),
    /// The ground truth's projected head top where the log has it (evaluation only).
    Truth,
}

impl BoxHead<'_> {
    fn of(self, b: [f64; 4], truth: Option<[f64; 2]>) -> [f64; 2] {
        let top_centre = [(b[0] + b[2]) / 2.0, b[1]];
        match self {
            BoxHead::TopCentre => top_centre,
            BoxHead::Axis(view, z) => cylinders::box_head_px(view, b, z).unwrap_or(top_centre),
            BoxHead::Truth => truth.unwrap_or(top_centre),
        }
    }
}

/// How the main run and the ground-truth-box run turn a box into a head point.
fn box_head<'a>(p: &Params, view: &'a CalibratedView) -> BoxHead<'a> {
    if p.box_head_on_axis {
        BoxHead::Axis(view, 0.5 * p.person_height_m)
    } else {
        BoxHead::TopCentre
    }
}

/// Boxes of one camera from a `Detection2DArray`.
fn boxes_from_detections(d: &Detection2DArray, head: BoxHead) -> Vec<Box2d> {
    d.detections
        .iter()
        .filter(|x| {
            [x.center_x, x.center_y, x.size_x, x.size_y]
                .iter()
                .all(|v| v.is_finite())
                && x.size_x > 0.0
                && x.size_y > 0.0
        })
        .map(|x| {
            let (x0, y0) = (x.center_x - x.size_x / 2.0, x.center_y - x.size_y / 2.0);
            let bbox = [x0, y0, x0 + x.size_x, y0 + x.size_y];
            Box2d {
                bbox,
                head_px: head.of(bbox, None),
                width_px: x.size_x,
                height_px: x.size_y,
            }
        })
        .collect()
}

/// Boxes of one camera from the ground truth: the visible box and its head point.
fn boxes_from_truth(gt: &PeopleFrame, camera: &str, head: BoxHead) -> Vec<(u32, Box2d)> {
    let mut out = Vec::new();
    for person in &gt.people {
        for v in person.cameras.iter().filter(|v| v.camera == camera) {
            let Some(b) = v.bbox else { continue };
            if b[3] - b[1] < 8.0 || b[2] - b[0] < 2.0 {
                continue;
            }
            out.push((
                person.id,
                Box2d {
                    bbox: b,
                    head_px: head.of(b, v.head_px),
                    width_px: b[2] - b[0],
                    height_px: b[3] - b[1],
                },
            ));
        }
    }
    out
}

fn nearest_truth(truth: &[(Nanos, PeopleFrame)], t: Nanos, tol_ns: u64) -> Option<&PeopleFrame> {
    let stamps: Vec<Nanos> = truth.iter().map(|x| x.0).collect();
    crate::log::sync::nearest(&stamps, t, tol_ns).map(|i| &truth[i].1)
}

/// Rows of the per-variant track table.
#[derive(Default)]
struct TrackCols {
    detector: Vec<String>,
    selection: Vec<String>,
    n_app: Vec<i64>,
    frame: Vec<i64>,
    stamp_ns: Vec<i64>,
    t_s: Vec<f64>,
    id: Vec<i64>,
    x_m: Vec<f64>,
    y_m: Vec<f64>,
    vx_mps: Vec<f64>,
    vy_mps: Vec<f64>,
    height_m: Vec<f64>,
    radius_m: Vec<f64>,
    cameras: Vec<i64>,
    support: Vec<String>,
    e_m_px: Vec<Option<f64>>,
    meas_x_m: Vec<Option<f64>>,
    meas_y_m: Vec<Option<f64>>,
    meas_height_m: Vec<Option<f64>>,
    meas_radius_m: Vec<Option<f64>>,
}

struct VariantOut {
    tracks: Vec<(usize, Vec<Cylinder>)>,
    combinations: usize,
    pruned_frames: usize,
    promoted: usize,
    discarded: usize,
}

fn run_variant(
    views: &[CalibratedView],
    params: CylinderParams,
    frames: &[Vec<cylinders::Object2d>],
) -> anyhow::Result<VariantOut> {
    let mut tracker = CylinderTracker::new(views.to_vec(), params)?;
    let mut out = VariantOut {
        tracks: Vec::with_capacity(frames.len()),
        combinations: 0,
        pruned_frames: 0,
        promoted: 0,
        discarded: 0,
    };
    for (k, objs) in frames.iter().enumerate() {
        let (cyl, stats) = tracker.step(objs);
        out.combinations += stats.combinations;
        out.pruned_frames += usize::from(stats.pruned);
        out.promoted += stats.promoted;
        out.discarded += stats.discarded;
        out.tracks.push((k, cyl));
    }
    Ok(out)
}

/// Ground error of triangulating each person's head points and blob centroids in the cameras
/// where a detection is associated with them (box overlap with the ground truth ≥ 0.25).
#[derive(Default)]
struct HeadCentroidCols {
    detector: Vec<String>,
    frame: Vec<i64>,
    id: Vec<i64>,
    cameras: Vec<i64>,
    occluded: Vec<bool>,
    clear: Vec<bool>,
    min_visibility: Vec<f64>,
    head_error_m: Vec<f64>,
    centroid_error_m: Vec<f64>,
}

/// A template detection matches a ground-truth person when its head point is within this many
/// visible-box widths of the person's projected head top.
pub(crate) const DETECTION_HEAD_TOL: f64 = 0.5;

/// Template detections scored against the visible ground-truth boxes, one row per frame and
/// camera; head offsets and height ratios are sums over the matched pairs.
#[derive(Default)]
struct Det2dCols {
    frame: Vec<i64>,
    camera: Vec<String>,
    truth: Vec<i64>,
    detections: Vec<i64>,
    matched: Vec<i64>,
    head_dx_abs: Vec<f64>,
    head_dy: Vec<f64>,
    height_ratio: Vec<f64>,
}

impl Det2dCols {
    /// Greedy one-to-one matching by increasing head distance: a detection's head point must
    /// lie within `head_tol` visible-box widths of the truth's head point (the point the 3-D
    /// stage triangulates; IoU would punish the full-body template box of a person whose legs
    /// a desk hides).
    fn push(
        &mut self,
        frame: usize,
        camera: &str,
        truth: &[Box2d],
        dets: &[Detection],
        head_tol: f64,
    ) {
        let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
        for (i, t) in truth.iter().enumerate() {
            for (j, d) in dets.iter().enumerate() {
                let dist = (d.head_px[0] - t.head_px[0]).hypot(d.head_px[1] - t.head_px[1]);
                if dist <= head_tol * t.width_px {
                    pairs.push((dist, i, j));
                }
            }
        }
        pairs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
        let (mut used_t, mut used_d) = (vec![false; truth.len()], vec![false; dets.len()]);
        let (mut n, mut dx, mut dy, mut hr) = (0i64, 0.0, 0.0, 0.0);
        for (_, i, j) in pairs {
            if used_t[i] || used_d[j] {
                continue;
            }
            used_t[i] = true;
            used_d[j] = true;
            n += 1;
            dx += (dets[j].head_px[0] - truth[i].head_px[0]).abs();
            dy += dets[j].head_px[1] - truth[i].head_px[1];
            hr += dets[j].height_px / truth[i].height_px.max(1.0);
        }
        self.frame.push(frame as i64);
        self.camera.push(camera.to_string());
        self.truth.push(truth.len() as i64);
        self.detections.push(dets.len() as i64);
        self.matched.push(n);
        self.head_dx_abs.push(dx);
        self.head_dy.push(dy);
        self.height_ratio.push(hr);
    }
}

/// `(head, centroid)` per person and camera, associated greedily by IoU with the truth.
#[allow(clippy::too_many_arguments)]
fn head_centroid_frame(
    cols: &mut HeadCentroidCols,
    detector: &str,
    frame: usize,
    gt: &PeopleFrame,
    cameras: &[String],
    views: &[CalibratedView],
    per_camera: &[Vec<([f64; 4], [f64; 2], [f64; 2])>],
    occluded_visibility: f64,
) {
    // per person: (camera, head, centroid, visibility, statically occluded)
    let mut assoc: BTreeMap<u32, Vec<(usize, [f64; 2], [f64; 2], f64, bool)>> = BTreeMap::new();
    for (c, cam) in cameras.iter().enumerate() {
        let Some(dets) = per_camera.get(c) else {
            continue;
        };
        let mut pairs = Vec::new();
        for person in &gt.people {
            let Some(view) = person.cameras.iter().find(|v| &v.camera == cam) else {
                continue;
            };
            let Some(b) = view.bbox else { continue };
            for (j, d) in dets.iter().enumerate() {
                let o = iou(&b, &d.0);
                if o >= 0.25 {
                    pairs.push((o, person.id, j, view.visibility, b));
                }
            }
        }
        pairs.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
        let (mut used_p, mut used_d) = (Vec::new(), Vec::new());
        for (_, id, j, vis, b) in pairs {
            if used_p.contains(&id) || used_d.contains(&j) {
                continue;
            }
            used_p.push(id);
            used_d.push(j);
            // static occlusion: partly hidden, and no other person's box overlaps this one
            let others_overlap = gt.people.iter().filter(|q| q.id != id).any(|q| {
                q.cameras
                    .iter()
                    .filter(|v| &v.camera == cam)
                    .any(|v| v.bbox.is_some_and(|ob| iou(&ob, &b) > 0.0))
            });
            let occluded = vis < occluded_visibility && !others_overlap;
            assoc
                .entry(id)
                .or_default()
                .push((c, dets[j].1, dets[j].2, vis, occluded));
        }
    }
    for person in &gt.people {
        let Some(list) = assoc.get(&person.id) else {
            continue;
        };
        if list.len() < 2 {
            continue;
        }
        let heads: Vec<(&CalibratedView, Point2<f64>)> = list
            .iter()
            .map(|(c, h, _, _, _)| (&views[*c], Point2::new(h[0], h[1])))
            .collect();
        let cents: Vec<(&CalibratedView, Point2<f64>)> = list
            .iter()
            .map(|(c, _, m, _, _)| (&views[*c], Point2::new(m[0], m[1])))
            .collect();
        let (Ok(h), Ok(m)) = (triangulate_dlt(&heads), triangulate_dlt(&cents)) else {
            continue;
        };
        let err = |p: Point3<f64>| (p.x - person.x).hypot(p.y - person.y);
        cols.detector.push(detector.to_string());
        cols.frame.push(frame as i64);
        cols.id.push(i64::from(person.id));
        cols.cameras.push(list.len() as i64);
        cols.occluded.push(list.iter().any(|x| x.4));
        cols.clear.push(list.iter().all(|x| x.3 >= 0.95));
        cols.min_visibility
            .push(list.iter().map(|x| x.3).fold(f64::INFINITY, f64::min));
        cols.head_error_m.push(err(h));
        cols.centroid_error_m.push(err(m));
    }
}

/// Up to `n` images per camera topic, evenly spread over the log (the message counts of the
/// summary pick which), for [`GaborBackground::bootstrap`]. Undecodable ones are skipped here:
/// the main pass counts and reports them.
fn bootstrap_images(
    log: &SessionLog,
    topics: &[String],
    n: usize,
) -> anyhow::Result<Vec<Vec<RgbImage>>> {
    let mut out: Vec<Vec<RgbImage>> = vec![Vec::new(); topics.len()];
    if n == 0 {
        return Ok(out);
    }
    let counts: Vec<u64> = topics
        .iter()
        .map(|tp| {
            let ch = log.summary().channel(tp);
            log.summary()
                .statistics
                .as_ref()
                .zip(ch)
                .and_then(|(st, ch)| st.channel_message_counts.get(&ch.id).copied())
                .unwrap_or(0)
        })
        .collect();
    let present: Vec<&str> = topics
        .iter()
        .map(String::as_str)
        .filter(|tp| log.summary().channel(tp).is_some())
        .collect();
    if present.is_empty() {
        return Ok(out);
    }
    let mut seen = vec![0u64; topics.len()];
    let mut decoders = Decoders::new();
    for m in log.messages_on(&present)? {
        let m = m?;
        let Some(c) = topics.iter().position(|tp| tp == m.topic()) else {
            continue;
        };
        let k = seen[c];
        seen[c] += 1;
        // message k is taken when it is the first at or after j · count / n for some j
        let step = (counts[c] / n as u64).max(1);
        if !k.is_multiple_of(step) || out[c].len() >= n {
            continue;
        }
        let payload = match m.channel.schema_name() {
            "sensor_msgs/msg/Image" | "foxglove.RawImage" => {
                decoders.typed::<Image>(log, &m).map(Payload::Raw)
            }
            _ => decoders
                .typed::<CompressedImage>(log, &m)
                .map(Payload::Compressed),
        };
        if let Ok(p) = payload
            && let Some(Ok(rgb)) = decode_image(&p)
        {
            out[c].push(rgb);
        }
    }
    Ok(out)
}

pub(crate) fn process(
    s: &Session,
    p: &Params,
    t: &Topics,
    bar: &dyn Progress,
) -> anyhow::Result<SessionTables> {
    let log = &s.log;
    let file = log.path().display().to_string();
    let calib = read_calibration(log, p, t)?;
    let n_cams = p.cameras.len();
    let use_images = p.detector == Detector::Templates;
    let has_gt = log.summary().channel(&t.ground_truth).is_some();

    // per-camera chains (templates detector)
    let bank = GaborBank::new(GaborParams {
        sigma_px: p.gabor_sigma_px,
        wavelength_px: p.gabor_wavelength_px,
    })?;
    let det_params = DetectorParams {
        threshold: p.template_threshold,
        stride_px: p.template_stride_px,
        nms_iou: p.nms_iou,
        nms_contained: p.nms_contained,
        ..DetectorParams::default()
    };
    let boot = if use_images {
        bar.set_message("background bootstrap");
        bootstrap_images(log, &t.image, p.bootstrap_frames)?
    } else {
        Vec::new()
    };
    let mut chains: Vec<CameraChain> = Vec::with_capacity(n_cams);
    for (c, view) in calib.views.iter().enumerate() {
        let templates = if use_images {
            template::calibrated_templates(
                view,
                p.room_m,
                p.person_height_m,
                p.template_scales,
                p.template_tilts,
            )
            .with_context(|| format!("{file}: templates of camera {}", p.cameras[c]))?
            .into_iter()
            .map(|t| t.padded(p.template_fill))
            .collect()
        } else {
            Vec::new()
        };
        let update = match p.background_update {
            BackgroundUpdate::All => Update::All,
            BackgroundUpdate::Selective => Update::Selective {
                foreground_alpha: p.foreground_alpha,
                dilate_px: bank.radius() as u32,
            },
        };
        let mut background =
            GaborBackground::new(bank.clone(), p.alpha, p.mad_k)?.with_update(update)?;
        if let Some(frames) = boot.get(c)
            && !frames.is_empty()
        {
            background.bootstrap(frames).with_context(|| {
                format!("{file}: background bootstrap of camera {}", p.cameras[c])
            })?;
        }
        let map = (use_images && p.templates_by_position).then(|| {
            template::TemplateMap::new(
                view,
                &templates,
                p.person_height_m,
                p.room_m,
                p.room_margin_m,
            )
        });
        chains.push(CameraChain {
            map,
            background,
            mask: Mask::default(),
            templates,
            tracker: GraphTracker::new(graph_params(p, 0.04)),
        });
    }

    // which topic is what
    let primary: &[String] = if use_images { &t.image } else { &t.detections };
    let mut role: BTreeMap<&str, usize> = BTreeMap::new();
    for (c, topic) in primary.iter().enumerate() {
        role.insert(topic.as_str(), c);
    }
    let mut topic_list: Vec<&str> = primary.iter().map(String::as_str).collect();
    if has_gt {
        topic_list.push(t.ground_truth.as_str());
    }
    let expected = primary
        .iter()
        .filter_map(|tp| log.summary().channel(tp).map(|_| tp))
        .count()
        .max(1);
    let total_msgs: u64 = log
        .summary()
        .statistics
        .as_ref()
        .map(|st| {
            primary
                .iter()
                .filter_map(|tp| log.summary().channel(tp))
                .map(|ch| st.channel_message_counts.get(&ch.id).copied().unwrap_or(0))
                .sum()
        })
        .unwrap_or(0);
    bar.set_length((total_msgs / expected as u64).max(1));
    bar.set_message("frames");

    let tol_ns = (p.sync_tolerance_s * 1e9) as u64;
    let mut decoders = Decoders::new();
    let mut truth: Vec<(Nanos, PeopleFrame)> = Vec::new();
    let mut bad_truth = 0usize;
    let mut decode_failures = 0usize;
    let mut missing_camera_frames = 0usize;
    let mut frames: Vec<FrameRec> = Vec::new();
    let mut cam_rows: (
        Vec<i64>,
        Vec<String>,
        Vec<f64>,
        Vec<f64>,
        Vec<i64>,
        Vec<i64>,
    ) = Default::default();
    let mut pending: Vec<Option<Payload>> = (0..n_cams).map(|_| None).collect();
    let mut pending_stamp: Option<Nanos> = None;
    let mut first_error: Option<String> = None;

    // process one assembled frame
    let flush = |pending: &mut Vec<Option<Payload>>,
                 stamp: Nanos,
                 chains: &mut Vec<CameraChain>,
                 frames: &mut Vec<FrameRec>,
                 cam_rows: &mut (
        Vec<i64>,
        Vec<String>,
        Vec<f64>,
        Vec<f64>,
        Vec<i64>,
        Vec<i64>,
    ),
                 decode_failures: &mut usize,
                 missing: &mut usize,
                 first_error: &mut Option<String>| {
        let payloads: Vec<Option<Payload>> = pending.iter_mut().map(Option::take).collect();
        let outs: Vec<CameraOut> = chains
            .par_iter_mut()
            .zip(payloads.into_par_iter())
            .enumerate()
            .map(|(c, (chain, payload))| {
                let mut out = CameraOut::default();
                let boxes: Vec<Box2d> = match payload {
                    None => Vec::new(),
                    Some(Payload::Detections(d)) => {
                        out.present = true;
                        boxes_from_detections(&d, box_head(p, &calib.views[c]))
                    }
                    Some(img) => {
                        out.present = true;
                        match decode_image(&img) {
                            Some(Ok(rgb)) => match chain.background.apply(&rgb, &mut chain.mask) {
                                Ok(seg) => {
                                    out.threshold = seg.threshold;
                                    out.foreground_frac = seg.foreground as f64
                                        / (f64::from(rgb.width()) * f64::from(rgb.height()));
                                    out.detections = template::detect_with(
                                        &chain.mask,
                                        &chain.templates,
                                        chain.map.as_ref(),
                                        &det_params,
                                    );
                                    out.detections
                                        .iter()
                                        .map(|d| Box2d {
                                            bbox: d.bbox,
                                            head_px: d.head_px,
                                            width_px: d.width_px,
                                            height_px: d.height_px,
                                        })
                                        .collect()
                                }
                                Err(e) => {
                                    out.failed = Some(e.to_string());
                                    Vec::new()
                                }
                            },
                            Some(Err(e)) => {
                                out.failed = Some(e);
                                Vec::new()
                            }
                            None => Vec::new(),
                        }
                    }
                };
                out.objects = chain
                    .tracker
                    .step(&boxes)
                    .into_iter()
                    .map(|o| cylinders::Object2d {
                        camera: c,
                        id: o.id,
                        head_px: o.head_px,
                        width_px: o.width_px,
                    })
                    .collect();
                out
            })
            .collect();
        let k = frames.len() as i64;
        let mut objects = Vec::new();
        let mut detections = Vec::with_capacity(outs.len());
        for (c, o) in outs.into_iter().enumerate() {
            if !o.present {
                *missing += 1;
            }
            if let Some(e) = o.failed {
                *decode_failures += 1;
                if first_error.is_none() {
                    *first_error =
                        Some(format!("camera {c} at {:.3} s: {e}", stamp.0 as f64 * 1e-9));
                }
            }
            if use_images {
                cam_rows.0.push(k);
                cam_rows.1.push(p.cameras[c].clone());
                cam_rows.2.push(o.threshold);
                cam_rows.3.push(o.foreground_frac);
                cam_rows.4.push(o.detections.len() as i64);
                cam_rows.5.push(o.objects.len() as i64);
            }
            objects.extend(o.objects);
            detections.push(o.detections);
        }
        frames.push(FrameRec {
            stamp,
            objects,
            detections,
        });
    };

    for m in log.messages_on(&topic_list)? {
        let m = m?;
        if m.topic() == t.ground_truth {
            match serde_json::from_slice::<PeopleFrame>(&m.data) {
                Ok(f) => truth.push((Nanos(f.stamp_ns), f)),
                Err(_) => bad_truth += 1, // counted and reported, not fatal
            }
            continue;
        }
        let Some(&c) = role.get(m.topic()) else {
            continue;
        };
        let decoded = if use_images {
            match m.channel.schema_name() {
                "sensor_msgs/msg/Image" | "foxglove.RawImage" => decoders
                    .typed::<Image>(log, &m)
                    .map(|i| (stamp_of(&m, i.header.stamp.nanos()), Payload::Raw(i))),
                _ => decoders
                    .typed::<CompressedImage>(log, &m)
                    .map(|i| (stamp_of(&m, i.header.stamp.nanos()), Payload::Compressed(i))),
            }
        } else {
            decoders
                .typed::<Detection2DArray>(log, &m)
                .map(|d| (stamp_of(&m, d.header.stamp.nanos()), Payload::Detections(d)))
        };
        let (stamp, payload) = match decoded {
            Ok(x) => x,
            Err(e) => {
                decode_failures += 1;
                if first_error.is_none() {
                    first_error = Some(e.to_string());
                }
                continue;
            }
        };
        if let Some(ps) = pending_stamp
            && (stamp.0.abs_diff(ps.0) > tol_ns || pending[c].is_some())
        {
            flush(
                &mut pending,
                ps,
                &mut chains,
                &mut frames,
                &mut cam_rows,
                &mut decode_failures,
                &mut missing_camera_frames,
                &mut first_error,
            );
            bar.inc(1);
            pending_stamp = None;
        }
        pending_stamp.get_or_insert(stamp);
        pending[c] = Some(payload);
    }
    if let Some(ps) = pending_stamp {
        flush(
            &mut pending,
            ps,
            &mut chains,
            &mut frames,
            &mut cam_rows,
            &mut decode_failures,
            &mut missing_camera_frames,
            &mut first_error,
        );
    }
    if frames.is_empty() {
        bail!("{file}: no frames on {}", primary.join(", "));
    }
    truth.sort_by_key(|x| x.0);

    // frame period from the stamps (median), for the filters
    let mut periods: Vec<f64> = frames
        .windows(2)
        .map(|w| (w[1].stamp.0.saturating_sub(w[0].stamp.0)) as f64 * 1e-9)
        .filter(|d| *d > 0.0)
        .collect();
    periods.sort_by(f64::total_cmp);
    let dt_s = periods.get(periods.len() / 2).copied().unwrap_or(0.04);
    let t0 = frames[0].stamp;

    // sources of 2-D objects for the 3-D stage
    let mut sources: Vec<(&'static str, Vec<Vec<cylinders::Object2d>>)> = vec![(
        main_detector(p),
        frames.iter().map(|f| f.objects.clone()).collect(),
    )];
    let gt_for_frame: Vec<Option<&PeopleFrame>> = frames
        .iter()
        .map(|f| nearest_truth(&truth, f.stamp, tol_ns.max(1)))
        .collect();
    let mut gt_box_frames: Vec<Vec<([f64; 4], [f64; 2], [f64; 2])>> = Vec::new();
    let mut gt_box_cam_frames: Vec<Vec<Vec<([f64; 4], [f64; 2], [f64; 2])>>> = Vec::new();
    if p.gt_boxes && !truth.is_empty() {
        let mut trackers: Vec<GraphTracker> = (0..n_cams)
            .map(|_| GraphTracker::new(graph_params(p, dt_s)))
            .collect();
        let mut per_frame = Vec::with_capacity(frames.len());
        for gt in &gt_for_frame {
            let mut objs = Vec::new();
            let mut cams = Vec::with_capacity(n_cams);
            for (c, tr) in trackers.iter_mut().enumerate() {
                let boxes: Vec<Box2d> = gt
                    .map(|g| boxes_from_truth(g, &p.cameras[c], box_head(p, &calib.views[c])))
                    .unwrap_or_default()
                    .into_iter()
                    .map(|(_, b)| b)
                    .collect();
                cams.push(
                    boxes
                        .iter()
                        .map(|b| {
                            (
                                b.bbox,
                                b.head_px,
                                [(b.bbox[0] + b.bbox[2]) / 2.0, (b.bbox[1] + b.bbox[3]) / 2.0],
                            )
                        })
                        .collect(),
                );
                objs.extend(tr.step(&boxes).into_iter().map(|o| cylinders::Object2d {
                    camera: c,
                    id: o.id,
                    head_px: o.head_px,
                    width_px: o.width_px,
                }));
            }
            per_frame.push(objs);
            gt_box_cam_frames.push(cams);
        }
        gt_box_frames.clear();
        sources.push((GT_BOXES, per_frame));
    }
    let _ = gt_box_frames;

    // the 3-D runs: configured, N_app sweep, the other selection rule
    let other = match p.selection {
        Selection::Corrected => Selection::Mean,
        Selection::Mean => Selection::Corrected,
    };
    let mut n_apps: Vec<u32> = p.n_app_sweep.clone();
    n_apps.push(p.n_app);
    n_apps.sort_unstable();
    n_apps.dedup();
    let mut variants: Vec<(usize, Selection, u32)> = Vec::new();
    for si in 0..sources.len() {
        for &n in &n_apps {
            variants.push((si, p.selection, n));
        }
        variants.push((si, other, p.n_app));
    }
    bar.set_message("3-D");
    let results: Vec<anyhow::Result<VariantOut>> = variants
        .par_iter()
        .map(|&(si, sel, n)| {
            run_variant(
                &calib.views,
                cylinder_params(p, dt_s, sel, n),
                &sources[si].1,
            )
        })
        .collect();

    let mut tc = TrackCols::default();
    let mut vrows: (
        Vec<String>,
        Vec<String>,
        Vec<i64>,
        Vec<i64>,
        Vec<i64>,
        Vec<i64>,
        Vec<i64>,
    ) = Default::default();
    let support_text = |sup: &[(usize, u32)]| {
        sup.iter()
            .map(|(c, id)| format!("{}:{id}", p.cameras[*c]))
            .collect::<Vec<_>>()
            .join(" ")
    };
    for (&(si, sel, n), r) in variants.iter().zip(results) {
        let r = r?;
        let det = sources[si].0;
        vrows.0.push(det.to_string());
        vrows.1.push(selection_label(sel).to_string());
        vrows.2.push(i64::from(n));
        vrows.3.push(r.combinations as i64);
        vrows.4.push(r.pruned_frames as i64);
        vrows.5.push(r.promoted as i64);
        vrows.6.push(r.discarded as i64);
        for (k, cyls) in &r.tracks {
            let stamp = frames[*k].stamp;
            for c in cyls {
                tc.detector.push(det.to_string());
                tc.selection.push(selection_label(sel).to_string());
                tc.n_app.push(i64::from(n));
                tc.frame.push(*k as i64);
                tc.stamp_ns.push(stamp.0 as i64);
                tc.t_s.push((stamp.0.saturating_sub(t0.0)) as f64 * 1e-9);
                tc.id.push(i64::from(c.id));
                tc.x_m.push(c.x_m);
                tc.y_m.push(c.y_m);
                tc.vx_mps.push(c.vx_mps);
                tc.vy_mps.push(c.vy_mps);
                tc.height_m.push(c.height_m);
                tc.radius_m.push(c.radius_m);
                tc.cameras.push(c.support.len() as i64);
                tc.support.push(support_text(&c.support));
                let m = c.measured.as_ref();
                tc.e_m_px.push(m.map(|h| h.e_m_px));
                tc.meas_x_m.push(m.map(|h| h.head_m.x));
                tc.meas_y_m.push(m.map(|h| h.head_m.y));
                tc.meas_height_m.push(m.map(|h| h.head_m.z));
                tc.meas_radius_m
                    .push(m.map(|h| h.radius_m).filter(|r| r.is_finite()));
            }
        }
    }
    bar.inc(1);

    // ground truth per frame
    let mut g: (
        Vec<i64>,
        Vec<i64>,
        Vec<f64>,
        Vec<i64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        Vec<i64>,
        Vec<bool>,
    ) = Default::default();
    let room = p.room_m;
    for (k, (f, gt)) in frames.iter().zip(&gt_for_frame).enumerate() {
        let Some(gt) = gt else { continue };
        for person in &gt.people {
            g.0.push(k as i64);
            g.1.push(f.stamp.0 as i64);
            g.2.push((f.stamp.0.saturating_sub(t0.0)) as f64 * 1e-9);
            g.3.push(i64::from(person.id));
            g.4.push(person.x);
            g.5.push(person.y);
            g.6.push(person.height);
            g.7.push(person.radius);
            g.8.push(
                person
                    .cameras
                    .iter()
                    .filter(|v| {
                        v.bbox.is_some() && v.visibility > 0.0 && p.cameras.contains(&v.camera)
                    })
                    .count() as i64,
            );
            g.9.push(
                person.x >= room[0]
                    && person.x <= room[2]
                    && person.y >= room[1]
                    && person.y <= room[3],
            );
        }
    }

    // head point vs blob centroid, per detector with per-camera detections
    let mut hc = HeadCentroidCols::default();
    for (k, gt) in gt_for_frame.iter().enumerate() {
        let Some(gt) = gt else { continue };
        if use_images {
            let per_cam: Vec<Vec<([f64; 4], [f64; 2], [f64; 2])>> = frames[k]
                .detections
                .iter()
                .map(|ds| {
                    ds.iter()
                        .map(|d| (d.bbox, d.head_px, d.centroid_px))
                        .collect()
                })
                .collect();
            head_centroid_frame(
                &mut hc,
                TEMPLATES,
                k,
                gt,
                &p.cameras,
                &calib.views,
                &per_cam,
                p.occluded_visibility,
            );
        }
        if let Some(per_cam) = gt_box_cam_frames.get(k) {
            head_centroid_frame(
                &mut hc,
                GT_BOXES,
                k,
                gt,
                &p.cameras,
                &calib.views,
                per_cam,
                p.occluded_visibility,
            );
        }
    }

    // the template detections against the visible ground-truth boxes, per frame and camera
    let mut d2 = Det2dCols::default();
    if use_images {
        for (k, gt) in gt_for_frame.iter().enumerate() {
            let Some(gt) = gt else { continue };
            for (c, cam) in p.cameras.iter().enumerate() {
                let truth_boxes: Vec<Box2d> = boxes_from_truth(gt, cam, BoxHead::Truth)
                    .into_iter()
                    .map(|(_, b)| b)
                    .collect();
                let dets = frames[k]
                    .detections
                    .get(c)
                    .map(Vec::as_slice)
                    .unwrap_or(&[]);
                d2.push(k, cam, &truth_boxes, dets, DETECTION_HEAD_TOL);
            }
        }
    }

    let tracks_df = df! {
        "detector" => tc.detector, "selection" => tc.selection, "n_app" => tc.n_app,
        "frame" => tc.frame, "stamp_ns" => tc.stamp_ns, "t_s" => tc.t_s, "id" => tc.id,
        "x_m" => tc.x_m, "y_m" => tc.y_m, "vx_mps" => tc.vx_mps, "vy_mps" => tc.vy_mps,
        "height_m" => tc.height_m, "radius_m" => tc.radius_m, "cameras" => tc.cameras,
        "support" => tc.support, "e_m_px" => tc.e_m_px, "meas_x_m" => tc.meas_x_m,
        "meas_y_m" => tc.meas_y_m, "meas_height_m" => tc.meas_height_m,
        "meas_radius_m" => tc.meas_radius_m,
    }?;
    let gt_df = df! {
        "frame" => g.0, "stamp_ns" => g.1, "t_s" => g.2, "id" => g.3, "x_m" => g.4, "y_m" => g.5,
        "height_m" => g.6, "radius_m" => g.7, "cameras_visible" => g.8, "in_room" => g.9,
    }?;
    let hc_df = df! {
        "detector" => hc.detector, "frame" => hc.frame, "id" => hc.id, "cameras" => hc.cameras,
        "occluded" => hc.occluded, "clear" => hc.clear, "min_visibility" => hc.min_visibility,
        "head_error_m" => hc.head_error_m, "centroid_error_m" => hc.centroid_error_m,
    }?;
    let det2d_df = df! {
        "frame" => d2.frame, "camera" => d2.camera, "truth" => d2.truth,
        "detections" => d2.detections, "matched" => d2.matched, "head_dx_abs_px" => d2.head_dx_abs,
        "head_dy_px" => d2.head_dy, "height_ratio" => d2.height_ratio,
    }?;
    let cams_df = df! {
        "frame" => cam_rows.0, "camera" => cam_rows.1, "threshold" => cam_rows.2,
        "foreground_frac" => cam_rows.3, "detections" => cam_rows.4, "objects_2d" => cam_rows.5,
    }?;
    let variants_df = df! {
        "detector" => vrows.0, "selection" => vrows.1, "n_app" => vrows.2,
        "combinations" => vrows.3, "pruned_frames" => vrows.4, "promoted" => vrows.5,
        "discarded" => vrows.6,
    }?;
    let session_df = df! {
        "frames" => [frames.len() as i64],
        "cameras" => [n_cams as i64],
        "dt_s" => [dt_s],
        "duration_s" => [(frames[frames.len() - 1].stamp.0.saturating_sub(t0.0)) as f64 * 1e-9],
        "first_stamp_ns" => [t0.0 as i64],
        "decode_failures" => [decode_failures as i64],
        "missing_camera_frames" => [missing_camera_frames as i64],
        "gt_frames" => [truth.len() as i64],
        "gt_bad_frames" => [bad_truth as i64],
        "first_error" => [first_error.unwrap_or_default()],
    }?;
    let calib_df = {
        let (mut cam, mut x, mut y, mut z, mut heading) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for (name, v) in p.cameras.iter().zip(&calib.views) {
            let c = v.center();
            let axis = v.world_from_camera.rotation * nalgebra::Vector3::z();
            cam.push(name.clone());
            x.push(c.x);
            y.push(c.y);
            z.push(c.z);
            heading.push(axis.y.atan2(axis.x));
        }
        df! { "camera" => cam, "x_m" => x, "y_m" => y, "z_m" => z, "heading_rad" => heading }?
    };
    Ok(SessionTables::from([
        ("calibration".to_string(), calib_df),
        ("tracks".to_string(), tracks_df),
        ("gt".to_string(), gt_df),
        ("head_centroid".to_string(), hc_df),
        ("cameras".to_string(), cams_df),
        ("detections_2d".to_string(), det2d_df),
        ("variants".to_string(), variants_df),
        ("session".to_string(), session_df),
    ]))
}

/// The images of all cameras at one stamp (for figures), in camera order.
pub(crate) fn images_at(
    path: &Path,
    p: &Params,
    t: &Topics,
    stamp: Nanos,
) -> anyhow::Result<Vec<Option<RgbImage>>> {
    let log = SessionLog::open(path)?;
    let mut out: Vec<Option<RgbImage>> = vec![None; p.cameras.len()];
    let topics: Vec<&str> = t
        .image
        .iter()
        .map(String::as_str)
        .filter(|tp| log.summary().channel(tp).is_some())
        .collect();
    if topics.is_empty() {
        return Ok(out);
    }
    let mut decoders = Decoders::new();
    for m in log.messages_on(&topics)? {
        let m = m?;
        let Some(c) = t.image.iter().position(|tp| tp == m.topic()) else {
            continue;
        };
        let img = match m.channel.schema_name() {
            "sensor_msgs/msg/Image" | "foxglove.RawImage" => {
                let i = decoders.typed::<Image>(log_ref(&log), &m)?;
                if stamp_of(&m, i.header.stamp.nanos()) != stamp {
                    continue;
                }
                decode_image(&Payload::Raw(i))
            }
            _ => {
                let i = decoders.typed::<CompressedImage>(log_ref(&log), &m)?;
                if stamp_of(&m, i.header.stamp.nanos()) != stamp {
                    continue;
                }
                decode_image(&Payload::Compressed(i))
            }
        };
        if let Some(Ok(rgb)) = img {
            out[c] = Some(rgb);
        }
        if out.iter().all(Option::is_some) || m.log_time.0 > stamp.0 + 5_000_000_000 {
            break;
        }
    }
    Ok(out)
}

fn log_ref(l: &SessionLog) -> &SessionLog {
    l
}

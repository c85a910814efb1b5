//! The main pass over the log: camera messages grouped into frames by header stamp (within
//! `sync_tolerance_s`; a camera's second message closes the frame), each frame through every
//! camera's chain (cameras in parallel), and the ground truth collected on the way.

use std::collections::BTreeMap;

use anyhow::bail;
use rayon::prelude::*;

use super::super::{Params, Topics};
use super::chain::{CameraChain, CameraOut, ChainSetup};
use super::input::{Payload, image_payload, message_count, stamp_of};
use crate::geometry::triangulate::CalibratedView;
use crate::groundtruth::PeopleFrame;
use crate::log::msgs::Detection2DArray;
use crate::log::{Decoders, Message, SessionLog};
use crate::pipelines::s004_mohedano_multicam::tables::CameraRow;
use crate::progress::Progress;
use crate::time::Nanos;
use crate::track::cylinders::Object2d;
use crate::vision::template::Detection;

/// Everything kept of one frame.
pub(crate) struct FrameRec {
    pub stamp: Nanos,
    /// 2-D objects of the main source (templates or log detections), all cameras.
    pub objects: Vec<Object2d>,
    /// Template detections per camera (for head vs centroid and the 2-D scores).
    pub detections: Vec<Vec<Detection>>,
}

/// What the pass produces.
#[derive(Default)]
pub(crate) struct Pass {
    pub frames: Vec<FrameRec>,
    /// Per frame and camera (templates detector only).
    pub camera_rows: Vec<CameraRow>,
    /// Ground-truth frames by stamp, sorted.
    pub truth: Vec<(Nanos, PeopleFrame)>,
    pub bad_truth: usize,
    pub decode_failures: usize,
    pub missing_camera_frames: usize,
    pub first_error: Option<String>,
}

impl Pass {
    fn failed(&mut self, e: String) {
        self.decode_failures += 1;
        if self.first_error.is_none() {
            self.first_error = Some(e);
        }
    }

    /// Record one frame's camera outputs.
    fn push_frame(&mut self, stamp: Nanos, outs: Vec<CameraOut>, p: &Params, use_images: bool) {
        let k = self.frames.len() as i64;
        let mut objects = Vec::new();
        let mut detections = Vec::with_capacity(outs.len());
        for (c, o) in outs.into_iter().enumerate() {
            if !o.present {
                self.missing_camera_frames += 1;
            }
            if let Some(e) = o.failed {
                self.failed(format!("camera {c} at {:.3} s: {e}", stamp.0 as f64 * 1e-9));
            }
            if use_images {
                self.camera_rows.push(CameraRow {
                    frame: k,
                    camera: p.cameras[c].clone(),
                    threshold: o.threshold,
                    foreground_frac: o.foreground_frac,
                    detections: o.detections.len() as i64,
                    objects_2d: o.objects.len() as i64,
                });
            }
            objects.extend(o.objects);
            detections.push(o.detections);
        }
        self.frames.push(FrameRec {
            stamp,
            objects,
            detections,
        });
    }
}

/// The cameras' chains and what they need per frame.
pub(crate) struct Chains<'a> {
    pub chains: Vec<CameraChain>,
    pub views: &'a [CalibratedView],
    pub setup: &'a ChainSetup,
}

impl Chains<'_> {
    /// Every camera's chain on one frame's payloads, in parallel.
    fn run(&mut self, payloads: Vec<Option<Payload>>, p: &Params) -> Vec<CameraOut> {
        let (views, det) = (self.views, &self.setup.detector);
        self.chains
            .par_iter_mut()
            .zip(payloads.into_par_iter())
            .enumerate()
            .map(|(c, (chain, payload))| chain.step(payload, p, &views[c], det))
            .collect()
    }
}

/// The topics that make frames (images or detections) and the progress bar's length.
fn primary<'t>(log: &SessionLog, t: &'t Topics, use_images: bool) -> (&'t [String], u64) {
    let primary: &[String] = if use_images { &t.image } else { &t.detections };
    let expected = primary
        .iter()
        .filter(|tp| log.summary().channel(tp).is_some())
        .count()
        .max(1);
    let total: u64 = if log.summary().statistics.is_some() {
        primary.iter().map(|tp| message_count(log, tp)).sum()
    } else {
        0
    };
    (primary, (total / expected as u64).max(1))
}

/// One camera message as a payload with its stamp.
fn payload(
    log: &SessionLog,
    decoders: &mut Decoders,
    m: &Message,
    use_images: bool,
) -> Result<(Nanos, Payload), crate::log::LogError> {
    if use_images {
        image_payload(log, decoders, m)
    } else {
        decoders
            .typed::<Detection2DArray>(log, m)
            .map(|d| (stamp_of(m, d.header.stamp.nanos()), Payload::Detections(d)))
    }
}

/// Read the log once, in time order, and run the chains on every frame.
pub(crate) fn run_pass(
    log: &SessionLog,
    p: &Params,
    t: &Topics,
    chains: &mut Chains,
    bar: &dyn Progress,
) -> anyhow::Result<Pass> {
    let use_images = chains.setup.use_images;
    let has_gt = log.summary().channel(&t.ground_truth).is_some();
    let (primary, length) = primary(log, t, use_images);
    let role: BTreeMap<&str, usize> = primary
        .iter()
        .enumerate()
        .map(|(c, tp)| (tp.as_str(), c))
        .collect();
    let mut topic_list: Vec<&str> = primary.iter().map(String::as_str).collect();
    if has_gt {
        topic_list.push(t.ground_truth.as_str());
    }
    bar.set_length(length);
    bar.set_message("frames");

    let tol_ns = (p.sync_tolerance_s * 1e9) as u64;
    let mut decoders = Decoders::new();
    let mut pass = Pass::default();
    let mut pending: Vec<Option<Payload>> = (0..p.cameras.len()).map(|_| None).collect();
    let mut pending_stamp: Option<Nanos> = None;
    for m in log.messages_on(&topic_list)? {
        let m = m?;
        if m.topic() == t.ground_truth {
            match serde_json::from_slice::<PeopleFrame>(&m.data) {
                Ok(f) => pass.truth.push((Nanos(f.stamp_ns), f)),
                Err(_) => pass.bad_truth += 1, // counted and reported, not fatal
            }
            continue;
        }
        let Some(&c) = role.get(m.topic()) else {
            continue;
        };
        let (stamp, payload) = match payload(log, &mut decoders, &m, use_images) {
            Ok(x) => x,
            Err(e) => {
                pass.failed(e.to_string());
                continue;
            }
        };
        if let Some(ps) = pending_stamp
            && (stamp.0.abs_diff(ps.0) > tol_ns || pending[c].is_some())
        {
            let outs = chains.run(pending.iter_mut().map(Option::take).collect(), p);
            pass.push_frame(ps, outs, p, use_images);
            bar.inc(1);
            pending_stamp = None;
        }
        pending_stamp.get_or_insert(stamp);
        pending[c] = Some(payload);
    }
    if let Some(ps) = pending_stamp {
        let outs = chains.run(pending.iter_mut().map(Option::take).collect(), p);
        pass.push_frame(ps, outs, p, use_images);
    }
    if pass.frames.is_empty() {
        bail!(
            "{}: no frames on {}",
            log.path().display(),
            primary.join(", ")
        );
    }
    pass.truth.sort_by_key(|x| x.0);
    Ok(pass)
}

//! The main pass over the log: the cameras' messages grouped into frames by header stamp
//! (`frames::multicam`: within `sync_tolerance_s`; a camera's second message closes the
//! frame), each frame through every camera's chain (cameras in parallel); the ground truth
//! (`frames::truth`).

use anyhow::bail;
use rayon::prelude::*;

use super::super::{Params, Topics};
use super::chain::{CameraChain, CameraOut, ChainSetup};
use super::errors::{self, Visited};
use super::input::{Payload, message_count};
use crate::frames::multicam::{self, CameraPayload};
use crate::frames::{ImageMsg, Skips, Stamped, truth};
use crate::geometry::triangulate::CalibratedView;
use crate::groundtruth::PeopleFrame;
use crate::log::SessionLog;
use crate::log::msgs::Detection2DArray;
use crate::pipelines::s004_mohedano_multicam::tables::{CameraRow, Error2dRow};
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
    /// The template chain's misses and false detections with their causes (`errors`).
    pub errors: Vec<Error2dRow>,
    /// Ground-truth frames by stamp.
    pub truth: Stamped<PeopleFrame>,
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
            self.errors.extend(o.errors);
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
    /// Every camera's chain on one frame's payloads, in parallel; `truth`: name the errors.
    fn run(
        &mut self,
        payloads: Vec<Option<Payload>>,
        p: &Params,
        truth: Option<&errors::Context>,
    ) -> Vec<CameraOut> {
        let (views, det) = (self.views, &self.setup.detector);
        self.chains
            .par_iter_mut()
            .zip(payloads.into_par_iter())
            .enumerate()
            .map(|(c, (chain, payload))| chain.step(payload, p, &views[c], det, truth))
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

/// Every frame of `topics` (one per camera) through the chains; the messages skipped.
fn frames_of<P: CameraPayload>(
    log: &SessionLog,
    topics: &[String],
    tol_ns: u64,
    payload: fn(P) -> Payload,
    run: &mut dyn FnMut(Nanos, Vec<Option<Payload>>),
) -> anyhow::Result<Skips> {
    let mut frames = multicam::group::<P>(log, topics, tol_ns)?;
    for f in &mut frames {
        let f = f?;
        run(
            f.stamp,
            f.cameras.into_iter().map(|c| c.map(payload)).collect(),
        );
    }
    Ok(frames.into_skips())
}

/// Read the ground truth, then the log's camera topics once, in time order, and run the chains
/// on every frame (naming the template chain's errors where the frame has ground truth).
pub(crate) fn run_pass(
    log: &SessionLog,
    p: &Params,
    t: &Topics,
    chains: &mut Chains,
    bar: &dyn Progress,
) -> anyhow::Result<Pass> {
    let use_images = chains.setup.use_images;
    let (primary, length) = primary(log, t, use_images);
    bar.set_length(length);
    bar.set_message("frames");
    let tol_ns = (p.sync_tolerance_s * 1e9) as u64;
    let (people, bad) = truth::people(log, &t.ground_truth)?;
    let visited = if use_images {
        Visited::new(people.items())
    } else {
        Visited::default()
    };
    let mut pass = Pass::default();
    let mut run = |stamp: Nanos, payloads: Vec<Option<Payload>>| {
        // the same ground-truth frame `process` scores this frame against
        let ctx = people
            .nearest(stamp, tol_ns.max(1))
            .filter(|_| use_images)
            .map(|gt| errors::Context {
                frame: pass.frames.len(),
                gt,
                visited: &visited,
            });
        let outs = chains.run(payloads, p, ctx.as_ref());
        pass.push_frame(stamp, outs, p, use_images);
        bar.inc(1);
    };
    let skips = if use_images {
        frames_of::<ImageMsg>(log, primary, tol_ns, Payload::Image, &mut run)?
    } else {
        frames_of::<Detection2DArray>(log, primary, tol_ns, Payload::Detections, &mut run)?
    };
    // messages that did not decode come first in the count; their first error wins
    let chain_error = pass.first_error.take();
    pass.decode_failures += skips.total() as usize;
    pass.first_error = skips.first_error().map(str::to_string).or(chain_error);
    if pass.frames.is_empty() {
        bail!(
            "{}: no frames on {}",
            log.path().display(),
            primary.join(", ")
        );
    }
    pass.truth = people;
    pass.bad_truth = bad.total() as usize;
    Ok(pass)
}

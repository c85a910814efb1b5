//! Local tracks: people followed frame to frame while they stay in one camera's view — the
//! observations re-identification links into global identities (Zajdel, Zivkovic & Kröse,
//! "Keeping track of humans: have I seen this person before?", ICRA 2005, section III; the
//! detector/tracker trade-offs of table 1 of the COGNIRON report D2.1.1).
//!
//! Per frame ([`LocalTracker::step`]):
//! 1. **Detection** (camera still): the adaptive GMM ([`super::gmm`]) gives a mask; shadow
//!    pixels are dropped, a 3×3 majority filter cleans it, and its connected components
//!    ([`super::blobs`]) of at least `min_area_px` pixels are the blobs, each summarised by
//!    its first two moments (an [`Ellipse`]). Blobs one above the other in one column are
//!    grouped into one person (`group_gap`, `local::fragments`: a shirt lost against the
//!    background splits a person in two), and with `upright_only` only blobs whose moments
//!    are taller than wide are kept. After the `warmup_frames` of a (re)start the model
//!    learns at the steady α = 1/T (`steady_after_warmup`; see `careful::learning_rate`).
//! 2. **Colour tracking**: tracks handed over to the colour tracker move with the EM-like
//!    algorithm ([`super::colortrack::em_like`]); a track whose similarity ρ drops below
//!    `min_similarity`, or that is lost or leaves the image, ends.
//! 3. **Association**: a blob may continue a track when its centroid lies within `gate_sigma`
//!    of the track's ellipse (for a colour-tracked track, also when the track's centre lies
//!    within `gate_sigma` of the blob's ellipse); pairs are taken greedily by increasing Mahalanobis distance
//!    (ties by track id, then blob label — deterministic). A colour-tracked track takes a blob
//!    back only if the blob's 2σ ellipse covers at least `reacquire_overlap` of the colour
//!    region's 2σ ellipse ([`Ellipse::covered_by`], not the IoU: on a uniformly coloured body
//!    the EM-like region settles with its 2.5σ boundary *inside* the body — every smaller
//!    size is a fixed point too, the weights being flat there — so its ellipse is much
//!    smaller than the blob's moment ellipse of the same person, σ ≈ 1.2–1.8 px against
//!    2.9 px across a 10 px body in the tests, and their IoU stays below 0.3 even when
//!    centred) and, for a person who stood still, once the blob's centre is
//!    `resume_px` away from where the person stopped (the still person's ghost cannot take
//!    the track back). Unmatched blobs within 2σ of a track's new ellipse are fragments of
//!    it and merge into it (moments add). Remaining blobs start tracks.
//! 4. **Hand-over to the colour tracker** (table 1: background subtraction cannot track with
//!    a moving camera, nor a person who stays still for long, the colour tracker can):
//!    - when the camera starts moving, every blob track is handed over; the GMM is not
//!      updated while the camera moves and restarts from scratch when it stops, with no blobs
//!      for `warmup_frames`, and *carefully* (section III-A: "the objects that were tracked
//!      during the moving phase might stay still and occlude a part of the background. This
//!      part of the background is learned only when the objects … leave"): every track that
//!      is colour-tracked when the camera stops is *protected* — the pixels of its body box
//!      (the √3σ box of the blob ellipse it was handed over with, times `protect_scale`,
//!      centred where the track is) do not update the model
//!      ([`AdaptiveGmm::apply_selective`]) until the track ends, or at most `protect_frames`
//!      frames (the paper's 220: by then a static object would have joined the background
//!      anyway). A pixel that has no model yet (frozen since the restart) is not foreground;
//!      it is learned from the first frame it is no longer covered;
//!    - when a track that has travelled at least `min_travel_px` from where it started has
//!      moved its centroid less than `still_speed_px` per frame over the last `still_frames`
//!      frames (the person stands still and will fade into the background). A track that
//!      never moved (a ghost, a moved chair) is never handed over: it ends with its blob.
//!
//!    The colour model is the kernel-weighted histogram (eq. 17) of the track's last blob
//!    ellipse, refreshed every frame the track is seen as a blob. Section III-C: the search
//!    starts from the previous region "but we also try some random initializations to find
//!    global maximum": besides the previous region, `random_starts` regions of the same shape
//!    shifted by a uniform draw within ±`random_start_sigma` σ per axis (a hash of the track,
//!    the frame and the draw: deterministic) are tracked too, and the one with the largest
//!    Bhattacharyya coefficient wins (the previous region on ties). How many, and how far,
//!    the paper does not say; these are ours. Off by default (`random_starts = 0`): on the
//!    quick `home_tour` log they kept colour tracks alive on background (see the README).
//!    A colour region whose size (√ area of its ellipse) falls below `min_region_scale` of the
//!    body it was handed over with has collapsed onto a small patch of similar colour (on
//!    `home_tour` a 4 px wide strip at the image border through a drive): the track ends. The
//!    EM-like region settles *inside* a uniformly coloured body (0.4–0.6 of the blob's size,
//!    above), so the default 0.25 (a 4× shrink) leaves room for that and for a person
//!    walking off to twice the distance.
//! 5. A blob track missed more than `max_missed` frames in a row ends.
//!
//! Each [`Observation`] names its track, the mode, the ellipse and box, and (in blob mode)
//! the labels of its blobs in [`LocalTracker::labels`] for that frame, so a caller can read
//! the exact pixels (re-identification's colour features).
//!
//! Whether the camera moves is the caller's input (from odometry in the pipelines). Not here:
//! the optic-flow detector of the paper (moving camera), splitting merged people, occlusion
//! reasoning.

use std::collections::VecDeque;

use nalgebra::Point2;
use serde::{Deserialize, Serialize};

use super::blobs::{self, Blob, BlobError, Connectivity, Moments};
use super::colortrack::{
    BinImage, ColorSpace, ColorTrackError, DEFAULT_CUTOFF_SIGMA, EmParams, Histogram, Shape,
    consistent_beta, em_like, kernel_histogram,
};
use super::ellipse::{Ellipse, SHAPE_SIGMA};
use super::gmm::{AdaptiveGmm, FOREGROUND, GmmError, GmmParams};
use super::view::ImageView;

/// Box of a colour-tracked region: the √3σ bounding box (a uniform rectangle's moments give
/// back the rectangle at √3σ).
pub const COLOUR_BOX_SIGMA: f64 = 1.732_050_807_568_877_2;

#[derive(Debug, thiserror::Error)]
pub enum LocalError {
    #[error("local tracking needs 3-channel RGB frames, not {channels}")]
    Channels { channels: usize },
    #[error("frame is {width}x{height} but the tracker started on {have_width}x{have_height}")]
    FrameSize {
        width: usize,
        height: usize,
        have_width: usize,
        have_height: usize,
    },
    // no `#[from]`: a source would be printed twice in an error chain (`From`s are below)
    #[error("background model: {0}")]
    Gmm(GmmError),
    #[error("blobs: {0}")]
    Blobs(BlobError),
    #[error("colour tracker: {0}")]
    Colour(ColorTrackError),
    #[error("parameter `{name}` = {value} {why}")]
    BadParam {
        name: &'static str,
        value: f64,
        why: &'static str,
    },
}

macro_rules! from_errors {
    ($($t:ty => $v:ident),*) => {
        $(impl From<$t> for LocalError {
            fn from(e: $t) -> Self {
                LocalError::$v(e)
            }
        })*
    };
}
from_errors!(GmmError => Gmm, BlobError => Blobs, ColorTrackError => Colour);

/// Why a track is colour-tracked.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum HandOver {
    CameraMoving,
    StandingStill,
}

/// Where a track's observation came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    /// Blobs of the background mask.
    Blob,
    /// The EM-like colour tracker.
    Colour(HandOver),
}

impl Mode {
    pub fn name(&self) -> &'static str {
        match self {
            Mode::Blob => "blob",
            Mode::Colour(HandOver::CameraMoving) => "colour (camera moving)",
            Mode::Colour(HandOver::StandingStill) => "colour (standing still)",
        }
    }
}

/// One track in one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Observation {
    pub track: u32,
    pub mode: Mode,
    pub region: Ellipse,
    /// `[x0, y0, x1, y1]`, right and bottom exclusive (blob: its pixel bounds; colour: the
    /// [`COLOUR_BOX_SIGMA`] box of the region).
    pub bbox: [f64; 4],
    /// Pixels of the blobs (0 in colour mode).
    pub area_px: u64,
    /// Colour mode: Bhattacharyya coefficient with the model.
    pub similarity: Option<f64>,
    /// Colour mode: iterations of the EM-like tracker.
    pub iterations: Option<u32>,
    /// Blob mode: labels of the blobs in [`LocalTracker::labels`].
    pub blobs: Vec<u32>,
}

#[derive(Debug, Clone)]
struct Track {
    id: u32,
    mode: Mode,
    region: Ellipse,
    model: Option<Histogram>,
    birth: Point2<f64>,
    travelled: bool,
    recent: VecDeque<Point2<f64>>,
    missed: u32,
    anchor: Option<Point2<f64>>,
    /// The blob ellipse the track was last handed over to the colour tracker with.
    body: Option<Ellipse>,
    /// Its body box is not learned (set at a restart of the background model).
    protected: bool,
    ended: bool,
    /// This frame's observation, if any.
    seen: Option<Observation>,
}

/// Counters over a tracker's life.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LocalStats {
    pub frames: u64,
    pub moving_frames: u64,
    pub gmm_restarts: u64,
    pub tracks_started: u64,
    pub handovers_camera: u64,
    pub handovers_still: u64,
    pub reacquired: u64,
    /// Frames on which some pixels were not learned (protected boxes after a restart).
    pub protected_frames: u64,
}

/// The local tracker of one camera.
#[derive(Debug, Clone)]
pub struct LocalTracker {
    params: LocalParams,
    gmm: AdaptiveGmm,
    shape: Option<(usize, usize)>,
    mask: Vec<u8>,
    filtered: Vec<u8>,
    labels: Vec<u32>,
    blobs: Vec<Blob>,
    tracks: Vec<Track>,
    next_id: u32,
    moving: bool,
    since_reset: u32,
    /// Per pixel: may the model learn it this frame (see the module doc, hand-over).
    learn: Vec<bool>,
    /// Some pixels may have no model (they were frozen since the restart).
    unmodelled: bool,
    observations: Vec<Observation>,
    stats: LocalStats,
}

impl LocalTracker {
    pub fn new(params: LocalParams) -> Result<Self, LocalError> {
        params.validate()?;
        Ok(Self {
            gmm: AdaptiveGmm::new(params.gmm)?,
            params,
            shape: None,
            mask: Vec::new(),
            filtered: Vec::new(),
            labels: Vec::new(),
            blobs: Vec::new(),
            tracks: Vec::new(),
            next_id: 1,
            moving: false,
            since_reset: 0,
            learn: Vec::new(),
            unmodelled: false,
            observations: Vec::new(),
            stats: LocalStats::default(),
        })
    }

    /// The GMM mask of the last frame (all 0 while the camera moves).
    pub fn mask(&self) -> &[u8] {
        &self.mask
    }
    /// The foreground the blobs of the last frame were cut from (the GMM mask without
    /// shadows, majority-filtered when `majority_filter` is on; [`FOREGROUND`] = a moving
    /// pixel, 0 = not), or `None` on a frame that took no blobs (the camera moving, or the
    /// warm-up after a restart): the pixels a robot knows to belong to people.
    pub fn foreground(&self) -> Option<&[u8]> {
        if self.moving || self.since_reset <= self.params.warmup_frames || self.mask.is_empty() {
            return None;
        }
        Some(if self.params.majority_filter {
            &self.filtered
        } else {
            &self.mask
        })
    }
    /// Blob labels of the last frame (0 = none), as named by [`Observation::blobs`].
    pub fn labels(&self) -> &[u32] {
        &self.labels
    }
    /// Blobs of the last frame that passed the size filter.
    pub fn blobs(&self) -> &[Blob] {
        &self.blobs
    }
    pub fn stats(&self) -> LocalStats {
        self.stats
    }
    pub fn params(&self) -> &LocalParams {
        &self.params
    }

    /// Process the next frame (RGB) of the camera; `camera_moving` says whether the camera
    /// moves at that instant. Returns this frame's observations, in track order.
    pub fn step(
        &mut self,
        frame: ImageView<'_>,
        camera_moving: bool,
    ) -> Result<&[Observation], LocalError> {
        if frame.channels() != 3 {
            return Err(LocalError::Channels {
                channels: frame.channels(),
            });
        }
        let (w, h) = (frame.width(), frame.height());
        match self.shape {
            None => {
                self.shape = Some((w, h));
                self.mask = vec![0; w * h];
                self.filtered = vec![0; w * h];
                self.labels = vec![0; w * h];
                self.learn = vec![true; w * h];
            }
            Some((hw, hh)) if (hw, hh) != (w, h) => {
                return Err(LocalError::FrameSize {
                    width: w,
                    height: h,
                    have_width: hw,
                    have_height: hh,
                });
            }
            Some(_) => {}
        }
        self.stats.frames += 1;
        self.observations.clear();
        self.tracks.retain(|t| !t.ended);
        for t in &mut self.tracks {
            t.seen = None;
        }
        let bins = BinImage::new(frame, self.params.color)?;
        self.detect(frame, camera_moving)?;
        self.colour_step(&bins)?;
        self.associate(&bins);
        for t in &self.tracks {
            if let Some(o) = &t.seen {
                self.observations.push(o.clone());
            }
        }
        Ok(&self.observations)
    }

    /// Background model, mask and blobs; hand-over when the camera starts moving.
    fn detect(&mut self, frame: ImageView<'_>, camera_moving: bool) -> Result<(), LocalError> {
        let (w, h) = (frame.width(), frame.height());
        self.blobs.clear();
        if camera_moving {
            self.stats.moving_frames += 1;
            if !self.moving {
                for t in &mut self.tracks {
                    if t.mode == Mode::Blob {
                        if t.model.is_some() {
                            t.mode = Mode::Colour(HandOver::CameraMoving);
                            t.anchor = None;
                            t.body = Some(t.region);
                            self.stats.handovers_camera += 1;
                        } else {
                            t.ended = true;
                        }
                    }
                }
                self.tracks.retain(|t| !t.ended);
            }
            self.moving = true;
            self.mask.fill(0);
            self.labels.fill(0);
            return Ok(());
        }
        if self.moving {
            self.gmm.reset();
            self.since_reset = 0;
            self.stats.gmm_restarts += 1;
            self.moving = false;
            for t in &mut self.tracks {
                t.protected = matches!(t.mode, Mode::Colour(_)) && t.body.is_some();
            }
        }
        self.learn_selectively(frame)?;
        self.since_reset = self.since_reset.saturating_add(1);
        if self.since_reset <= self.params.warmup_frames {
            self.labels.fill(0);
            return Ok(());
        }
        let src = if self.params.majority_filter {
            blobs::majority_filter(&self.mask, w, h, FOREGROUND, &mut self.filtered)?;
            &self.filtered
        } else {
            &self.mask
        };
        let all = blobs::label(
            src,
            w,
            h,
            self.params.connectivity,
            FOREGROUND,
            &mut self.labels,
        )?;
        let kept = all
            .into_iter()
            .filter(|b| b.area() >= self.params.min_area_px)
            .collect();
        self.blobs = fragments::group(kept, &mut self.labels, self.params.group_gap);
        if self.params.upright_only {
            self.blobs.retain(fragments::upright);
        }
        Ok(())
    }

    /// Move the colour-tracked tracks with the EM-like tracker, from the previous region and
    /// from `random_starts` random shifts of it (section III-C); the most similar result wins.
    fn colour_step(&mut self, bins: &BinImage) -> Result<(), LocalError> {
        let (w, h) = (bins.width() as f64, bins.height() as f64);
        let p = self.params;
        for t in &mut self.tracks {
            let Mode::Colour(_) = t.mode else {
                continue;
            };
            let Some(model) = &t.model else {
                t.ended = true;
                continue;
            };
            let mut r = em_like(bins, model, &t.region, &p.em)?;
            for k in 0..p.random_starts {
                let start = careful::random_start(&t.region, t.id, self.stats.frames, k, &p);
                let other = em_like(bins, model, &start, &p.em)?;
                if !other.lost && (r.lost || other.similarity > r.similarity) {
                    r = other;
                }
            }
            let c = r.region.center;
            let inside = c.x >= 0.0 && c.y >= 0.0 && c.x < w && c.y < h;
            if r.lost
                || !inside
                || r.similarity < self.params.min_similarity
                || careful::collapsed(&r.region, t.body.as_ref(), p.min_region_scale)
            {
                t.ended = true;
                continue;
            }
            t.region = r.region;
            t.seen = Some(Observation {
                track: t.id,
                mode: t.mode,
                region: r.region,
                bbox: r.region.bbox(COLOUR_BOX_SIGMA),
                area_px: 0,
                similarity: Some(r.similarity),
                iterations: Some(r.iterations),
                blobs: Vec::new(),
            });
        }
        Ok(())
    }

    /// Blobs to tracks, fragments, new tracks, misses and stillness.
    fn associate(&mut self, bins: &BinImage) {
        let ellipses: Vec<Ellipse> = self.blobs.iter().map(Blob::ellipse).collect();
        let (blob_owner, track_blobs, held) = self.match_blobs(&ellipses);
        self.update_matched(bins, &ellipses, &track_blobs);
        self.start_tracks(bins, &ellipses, &blob_owner, &held);
    }

    /// Each live track's nearest blob within the gate (greedy, nearest first), then the
    /// fragments around matched blobs. Returns each blob's track, each track's blobs (its
    /// main blob first) and the blobs held by a still person's colour track.
    #[allow(clippy::type_complexity)]
    fn match_blobs(
        &self,
        ellipses: &[Ellipse],
    ) -> (Vec<Option<usize>>, Vec<Vec<usize>>, Vec<bool>) {
        let p = self.params;
        let gate2 = p.gate_sigma * p.gate_sigma;
        let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
        let mut held = vec![false; self.blobs.len()];
        for (ti, t) in self.tracks.iter().enumerate() {
            if t.ended {
                continue;
            }
            for (bi, e) in ellipses.iter().enumerate() {
                let Some(mut d2) = t.region.mahalanobis2(e.center) else {
                    continue;
                };
                if let Mode::Colour(_) = t.mode {
                    // the colour region sits inside the body (see the module doc): its centre
                    // within the gate of the blob's ellipse is as good a match
                    if let Some(back) = e.mahalanobis2(t.region.center) {
                        d2 = d2.min(back);
                    }
                }
                if d2 > gate2 {
                    continue;
                }
                if let Mode::Colour(why) = t.mode {
                    if why == HandOver::StandingStill
                        && t.anchor
                            .is_some_and(|a| (e.center - a).norm() < p.resume_px)
                    {
                        // the still person's own (fading) blob: it neither takes the track
                        // back nor starts a new one
                        held[bi] = true;
                        continue;
                    }
                    if t.region.covered_by(e) < p.reacquire_overlap {
                        continue;
                    }
                }
                pairs.push((d2, ti, bi));
            }
        }
        pairs.sort_by(|a, b| {
            a.0.total_cmp(&b.0)
                .then(self.tracks[a.1].id.cmp(&self.tracks[b.1].id))
                .then(a.2.cmp(&b.2))
        });
        let mut blob_owner: Vec<Option<usize>> = vec![None; self.blobs.len()];
        let mut track_blobs: Vec<Vec<usize>> = vec![Vec::new(); self.tracks.len()];
        for &(_, ti, bi) in &pairs {
            if blob_owner[bi].is_some() || !track_blobs[ti].is_empty() {
                continue;
            }
            blob_owner[bi] = Some(ti);
            track_blobs[ti].push(bi);
        }
        // fragments: unmatched blobs inside the 2σ ellipse of a matched track's blob
        let sigma2 = SHAPE_SIGMA * SHAPE_SIGMA;
        for bi in 0..self.blobs.len() {
            if blob_owner[bi].is_some() || held[bi] {
                continue;
            }
            let host = (0..self.tracks.len()).find(|&ti| {
                track_blobs[ti].first().is_some_and(|&main| {
                    ellipses[main]
                        .mahalanobis2(ellipses[bi].center)
                        .is_some_and(|d2| d2 <= sigma2)
                })
            });
            if let Some(ti) = host {
                blob_owner[bi] = Some(ti);
                track_blobs[ti].push(bi);
            }
        }
        (blob_owner, track_blobs, held)
    }

    /// Matched tracks take their blobs' merged region (back to blob mode); unmatched blob
    /// tracks count a miss; a blob track that stood still hands over to the colour tracker.
    fn update_matched(
        &mut self,
        bins: &BinImage,
        ellipses: &[Ellipse],
        track_blobs: &[Vec<usize>],
    ) {
        let p = self.params;
        for (ti, t) in self.tracks.iter_mut().enumerate() {
            if t.ended {
                continue;
            }
            let mine = &track_blobs[ti];
            if mine.is_empty() {
                if t.mode == Mode::Blob {
                    t.missed += 1;
                    if t.missed > p.max_missed {
                        t.ended = true;
                    }
                }
                continue;
            }
            if t.mode != Mode::Blob {
                self.stats.reacquired += 1;
                t.recent.clear();
                t.anchor = None;
            }
            let mut m = Moments::default();
            let mut bbox = [
                f64::INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::NEG_INFINITY,
            ];
            let mut labels = Vec::with_capacity(mine.len());
            for &bi in mine {
                let b = &self.blobs[bi];
                m = m.merged(&b.moments);
                bbox[0] = bbox[0].min(f64::from(b.bbox[0]));
                bbox[1] = bbox[1].min(f64::from(b.bbox[1]));
                bbox[2] = bbox[2].max(f64::from(b.bbox[2]) + 1.0);
                bbox[3] = bbox[3].max(f64::from(b.bbox[3]) + 1.0);
                labels.push(b.label);
            }
            labels.sort_unstable();
            let region = m
                .ellipse(blobs::PIXEL_VARIANCE)
                .unwrap_or(ellipses[mine[0]]);
            t.mode = Mode::Blob;
            t.missed = 0;
            t.region = region;
            if let Some(h) = kernel_histogram(bins, &region, p.em.cutoff_sigma) {
                t.model = Some(h);
            }
            t.seen = Some(Observation {
                track: t.id,
                mode: Mode::Blob,
                region,
                bbox,
                area_px: m.m00,
                similarity: None,
                iterations: None,
                blobs: labels,
            });
            // stillness
            t.travelled |= (region.center - t.birth).norm() >= p.min_travel_px;
            t.recent.push_back(region.center);
            while t.recent.len() > p.still_frames + 1 {
                t.recent.pop_front();
            }
            if t.travelled
                && t.recent.len() == p.still_frames + 1
                && let (Some(first), Some(last)) = (t.recent.front(), t.recent.back())
                && (last - first).norm() / (p.still_frames as f64) < p.still_speed_px
                && t.model.is_some()
            {
                t.mode = Mode::Colour(HandOver::StandingStill);
                t.anchor = Some(*last);
                t.body = Some(region);
                self.stats.handovers_still += 1;
            }
        }
    }

    /// New tracks from the blobs nobody took, in label order.
    fn start_tracks(
        &mut self,
        bins: &BinImage,
        ellipses: &[Ellipse],
        blob_owner: &[Option<usize>],
        held: &[bool],
    ) {
        let p = self.params;
        for (bi, b) in self.blobs.iter().enumerate() {
            if blob_owner[bi].is_some() || held[bi] {
                continue;
            }
            let region = ellipses[bi];
            let id = self.next_id;
            self.next_id += 1;
            self.stats.tracks_started += 1;
            let model = kernel_histogram(bins, &region, p.em.cutoff_sigma);
            let mut recent = VecDeque::new();
            recent.push_back(region.center);
            self.tracks.push(Track {
                id,
                mode: Mode::Blob,
                region,
                model,
                birth: region.center,
                travelled: false,
                recent,
                missed: 0,
                anchor: None,
                body: None,
                protected: false,
                ended: false,
                seen: Some(Observation {
                    track: id,
                    mode: Mode::Blob,
                    region,
                    bbox: [
                        f64::from(b.bbox[0]),
                        f64::from(b.bbox[1]),
                        f64::from(b.bbox[2]) + 1.0,
                        f64::from(b.bbox[3]) + 1.0,
                    ],
                    area_px: b.area(),
                    similarity: None,
                    iterations: None,
                    blobs: vec![b.label],
                }),
            });
        }
    }
}

mod careful;
mod fragments;
mod params;
pub use params::LocalParams;
#[cfg(test)]
mod tests;

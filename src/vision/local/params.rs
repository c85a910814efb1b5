//! [`LocalParams`]: the local tracker's parameters, their defaults (the values in
//! `pipelines/s003_zivkovic_background.toml`) and their range checks.

use super::*;

/// Parameters; [`Default`] gives the values in `pipelines/s003_zivkovic_background.toml`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LocalParams {
    /// The background model (OpenCV MOG2 defaults).
    pub gmm: GmmParams,
    pub connectivity: Connectivity,
    /// Apply the 3×3 majority filter to the foreground before labelling.
    pub majority_filter: bool,
    /// Smallest blob that is a person candidate (pixels).
    pub min_area_px: u64,
    /// Blobs sharing a column with at most this share of their union's height between them
    /// are fragments of one person (`local::fragments`); ≤ −1 turns grouping off.
    pub group_gap: f64,
    /// Only upright blobs (vertical variance of the moments ≥ horizontal) are person
    /// candidates, after grouping (Zajdel et al. §III-A: "just first two moments of the blobs
    /// to detect the interesting ones").
    pub upright_only: bool,
    /// A blob continues a track when its centroid is within this many σ of the track.
    pub gate_sigma: f64,
    /// Frames a blob track may go unseen before it ends.
    pub max_missed: u32,
    /// Window over which stillness is judged (frames).
    pub still_frames: usize,
    /// Below this mean centroid speed over the window a track is standing still (px/frame).
    pub still_speed_px: f64,
    /// Only tracks that have moved this far from their start are handed over when still (px).
    pub min_travel_px: f64,
    /// Frames after a (re)start of the background model during which no blobs are taken.
    pub warmup_frames: u32,
    /// After the warm-up the model learns at the steady α = 1/T (a still person joins the
    /// background after the paper's 220 frames) instead of OpenCV's bootstrap 1/(2n).
    pub steady_after_warmup: bool,
    /// Colour space of the colour tracker.
    pub color: ColorSpace,
    /// The colour tracker.
    pub em: EmParams,
    /// A colour-tracked track ends below this Bhattacharyya coefficient.
    pub min_similarity: f64,
    /// Fraction of a colour-tracked region's 2σ ellipse a blob's 2σ ellipse must cover to take
    /// the track back.
    pub reacquire_overlap: f64,
    /// A track that stood still is taken back by a blob only this far from where it stopped (px).
    pub resume_px: f64,
    /// After a restart, a colour-tracked track's body box (the √3σ box of its hand-over blob
    /// ellipse) times this is not learned while the track lives.
    pub protect_scale: f64,
    /// Frames after a restart at most during which protected boxes are not learned.
    pub protect_frames: u32,
    /// Random initialisations of the colour tracker per frame, besides the previous region.
    pub random_starts: u32,
    /// They are shifted uniformly within ± this many σ of the region, per axis.
    pub random_start_sigma: f64,
    /// A colour-tracked region whose size (√ of its ellipse's area) falls below this share of
    /// the body it was handed over with has collapsed: the track ends (0 never ends one).
    pub min_region_scale: f64,
}

impl Default for LocalParams {
    fn default() -> Self {
        Self {
            gmm: GmmParams::default(),
            connectivity: Connectivity::Eight,
            majority_filter: true,
            min_area_px: 120,
            group_gap: 0.3,
            upright_only: true,
            gate_sigma: 3.0,
            max_missed: 5,
            still_frames: 15,
            still_speed_px: 0.5,
            min_travel_px: 10.0,
            warmup_frames: 30,
            steady_after_warmup: true,
            color: ColorSpace::Hs,
            // β consistent with the 2-D cut-off: the paper's 1.1 shrinks the region every
            // frame (see `colortrack::consistent_beta`), which a long hand-over cannot afford
            em: EmParams {
                shape: Shape::Diagonal,
                beta: consistent_beta(DEFAULT_CUTOFF_SIGMA),
                ..EmParams::default()
            },
            min_similarity: 0.6,
            reacquire_overlap: 0.3,
            resume_px: 8.0,
            protect_scale: 2.0,
            protect_frames: 220,
            random_starts: 0,
            random_start_sigma: 1.0,
            min_region_scale: 0.25,
        }
    }
}

impl LocalParams {
    pub fn validate(&self) -> Result<(), LocalError> {
        self.gmm.validate()?;
        self.em.validate()?;
        let bad = |name, value: f64, why| Err(LocalError::BadParam { name, value, why });
        for (name, v) in [
            ("gate_sigma", self.gate_sigma),
            ("still_speed_px", self.still_speed_px),
            ("min_travel_px", self.min_travel_px),
            ("resume_px", self.resume_px),
            ("protect_scale", self.protect_scale),
            ("random_start_sigma", self.random_start_sigma),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(name, v, "must be finite and non-negative");
            }
        }
        for (name, v) in [
            ("min_similarity", self.min_similarity),
            ("reacquire_overlap", self.reacquire_overlap),
            ("min_region_scale", self.min_region_scale),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return bad(name, v, "must be in [0, 1]");
            }
        }
        if !self.group_gap.is_finite() {
            return bad("group_gap", self.group_gap, "must be finite");
        }
        if self.still_frames == 0 {
            return bad("still_frames", 0.0, "must be at least 1");
        }
        Ok(())
    }
}

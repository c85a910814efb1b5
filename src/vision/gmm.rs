//! Adaptive Gaussian-mixture background subtraction: Z. Zivkovic, "Improved Adaptive Gaussian
//! Mixture Model for Background Subtraction", ICPR 2004 (sections 3–4, eq. 1–14), the
//! algorithm behind OpenCV's `BackgroundSubtractorMOG2`, and the Stauffer–Grimson baseline
//! the paper compares it with ([`GmmParams::stauffer_grimson`]).
//!
//! Every pixel holds up to M components (weight π, isotropic variance σ², mean µ over the 1 or
//! 3 channels), sorted by descending weight. For each new sample x:
//!
//! - every component's weight follows eq. 14, `π ← (1 − α)π − αc_T (+ α if it owns x)`;
//!   a component whose weight falls below `αc_T` after that step is dropped (OpenCV's test,
//!   [`Pruning::OpenCv`], the default); [`Pruning::Negative`] drops it, as the paper prints,
//!   "when its weight π_m becomes negative" (below 0) — the kernel takes both rules, it only
//!   changes the comparison's threshold;
//! - the first component (in weight order) with squared Mahalanobis distance
//!   `|x − µ|²/σ² < varThresholdGen` owns x: eq. 5–6 update its mean and variance with
//!   `α/π`, the variance is clamped to `[fVarMin, fVarMax]`, and it moves up the weight order;
//! - the pixel is background if that test passes with `varThreshold` (c_thr, eq. 2) for a
//!   component among the first B of eq. 8 (cumulative weight before it `< 1 − c_f`);
//! - weights are renormalised; if no component owns x a new one starts at µ = x,
//!   σ² = fVarInit, π = α (1 for the first), replacing the weakest when M are in use;
//! - a foreground pixel that is a darker copy of a background component (brightness ratio
//!   in [τ, 1], colour distortion within `varThreshold`: Prati et al., OpenCV's
//!   `detectShadowGMM`) is a shadow.
//!
//! **Selective learning** ([`AdaptiveGmm::apply_selective`]): a per-pixel update mask; a
//! pixel left out keeps its mixture exactly (used by `vision::local` for the careful restart
//! after the camera stops). Its mask is still written; with every pixel learning it is
//! [`AdaptiveGmm::apply`] bit for bit.
//!
//! Mask values: [`BACKGROUND`] 0, shadow [`GmmParams::shadow_value`] (127), [`FOREGROUND`] 255.
//! The learning rate follows OpenCV: `α = 1/min(2n, history)` on frame n unless the caller
//! gives one (and the first frame always uses 1/2).
//!
//! **Agreement with OpenCV.** The arithmetic is OpenCV's, in `f32`, in the same order and
//! without fused multiply-adds, so the same parameters on the same 8-bit frames give the
//! same masks bit for bit (`make opencv-agreement` measures it: 100 % of pixels equal on
//! Wallflower WavingTrees and on synthetic RGB, grey and Stauffer–Grimson runs, OpenCV
//! 4.12). Bit-exactness assumes the same channel order on both sides: BGR instead of RGB
//! may round the distance sums differently (on WavingTrees it changed no pixel).
//!
//! Differences by design: a frame whose shape differs from the model's is an error here
//! (OpenCV silently restarts; call [`AdaptiveGmm::reset`]); a negative or NaN learning rate
//! is an error (use `None`). As in OpenCV, a learning rate ≥ 1 restarts the model.
//!
//! **Speed.** The state is structure-of-arrays in groups of 8 neighbouring pixels (per
//! component slot, separate lane vectors of weights, variances and each channel's means),
//! updated in lock-step with lane masks for the per-pixel component count (`kernel`): one
//! SIMD instruction per step of the recursion for 8 pixels. AVX2 (`std::arch`) is chosen at
//! run time when present, plain arrays otherwise (`kernel` says why not the `wide` crate).
//! Rows run in parallel with rayon, in blocks of at least 16; pixels never interact, so the masks are identical for
//! any thread count. `make bench-gmm` measures frames/s beside OpenCV MOG2 on the same frames.
//!
//! **Saved state** ([`AdaptiveGmm::save`] / [`AdaptiveGmm::load`] in `saved`; OpenCV cannot
//! do this), all numbers little-endian:
//!
//! ```text
//! magic    b"PTGMM\0", version u16 = 1 (OpenCV's pruning) or 2 (any other pruning rule)
//! params   history u32, var_threshold f32, n_mixtures u32, background_ratio f32,
//!          var_threshold_gen f32, var_init f32, var_min f32, var_max f32,
//!          complexity_reduction f32, detect_shadows u8, shadow_threshold f32, shadow_value u8,
//!          version 2 only: pruning u8 (1 = Pruning::Negative)
//! frames   frames seen u64 (the learning-rate schedule)
//! shape    width u32, height u32, channels u8 (all 0 before the first frame)
//! pixels   width*height records in row-major order: n u8 (≤ n_mixtures), then n components
//!          of (weight f32, variance f32, mean f32 × channels), in weight order
//! ```
//!
//! Not done here: morphological post-filtering, colour-space conversion, frame-to-frame
//! (temporal) reasoning beyond the per-pixel recursion.

mod kernel;
#[cfg(test)]
mod pruning_tests;
#[cfg(test)]
mod reference;
mod saved;
#[cfg(test)]
mod tests;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::view::ImageView;
use kernel::{Coeffs, Isa, LANES, LaneBuf, Layout};

/// Mask value of a background pixel.
pub const BACKGROUND: u8 = 0;
/// Mask value of a foreground pixel.
pub const FOREGROUND: u8 = 255;
/// Largest number of components per pixel accepted (OpenCV's default is 5).
pub const MAX_MIXTURES: usize = 16;

/// History T in frames (α = 1/T once the start-up schedule is over); OpenCV's default.
pub const DEFAULT_HISTORY: u32 = 500;
/// c_thr of eq. 2 as a squared Mahalanobis distance (4σ); OpenCV's `varThreshold`.
pub const DEFAULT_VAR_THRESHOLD: f32 = 16.0;
/// Maximum number of components M; OpenCV's `nmixtures`.
pub const DEFAULT_N_MIXTURES: usize = 5;
/// 1 − c_f of eq. 8 (c_f = 0.1); OpenCV's `backgroundRatio`.
pub const DEFAULT_BACKGROUND_RATIO: f32 = 0.9;
/// Ownership ("close") threshold as a squared Mahalanobis distance (3σ); `varThresholdGen`.
pub const DEFAULT_VAR_THRESHOLD_GEN: f32 = 9.0;
/// σ₀² of a new component, in grey levels²; OpenCV's `fVarInit`.
pub const DEFAULT_VAR_INIT: f32 = 15.0;
/// Lower clamp of σ², grey levels²; OpenCV's `fVarMin`.
pub const DEFAULT_VAR_MIN: f32 = 4.0;
/// Upper clamp of σ², grey levels² (5 σ₀²); OpenCV's `fVarMax`.
pub const DEFAULT_VAR_MAX: f32 = 75.0;
/// c_T of eq. 14, the Dirichlet-prior (complexity reduction) constant; OpenCV's `fCT`.
pub const DEFAULT_COMPLEXITY_REDUCTION: f32 = 0.05;
/// τ: a shadow is at least this fraction of the background's brightness; OpenCV's `fTau`.
pub const DEFAULT_SHADOW_THRESHOLD: f32 = 0.5;
/// Mask value of a shadow pixel; OpenCV's `nShadowDetection`.
pub const DEFAULT_SHADOW_VALUE: u8 = 127;

/// Errors of the background subtractor. Nothing here panics on input.
#[derive(Debug, thiserror::Error)]
pub enum GmmError {
    #[error("the model takes 1 (grey) or 3 (colour) channels, not {channels}")]
    UnsupportedChannels { channels: usize },
    #[error("mask has {have} bytes, the frame has {need} pixels")]
    MaskSize { have: usize, need: usize },
    #[error("update mask has {have} flags, the frame has {need} pixels")]
    UpdateMaskSize { have: usize, need: usize },
    #[error(
        "frame is {width}x{height}x{channels} but the model holds {model_width}x{model_height}x{model_channels} (call reset to start over)"
    )]
    ShapeMismatch {
        width: usize,
        height: usize,
        channels: usize,
        model_width: usize,
        model_height: usize,
        model_channels: usize,
    },
    #[error("learning rate {0} is negative or NaN (use None for OpenCV's automatic rate)")]
    BadLearningRate(f32),
    #[error("parameter `{name}` = {value} {why}")]
    BadParam {
        name: &'static str,
        value: f64,
        why: &'static str,
    },
    #[error("the model has seen no frame yet")]
    NoFrames,
    #[error("pixel ({x}, {y}) is outside the {width}x{height} model")]
    OutOfBounds {
        x: usize,
        y: usize,
        width: usize,
        height: usize,
    },
    #[error("saved model state is invalid: {what}")]
    BadState { what: String },
    // no `#[from]`: a source would be printed twice in an error chain (`From` is below)
    #[error("saved model state: {0}")]
    Io(std::io::Error),
}

impl From<std::io::Error> for GmmError {
    fn from(e: std::io::Error) -> Self {
        GmmError::Io(e)
    }
}

/// When eq. 14 drops a component that the data no longer support.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Pruning {
    /// OpenCV MOG2's test: drop when the weight after eq. 14 is below `αc_T` (TOML `"opencv"`).
    #[default]
    #[serde(rename = "opencv")]
    OpenCv,
    /// The paper's sentence (Zivkovic 2004, section 4): "we discard the component m when its
    /// weight π_m becomes negative", i.e. below 0 after eq. 14 (TOML `"negative"`).
    Negative,
}

/// Parameters; [`Default`] gives OpenCV MOG2's defaults.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GmmParams {
    /// T in frames: the automatic learning rate settles at α = 1/T.
    pub history: u32,
    /// c_thr of eq. 2 as a squared Mahalanobis distance: background if closer than this.
    pub var_threshold: f32,
    /// M, the most components a pixel may hold.
    pub n_mixtures: usize,
    /// 1 − c_f of eq. 8: the first components whose weights reach this are background.
    pub background_ratio: f32,
    /// Squared Mahalanobis distance under which a component owns a sample.
    pub var_threshold_gen: f32,
    /// σ₀², variance of a new component (grey levels²).
    pub var_init: f32,
    /// Lower clamp of a component's variance (grey levels²).
    pub var_min: f32,
    /// Upper clamp of a component's variance (grey levels²).
    pub var_max: f32,
    /// c_T of eq. 14; 0 gives the Stauffer–Grimson update (no prior, nothing dropped).
    pub complexity_reduction: f32,
    /// Mark shadows with [`Self::shadow_value`] instead of foreground.
    pub detect_shadows: bool,
    /// τ: lowest brightness ratio of a shadow to the background.
    pub shadow_threshold: f32,
    /// Mask value of a shadow pixel.
    pub shadow_value: u8,
    /// When a component is dropped (OpenCV's rule by default).
    pub pruning: Pruning,
}

impl Default for GmmParams {
    fn default() -> Self {
        Self {
            history: DEFAULT_HISTORY,
            var_threshold: DEFAULT_VAR_THRESHOLD,
            n_mixtures: DEFAULT_N_MIXTURES,
            background_ratio: DEFAULT_BACKGROUND_RATIO,
            var_threshold_gen: DEFAULT_VAR_THRESHOLD_GEN,
            var_init: DEFAULT_VAR_INIT,
            var_min: DEFAULT_VAR_MIN,
            var_max: DEFAULT_VAR_MAX,
            complexity_reduction: DEFAULT_COMPLEXITY_REDUCTION,
            detect_shadows: true,
            shadow_threshold: DEFAULT_SHADOW_THRESHOLD,
            shadow_value: DEFAULT_SHADOW_VALUE,
            pruning: Pruning::OpenCv,
        }
    }
}

impl GmmParams {
    /// The baseline of the paper's experiments (Stauffer & Grimson, CVPR 1999, as the paper
    /// and OpenCV model it): a fixed budget of M = 4 components and no Dirichlet prior
    /// (c_T = 0), so no component is ever dropped; everything else as [`Default`].
    /// (The original ranks components by π/σ and uses a per-component learning rate; like
    /// the paper, we keep the common update and change only M and c_T. The original as
    /// published is [`super::sg1999`].)
    pub fn stauffer_grimson() -> Self {
        Self {
            n_mixtures: 4,
            complexity_reduction: 0.0,
            ..Self::default()
        }
    }

    /// Zivkovic's model as the paper prints it (section 4): c_T = 0.01 ("at least
    /// c = 0.01 · T samples support a component"), a component dropped when its weight
    /// becomes negative ([`Pruning::Negative`]), T = 500. The paper states no largest number
    /// of components: M = 5 is OpenCV's; everything else as [`Default`] (OpenCV's).
    pub fn zivkovic_printed() -> Self {
        Self {
            complexity_reduction: 0.01,
            pruning: Pruning::Negative,
            ..Self::default()
        }
    }

    /// Check every parameter: finite, non-negative, M in `1..=MAX_MIXTURES`, T ≥ 1.
    pub fn validate(&self) -> Result<(), GmmError> {
        let bad = |name, value: f64, why| Err(GmmError::BadParam { name, value, why });
        if self.history == 0 {
            return bad("history", 0.0, "must be at least 1 frame");
        }
        if self.n_mixtures == 0 || self.n_mixtures > MAX_MIXTURES {
            return bad(
                "n_mixtures",
                self.n_mixtures as f64,
                "must be between 1 and 16",
            );
        }
        for (name, v) in [
            ("var_threshold", self.var_threshold),
            ("background_ratio", self.background_ratio),
            ("var_threshold_gen", self.var_threshold_gen),
            ("var_init", self.var_init),
            ("var_min", self.var_min),
            ("var_max", self.var_max),
            ("complexity_reduction", self.complexity_reduction),
            ("shadow_threshold", self.shadow_threshold),
        ] {
            if !v.is_finite() || v < 0.0 {
                return bad(name, f64::from(v), "must be finite and non-negative");
            }
        }
        Ok(())
    }
}

/// One component of a pixel's mixture (for inspection and tests).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Component {
    /// π, the mixing weight.
    pub weight: f32,
    /// σ², grey levels².
    pub variance: f32,
    /// µ per channel; a grey model uses `mean[0]` only.
    pub mean: [f32; 3],
}

/// Shape of the frames a model holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Shape {
    width: usize,
    height: usize,
    channels: usize,
}

/// Where one pixel's mixture lives in [`AdaptiveGmm::state`].
#[derive(Debug, Clone, Copy)]
struct PixelAt {
    /// First lane vector of the pixel's row.
    row_base: usize,
    layout: Layout,
    /// Group within the row.
    g: usize,
    /// Index of the group in [`AdaptiveGmm::modes`].
    group: usize,
    lane: usize,
}

/// Zivkovic's adaptive GMM background subtractor (or, with
/// [`GmmParams::stauffer_grimson`], the fixed-M baseline).
#[derive(Debug, Clone)]
pub struct AdaptiveGmm {
    params: GmmParams,
    /// Frames seen since the model was (re)initialised.
    frames: u64,
    shape: Option<Shape>,
    /// Rows of [`Layout::row_len`] lane vectors (see `kernel` for the layout).
    state: LaneBuf,
    /// Per row, one lane vector of component counts per group.
    modes: Vec<[u8; LANES]>,
}

impl AdaptiveGmm {
    /// A model with no frame seen yet; its shape is fixed by the first frame.
    pub fn new(params: GmmParams) -> Result<Self, GmmError> {
        params.validate()?;
        Ok(Self {
            params,
            frames: 0,
            shape: None,
            state: LaneBuf::default(),
            modes: Vec::new(),
        })
    }

    pub fn params(&self) -> &GmmParams {
        &self.params
    }

    /// Frames seen since the model started (drives the automatic learning rate).
    pub fn frames_seen(&self) -> u64 {
        self.frames
    }

    /// `(width, height, channels)` of the frames the model holds, once it has seen one.
    pub fn shape(&self) -> Option<(usize, usize, usize)> {
        self.shape.map(|s| (s.width, s.height, s.channels))
    }

    /// Forget everything: the next frame starts a new model (of any shape).
    pub fn reset(&mut self) {
        self.frames = 0;
        self.shape = None;
        self.state = LaneBuf::default();
        self.modes = Vec::new();
    }

    /// The learning rate α that [`Self::apply`] uses for the next frame given `learning_rate`
    /// (OpenCV's rule, in `f64` as OpenCV computes it).
    fn next_alpha(&self, learning_rate: Option<f32>, restart: bool) -> f64 {
        let n = if restart { 1 } else { self.frames + 1 };
        match learning_rate {
            Some(lr) if n > 1 => f64::from(lr),
            _ => 1.0 / (2 * n).min(u64::from(self.params.history)) as f64,
        }
    }

    /// Update the model with `frame` and write its mask (0 background, 255 foreground,
    /// [`GmmParams::shadow_value`] shadow) into `mask`, one byte per pixel, row-major.
    ///
    /// `learning_rate`: `None` for OpenCV's automatic rate, `Some(α)` with α ≥ 0 otherwise
    /// (α = 0 freezes the model; α ≥ 1 restarts it from this frame, as OpenCV does).
    pub fn apply(
        &mut self,
        frame: ImageView<'_>,
        learning_rate: Option<f32>,
        mask: &mut [u8],
    ) -> Result<(), GmmError> {
        self.apply_with(Isa::detect(), frame, learning_rate, None, mask)
    }

    /// [`Self::apply`] with selective learning: only the pixels whose `learn` flag is set
    /// (one per pixel, row-major) update their mixture; a frozen pixel's model stays exactly
    /// as it was (no weight decays, no component is created or dropped — before its first
    /// update it has no component at all). Every pixel's mask is what [`Self::apply`] would
    /// write for this frame, and the learning-rate schedule counts the frame for all pixels.
    /// With every flag set the result is bit for bit that of [`Self::apply`].
    ///
    /// This is the careful restart of Zajdel et al. (ICRA 2005, §III-A): "the objects that
    /// were tracked during the moving phase might stay still and occlude a part of the
    /// background. This part of the background is learned only when the objects … leave".
    pub fn apply_selective(
        &mut self,
        frame: ImageView<'_>,
        learning_rate: Option<f32>,
        learn: &[bool],
        mask: &mut [u8],
    ) -> Result<(), GmmError> {
        if learn.len() != frame.pixels() {
            return Err(GmmError::UpdateMaskSize {
                have: learn.len(),
                need: frame.pixels(),
            });
        }
        let learn = (!learn.iter().all(|&l| l)).then_some(learn);
        self.apply_with(Isa::detect(), frame, learning_rate, learn, mask)
    }

    /// [`Self::apply`] / [`Self::apply_selective`] on a given instruction set (the tests run
    /// every one available); `learn` has been checked to hold one flag per pixel.
    fn apply_with(
        &mut self,
        isa: Isa,
        frame: ImageView<'_>,
        learning_rate: Option<f32>,
        learn: Option<&[bool]>,
        mask: &mut [u8],
    ) -> Result<(), GmmError> {
        let shape = Shape {
            width: frame.width(),
            height: frame.height(),
            channels: frame.channels(),
        };
        if shape.channels != 1 && shape.channels != 3 {
            return Err(GmmError::UnsupportedChannels {
                channels: shape.channels,
            });
        }
        if mask.len() != frame.pixels() {
            return Err(GmmError::MaskSize {
                have: mask.len(),
                need: frame.pixels(),
            });
        }
        if let Some(lr) = learning_rate
            && (lr.is_nan() || lr < 0.0)
        {
            return Err(GmmError::BadLearningRate(lr));
        }
        if let Some(have) = self.shape
            && have != shape
        {
            return Err(GmmError::ShapeMismatch {
                width: shape.width,
                height: shape.height,
                channels: shape.channels,
                model_width: have.width,
                model_height: have.height,
                model_channels: have.channels,
            });
        }
        let restart = self.shape.is_none() || learning_rate.is_some_and(|lr| lr >= 1.0);
        let alpha = self.next_alpha(learning_rate, restart);
        if restart {
            self.init(shape);
        }
        self.frames += 1;
        let co = self.coeffs(alpha);

        let layout = self.layout(shape);
        let (groups, row_state) = (layout.groups, layout.row_len());
        let row_bytes = shape.width * shape.channels;
        self.state
            .as_mut_slice()
            .par_chunks_mut(row_state)
            .zip(self.modes.par_chunks_mut(groups))
            .zip(frame.data().par_chunks(row_bytes))
            .zip(mask.par_chunks_mut(shape.width))
            .enumerate()
            // Blocks of at least 16 rows per task: split row by row, the two threads of a
            // 640x480 frame scaled 1.69-1.78x; in blocks, 1.99x (`make bench-gmm`, 2026-11-25).
            .with_min_len(16)
            .for_each(|(y, (((state, modes), pixels), mask))| {
                let learn = learn.map(|l| &l[y * shape.width..(y + 1) * shape.width]);
                kernel::update_row(isa, shape.channels, state, modes, pixels, mask, learn, &co);
            });
        Ok(())
    }

    fn init(&mut self, shape: Shape) {
        let layout = self.layout(shape);
        self.frames = 0;
        self.shape = Some(shape);
        self.state = LaneBuf::zeroed(layout.row_len() * shape.height);
        self.modes = vec![[0; LANES]; layout.groups * shape.height];
    }

    /// The per-frame constants, rounded to `f32` where and as OpenCV rounds them.
    fn coeffs(&self, alpha: f64) -> Coeffs {
        let p = &self.params;
        let alpha_f = alpha as f32;
        Coeffs {
            alpha: alpha_f,
            alpha1: 1.0 - alpha_f,
            prune: (-alpha * f64::from(p.complexity_reduction)) as f32,
            drop_below: match p.pruning {
                Pruning::OpenCv => -((-alpha * f64::from(p.complexity_reduction)) as f32),
                Pruning::Negative => 0.0,
            },
            tb: p.var_threshold,
            background_ratio: p.background_ratio,
            tg: p.var_threshold_gen,
            var_init: p.var_init,
            var_min: p.var_min.min(p.var_max),
            var_max: p.var_min.max(p.var_max),
            tau: p.shadow_threshold,
            detect_shadows: p.detect_shadows,
            shadow_value: p.shadow_value,
            n_mix: p.n_mixtures,
        }
    }

    fn layout(&self, shape: Shape) -> Layout {
        Layout::new(shape.width, self.params.n_mixtures, shape.channels)
    }

    fn pixel_at(&self, shape: Shape, x: usize, y: usize) -> PixelAt {
        let layout = self.layout(shape);
        let g = x / LANES;
        PixelAt {
            row_base: y * layout.row_len(),
            layout,
            g,
            group: y * layout.groups + g,
            lane: x % LANES,
        }
    }

    /// Field `f` (0 weight, 1 variance, 2.. mean) of component `k` of a pixel.
    fn field(&self, p: PixelAt, k: usize, f: usize) -> f32 {
        self.state.as_slice()[p.row_base + p.layout.index(p.g, k, f)][p.lane]
    }

    fn field_mut(&mut self, p: PixelAt, k: usize, f: usize) -> &mut f32 {
        &mut self.state.as_mut_slice()[p.row_base + p.layout.index(p.g, k, f)][p.lane]
    }

    fn count(&self, p: PixelAt) -> usize {
        usize::from(self.modes[p.group][p.lane])
    }

    /// The components of pixel `(x, y)`, in weight order.
    pub fn components(&self, x: usize, y: usize) -> Result<Vec<Component>, GmmError> {
        let shape = self.shape.ok_or(GmmError::NoFrames)?;
        if x >= shape.width || y >= shape.height {
            return Err(GmmError::OutOfBounds {
                x,
                y,
                width: shape.width,
                height: shape.height,
            });
        }
        let p = self.pixel_at(shape, x, y);
        Ok((0..self.count(p))
            .map(|k| {
                let mut mean = [0.0; 3];
                for (c, m) in mean.iter_mut().enumerate().take(shape.channels) {
                    *m = self.field(p, k, 2 + c);
                }
                Component {
                    weight: self.field(p, k, 0),
                    variance: self.field(p, k, 1),
                    mean,
                }
            })
            .collect())
    }

    /// Number of components in use per pixel, row-major (the grey image of the paper's
    /// fig. 2 once scaled); empty before the first frame.
    pub fn components_per_pixel(&self) -> Vec<u8> {
        let Some(shape) = self.shape else {
            return Vec::new();
        };
        let groups = self.layout(shape).groups;
        let mut out = Vec::with_capacity(shape.width * shape.height);
        for row in self.modes.chunks_exact(groups) {
            out.extend(row.iter().flatten().take(shape.width));
        }
        out
    }

    /// The background as OpenCV's `getBackgroundImage` computes it: per pixel, the
    /// weight-averaged mean of the first components whose weights exceed
    /// `background_ratio`, rounded to 8 bits; `width * height * channels` bytes.
    pub fn background_image(&self) -> Result<Vec<u8>, GmmError> {
        let shape = self.shape.ok_or(GmmError::NoFrames)?;
        let mut out = Vec::with_capacity(shape.width * shape.height * shape.channels);
        for y in 0..shape.height {
            for x in 0..shape.width {
                let p = self.pixel_at(shape, x, y);
                let mut sum = [0.0f32; 3];
                let mut total = 0.0f32;
                for k in 0..self.count(p) {
                    let w = self.field(p, k, 0);
                    for (c, s) in sum.iter_mut().enumerate().take(shape.channels) {
                        *s += w * self.field(p, k, 2 + c);
                    }
                    total += w;
                    if total > self.params.background_ratio {
                        break;
                    }
                }
                let inv = if total.abs() > f32::EPSILON {
                    1.0 / total
                } else {
                    0.0
                };
                for s in sum.iter().take(shape.channels) {
                    out.push((s * inv).round_ties_even().clamp(0.0, 255.0) as u8);
                }
            }
        }
        Ok(out)
    }
}

//! Stauffer & Grimson's adaptive background mixture model as originally published: C.
//! Stauffer and W. E. L. Grimson, "Adaptive background mixture models for real-time
//! tracking", CVPR 1999, section 3 — the "original algorithm [3]" of seed 003's comparison,
//! beside [`super::gmm`] (Zivkovic / OpenCV MOG2, whose `GmmParams::stauffer_grimson` is the
//! common update with M = 4 and c_T = 0, as the later papers and OpenCV model the baseline).
//!
//! Every pixel holds up to K components (weight ω, isotropic covariance σ²I — the paper's
//! simplification for RGB —, mean µ over the 1 or 3 channels), kept in the order of ω/σ
//! (descending). For each new sample x, in `f64`:
//!
//! - the first component in that order with `|x − µ|²/σ² < 2.5²` ("within 2.5 standard
//!   deviations") matches (M = 1 for it, 0 for the rest);
//! - every weight follows `ω ← (1 − α)ω + αM`;
//! - the matched component: `ρ = α η(x | µ, σ)` (η the Gaussian density of the
//!   1- or 3-D sample, in grey levels), `µ ← (1 − ρ)µ + ρx`,
//!   `σ² ← (1 − ρ)σ² + ρ (x − µ)ᵀ(x − µ)` with the new µ, as printed;
//!   unmatched components keep µ and σ;
//! - no match: the least probable component (last in ω/σ order; a free slot while fewer
//!   than K are in use) is replaced by µ = x, a high variance and a low weight;
//! - the weights are renormalised to sum to one and the components re-sorted by ω/σ.
//!
//! The background is the first B components in ω/σ order with
//! `B = argmin_b (Σ_{k≤b} ω_k > T)`. The model's own decision ([`Sg1999::apply`]): x is
//! background when the component it matched is among the first B. For a ROC
//! ([`Sg1999::apply_distance`]) the decision threshold is swept instead: the smallest squared
//! Mahalanobis distance `|x − µ|²/σ²` to one of the first B components is returned per
//! pixel, background when it is below c_thr (at c_thr = 6.25 this is the model's own
//! decision); the model's update — its match — always uses 2.5σ. The decision reads the
//! model before the sample updates it. No shadow detection (the original has none): a mask
//! is 0 or 255.
//!
//! **Values the original leaves open**, and where ours come from:
//!
//! - α: the paper's constant learning rate, `1 / history` with `history` = 500 (T of
//!   Zivkovic's experiments and OpenCV's default), from the first frame on (no start-up
//!   schedule: the original has none);
//! - K = 4: Zivkovic's experiments use the original "with fixed number of components
//!   M = 4" (the original says "3 to 5");
//! - T = 0.9: the same as the other models' `background_ratio` (1 − c_f), so the rows
//!   differ only by the model;
//! - "an initially high variance": σ₀² = 900 (σ₀ = 30 grey levels) and "a low prior
//!   weight": 0.05 — OpenCV's legacy `BackgroundSubtractorMOG` (bgsegm, KaewTraKulPong &
//!   Bowden's implementation of this model): `var0 = (2 · defaultNoiseSigma)²` with
//!   `defaultNoiseSigma = 15`, `defaultInitialWeight = 0.05`;
//! - a variance floor of 4 grey levels² (`var_min`, MOG2's `fVarMin`) and ρ ≤ 1: not in the
//!   original; without them a noise-free pixel's σ shrinks towards 0, η grows without bound
//!   and ρ = αη exceeds 1;
//! - `(x − µ)ᵀ(x − µ)` is the 3-channel sum, as printed (and as Zivkovic's eq. 6 and OpenCV
//!   compute it), not divided by the number of channels;
//! - with no match the weights are first updated with M = 0 for all, then the replacement
//!   gets its low weight, then all are renormalised.
//!
//! Pixels never interact: rows run in parallel with rayon and the output does not depend on
//! the thread count. This is a plain scalar model (no SIMD): it is a baseline, not a product.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::gmm::{BACKGROUND, FOREGROUND, GmmError, MAX_MIXTURES};
use super::view::ImageView;

/// Parameters; [`Default`] gives the values listed in the module documentation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Sg1999Params {
    /// K, the number of components per pixel.
    pub k: usize,
    /// α = 1 / history, constant.
    pub history: u32,
    /// A sample matches a component within this many standard deviations (2.5).
    pub match_sigma: f64,
    /// T: the first B components (ω/σ order) whose weights exceed it are background.
    pub background_ratio: f64,
    /// σ₀² of a replacement component (grey levels², "an initially high variance").
    pub var_init: f64,
    /// ω of a replacement component before renormalisation ("low prior weight").
    pub weight_init: f64,
    /// Floor of σ² (grey levels²); not in the original (see the module documentation).
    pub var_min: f64,
}

impl Default for Sg1999Params {
    fn default() -> Self {
        Self {
            k: 4,
            history: 500,
            match_sigma: 2.5,
            background_ratio: 0.9,
            var_init: 900.0,
            weight_init: 0.05,
            var_min: 4.0,
        }
    }
}

impl Sg1999Params {
    /// Check every parameter: K in `1..=16`, history ≥ 1, finite positive values.
    pub fn validate(&self) -> Result<(), GmmError> {
        let bad = |name, value: f64, why| Err(GmmError::BadParam { name, value, why });
        if self.k == 0 || self.k > MAX_MIXTURES {
            return bad("k", self.k as f64, "must be between 1 and 16");
        }
        if self.history == 0 {
            return bad("history", 0.0, "must be at least 1 frame");
        }
        for (name, v) in [
            ("match_sigma", self.match_sigma),
            ("background_ratio", self.background_ratio),
            ("var_init", self.var_init),
            ("weight_init", self.weight_init),
            ("var_min", self.var_min),
        ] {
            if !v.is_finite() || v <= 0.0 {
                return bad(name, v, "must be finite and positive");
            }
        }
        Ok(())
    }
}

/// One component of a pixel's mixture.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SgComponent {
    /// ω, the prior weight.
    pub weight: f64,
    /// σ², grey levels².
    pub variance: f64,
    /// µ per channel; a grey model uses `mean[0]` only.
    pub mean: [f64; 3],
}

impl SgComponent {
    /// The ranking key ω/σ.
    fn key(&self) -> f64 {
        self.weight / self.variance.sqrt()
    }

    fn dist2(&self, x: &[f64; 3], channels: usize) -> f64 {
        let d: f64 = (0..channels).map(|c| (x[c] - self.mean[c]).powi(2)).sum();
        d / self.variance
    }
}

/// The Stauffer–Grimson (1999) background model of a sequence of frames.
#[derive(Debug, Clone)]
pub struct Sg1999 {
    params: Sg1999Params,
    /// `(width, height, channels)` once a frame was seen.
    shape: Option<(usize, usize, usize)>,
    /// K slots per pixel, the first `used[p]` of which are the mixture in ω/σ order.
    slots: Vec<SgComponent>,
    used: Vec<u8>,
}

impl Sg1999 {
    pub fn new(params: Sg1999Params) -> Result<Self, GmmError> {
        params.validate()?;
        Ok(Self {
            params,
            shape: None,
            slots: Vec::new(),
            used: Vec::new(),
        })
    }

    pub fn params(&self) -> &Sg1999Params {
        &self.params
    }

    /// Update with `frame`; `mask` gets the model's own decision (0 background, 255
    /// foreground: the matched component is / is not among the first B).
    pub fn apply(&mut self, frame: ImageView<'_>, mask: &mut [u8]) -> Result<(), GmmError> {
        let mut dist2 = vec![0.0f32; mask.len()];
        self.run(frame, &mut dist2, mask)
    }

    /// Update with `frame`; `dist2` gets, per pixel, the smallest squared Mahalanobis distance
    /// to one of the first B components before the update (∞ when the pixel had none): the
    /// pixel is background at c_thr when `dist2 < c_thr`.
    pub fn apply_distance(
        &mut self,
        frame: ImageView<'_>,
        dist2: &mut [f32],
    ) -> Result<(), GmmError> {
        let mut mask = vec![0u8; dist2.len()];
        self.run(frame, dist2, &mut mask)
    }

    fn run(
        &mut self,
        frame: ImageView<'_>,
        dist2: &mut [f32],
        mask: &mut [u8],
    ) -> Result<(), GmmError> {
        let shape = (frame.width(), frame.height(), frame.channels());
        let (w, _, channels) = shape;
        if channels != 1 && channels != 3 {
            return Err(GmmError::UnsupportedChannels { channels });
        }
        for have in [dist2.len(), mask.len()] {
            if have != frame.pixels() {
                return Err(GmmError::MaskSize {
                    have,
                    need: frame.pixels(),
                });
            }
        }
        match self.shape {
            Some(have) if have != shape => {
                return Err(GmmError::ShapeMismatch {
                    width: shape.0,
                    height: shape.1,
                    channels,
                    model_width: have.0,
                    model_height: have.1,
                    model_channels: have.2,
                });
            }
            Some(_) => {}
            None => {
                self.shape = Some(shape);
                self.slots = vec![SgComponent::default(); frame.pixels() * self.params.k];
                self.used = vec![0; frame.pixels()];
            }
        }
        if w == 0 {
            return Ok(());
        }
        let p = self.params;
        let k = p.k;
        self.slots
            .par_chunks_mut(w * k)
            .zip(self.used.par_chunks_mut(w))
            .zip(frame.data().par_chunks(w * channels))
            .zip(dist2.par_chunks_mut(w).zip(mask.par_chunks_mut(w)))
            .for_each(|(((slots, used), pixels), (dist2, mask))| {
                for (i, n) in used.iter_mut().enumerate() {
                    let mut x = [0.0f64; 3];
                    for (c, v) in x.iter_mut().enumerate().take(channels) {
                        *v = f64::from(pixels[i * channels + c]);
                    }
                    let slots = &mut slots[i * k..(i + 1) * k];
                    let (best, own) = update_pixel(&p, slots, n, &x, channels);
                    dist2[i] = best as f32;
                    mask[i] = if own { BACKGROUND } else { FOREGROUND };
                }
            });
        Ok(())
    }

    /// The components of pixel `(x, y)`, in ω/σ order (empty before the first frame or
    /// outside the image).
    pub fn components(&self, x: usize, y: usize) -> Vec<SgComponent> {
        let Some((w, h, _)) = self.shape else {
            return Vec::new();
        };
        if x >= w || y >= h {
            return Vec::new();
        }
        let p = y * w + x;
        let k = self.params.k;
        self.slots[p * k..p * k + usize::from(self.used[p])].to_vec()
    }

    /// Number of components in use per pixel, row-major; empty before the first frame.
    pub fn components_per_pixel(&self) -> Vec<u8> {
        self.used.clone()
    }
}

/// One pixel's step: returns the smallest squared distance to the first B components (read
/// before the update) and whether the matched component is one of them (the model's own
/// decision: background).
fn update_pixel(
    p: &Sg1999Params,
    slots: &mut [SgComponent],
    used: &mut u8,
    x: &[f64; 3],
    channels: usize,
) -> (f64, bool) {
    let alpha = 1.0 / f64::from(p.history);
    let mut n = usize::from(*used);
    // B: the first components (ω/σ order) whose weights exceed T.
    let mut b = n;
    let mut cum = 0.0;
    for (i, s) in slots[..n].iter().enumerate() {
        cum += s.weight;
        if cum > p.background_ratio {
            b = i + 1;
            break;
        }
    }
    let match2 = p.match_sigma * p.match_sigma;
    let mut best = f64::INFINITY;
    let mut matched = None;
    for (i, s) in slots[..n].iter().enumerate() {
        let d2 = s.dist2(x, channels);
        if i < b {
            best = best.min(d2);
        }
        if matched.is_none() && d2 < match2 {
            matched = Some(i);
        }
    }
    let own = matched.is_some_and(|i| i < b);
    for (i, s) in slots[..n].iter_mut().enumerate() {
        let m = if matched == Some(i) { 1.0 } else { 0.0 };
        s.weight = (1.0 - alpha) * s.weight + alpha * m;
    }
    match matched {
        Some(i) => {
            let s = &mut slots[i];
            let rho = (alpha * density(s, x, channels)).min(1.0);
            let mut d2 = 0.0;
            for (m, &xc) in s.mean.iter_mut().zip(x).take(channels) {
                *m = (1.0 - rho) * *m + rho * xc;
                d2 += (xc - *m).powi(2);
            }
            s.variance = ((1.0 - rho) * s.variance + rho * d2).max(p.var_min);
        }
        None => {
            let i = if n < p.k {
                n += 1;
                n - 1
            } else {
                n - 1
            };
            slots[i] = SgComponent {
                weight: p.weight_init,
                variance: p.var_init,
                mean: *x,
            };
        }
    }
    let total: f64 = slots[..n].iter().map(|s| s.weight).sum();
    if total > 0.0 {
        for s in &mut slots[..n] {
            s.weight /= total;
        }
    }
    // Stable insertion sort by ω/σ, descending (ties keep their order).
    for i in 1..n {
        let mut j = i;
        while j > 0 && slots[j].key() > slots[j - 1].key() {
            slots.swap(j, j - 1);
            j -= 1;
        }
    }
    *used = n as u8;
    (best, own)
}

/// η(x | µ, σ²I), the Gaussian density of the sample (grey levels^−channels).
fn density(s: &SgComponent, x: &[f64; 3], channels: usize) -> f64 {
    let d2 = s.dist2(x, channels);
    (2.0 * std::f64::consts::PI * s.variance).powf(-(channels as f64) / 2.0) * (-0.5 * d2).exp()
}

#[cfg(test)]
mod tests;

//! A plain scalar, one-pixel-at-a-time statement of the update (test only). The vectorised
//! kernel must reproduce it bit for bit; it is written for reading, not for speed.
//!
//! Comments tag each step with its equation in Zivkovic, "Improved Adaptive Gaussian Mixture
//! Model for Background Subtraction", ICPR 2004 (the numbering the kernel uses).
// Channel loops index several arrays at once, as the C++ they mirror does.
#![allow(clippy::needless_range_loop)]

use super::{GmmParams, Pruning};

#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Slot {
    pub weight: f32,
    pub variance: f32,
    pub mean: [f32; 3],
}

pub(super) struct ReferenceGmm {
    pub params: GmmParams,
    pub channels: usize,
    pub frames: u64,
    /// Per pixel: `n_mixtures` slots, the first `used` of which are the mixture.
    pub slots: Vec<Vec<Slot>>,
    pub used: Vec<usize>,
}

impl ReferenceGmm {
    pub fn new(params: GmmParams, pixels: usize, channels: usize) -> Self {
        Self {
            params,
            channels,
            frames: 0,
            slots: vec![vec![Slot::default(); params.n_mixtures]; pixels],
            used: vec![0; pixels],
        }
    }

    pub fn apply(&mut self, frame: &[u8], learning_rate: Option<f32>, mask: &mut [u8]) {
        self.apply_masked(frame, learning_rate, None, mask);
    }

    /// Selective learning: a pixel whose `learn` flag is false is updated as usual for its
    /// mask, then gets its old mixture back (the model of a frozen pixel does not change).
    pub fn apply_masked(
        &mut self,
        frame: &[u8],
        learning_rate: Option<f32>,
        learn: Option<&[bool]>,
        mask: &mut [u8],
    ) {
        self.frames += 1;
        // α of eq. 4–6 and 14 (α ≈ 1/T, section 3); OpenCV's schedule 1/min(2n, history).
        let alpha = match learning_rate {
            Some(lr) if self.frames > 1 => f64::from(lr),
            _ => 1.0 / (2 * self.frames).min(u64::from(self.params.history)) as f64,
        };
        // −α c_T: the Dirichlet-prior term of eq. 14.
        let prune = (-alpha * f64::from(self.params.complexity_reduction)) as f32;
        // The drop threshold of eq. 14: α c_T (OpenCV) or 0 (the paper's "negative").
        let drop_below = match self.params.pruning {
            Pruning::OpenCv => -prune,
            Pruning::Negative => 0.0,
        };
        let alpha = alpha as f32;
        let c = self.channels;
        for p in 0..self.used.len() {
            let mut x = [0.0f32; 3];
            for ch in 0..c {
                x[ch] = f32::from(frame[p * c + ch]);
            }
            let frozen = learn.is_some_and(|l| !l[p]);
            let saved = frozen.then(|| (self.slots[p].clone(), self.used[p]));
            mask[p] = self.pixel(p, &x, alpha, prune, drop_below);
            if let Some((slots, used)) = saved {
                self.slots[p] = slots;
                self.used[p] = used;
            }
        }
    }

    fn pixel(&mut self, p: usize, x: &[f32; 3], alpha: f32, prune: f32, drop_below: f32) -> u8 {
        let pr = self.params;
        let c = self.channels;
        let var_min = pr.var_min.min(pr.var_max);
        let var_max = pr.var_min.max(pr.var_max);
        let s = &mut self.slots[p];
        let mut n = self.used[p];
        let mut background = false;
        let mut owned = false;
        // Cumulative weight of the components before k: the sum of eq. 8.
        let mut total = 0.0f32;
        let mut k = 0;
        while k < n {
            // Eq. 14 with o_m = 0: π ← (1 − α)π − α c_T (the owner adds α below).
            let mut w = (1.0 - alpha) * s[k].weight + prune;
            let mut moved = 0;
            if !owned {
                let var = s[k].variance;
                let mut d = [0.0f32; 3];
                // δᵀδ with δ = µ − x (the paper's δ_m with the sign flipped): D_m² σ² (section 3).
                let mut dist2 = 0.0f32;
                for ch in 0..c {
                    d[ch] = s[k].mean[ch] - x[ch];
                    dist2 = if ch == 0 {
                        d[0] * d[0]
                    } else {
                        dist2 + d[ch] * d[ch]
                    };
                }
                // Background (eq. 2, c_thr = var_threshold) if close to one of the first B components
                // of eq. 7–8 (cumulative weight before it below 1 − c_f = background_ratio).
                if total < pr.background_ratio && dist2 < pr.var_threshold * var {
                    background = true;
                }
                // The first (heaviest) "close" component owns the sample: o_m = 1 (section 3).
                if dist2 < pr.var_threshold_gen * var {
                    owned = true;
                    // Eq. 14 with o_m = 1: + α.
                    w += alpha;
                    let r = alpha / w;
                    // Eq. 5: µ ← µ + o_m (α/π) δ_m, with π already updated.
                    for ch in 0..c {
                        s[k].mean[ch] -= r * d[ch];
                    }
                    // Eq. 6: σ² ← σ² + o_m (α/π)(δᵀδ − σ²), clamped to [var_min, var_max] as OpenCV does.
                    let mut v = var + r * (dist2 - var);
                    if v < var_min {
                        v = var_min;
                    }
                    if v > var_max {
                        v = var_max;
                    }
                    s[k].variance = v;
                    // Keep the components sorted by weight (for the B of eq. 8): the owner moves up.
                    let mut i = k;
                    while i > 0 && w >= s[i - 1].weight {
                        s.swap(i, i - 1);
                        moved += 1;
                        i -= 1;
                    }
                }
            }
            // Eq. 14: discard the component when its weight goes negative (OpenCV tests < α c_T).
            if w < drop_below {
                w = 0.0;
                n -= 1;
            }
            s[k - moved].weight = w;
            total += w;
            k += 1;
        }
        // Normalise the weights to sum to one after eq. 14 (section 4).
        let inv = if total.abs() > f32::EPSILON {
            1.0 / total
        } else {
            0.0
        };
        for slot in s.iter_mut().take(n) {
            slot.weight *= inv;
        }
        // No close component: a new one with π = α, µ = x, σ² = σ_0 (var_init), replacing the
        // smallest when M are in use (section 3); the others are scaled by 1 − α to keep the sum.
        if !owned && alpha > 0.0 {
            let k = if n == pr.n_mixtures {
                n - 1
            } else {
                n += 1;
                n - 1
            };
            if n == 1 {
                s[k].weight = 1.0;
            } else {
                s[k].weight = alpha;
                for slot in s.iter_mut().take(n - 1) {
                    slot.weight *= 1.0 - alpha;
                }
            }
            s[k].mean = *x;
            s[k].variance = pr.var_init;
            let mut i = n - 1;
            while i > 0 && alpha >= s[i - 1].weight {
                s.swap(i, i - 1);
                i -= 1;
            }
        }
        self.used[p] = n;
        if background {
            return 0;
        }
        // Not in the paper: the shadow test of Prati et al. as OpenCV's detectShadowGMM applies it.
        if pr.detect_shadows && self.shadow(p, x) {
            return pr.shadow_value;
        }
        255
    }

    /// A darker copy of one of the first B background components (eq. 8), with the colour
    /// distortion within the threshold of eq. 2 (Prati et al.; not part of the paper).
    fn shadow(&self, p: usize, x: &[f32; 3]) -> bool {
        let pr = self.params;
        let c = self.channels;
        let mut sum = 0.0f32;
        for slot in &self.slots[p][..self.used[p]] {
            let (mut num, mut den) = (0.0f32, 0.0f32);
            for ch in 0..c {
                num += x[ch] * slot.mean[ch];
                den += slot.mean[ch] * slot.mean[ch];
            }
            if den == 0.0 {
                return false;
            }
            if num <= den && num >= pr.shadow_threshold * den {
                let a = num / den;
                let mut dist2a = 0.0f32;
                for ch in 0..c {
                    let d = a * slot.mean[ch] - x[ch];
                    dist2a += d * d;
                }
                if dist2a < pr.var_threshold * slot.variance * a * a {
                    return true;
                }
            }
            sum += slot.weight;
            if sum > pr.background_ratio {
                return false;
            }
        }
        false
    }
}

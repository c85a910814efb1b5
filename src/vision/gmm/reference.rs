//! A plain scalar, one-pixel-at-a-time statement of the update (test only). The vectorised
//! kernel must reproduce it bit for bit; it is written for reading, not for speed.
// Channel loops index several arrays at once, as the C++ they mirror does.
#![allow(clippy::needless_range_loop)]

use super::GmmParams;

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
        self.frames += 1;
        let alpha = match learning_rate {
            Some(lr) if self.frames > 1 => f64::from(lr),
            _ => 1.0 / (2 * self.frames).min(u64::from(self.params.history)) as f64,
        };
        let prune = (-alpha * f64::from(self.params.complexity_reduction)) as f32;
        let alpha = alpha as f32;
        let c = self.channels;
        for p in 0..self.used.len() {
            let mut x = [0.0f32; 3];
            for ch in 0..c {
                x[ch] = f32::from(frame[p * c + ch]);
            }
            mask[p] = self.pixel(p, &x, alpha, prune);
        }
    }

    fn pixel(&mut self, p: usize, x: &[f32; 3], alpha: f32, prune: f32) -> u8 {
        let pr = self.params;
        let c = self.channels;
        let var_min = pr.var_min.min(pr.var_max);
        let var_max = pr.var_min.max(pr.var_max);
        let s = &mut self.slots[p];
        let mut n = self.used[p];
        let mut background = false;
        let mut owned = false;
        let mut total = 0.0f32;
        let mut k = 0;
        while k < n {
            let mut w = (1.0 - alpha) * s[k].weight + prune;
            let mut moved = 0;
            if !owned {
                let var = s[k].variance;
                let mut d = [0.0f32; 3];
                let mut dist2 = 0.0f32;
                for ch in 0..c {
                    d[ch] = s[k].mean[ch] - x[ch];
                    dist2 = if ch == 0 {
                        d[0] * d[0]
                    } else {
                        dist2 + d[ch] * d[ch]
                    };
                }
                if total < pr.background_ratio && dist2 < pr.var_threshold * var {
                    background = true;
                }
                if dist2 < pr.var_threshold_gen * var {
                    owned = true;
                    w += alpha;
                    let r = alpha / w;
                    for ch in 0..c {
                        s[k].mean[ch] -= r * d[ch];
                    }
                    let mut v = var + r * (dist2 - var);
                    if v < var_min {
                        v = var_min;
                    }
                    if v > var_max {
                        v = var_max;
                    }
                    s[k].variance = v;
                    let mut i = k;
                    while i > 0 && w >= s[i - 1].weight {
                        s.swap(i, i - 1);
                        moved += 1;
                        i -= 1;
                    }
                }
            }
            if w < -prune {
                w = 0.0;
                n -= 1;
            }
            s[k - moved].weight = w;
            total += w;
            k += 1;
        }
        let inv = if total.abs() > f32::EPSILON {
            1.0 / total
        } else {
            0.0
        };
        for slot in s.iter_mut().take(n) {
            slot.weight *= inv;
        }
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
        if pr.detect_shadows && self.shadow(p, x) {
            return pr.shadow_value;
        }
        255
    }

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

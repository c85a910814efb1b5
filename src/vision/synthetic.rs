//! A deterministic synthetic RGB scene for testing and benchmarking background subtraction:
//! a textured static background with per-pixel noise, a flickering region (a two-state,
//! "monitor or leaves" background), and a coloured rectangle that moves across the scene
//! casting a darker shadow beside it.
//!
//! Every frame is a pure function of `(width, height, seed, t)`, so the same frames can be
//! regenerated anywhere (the OpenCV comparison and the benchmark rely on this). Not a model
//! of any real camera.

/// Scene description; [`Scene::frame_into`] renders frame `t`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Scene {
    pub width: usize,
    pub height: usize,
    pub seed: u64,
}

/// Amplitude of the per-pixel noise (grey levels; a sum of three uniforms in `[-2, 2]`,
/// so roughly σ = 2).
const NOISE_HALF_WIDTH: i32 = 2;

fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Scene {
    /// The benchmark / agreement size, 320×240.
    pub fn qvga(seed: u64) -> Self {
        Self {
            width: 320,
            height: 240,
            seed,
        }
    }

    /// Static background colour at `(x, y)`.
    fn background(&self, x: usize, y: usize) -> [i32; 3] {
        let (xf, yf) = (x as f64, y as f64);
        let r = 120.0 + 70.0 * (xf / 11.0).sin() * (yf / 17.0).cos();
        let g = 110.0 + 60.0 * ((xf + yf) / 23.0).sin();
        let checker = ((x / 16) + (y / 16)).is_multiple_of(2);
        let b = if checker { 170.0 } else { 60.0 } + 20.0 * (yf / 7.0).sin();
        [r as i32, g as i32, b as i32]
    }

    /// Rectangle of the moving object in frame `t`: `(x0, y0, w, h)`.
    fn object(&self, t: usize) -> (usize, usize, usize, usize) {
        let w = (self.width / 8).max(1);
        let h = (self.height / 6).max(1);
        let span = self.width.saturating_sub(w).max(1);
        let step = (self.width / 80).max(1);
        let p = (t * step) % (2 * span);
        let x0 = if p < span { p } else { 2 * span - p };
        let y0 = self.height / 3 + ((t / 7) % 3) * (self.height / 40).max(1);
        (x0.min(span), y0.min(self.height.saturating_sub(h)), w, h)
    }

    /// Render frame `t` into `dst` (`width * height * 3` bytes, RGB); `false` if `dst` has
    /// another length.
    pub fn frame_into(&self, t: usize, dst: &mut [u8]) -> bool {
        let (w, h) = (self.width, self.height);
        if dst.len() != w * h * 3 {
            return false;
        }
        let (ox, oy, ow, oh) = self.object(t);
        // The shadow is the object's footprint shifted down and to the right.
        let (sx, sy) = (ox + ow / 3, oy + oh / 2);
        let flicker_on = !mix(self.seed ^ (t as u64).wrapping_mul(0x51)).is_multiple_of(3);
        let (fx0, fy0, fx1, fy1) = (w * 3 / 4, h * 2 / 3, w * 3 / 4 + w / 6, h * 2 / 3 + h / 5);
        for y in 0..h {
            for x in 0..w {
                let mut px = self.background(x, y);
                if (fx0..fx1).contains(&x) && (fy0..fy1).contains(&y) {
                    px = if flicker_on {
                        [40, 200, 220]
                    } else {
                        [210, 210, 60]
                    };
                }
                if (sx..sx + ow).contains(&x) && (sy..sy + oh).contains(&y) {
                    px = px.map(|v| v * 6 / 10);
                }
                if (ox..ox + ow).contains(&x) && (oy..oy + oh).contains(&y) {
                    px = [230, 40 + ((x + y) % 20) as i32, 50];
                }
                let i = y * w + x;
                let r = mix(self.seed ^ ((t as u64) << 32) ^ i as u64);
                for (c, v) in px.iter().enumerate() {
                    let n: i32 = (0..3)
                        .map(|k| {
                            ((r >> (16 * c + 5 * k)) & 0x1f) as i32 % (2 * NOISE_HALF_WIDTH + 1)
                        })
                        .sum::<i32>()
                        - 3 * NOISE_HALF_WIDTH;
                    dst[i * 3 + c] = (v + n).clamp(0, 255) as u8;
                }
            }
        }
        true
    }

    /// Frame `t` as a new buffer.
    pub fn frame(&self, t: usize) -> Vec<u8> {
        let mut v = vec![0u8; self.width * self.height * 3];
        self.frame_into(t, &mut v);
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_deterministic_and_change() {
        let s = Scene {
            width: 64,
            height: 48,
            seed: 3,
        };
        assert_eq!(s.frame(5), s.frame(5));
        assert_ne!(s.frame(5), s.frame(6));
        assert!(!s.frame_into(0, &mut [0u8; 10]));
        // The object moves.
        assert_ne!(s.object(0), s.object(10));
    }
}

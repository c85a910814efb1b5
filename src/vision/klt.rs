//! Corner features tracked frame to frame (KLT): Shi–Tomasi "good features to track" (the
//! smaller eigenvalue of the gradient structure tensor over a window, non-maximum suppression
//! by distance) and Bouguet's pyramidal Lucas–Kanade (iterative, with bilinear sampling, the
//! guess carried from coarse to fine levels). Seed 003 (Zajdel et al. §III) tracks about 100
//! such features to find what moves against the scene seen by a moving robot; seed 001's
//! Method 1 (§IV) tracks features on the omni image the same way.
//!
//! Written by hand on plain `f32` buffers: `imageproc` has corner detectors (FAST, Harris)
//! but no Shi–Tomasi score and no optical flow, and no maintained Rust crate offers
//! pyramidal Lucas–Kanade. The pyramid smooths with the 5-tap binomial kernel before halving.

use image::GrayImage;

/// An image as `f32` intensities, row-major.
#[derive(Debug, Clone)]
struct Plane {
    w: usize,
    h: usize,
    v: Vec<f32>,
}

impl Plane {
    fn at(&self, x: usize, y: usize) -> f32 {
        self.v[y * self.w + x]
    }

    /// Bilinear sample; `None` outside `[0, w−1] × [0, h−1]`.
    fn sample(&self, x: f32, y: f32) -> Option<f32> {
        if !(x >= 0.0 && y >= 0.0 && x <= (self.w - 1) as f32 && y <= (self.h - 1) as f32) {
            return None;
        }
        let (x0, y0) = (x.floor() as usize, y.floor() as usize);
        let (x1, y1) = ((x0 + 1).min(self.w - 1), (y0 + 1).min(self.h - 1));
        let (fx, fy) = (x - x0 as f32, y - y0 as f32);
        let top = self.at(x0, y0) * (1.0 - fx) + self.at(x1, y0) * fx;
        let bottom = self.at(x0, y1) * (1.0 - fx) + self.at(x1, y1) * fx;
        Some(top * (1.0 - fy) + bottom * fy)
    }

    /// Smoothed with [1 4 6 4 1]/16 both ways (edges clamped), then every second pixel.
    fn half(&self) -> Plane {
        const K: [f32; 5] = [1.0 / 16.0, 4.0 / 16.0, 6.0 / 16.0, 4.0 / 16.0, 1.0 / 16.0];
        let clamp = |i: isize, n: usize| i.clamp(0, n as isize - 1) as usize;
        let mut rows = vec![0.0; self.w * self.h];
        for y in 0..self.h {
            for x in 0..self.w {
                rows[y * self.w + x] = (0..5)
                    .map(|k| K[k] * self.at(clamp(x as isize + k as isize - 2, self.w), y))
                    .sum();
            }
        }
        let (w, h) = (self.w.div_ceil(2), self.h.div_ceil(2));
        let mut v = vec![0.0; w * h];
        for y in 0..h {
            for x in 0..w {
                v[y * w + x] = (0..5)
                    .map(|k| {
                        K[k] * rows[clamp(2 * y as isize + k as isize - 2, self.h) * self.w + 2 * x]
                    })
                    .sum();
            }
        }
        Plane { w, h, v }
    }
}

/// An image pyramid: level 0 the image, each next level half the size.
#[derive(Debug, Clone)]
pub struct Pyramid {
    levels: Vec<Plane>,
}

impl Pyramid {
    /// `levels` levels (at least 1; fewer when the image gets smaller than 16 px).
    pub fn new(img: &GrayImage, levels: usize) -> Pyramid {
        let base = Plane {
            w: img.width() as usize,
            h: img.height() as usize,
            v: img.as_raw().iter().map(|&p| f32::from(p)).collect(),
        };
        let mut out = vec![base];
        while out.len() < levels.max(1) {
            let last = &out[out.len() - 1];
            if last.w < 32 || last.h < 32 {
                break;
            }
            let next = last.half();
            out.push(next);
        }
        Pyramid { levels: out }
    }
}

/// Up to `max` corners, strongest first: Shi–Tomasi score over a (2·`half_window`+1)² window
/// at least `quality` × the best score, local maxima, no two closer than `min_distance` px.
pub fn good_features(
    img: &GrayImage,
    max: usize,
    quality: f32,
    min_distance: f32,
    half_window: usize,
) -> Vec<[f32; 2]> {
    let p = Pyramid::new(img, 1).levels.remove(0);
    let (w, h) = (p.w, p.h);
    if w < 3 || h < 3 {
        return Vec::new();
    }
    // central-difference gradients products
    let mut gxx = vec![0.0f32; w * h];
    let mut gxy = vec![0.0f32; w * h];
    let mut gyy = vec![0.0f32; w * h];
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let gx = 0.5 * (p.at(x + 1, y) - p.at(x - 1, y));
            let gy = 0.5 * (p.at(x, y + 1) - p.at(x, y - 1));
            let i = y * w + x;
            gxx[i] = gx * gx;
            gxy[i] = gx * gy;
            gyy[i] = gy * gy;
        }
    }
    let r = half_window;
    let mut score = vec![0.0f32; w * h];
    for y in r + 1..h.saturating_sub(r + 1) {
        for x in r + 1..w.saturating_sub(r + 1) {
            let (mut a, mut b, mut c) = (0.0, 0.0, 0.0);
            for yy in y - r..=y + r {
                for xx in x - r..=x + r {
                    let i = yy * w + xx;
                    a += gxx[i];
                    b += gxy[i];
                    c += gyy[i];
                }
            }
            // smaller eigenvalue of [[a, b], [b, c]]
            score[y * w + x] = 0.5 * ((a + c) - ((a - c) * (a - c) + 4.0 * b * b).sqrt());
        }
    }
    let best = score.iter().copied().fold(0.0f32, f32::max);
    if best <= 0.0 {
        return Vec::new();
    }
    let mut candidates: Vec<(f32, usize, usize)> = Vec::new();
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let s = score[y * w + x];
            let local_max =
                (y - 1..=y + 1).all(|yy| (x - 1..=x + 1).all(|xx| score[yy * w + xx] <= s));
            if s >= quality * best && local_max {
                candidates.push((s, x, y));
            }
        }
    }
    // strongest first; ties in raster order
    candidates.sort_by(|a, b| b.0.total_cmp(&a.0).then((a.2, a.1).cmp(&(b.2, b.1))));
    let mut out: Vec<[f32; 2]> = Vec::new();
    for (_, x, y) in candidates {
        let q = [x as f32, y as f32];
        if out
            .iter()
            .all(|o| (o[0] - q[0]).hypot(o[1] - q[1]) >= min_distance)
        {
            out.push(q);
            if out.len() == max {
                break;
            }
        }
    }
    out
}

/// Settings of the pyramidal Lucas–Kanade tracker.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LkParams {
    /// The window is (2·`half_window`+1)² pixels.
    pub half_window: usize,
    pub max_iterations: usize,
    /// Stop when an update moves less than this (px).
    pub epsilon: f32,
    /// Lost when the window's structure tensor has a smaller eigenvalue per pixel below this.
    pub min_eigen: f32,
}

impl Default for LkParams {
    fn default() -> Self {
        Self {
            half_window: 7,
            max_iterations: 20,
            epsilon: 0.01,
            min_eigen: 1e-3,
        }
    }
}

/// Where each point of `prev` went in `next` (`None`: lost — window outside the image, no
/// texture, or no convergence).
pub fn track(
    prev: &Pyramid,
    next: &Pyramid,
    pts: &[[f32; 2]],
    p: &LkParams,
) -> Vec<Option<[f32; 2]>> {
    let levels = prev.levels.len().min(next.levels.len());
    pts.iter()
        .map(|&pt| track_one(prev, next, pt, levels, p))
        .collect()
}

fn track_one(
    prev: &Pyramid,
    next: &Pyramid,
    pt: [f32; 2],
    levels: usize,
    p: &LkParams,
) -> Option<[f32; 2]> {
    let r = p.half_window as isize;
    let mut guess = [0.0f32; 2];
    for level in (0..levels).rev() {
        let scale = (1u32 << level) as f32;
        let (i, j) = (&prev.levels[level], &next.levels[level]);
        let (ux, uy) = (pt[0] / scale, pt[1] / scale);
        // the window's gradients and structure tensor in the previous image
        let mut win = Vec::with_capacity(((2 * r + 1) * (2 * r + 1)) as usize);
        let (mut a, mut b, mut c) = (0.0f32, 0.0f32, 0.0f32);
        for dy in -r..=r {
            for dx in -r..=r {
                let (x, y) = (ux + dx as f32, uy + dy as f32);
                let gx = 0.5 * (i.sample(x + 1.0, y)? - i.sample(x - 1.0, y)?);
                let gy = 0.5 * (i.sample(x, y + 1.0)? - i.sample(x, y - 1.0)?);
                a += gx * gx;
                b += gx * gy;
                c += gy * gy;
                win.push((x, y, i.sample(x, y)?, gx, gy));
            }
        }
        let det = a * c - b * b;
        let n = win.len() as f32;
        let min_eig = 0.5 * ((a + c) - ((a - c) * (a - c) + 4.0 * b * b).sqrt()) / n;
        if min_eig < p.min_eigen || det <= 0.0 {
            return None;
        }
        let mut v = [0.0f32; 2];
        for _ in 0..p.max_iterations {
            let (mut ex, mut ey) = (0.0f32, 0.0f32);
            for &(x, y, ival, gx, gy) in &win {
                let jval = j.sample(x + guess[0] + v[0], y + guess[1] + v[1])?;
                let d = ival - jval;
                ex += d * gx;
                ey += d * gy;
            }
            let step = [(c * ex - b * ey) / det, (a * ey - b * ex) / det];
            v[0] += step[0];
            v[1] += step[1];
            if step[0].hypot(step[1]) < p.epsilon {
                break;
            }
        }
        let total = [guess[0] + v[0], guess[1] + v[1]];
        guess = if level > 0 {
            [2.0 * total[0], 2.0 * total[1]]
        } else {
            total
        };
    }
    let out = [pt[0] + guess[0], pt[1] + guess[1]];
    let (w, h) = (next.levels[0].w as f32, next.levels[0].h as f32);
    (out[0] >= 0.0 && out[1] >= 0.0 && out[0] <= w - 1.0 && out[1] <= h - 1.0).then_some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A smooth texture (sum of sinusoids) seen shifted by `(sx, sy)` px.
    fn texture(w: u32, h: u32, sx: f32, sy: f32) -> GrayImage {
        GrayImage::from_fn(w, h, |x, y| {
            let (x, y) = (x as f32 - sx, y as f32 - sy);
            let v = 128.0
                + 40.0 * (0.21 * x + 0.05 * y).sin()
                + 35.0 * (0.07 * x - 0.19 * y).cos()
                + 25.0 * (0.13 * x + 0.11 * y).sin();
            image::Luma([v.round().clamp(0.0, 255.0) as u8])
        })
    }

    #[test]
    fn a_shifted_texture_is_tracked_to_a_tenth_of_a_pixel() {
        for (sx, sy) in [(2.3f32, -1.7f32), (11.6, 7.2)] {
            let a = Pyramid::new(&texture(160, 120, 0.0, 0.0), 3);
            let b = Pyramid::new(&texture(160, 120, sx, sy), 3);
            let pts = [[60.0, 50.0], [80.0, 60.0], [100.0, 70.0]];
            for (p, q) in pts.iter().zip(track(&a, &b, &pts, &LkParams::default())) {
                let q = q.expect("tracked");
                let err = (q[0] - p[0] - sx).hypot(q[1] - p[1] - sy);
                // the texture is rounded to whole grey levels: a few hundredths of a pixel of noise
                assert!(err < 0.1, "shift ({sx}, {sy}) at {p:?}: error {err} px");
            }
        }
    }

    #[test]
    fn flat_windows_and_points_leaving_the_image_are_lost() {
        let flat = Pyramid::new(&GrayImage::from_pixel(64, 64, image::Luma([90])), 2);
        assert_eq!(
            track(&flat, &flat, &[[30.0, 30.0]], &LkParams::default()),
            [None]
        );
        let a = Pyramid::new(&texture(64, 64, 0.0, 0.0), 1);
        assert_eq!(track(&a, &a, &[[2.0, 30.0]], &LkParams::default()), [None]);
    }

    #[test]
    fn the_corners_of_a_square_are_the_good_features() {
        let img = GrayImage::from_fn(64, 64, |x, y| {
            image::Luma([if (20..44).contains(&x) && (16..40).contains(&y) {
                220
            } else {
                20
            }])
        });
        let mut got = good_features(&img, 4, 0.1, 5.0, 2);
        got.sort_by(|a, b| (a[1], a[0]).partial_cmp(&(b[1], b[0])).expect("finite"));
        let want = [[20.0, 16.0], [43.0, 16.0], [20.0, 39.0], [43.0, 39.0]];
        assert_eq!(got.len(), 4, "{got:?}");
        for (g, w) in got.iter().zip(want) {
            assert!(
                (g[0] - w[0]).abs() <= 1.0 && (g[1] - w[1]).abs() <= 1.0,
                "{got:?}"
            );
        }
        assert!(good_features(&GrayImage::new(64, 64), 4, 0.1, 5.0, 2).is_empty());
    }
}

//! Skin segmentation of seed 002 §4: a colour histogram in normalised rgb (r = R/(R+G+B),
//! g = G/(R+G+B)) built off-line from labelled skin pixels, back-projection (a pixel's skin
//! likeness is its bin's count over the largest bin's count), Gaussian smoothing, and
//! hysteresis thresholding bounded by the Canny edges of the grey frame: regions grow from
//! pixels above `high` through 8-neighbours above `low`, never into an edge pixel.
//!
//! Then the person test of §4: a moving blob is a person when the top fifth of its rectangle
//! holds at least `min_skin_fraction` skin pixels; the observation is the head top, the top row
//! of the rectangle at the mean column of those skin pixels.
//!
//! Canny and the Gaussian come from `imageproc`; the histogram, back-projection and the
//! edge-bounded hysteresis are hand-written (imageproc's hysteresis lives inside its Canny and
//! takes no barrier). Pure functions of images; no I/O.

use std::collections::VecDeque;

use image::{GrayImage, ImageBuffer, Luma, RgbImage};
use imageproc::edges::canny;
use imageproc::filter::gaussian_blur_f32;

/// A normalised-rgb skin histogram, `bins × bins` over (r, g) in [0, 1].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SkinHistogram {
    pub bins: usize,
    pub counts: Vec<u64>,
    /// Skin pixels added.
    pub pixels: u64,
}

/// Parameters of the segmentation (seed 002 gives none; chosen on the quick profile).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkinParams {
    /// σ of the Gaussian smoothing of the back-projection, px (0: none).
    pub smooth_sigma_px: f32,
    /// Hysteresis thresholds on the smoothed back-projection, in [0, 1].
    pub low: f32,
    pub high: f32,
    /// Canny thresholds on the grey frame (gradient magnitude).
    pub canny_low: f32,
    pub canny_high: f32,
}

impl SkinHistogram {
    pub fn new(bins: usize) -> SkinHistogram {
        let bins = bins.max(1);
        SkinHistogram {
            bins,
            counts: vec![0; bins * bins],
            pixels: 0,
        }
    }

    /// Bin of a colour (`None` for black, which has no chromaticity).
    pub fn bin(&self, p: [u8; 3]) -> Option<usize> {
        let s = u32::from(p[0]) + u32::from(p[1]) + u32::from(p[2]);
        if s == 0 {
            return None;
        }
        let b = self.bins as u32;
        let idx = |c: u8| ((u32::from(c) * b / s).min(b - 1)) as usize;
        Some(idx(p[0]) * self.bins + idx(p[1]))
    }

    /// Add the pixels of `img` where `mask` is non-zero (sizes must agree; otherwise nothing
    /// is added and `false` returned).
    pub fn add(&mut self, img: &RgbImage, mask: &[u8]) -> bool {
        if mask.len() != (img.width() as usize) * (img.height() as usize) {
            return false;
        }
        for (p, m) in img.pixels().zip(mask) {
            if *m != 0
                && let Some(b) = self.bin(p.0)
            {
                self.counts[b] += 1;
                self.pixels += 1;
            }
        }
        true
    }

    /// Back-projection: each pixel's bin count over the largest count, in [0, 1].
    pub fn back_project(&self, img: &RgbImage) -> Vec<f32> {
        let max = self.counts.iter().copied().max().unwrap_or(0).max(1) as f32;
        img.pixels()
            .map(|p| self.bin(p.0).map_or(0.0, |b| self.counts[b] as f32 / max))
            .collect()
    }
}

/// Hysteresis thresholding bounded by a barrier: 255 for pixels connected (8-neighbours) to a
/// pixel `>= high` through pixels `>= low`, where no pixel on the way (seed included) is a
/// barrier; 0 elsewhere. `values` and `barrier` are `width * height`, row-major.
pub fn hysteresis(
    values: &[f32],
    barrier: &[bool],
    width: usize,
    height: usize,
    low: f32,
    high: f32,
) -> Vec<u8> {
    let n = width * height;
    let mut out = vec![0u8; n];
    if values.len() != n || barrier.len() != n {
        return out;
    }
    let mut queue = VecDeque::new();
    for i in 0..n {
        if values[i] >= high && !barrier[i] && out[i] == 0 {
            out[i] = 255;
            queue.push_back(i);
            while let Some(j) = queue.pop_front() {
                let (x, y) = ((j % width) as i64, (j / width) as i64);
                for dy in -1..=1i64 {
                    for dx in -1..=1i64 {
                        let (nx, ny) = (x + dx, y + dy);
                        if nx < 0 || ny < 0 || nx >= width as i64 || ny >= height as i64 {
                            continue;
                        }
                        let k = ny as usize * width + nx as usize;
                        if out[k] == 0 && !barrier[k] && values[k] >= low {
                            out[k] = 255;
                            queue.push_back(k);
                        }
                    }
                }
            }
        }
    }
    out
}

/// The skin mask of a frame (255 skin) and its intermediate images: the smoothed
/// back-projection and the Canny edges.
pub struct SkinSegmentation {
    pub back_projection: Vec<f32>,
    pub edges: GrayImage,
    pub mask: Vec<u8>,
}

/// Segment skin in `img` with histogram `hist`.
pub fn segment(img: &RgbImage, hist: &SkinHistogram, p: &SkinParams) -> SkinSegmentation {
    let (w, h) = img.dimensions();
    let bp = hist.back_project(img);
    let back_projection = if p.smooth_sigma_px > 0.0 {
        match ImageBuffer::<Luma<f32>, Vec<f32>>::from_raw(w, h, bp.clone()) {
            Some(b) => gaussian_blur_f32(&b, p.smooth_sigma_px).into_raw(),
            None => bp,
        }
    } else {
        bp
    };
    let grey = image::imageops::grayscale(img);
    let edges = canny(&grey, p.canny_low, p.canny_high);
    let barrier: Vec<bool> = edges.as_raw().iter().map(|e| *e != 0).collect();
    let mask = hysteresis(
        &back_projection,
        &barrier,
        w as usize,
        h as usize,
        p.low,
        p.high,
    );
    SkinSegmentation {
        back_projection,
        edges,
        mask,
    }
}

/// Seed 002's person test on a moving blob's rectangle `[x0, y0, x1, y1]` (inclusive): the
/// share of skin pixels in its top fifth, and, when it reaches `min_skin_fraction`, the head
/// top pixel `(u, v)` — the mean column of those skin pixels (pixel centres) on the rectangle's
/// top edge.
pub fn head_top(
    rect: [u32; 4],
    skin: &[u8],
    width: usize,
    min_skin_fraction: f64,
) -> (f64, Option<[f64; 2]>) {
    let [x0, y0, x1, y1] = rect;
    let rows = (y1 - y0 + 1).div_ceil(5);
    let (mut count, mut total, mut sum_x) = (0u64, 0u64, 0.0f64);
    for y in y0..y0 + rows {
        for x in x0..=x1 {
            total += 1;
            let i = y as usize * width + x as usize;
            if skin.get(i).is_some_and(|s| *s != 0) {
                count += 1;
                sum_x += f64::from(x) + 0.5;
            }
        }
    }
    let fraction = count as f64 / total.max(1) as f64;
    let top =
        (count > 0 && fraction >= min_skin_fraction).then(|| [sum_x / count as f64, f64::from(y0)]);
    (fraction, top)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hysteresis_on_a_hand_made_image() {
        // 6×4 values; one seed at (1,1) >= high; low region spreads right but an edge column
        // at x = 3 stops it; the isolated weak pixel at (5,3) stays off; a strong pixel on the
        // barrier (4,0) never seeds.
        #[rustfmt::skip]
        let values = [
            0.1, 0.5, 0.5, 0.5, 0.9, 0.5,
            0.5, 0.9, 0.5, 0.5, 0.5, 0.5,
            0.1, 0.5, 0.1, 0.5, 0.5, 0.1,
            0.1, 0.1, 0.1, 0.1, 0.1, 0.5,
        ];
        let mut barrier = [false; 24];
        for y in 0..4 {
            barrier[y * 6 + 3] = true;
        }
        barrier[4] = true;
        let out = hysteresis(&values, &barrier, 6, 4, 0.4, 0.8);
        #[rustfmt::skip]
        let want = [
            0, 1, 1, 0, 0, 0,
            1, 1, 1, 0, 0, 0,
            0, 1, 0, 0, 0, 0,
            0, 0, 0, 0, 0, 0,
        ];
        let got: Vec<u8> = out.iter().map(|v| u8::from(*v == 255)).collect();
        assert_eq!(got, want);
        // without the barrier everything >= low connected to a seed is on
        let out = hysteresis(&values, &[false; 24], 6, 4, 0.4, 0.8);
        let on = out.iter().filter(|v| **v == 255).count();
        assert_eq!(on, 15);
    }

    #[test]
    fn back_projection_ranks_the_trained_chromaticity_and_head_top_needs_skin() {
        let skin = image::Rgb([200u8, 140, 110]);
        let mut train = RgbImage::from_pixel(4, 4, image::Rgb([50, 60, 200]));
        let mut mask = vec![0u8; 16];
        for i in 0..8 {
            train.put_pixel(i % 4, i / 4, skin);
            mask[i as usize] = 255;
        }
        let mut hist = SkinHistogram::new(16);
        assert!(hist.add(&train, &mask));
        assert_eq!(hist.pixels, 8);
        // a darker pixel of the same chromaticity projects to 1, the blue one to 0
        let test = RgbImage::from_fn(2, 1, |x, _| {
            if x == 0 {
                image::Rgb([100, 70, 55])
            } else {
                image::Rgb([50, 60, 200])
            }
        });
        assert_eq!(hist.back_project(&test), vec![1.0, 0.0]);
        // head top: a 5-row rectangle, its top row (the fifth) has skin at x = 2, 3 of 0..=4
        let mut sk = vec![0u8; 25];
        sk[2] = 255;
        sk[3] = 255;
        let (frac, top) = head_top([0, 0, 4, 4], &sk, 5, 0.3);
        assert!((frac - 0.4).abs() < 1e-12);
        assert_eq!(top, Some([3.0, 0.0]));
        assert_eq!(head_top([0, 0, 4, 4], &sk, 5, 0.5).1, None);
    }
}

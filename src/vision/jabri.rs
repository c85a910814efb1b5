//! Background subtraction after Jabri, Duric, Wechsler & Rosenfeld (ICPR 2000) as seed 002 §4
//! uses it: each frame is split into colour planes (R, G, B or grey) and edge planes (a
//! Laplacian, horizontal + vertical Sobel, or none); every pixel of every plane keeps a mean
//! and a standard deviation updated recursively with an exponential forgetting factor α,
//!
//!   μ_t = α x_t + (1 − α) μ_{t−1},   σ²_t = α (x_t − μ_t)² + (1 − α) σ²_{t−1},
//!
//! and a pixel is moving when, in some plane, it lies more than `k_sigma` standard deviations
//! from that plane's mean (σ floored at `sigma_floor`, so a perfectly still pixel does not make
//! every sensor-noise flicker a detection). Moving blobs are the bounding rectangles of the
//! 8-connected components of the majority-filtered mask (`vision::blobs`).
//!
//! Jabri et al. fuse colour and edge confidences with a ramp between two thresholds; seed 002
//! gives no detector details, so this module uses the single `k_sigma` test on every plane —
//! which is what makes the cost scale with the number of planes, the §4 claim the s002 pipeline
//! measures. The Sobel and Laplacian responses come from `imageproc`; the recursion is
//! hand-written (a few lines; no crate keeps per-pixel running statistics). It does not track.

use image::RgbImage;
use imageproc::filter::laplacian_filter;
use imageproc::gradients::{horizontal_sobel, vertical_sobel};

use super::blobs::{self, BlobError, Connectivity};

/// Colour planes of the split.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ColourPlanes {
    /// One plane: (R + G + B) / 3.
    Grey,
    /// Three planes: R, G, B.
    Rgb,
}

/// Edge planes of the split (of the grey image).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EdgePlanes {
    None,
    /// One plane: the 3×3 Laplacian.
    Laplacian,
    /// Two planes: horizontal and vertical Sobel.
    Sobel,
}

/// Which planes a frame is split into.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Planes {
    pub colour: ColourPlanes,
    pub edges: EdgePlanes,
}

impl Planes {
    pub fn colour_count(&self) -> usize {
        match self.colour {
            ColourPlanes::Grey => 1,
            ColourPlanes::Rgb => 3,
        }
    }

    pub fn edge_count(&self) -> usize {
        match self.edges {
            EdgePlanes::None => 0,
            EdgePlanes::Laplacian => 1,
            EdgePlanes::Sobel => 2,
        }
    }

    pub fn count(&self) -> usize {
        self.colour_count() + self.edge_count()
    }

    /// Split `img` into the planes, each `width * height` values, colour planes first.
    pub fn split(&self, img: &RgbImage) -> Vec<Vec<f32>> {
        let mut out = Vec::with_capacity(self.count());
        let raw = img.as_raw();
        match self.colour {
            ColourPlanes::Grey => out.push(
                raw.chunks_exact(3)
                    .map(|p| (f32::from(p[0]) + f32::from(p[1]) + f32::from(p[2])) / 3.0)
                    .collect(),
            ),
            ColourPlanes::Rgb => {
                for c in 0..3 {
                    out.push(raw.chunks_exact(3).map(|p| f32::from(p[c])).collect());
                }
            }
        }
        if self.edges != EdgePlanes::None {
            let grey = image::imageops::grayscale(img);
            let plane = |i: image::ImageBuffer<image::Luma<i16>, Vec<i16>>| {
                i.into_raw()
                    .into_iter()
                    .map(f32::from)
                    .collect::<Vec<f32>>()
            };
            match self.edges {
                EdgePlanes::None => {}
                EdgePlanes::Laplacian => out.push(plane(laplacian_filter(&grey))),
                EdgePlanes::Sobel => {
                    out.push(plane(horizontal_sobel(&grey)));
                    out.push(plane(vertical_sobel(&grey)));
                }
            }
        }
        out
    }
}

/// Parameters of the background model (seed 002 gives none; chosen on the quick profile of
/// `office_network`, see the s002 pipeline file).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JabriParams {
    /// Forgetting factor α of the recursive mean and variance.
    pub alpha: f32,
    /// A pixel moves when |x − μ| > k σ in some plane.
    pub k_sigma: f32,
    /// Floor on σ (plane units, 8-bit grey levels for colour planes).
    pub sigma_floor: f32,
    /// σ of a pixel when the model starts.
    pub sigma_init: f32,
    /// Smallest moving blob kept, pixels.
    pub min_blob_px: u64,
}

/// One step of the recursion for one pixel of one plane: `(μ_t, σ²_t)` from `(μ_{t−1},
/// σ²_{t−1})` and the new value `x`.
pub fn update_pixel(mean: f32, var: f32, x: f32, alpha: f32) -> (f32, f32) {
    let m = alpha * x + (1.0 - alpha) * mean;
    let d = x - m;
    (m, alpha * d * d + (1.0 - alpha) * var)
}

/// Errors of the background model.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum JabriError {
    #[error("frame is {have_w}x{have_h}, the background model is {want_w}x{want_h}")]
    Size {
        have_w: u32,
        have_h: u32,
        want_w: u32,
        want_h: u32,
    },
    #[error(transparent)]
    Blobs(#[from] BlobError),
}

/// The per-pixel, per-plane running mean and variance of one camera.
#[derive(Debug, Clone)]
pub struct JabriBackground {
    planes: Planes,
    params: JabriParams,
    size: Option<(u32, u32)>,
    mean: Vec<Vec<f32>>,
    var: Vec<Vec<f32>>,
}

impl JabriBackground {
    pub fn new(planes: Planes, params: JabriParams) -> JabriBackground {
        JabriBackground {
            planes,
            params,
            size: None,
            mean: Vec::new(),
            var: Vec::new(),
        }
    }

    /// Feed one frame: the moving-pixel mask (255 moving, 0 still) against the model before
    /// this frame, then the model updated with it. The first frame only starts the model
    /// (its mask is empty).
    pub fn apply(&mut self, img: &RgbImage) -> Result<Vec<u8>, JabriError> {
        let (w, h) = img.dimensions();
        let values = self.planes.split(img);
        let n = (w as usize) * (h as usize);
        let Some((mw, mh)) = self.size else {
            self.size = Some((w, h));
            let v0 = self.params.sigma_init * self.params.sigma_init;
            self.var = values.iter().map(|_| vec![v0; n]).collect();
            self.mean = values;
            return Ok(vec![0; n]);
        };
        if (mw, mh) != (w, h) {
            return Err(JabriError::Size {
                have_w: w,
                have_h: h,
                want_w: mw,
                want_h: mh,
            });
        }
        let p = self.params;
        let mut mask = vec![0u8; n];
        for ((x, mean), var) in values.iter().zip(&mut self.mean).zip(&mut self.var) {
            for (((xv, m), v), out) in x
                .iter()
                .zip(mean.iter_mut())
                .zip(var.iter_mut())
                .zip(&mut mask)
            {
                let sigma = v.sqrt().max(p.sigma_floor);
                if (xv - *m).abs() > p.k_sigma * sigma {
                    *out = 255;
                }
                (*m, *v) = update_pixel(*m, *v, *xv, p.alpha);
            }
        }
        Ok(mask)
    }

    /// Moving blobs of a mask as inclusive rectangles `[x0, y0, x1, y1]`, largest first
    /// (ties in raster order), at least `min_blob_px` pixels after a 3×3 majority filter.
    pub fn blobs(
        &self,
        mask: &[u8],
        width: usize,
        height: usize,
    ) -> Result<Vec<[u32; 4]>, JabriError> {
        let mut filtered = vec![0u8; mask.len()];
        blobs::majority_filter(mask, width, height, 255, &mut filtered)?;
        let mut labels = vec![0u32; mask.len()];
        let mut found = blobs::label(
            &filtered,
            width,
            height,
            Connectivity::Eight,
            255,
            &mut labels,
        )?;
        found.retain(|b| b.area() >= self.params.min_blob_px);
        found.sort_by_key(|b| std::cmp::Reverse(b.area()));
        Ok(found.into_iter().map(|b| b.bbox).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_update_on_a_constant_pixel_follows_the_closed_form() {
        // μ_t = c + (1−α)^t (μ0 − c); with d_t = c − μ_t = −(1−α)^t (μ0 − c),
        // σ²_t = (1−α)^t σ²_0 + α Σ_{k=1..t} (1−α)^{t−k} (1−α)^{2k} (μ0 − c)².
        let (alpha, c, mu0, var0) = (0.1f64, 100.0f64, 20.0f64, 25.0f64);
        let (mut m, mut v) = (mu0 as f32, var0 as f32);
        for t in 1..=60i32 {
            (m, v) = update_pixel(m, v, c as f32, alpha as f32);
            let q = 1.0 - alpha;
            let mu_t = c + q.powi(t) * (mu0 - c);
            let sum: f64 = (1..=t).map(|k| q.powi(t - k) * q.powi(2 * k)).sum();
            let var_t = q.powi(t) * var0 + alpha * sum * (mu0 - c).powi(2);
            assert!((f64::from(m) - mu_t).abs() < 1e-3, "t {t}: μ {m} vs {mu_t}");
            assert!(
                (f64::from(v) - var_t).abs() < 1e-2 * var_t.max(1.0),
                "t {t}: σ² {v} vs {var_t}"
            );
        }
        // and it converges: μ → c, σ² → 0
        for _ in 0..400 {
            (m, v) = update_pixel(m, v, c as f32, alpha as f32);
        }
        assert!((m - 100.0).abs() < 1e-3 && v < 1e-6);
    }

    fn params() -> JabriParams {
        JabriParams {
            alpha: 0.05,
            k_sigma: 3.0,
            sigma_floor: 4.0,
            sigma_init: 10.0,
            min_blob_px: 4,
        }
    }

    #[test]
    fn planes_split_counts_and_a_new_square_is_the_only_moving_blob() {
        for (colour, edges, n) in [
            (ColourPlanes::Grey, EdgePlanes::None, 1),
            (ColourPlanes::Rgb, EdgePlanes::Laplacian, 4),
            (ColourPlanes::Rgb, EdgePlanes::Sobel, 5),
        ] {
            let planes = Planes { colour, edges };
            let bg = RgbImage::from_pixel(20, 10, image::Rgb([100, 100, 100]));
            assert_eq!(planes.split(&bg).len(), n);
            let mut model = JabriBackground::new(planes, params());
            for _ in 0..30 {
                let m = model.apply(&bg).expect("same size");
                assert!(m.iter().all(|v| *v == 0));
            }
            let mut fg = bg.clone();
            for y in 3..7 {
                for x in 5..9 {
                    fg.put_pixel(x, y, image::Rgb([200, 200, 40]));
                }
            }
            let mask = model.apply(&fg).expect("same size");
            let rects = model.blobs(&mask, 20, 10).expect("sizes");
            assert_eq!(rects.len(), 1, "{colour:?} {edges:?}");
            // the square itself, and with edge planes possibly a one-pixel edge ring
            let [x0, y0, x1, y1] = rects[0];
            assert!(
                (4..=5).contains(&x0) && (2..=3).contains(&y0),
                "{:?}",
                rects[0]
            );
            assert!(
                (8..=9).contains(&x1) && (6..=7).contains(&y1),
                "{:?}",
                rects[0]
            );
        }
        let mut model = JabriBackground::new(
            Planes {
                colour: ColourPlanes::Grey,
                edges: EdgePlanes::None,
            },
            params(),
        );
        model.apply(&RgbImage::new(4, 4)).expect("first");
        assert!(matches!(
            model.apply(&RgbImage::new(5, 4)),
            Err(JabriError::Size { .. })
        ));
    }
}

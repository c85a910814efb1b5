//! Moving-region segmentation in a Gabor feature space (seed 004 §2, eq. 1–2).
//!
//! Every pixel is described by a vector of 16 filter responses (eq. 1): the even (cosine)
//! Gabor filter at θ ∈ {0°, 45°, 90°, 135°} on the luminance `Y = 0.299 R + 0.587 G + 0.114 B`,
//! and the half-wave rectified responses `max(0, ·)` of the same four filters on the R, G and B
//! channels (values in [0, 1]). The filter is
//!
//! ```text
//! g_θ(x, y) = exp(−(x² + y²) / 2σ²) / (2πσ²) · cos(2π (x cos θ + y sin θ) / λ)
//! ```
//!
//! (x right, y down, in pixels; applied as a correlation with replicated borders). With an
//! isotropic envelope every orientation is a sum of at most two separable products,
//! `cos(a + b) = cos a cos b − sin a sin b`, so the bank costs five row passes and four column
//! passes per channel instead of sixteen 2-D convolutions (0° and 90° are one product each;
//! 45° and 135° share their two products, as `P − Q` and `P + Q`). At the default
//! σ = 2 px (13 taps) that is ~9 × 13 multiply-adds per pixel and channel against 4 × 169 for
//! direct 2-D filtering; an FFT is not faster at this kernel size. Passes run in parallel over
//! rows (rayon; each row is computed independently, so results do not depend on threads).
//!
//! The background `B` is a running average of the feature images `M` (eq. 2,
//! `Bᵗ = (1 − α) Bᵗ⁻¹ + α Mᵗ`, initialised with the first frame, or — the paper does not say —
//! with the features of the per-pixel temporal median of frames sampled over the log,
//! [`GaborBackground::bootstrap`], so that people in the first frame leave no ghost); the
//! moving-region image is
//! the Euclidean distance `‖Bᵗ − Mᵗ‖` per pixel, thresholded at
//! `median + k · 1.4826 · MAD` (Median Absolute Deviation, Rosin 1999 [4]; 1.4826 makes the
//! MAD a consistent estimate of a Gaussian σ).
//!
//! Besides eq. 2, which updates every pixel, [`Update::Selective`] (our addition, not in the
//! paper) learns foreground pixels at a lower rate: a person walking over a pixel for ~9
//! frames otherwise blends `1 − (1 − α)⁹` of their contrast into `B` (17 % at α = 0.02), and
//! that residue stays above a noise-level MAD threshold for seconds — a trail behind every
//! walker. The selective rule segments against `Bᵗ⁻¹`, dilates the mask by the filter radius
//! (the features of pixels next to a person see the person through the kernel), and then
//! updates with α outside and `α_fg` inside it. With the all-pixel rule the order does not
//! matter for the mask: `‖Bᵗ − Mᵗ‖ = (1 − α) ‖Bᵗ⁻¹ − Mᵗ‖`, and a median + k·MAD threshold is
//! scale-invariant.
//!
//! [`GhostTest`] (our addition, off unless asked for; `gabor/ghosts.rs`) removes *ghosts*, the
//! regions a person left behind in a background that held them, by comparing the luminance
//! edges along each region's contour in the frame and in the background.
//!
//! What it does not do: no shadow model, no morphology on the segmentation. σ, λ and k are
//! not given in the paper; they are parameters.

use image::RgbImage;
use rayon::prelude::*;

mod ghosts;
pub use ghosts::{GhostTest, sobel_magnitude};

/// Number of filters in the bank (eq. 1): 4 orientations × (luminance + R, G, B).
pub const FILTERS: usize = 16;
/// Filter orientations θ_m (degrees), eq. 1.
pub const ORIENTATIONS_DEG: [f64; 4] = [0.0, 45.0, 90.0, 135.0];
/// Scale that turns a MAD into a standard deviation for Gaussian data.
pub const MAD_TO_SIGMA: f64 = 1.482_602_218_505_602;
/// Paper range of the background learning rate α (eq. 2): (0.01, 0.1).
pub const ALPHA_RANGE: (f64, f64) = (0.01, 0.1);

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GaborError {
    #[error("{what}: expected {expected_w}x{expected_h}, got {got_w}x{got_h}")]
    SizeMismatch {
        what: &'static str,
        expected_w: u32,
        expected_h: u32,
        got_w: u32,
        got_h: u32,
    },
    #[error("the image is empty")]
    Empty,
    #[error("bad parameter `{name}`: {reason}")]
    BadParameter { name: &'static str, reason: String },
}

/// Envelope width and wavelength of the bank.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaborParams {
    /// Standard deviation σ of the Gaussian envelope (pixels).
    pub sigma_px: f64,
    /// Wavelength λ of the carrier (pixels).
    pub wavelength_px: f64,
}

impl Default for GaborParams {
    fn default() -> Self {
        GaborParams {
            sigma_px: 2.0,
            wavelength_px: 8.0,
        }
    }
}

/// The closed form of the filter at orientation `theta_rad`, sampled on the integer grid
/// `−r..=r` (row-major, y outer): what the separable passes must reproduce.
pub fn gabor_kernel(p: GaborParams, theta_rad: f64, radius: usize) -> Vec<f64> {
    let r = radius as i64;
    let s2 = p.sigma_px * p.sigma_px;
    let norm = 1.0 / (2.0 * std::f64::consts::PI * s2);
    let k = 2.0 * std::f64::consts::PI / p.wavelength_px;
    let (c, s) = (theta_rad.cos(), theta_rad.sin());
    let mut out = Vec::with_capacity((2 * radius + 1).pow(2));
    for y in -r..=r {
        for x in -r..=r {
            let (x, y) = (x as f64, y as f64);
            out.push(norm * (-(x * x + y * y) / (2.0 * s2)).exp() * (k * (x * c + y * s)).cos());
        }
    }
    out
}

/// A feature image: [`FILTERS`] planes of `width × height` responses, in eq. 1's order
/// (`G_Y(θ1..4)`, `R_R(θ1..4)`, `R_G(θ1..4)`, `R_B(θ1..4)`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Features {
    pub width: u32,
    pub height: u32,
    pub planes: Vec<Vec<f32>>,
}

impl Features {
    pub fn new(width: u32, height: u32) -> Features {
        let n = width as usize * height as usize;
        Features {
            width,
            height,
            planes: vec![vec![0.0; n]; FILTERS],
        }
    }
}

/// A binary image (0 or 1 per pixel), row-major.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Mask {
    pub width: u32,
    pub height: u32,
    pub data: Vec<u8>,
}

impl Mask {
    pub fn new(width: u32, height: u32) -> Mask {
        Mask {
            width,
            height,
            data: vec![0; width as usize * height as usize],
        }
    }

    pub fn get(&self, x: u32, y: u32) -> u8 {
        self.data[y as usize * self.width as usize + x as usize]
    }

    pub fn count(&self) -> usize {
        self.data.iter().map(|&v| usize::from(v)).sum()
    }
}

/// The 16-filter bank as 1-D taps: the Gaussian `g`, and `g·cos`, `g·sin` at the carrier
/// frequencies of the axis-aligned (`k`) and diagonal (`k/√2`) orientations.
#[derive(Debug, Clone)]
pub struct GaborBank {
    params: GaborParams,
    radius: usize,
    gauss: Vec<f32>,
    cos_k: Vec<f32>,
    cos_d: Vec<f32>,
    sin_d: Vec<f32>,
    /// f64 copies for [`Self::kernel`].
    taps64: [Vec<f64>; 4],
}

/// Scratch planes reused between frames.
#[derive(Debug, Default, Clone)]
pub struct Scratch {
    channel: Vec<f32>,
    rows: [Vec<f32>; 4],
    tmp: Vec<f32>,
}

impl GaborBank {
    pub fn new(params: GaborParams) -> Result<GaborBank, GaborError> {
        if !(params.sigma_px.is_finite() && (0.5..=20.0).contains(&params.sigma_px)) {
            return Err(GaborError::BadParameter {
                name: "sigma_px",
                reason: format!("{} is not in [0.5, 20] px", params.sigma_px),
            });
        }
        if !(params.wavelength_px.is_finite() && params.wavelength_px >= 2.0) {
            return Err(GaborError::BadParameter {
                name: "wavelength_px",
                reason: format!("{} is below 2 px (the Nyquist limit)", params.wavelength_px),
            });
        }
        let radius = (3.0 * params.sigma_px).ceil() as usize;
        let k = 2.0 * std::f64::consts::PI / params.wavelength_px;
        let kd = k / std::f64::consts::SQRT_2;
        // the 1/(2πσ²) of the 2-D envelope is split evenly between the row and column taps
        let half_norm = (1.0 / (2.0 * std::f64::consts::PI * params.sigma_px.powi(2))).sqrt();
        let r = radius as i64;
        let make = |f: &dyn Fn(f64) -> f64| -> Vec<f64> {
            (-r..=r)
                .map(|i| {
                    let x = i as f64;
                    half_norm * (-(x * x) / (2.0 * params.sigma_px.powi(2))).exp() * f(x)
                })
                .collect()
        };
        let gauss = make(&|_| 1.0);
        let cos_k = make(&|x| (k * x).cos());
        let cos_d = make(&|x| (kd * x).cos());
        let sin_d = make(&|x| (kd * x).sin());
        let f32s = |v: &[f64]| v.iter().map(|&x| x as f32).collect::<Vec<f32>>();
        Ok(GaborBank {
            params,
            radius,
            gauss: f32s(&gauss),
            cos_k: f32s(&cos_k),
            cos_d: f32s(&cos_d),
            sin_d: f32s(&sin_d),
            taps64: [gauss, cos_k, cos_d, sin_d],
        })
    }

    pub fn params(&self) -> GaborParams {
        self.params
    }

    /// Kernel radius (taps `−radius..=radius`): ⌈3σ⌉.
    pub fn radius(&self) -> usize {
        self.radius
    }

    /// The 2-D kernel of orientation `m` (0..4) as the separable passes realise it (f64,
    /// row-major, y outer); equals [`gabor_kernel`] up to rounding.
    pub fn kernel(&self, m: usize) -> Vec<f64> {
        let [g, ck, cd, sd] = &self.taps64;
        let n = 2 * self.radius + 1;
        let mut out = Vec::with_capacity(n * n);
        for y in 0..n {
            for x in 0..n {
                out.push(match m % 4 {
                    0 => ck[x] * g[y],
                    1 => cd[x] * cd[y] - sd[x] * sd[y],
                    2 => g[x] * ck[y],
                    _ => cd[x] * cd[y] + sd[x] * sd[y],
                });
            }
        }
        out
    }

    /// The 16 responses of an RGB image into `dst` (resized if needed).
    pub fn features(
        &self,
        rgb: &RgbImage,
        dst: &mut Features,
        scratch: &mut Scratch,
    ) -> Result<(), GaborError> {
        let (w, h) = rgb.dimensions();
        if w == 0 || h == 0 {
            return Err(GaborError::Empty);
        }
        if dst.width != w || dst.height != h || dst.planes.len() != FILTERS {
            *dst = Features::new(w, h);
        }
        let n = w as usize * h as usize;
        scratch.channel.resize(n, 0.0);
        for r in scratch.rows.iter_mut() {
            r.resize(n, 0.0);
        }
        scratch.tmp.resize(n, 0.0);
        let raw = rgb.as_raw();
        for ch in 0..4 {
            let plane = &mut scratch.channel;
            plane
                .par_chunks_mut(w as usize)
                .enumerate()
                .for_each(|(y, row)| {
                    let src = &raw[y * w as usize * 3..(y + 1) * w as usize * 3];
                    for (x, v) in row.iter_mut().enumerate() {
                        let (r, g, b) = (
                            f32::from(src[3 * x]),
                            f32::from(src[3 * x + 1]),
                            f32::from(src[3 * x + 2]),
                        );
                        *v = match ch {
                            0 => (0.299 * r + 0.587 * g + 0.114 * b) / 255.0,
                            1 => r / 255.0,
                            2 => g / 255.0,
                            _ => b / 255.0,
                        };
                    }
                });
            let [rg, rck, rcd, rsd] = &mut scratch.rows;
            row_pass(plane, rg, w, &self.gauss);
            row_pass(plane, rck, w, &self.cos_k);
            row_pass(plane, rcd, w, &self.cos_d);
            row_pass(plane, rsd, w, &self.sin_d);
            let out = &mut dst.planes[4 * ch..4 * ch + 4];
            let (o0, rest) = out.split_at_mut(1);
            let (o1, rest) = rest.split_at_mut(1);
            let (o2, o3) = rest.split_at_mut(1);
            // 0°: cos(kx)·g(y)
            col_pass(rck, &mut o0[0], w, h, &self.gauss);
            // 90°: g(x)·cos(ky)
            col_pass(rg, &mut o2[0], w, h, &self.cos_k);
            // 45° = P − Q, 135° = P + Q with P = cos·cos, Q = sin·sin (diagonal frequency)
            col_pass(rcd, &mut o1[0], w, h, &self.cos_d);
            col_pass(rsd, &mut scratch.tmp, w, h, &self.sin_d);
            let (p45, p135) = (&mut o1[0], &mut o3[0]);
            p45.par_iter_mut()
                .zip(p135.par_iter_mut())
                .zip(scratch.tmp.par_iter())
                .for_each(|((a, b), q)| {
                    let p = *a;
                    *a = p - q;
                    *b = p + q;
                });
            if ch > 0 {
                // half-wave rectification of the colour responses
                for plane in out.iter_mut() {
                    plane.par_iter_mut().for_each(|v| *v = v.max(0.0));
                }
            }
        }
        Ok(())
    }
}

/// Horizontal correlation with replicated borders: `dst[y][x] = Σ_i k[i] · src[y][x + i − r]`.
fn row_pass(src: &[f32], dst: &mut [f32], w: u32, taps: &[f32]) {
    let w = w as usize;
    let r = taps.len() / 2;
    dst.par_chunks_mut(w)
        .zip(src.par_chunks(w))
        .for_each(|(out, row)| {
            for (x, o) in out.iter_mut().enumerate() {
                let mut acc = 0.0f32;
                if x >= r && x + r < w {
                    let win = &row[x - r..=x + r];
                    for (k, v) in taps.iter().zip(win) {
                        acc += k * v;
                    }
                } else {
                    for (i, k) in taps.iter().enumerate() {
                        let xi = (x + i).saturating_sub(r).min(w - 1);
                        acc += k * row[xi];
                    }
                }
                *o = acc;
            }
        });
}

/// Vertical correlation with replicated borders, accumulated a whole row at a time.
fn col_pass(src: &[f32], dst: &mut [f32], w: u32, h: u32, taps: &[f32]) {
    let (w, h) = (w as usize, h as usize);
    let r = taps.len() / 2;
    dst.par_chunks_mut(w).enumerate().for_each(|(y, out)| {
        out.fill(0.0);
        for (i, k) in taps.iter().enumerate() {
            let yi = (y + i).saturating_sub(r).min(h - 1);
            let row = &src[yi * w..(yi + 1) * w];
            for (o, v) in out.iter_mut().zip(row) {
                *o += k * v;
            }
        }
    });
}

/// Median of a sample (mean of the two middle values for an even count); `None` if empty or
/// not finite. Reorders `values`.
pub fn median(values: &mut [f32]) -> Option<f64> {
    let n = values.len();
    if n == 0 || values.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let mid = n / 2;
    let (lower, m, _) = values.select_nth_unstable_by(mid, f32::total_cmp);
    let upper = f64::from(*m);
    if n % 2 == 1 {
        return Some(upper);
    }
    let below = lower.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    Some(0.5 * (f64::from(below) + upper))
}

/// The MAD threshold of a sample: `(threshold, median, MAD)` with
/// `threshold = median + k · 1.4826 · MAD` and `MAD = median(|v − median|)`.
pub fn mad_threshold(values: &[f32], k: f64) -> Option<(f64, f64, f64)> {
    let mut work = values.to_vec();
    let med = median(&mut work)?;
    for (w, v) in work.iter_mut().zip(values) {
        *w = (f64::from(*v) - med).abs() as f32;
    }
    let mad = median(&mut work)?;
    Some((med + k * MAD_TO_SIGMA * mad, med, mad))
}

/// What one frame's segmentation measured.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Segmentation {
    /// Distance threshold used (feature units).
    pub threshold: f64,
    pub median: f64,
    pub mad: f64,
    /// Foreground pixels (after ghost removal).
    pub foreground: usize,
    /// Regions judged ghosts and learnt into the background ([`GhostTest`]).
    pub ghosts: usize,
}

/// How the background model learns from a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Update {
    /// Eq. 2 as printed: every pixel with weight α.
    All,
    /// Our addition: α outside the foreground (dilated by `dilate_px`), `foreground_alpha`
    /// inside it (0 freezes it; a small rate lets wrongly segmented regions heal).
    Selective {
        foreground_alpha: f64,
        dilate_px: u32,
    },
}

/// The running-average Gabor background of one camera.
#[derive(Debug, Clone)]
pub struct GaborBackground {
    bank: GaborBank,
    /// Learning rate α of eq. 2.
    alpha: f32,
    update: Update,
    /// The update mask of [`Update::Selective`] (dilated foreground) and its row-pass scratch.
    grown: Vec<u8>,
    grown_rows: Vec<u8>,
    /// k of the MAD threshold.
    mad_k: f64,
    model: Option<Features>,
    current: Features,
    distance: Vec<f32>,
    scratch: Scratch,
    /// The ghost test and, with it, the luminance of the frame and of the background.
    ghosts: Option<GhostTest>,
    luma: Vec<f32>,
    luma_bg: Vec<f32>,
    ghost_scratch: ghosts::GhostScratch,
}

impl GaborBackground {
    pub fn new(bank: GaborBank, alpha: f64, mad_k: f64) -> Result<GaborBackground, GaborError> {
        if !(alpha.is_finite() && alpha > 0.0 && alpha < 1.0) {
            return Err(GaborError::BadParameter {
                name: "alpha",
                reason: format!("{alpha} is not in (0, 1)"),
            });
        }
        if !(mad_k.is_finite() && mad_k >= 0.0) {
            return Err(GaborError::BadParameter {
                name: "mad_k",
                reason: format!("{mad_k} is not a finite number ≥ 0"),
            });
        }
        Ok(GaborBackground {
            bank,
            alpha: alpha as f32,
            update: Update::All,
            grown: Vec::new(),
            grown_rows: Vec::new(),
            mad_k,
            model: None,
            current: Features::default(),
            distance: Vec::new(),
            scratch: Scratch::default(),
            ghosts: None,
            luma: Vec::new(),
            luma_bg: Vec::new(),
            ghost_scratch: ghosts::GhostScratch::default(),
        })
    }

    /// Remove ghosts with `test` after each segmentation (our addition, [`GhostTest`]).
    pub fn with_ghost_removal(mut self, test: GhostTest) -> GaborBackground {
        self.ghosts = Some(test);
        self
    }

    /// Use `update` instead of eq. 2's all-pixel rule.
    pub fn with_update(mut self, update: Update) -> Result<GaborBackground, GaborError> {
        if let Update::Selective {
            foreground_alpha, ..
        } = update
            && !(foreground_alpha.is_finite() && (0.0..1.0).contains(&foreground_alpha))
        {
            return Err(GaborError::BadParameter {
                name: "foreground_alpha",
                reason: format!("{foreground_alpha} is not in [0, 1)"),
            });
        }
        self.update = update;
        Ok(self)
    }

    /// The distance image of the last frame (`‖Bᵗ − Mᵗ‖`, row-major).
    pub fn distance(&self) -> &[f32] {
        &self.distance
    }

    /// The background feature image, once a frame has been seen.
    pub fn model(&self) -> Option<&Features> {
        self.model.as_ref()
    }

    /// Start the model from the features of the per-pixel, per-channel temporal median of
    /// `frames` instead of from the first frame segmented. A person present in only a minority
    /// of the frames is left out of the median, so the model does not start with people in it
    /// (the paper does not say how `B⁰` is obtained; with the first frame, every person in it
    /// leaves a ghost that eq. 2 takes ~`ln(threshold / contrast) / ln(1 − α)` frames to fade).
    pub fn bootstrap(&mut self, frames: &[RgbImage]) -> Result<(), GaborError> {
        let Some(first) = frames.first() else {
            return Err(GaborError::Empty);
        };
        let (w, h) = first.dimensions();
        if w == 0 || h == 0 {
            return Err(GaborError::Empty);
        }
        if let Some(f) = frames.iter().find(|f| f.dimensions() != (w, h)) {
            return Err(GaborError::SizeMismatch {
                what: "bootstrap frame",
                expected_w: w,
                expected_h: h,
                got_w: f.width(),
                got_h: f.height(),
            });
        }
        let mut median = RgbImage::new(w, h);
        let k = frames.len();
        let pixels: &mut [u8] = &mut median;
        pixels
            .par_chunks_mut(3 * w as usize)
            .enumerate()
            .for_each(|(y, row)| {
                let mut v: Vec<u8> = Vec::with_capacity(k);
                let off = y * 3 * w as usize;
                for (i, out) in row.iter_mut().enumerate() {
                    v.clear();
                    v.extend(frames.iter().map(|f| f.as_raw()[off + i]));
                    v.sort_unstable();
                    // lower median for an even count: a value that was really observed
                    *out = v[(k - 1) / 2];
                }
            });
        let mut model = Features::default();
        self.bank.features(&median, &mut model, &mut self.scratch)?;
        self.model = Some(model);
        if self.ghosts.is_some() {
            ghosts::luma(median.as_raw(), &mut self.luma_bg);
        }
        Ok(())
    }

    /// Segment one frame into `mask` and update the background. The first frame initialises
    /// the model and gives an empty mask (unless [`Self::bootstrap`] started it).
    pub fn apply(&mut self, rgb: &RgbImage, mask: &mut Mask) -> Result<Segmentation, GaborError> {
        let (w, h) = rgb.dimensions();
        if let Some(m) = &self.model
            && (m.width != w || m.height != h)
        {
            return Err(GaborError::SizeMismatch {
                what: "frame vs background model",
                expected_w: m.width,
                expected_h: m.height,
                got_w: w,
                got_h: h,
            });
        }
        self.bank
            .features(rgb, &mut self.current, &mut self.scratch)?;
        if mask.width != w || mask.height != h {
            *mask = Mask::new(w, h);
        }
        let n = w as usize * h as usize;
        if self.ghosts.is_some() {
            ghosts::luma(rgb.as_raw(), &mut self.luma);
            if self.model.is_some() && self.luma_bg.len() != n {
                // the test was switched on after the model started: start its luminance here
                self.luma_bg.clone_from(&self.luma);
            }
        }
        let Some(model) = self.model.as_mut() else {
            self.model = Some(self.current.clone());
            self.luma_bg.clone_from(&self.luma);
            mask.data.fill(0);
            self.distance.clear();
            self.distance.resize(n, 0.0);
            return Ok(Segmentation::default());
        };
        // eq. 2: Bᵗ = (1 − α) Bᵗ⁻¹ + α Mᵗ, then the distance ‖Bᵗ − Mᵗ‖ (the selective rule
        // measures against Bᵗ⁻¹ and updates after thresholding)
        let a = self.alpha;
        if self.update == Update::All {
            for (b, m) in model.planes.iter_mut().zip(&self.current.planes) {
                b.par_iter_mut()
                    .zip(m.par_iter())
                    .for_each(|(b, m)| *b = (1.0 - a) * *b + a * m);
            }
            if self.ghosts.is_some() {
                self.luma_bg
                    .iter_mut()
                    .zip(&self.luma)
                    .for_each(|(b, m)| *b = (1.0 - a) * *b + a * m);
            }
        }
        self.distance.resize(n, 0.0);
        let (bp, mp) = (&model.planes, &self.current.planes);
        self.distance
            .par_chunks_mut(w as usize)
            .enumerate()
            .for_each(|(y, row)| {
                let off = y * w as usize;
                for (x, d) in row.iter_mut().enumerate() {
                    let mut s = 0.0f32;
                    for f in 0..FILTERS {
                        let e = bp[f][off + x] - mp[f][off + x];
                        s += e * e;
                    }
                    *d = s.sqrt();
                }
            });
        let (threshold, median, mad) =
            mad_threshold(&self.distance, self.mad_k).ok_or(GaborError::Empty)?;
        let t = threshold as f32;
        mask.data
            .par_iter_mut()
            .zip(self.distance.par_iter())
            .for_each(|(m, d)| *m = u8::from(*d > t));
        let mut ghost_count = 0;
        if let Some(test) = self.ghosts {
            ghost_count = ghosts::find(
                &mask.data,
                w as usize,
                &self.luma,
                &self.luma_bg,
                test,
                &mut self.ghost_scratch,
            );
            if ghost_count > 0 {
                // the ghost's pixels become background: learnt at once, out of the mask
                let heal = &self.ghost_scratch.heal;
                ghosts::learn(model, &self.current, &mut self.luma_bg, &self.luma, heal);
                mask.data
                    .iter_mut()
                    .zip(heal)
                    .for_each(|(k, &g)| *k &= 1 - g);
            }
        }
        if let Update::Selective {
            foreground_alpha,
            dilate_px,
        } = self.update
        {
            dilate(
                &mask.data,
                w as usize,
                dilate_px as usize,
                &mut self.grown_rows,
                &mut self.grown,
            );
            let rates = [a, foreground_alpha as f32];
            let grown = &self.grown;
            for (b, m) in model.planes.iter_mut().zip(&self.current.planes) {
                b.par_iter_mut()
                    .zip(m.par_iter())
                    .zip(grown.par_iter())
                    .for_each(|((b, m), &g)| {
                        let a = rates[usize::from(g)];
                        *b = (1.0 - a) * *b + a * m;
                    });
            }
            if self.ghosts.is_some() {
                for ((b, m), &g) in self.luma_bg.iter_mut().zip(&self.luma).zip(grown) {
                    let a = rates[usize::from(g)];
                    *b = (1.0 - a) * *b + a * m;
                }
            }
        }
        Ok(Segmentation {
            threshold,
            median,
            mad,
            foreground: mask.count(),
            ghosts: ghost_count,
        })
    }
}

/// Binary dilation of a 0/1 image (row-major, `w` wide) by a `(2r + 1)²` square: a row pass
/// (distance to the nearest set pixel, both ways), then an OR of `2r + 1` rows.
fn dilate(src: &[u8], w: usize, r: usize, rows: &mut Vec<u8>, out: &mut Vec<u8>) {
    let n = src.len();
    out.clear();
    out.resize(n, 0);
    if w == 0 || n == 0 {
        return;
    }
    if r == 0 {
        out.copy_from_slice(src);
        return;
    }
    let h = n / w;
    rows.clear();
    rows.resize(n, 0);
    rows.par_chunks_mut(w)
        .zip(src.par_chunks(w))
        .for_each(|(dst, line)| {
            // any set pixel within ±r along the row: the distance to the last set pixel,
            // sweeping left to right and then right to left (no allocation per row)
            let mut since = usize::MAX;
            for (d, &v) in dst.iter_mut().zip(line) {
                since = if v != 0 { 0 } else { since.saturating_add(1) };
                *d = u8::from(since <= r);
            }
            since = usize::MAX;
            for (d, &v) in dst.iter_mut().zip(line).rev() {
                since = if v != 0 { 0 } else { since.saturating_add(1) };
                *d |= u8::from(since <= r);
            }
        });
    let rows: &[u8] = rows;
    // column pass: OR of the row-dilated lines y − r ..= y + r (O(r) per pixel; r is the
    // filter radius, a few pixels)
    out.par_chunks_mut(w).enumerate().for_each(|(y, dst)| {
        for yy in y.saturating_sub(r)..(y + r + 1).min(h) {
            for (d, &v) in dst.iter_mut().zip(&rows[yy * w..(yy + 1) * w]) {
                *d |= v;
            }
        }
    });
}

#[cfg(test)]
mod tests;

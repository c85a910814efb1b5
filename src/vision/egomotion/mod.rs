//! Seed 001 §IV (Kobilarov et al.), "Method 1": egomotion-compensated frame differencing on
//! an omnidirectional camera, after Jung & Sukhatme (IAS 2004). Per frame:
//!
//! 1. [`views`]: the raw paracatadioptric image as 8 perspective views, axes 45° apart;
//! 2. Shi–Tomasi corners of the previous raw grey image tracked into the current one by
//!    pyramidal Lucas–Kanade ([`crate::vision::klt`]) — on the raw image, as the paper does
//!    "to avoid the effect of aliasing" — each pair mapped into local coordinates of every
//!    view its previous position projects onto;
//! 3. [`bilinear`]: per view a bilinear pixel transform fitted by linear regression on those
//!    pairs (affine / translation / identity fallbacks when too few, counted), the previous view
//!    warped onto the current one and differenced;
//! 4. [`particles`]: a particle filter over directions `(θ, φ)` weighed by the thresholded
//!    difference, EM clustering of the particles; the strongest cluster is the detection, a
//!    bearing in the omni camera frame.
//!
//! The paper reports that this method fails — frequent losses, unreliable above 1 m/s (fig. 3)
//! — because the bilinear (affine-camera) model does not hold for close obstacles. This module
//! reproduces the method; [`loss_by_speed`] measures the loss rate against robot speed. It does
//! not estimate range (the paper uses the laser for that) and does no following control.

pub mod bilinear;
pub mod particles;
pub mod views;

use image::{GrayImage, RgbImage};
use nalgebra::{Point2, Vector3};

use crate::geometry::camera::Paracatadioptric;
use crate::vision::klt::{self, LkParams, Pyramid};
use bilinear::{Bilinear, FitKind};
use particles::{DiffField, ParticleFilter, ParticleParams};
use views::{Plane, ViewParams, Views, wrap_angle};

/// Errors of Method 1.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EgomotionError {
    #[error("method 1 parameters: {0}")]
    BadParams(String),
    #[error("omni image is {got_w}x{got_h}, the camera model says {want_w}x{want_h}")]
    ImageSize {
        got_w: u32,
        got_h: u32,
        want_w: u32,
        want_h: u32,
    },
}

/// Method 1's parameters (a pipeline TOML's `[method1]` table; every key optional).
#[derive(Debug, Clone, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct Method1Params {
    pub views: ViewParams,
    pub particles: ParticleParams,
    /// Corners tracked per frame on the raw image.
    pub max_features: usize,
    /// Shi–Tomasi: keep corners scoring at least this fraction of the best.
    pub feature_quality: f32,
    pub feature_min_distance_px: f32,
    /// Shi–Tomasi window half-size (px).
    pub feature_half_window: usize,
    /// Corners closer than this to the mirror ring's edges are not used (px): the ring's rim
    /// is a strong edge that does not move with the scene.
    pub ring_margin_px: f64,
    pub lk_levels: usize,
    pub lk_half_window: usize,
    /// Bilinear fit needs at least this many pairs in a view, else the affine fallback.
    pub min_bilinear: usize,
    /// Affine fit needs at least this many pairs, else a translation.
    pub min_affine: usize,
    /// Differences at or below this many grey levels weigh nothing (camera noise: the
    /// difference of two frames with σ = 2.5 has σ ≈ 3.5; 15 is about 4σ).
    pub diff_threshold: f32,
    /// A particle weighs the mean thresholded difference over a (2h+1)² window (px).
    pub weight_half_window: usize,
}

impl Default for Method1Params {
    fn default() -> Self {
        Self {
            views: ViewParams::default(),
            particles: ParticleParams::default(),
            max_features: 150,
            feature_quality: 0.01,
            feature_min_distance_px: 10.0,
            feature_half_window: 2,
            ring_margin_px: 10.0,
            lk_levels: 3,
            lk_half_window: 7,
            min_bilinear: 8,
            min_affine: 4,
            diff_threshold: 15.0,
            weight_half_window: 2,
        }
    }
}

/// The detected motion: a bearing in the omni camera frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Detection {
    /// Azimuth θ (rad, (−π, π]).
    pub azimuth: f64,
    /// Elevation φ (rad).
    pub elevation: f64,
    /// Mixing weight of the strongest EM cluster (share of the particles' weight).
    pub weight: f64,
}

/// What one frame gave.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Method1Output {
    pub detection: Option<Detection>,
    /// Corner pairs tracked from the previous frame (0 on the first frame).
    pub features_tracked: usize,
    /// Views whose transform fell back from bilinear (affine, translation or identity).
    pub fallback_views: usize,
}

/// The previous frame's state.
struct Previous {
    grey: GrayImage,
    pyramid: Pyramid,
    views: Vec<Plane>,
}

/// Method 1, fed one omni image per call in time order.
pub struct Method1 {
    p: Method1Params,
    views: Views,
    filter: ParticleFilter,
    previous: Option<Previous>,
    diffs: Vec<Plane>,
}

impl Method1 {
    pub fn new(
        model: &Paracatadioptric,
        p: &Method1Params,
        seed: u64,
    ) -> Result<Method1, EgomotionError> {
        if p.min_bilinear < 4 || p.min_affine < 3 || p.particles.particles == 0 {
            return Err(EgomotionError::BadParams(
                "min_bilinear >= 4, min_affine >= 3 and particles >= 1 are needed".into(),
            ));
        }
        let views = Views::new(model, &p.views)?;
        let band = elevation_band(&views);
        Ok(Method1 {
            p: p.clone(),
            filter: ParticleFilter::new(&p.particles, band, seed),
            views,
            previous: None,
            diffs: Vec::new(),
        })
    }

    pub fn views(&self) -> &Views {
        &self.views
    }

    /// The last frame's compensated difference image per view.
    pub fn differences(&self) -> &[Plane] {
        &self.diffs
    }

    pub fn step(&mut self, omni: &RgbImage) -> Result<Method1Output, EgomotionError> {
        let m = self.views.omni();
        if omni.width() != m.width || omni.height() != m.height {
            return Err(EgomotionError::ImageSize {
                got_w: omni.width(),
                got_h: omni.height(),
                want_w: m.width,
                want_h: m.height,
            });
        }
        let grey = image::imageops::grayscale(omni);
        let pyramid = Pyramid::new(&grey, self.p.lk_levels);
        let mut current_views = Vec::new();
        self.views.render(&grey, &mut current_views);
        let Some(prev) = self.previous.take() else {
            self.previous = Some(Previous {
                grey,
                pyramid,
                views: current_views,
            });
            return Ok(Method1Output {
                detection: None,
                features_tracked: 0,
                fallback_views: 0,
            });
        };
        let pairs = self.track_corners(&prev, &pyramid);
        let per_view = pairs_per_view(&self.views, &pairs);
        let mut fallback_views = 0;
        self.diffs
            .resize_with(self.views.len(), || Plane::new(0, 0, 0.0));
        for (k, (cur_pts, prev_pts)) in per_view.iter().enumerate() {
            let (t, kind): (Bilinear, FitKind) =
                bilinear::fit(cur_pts, prev_pts, self.p.min_bilinear, self.p.min_affine);
            if kind != FitKind::Bilinear {
                fallback_views += 1;
            }
            bilinear::compensated_difference(
                &current_views[k],
                &prev.views[k],
                &t,
                &mut self.diffs[k],
            );
        }
        let field = DiffViews {
            views: &self.views,
            diffs: &self.diffs,
            threshold: self.p.diff_threshold,
            half_window: self.p.weight_half_window,
        };
        let detection = self.filter.step(&field).map(|c| Detection {
            azimuth: c.azimuth,
            elevation: c.elevation,
            weight: c.weight,
        });
        self.previous = Some(Previous {
            grey,
            pyramid,
            views: current_views,
        });
        Ok(Method1Output {
            detection,
            features_tracked: pairs.len(),
            fallback_views,
        })
    }

    /// Corners of the previous raw image that project onto a view (away from the mirror
    /// ring's rims), tracked into the current one: `(previous, current)` omni positions (pixel
    /// centres at `i + 0.5`). The strongest `8 × max_features` corners of the whole image are
    /// found first and the first `max_features` of them on the views kept.
    fn track_corners(&self, prev: &Previous, pyramid: &Pyramid) -> Vec<([f64; 2], [f64; 2])> {
        let m = self.views.omni();
        let (lo, hi) = (
            m.r_min + self.p.ring_margin_px,
            m.r_max - self.p.ring_margin_px,
        );
        let centre = |q: &[f32; 2]| Point2::new(f64::from(q[0]) + 0.5, f64::from(q[1]) + 0.5);
        let in_ring = |q: &[f32; 2]| {
            let r = (centre(q) - Point2::new(m.xc, m.yc)).norm();
            r >= lo && r <= hi
        };
        let corners: Vec<[f32; 2]> = klt::good_features(
            &prev.grey,
            self.p.max_features.saturating_mul(8),
            self.p.feature_quality,
            self.p.feature_min_distance_px,
            self.p.feature_half_window,
        )
        .into_iter()
        .filter(|q| in_ring(q) && self.views.omni_to_view(&centre(q)).is_some())
        .take(self.p.max_features)
        .collect();
        let lk = LkParams {
            half_window: self.p.lk_half_window,
            ..LkParams::default()
        };
        let tracked = klt::track(&prev.pyramid, pyramid, &corners, &lk);
        corners
            .iter()
            .zip(tracked)
            .filter_map(|(a, b)| {
                let b = b.filter(in_ring)?;
                let (a, b) = (centre(a), centre(&b));
                Some(([a.x, a.y], [b.x, b.y]))
            })
            .collect()
    }
}

/// `(current, previous)` positions of the corner pairs of one view.
pub type ViewPairs = (Vec<[f64; 2]>, Vec<[f64; 2]>);

/// Per view, `(current, previous)` positions of the pairs whose previous position lies in that
/// view (a pair in the overlap of two views serves both).
pub fn pairs_per_view(views: &Views, pairs: &[([f64; 2], [f64; 2])]) -> Vec<ViewPairs> {
    let mut out = vec![(Vec::new(), Vec::new()); views.len()];
    let omni = views.omni();
    for (a, b) in pairs {
        let (Some(ra), Some(rb)) = (
            omni.ray(&Point2::new(a[0], a[1])),
            omni.ray(&Point2::new(b[0], b[1])),
        ) else {
            continue;
        };
        for (k, v) in views.views().iter().enumerate() {
            let Some(pa) = v.project(&ra.dir).filter(|p| v.contains(p)) else {
                continue;
            };
            let Some(pb) = v.project(&rb.dir) else {
                continue;
            };
            out[k].0.push([pb.x, pb.y]);
            out[k].1.push([pa.x, pa.y]);
        }
    }
    out
}

/// The elevations the views cover along their centre column (rad).
fn elevation_band(views: &Views) -> (f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for v in views.views() {
        let cx = f64::from(v.pinhole.width) / 2.0;
        for y in [0.0, f64::from(v.pinhole.height)] {
            let r = v.ray(&Point2::new(cx, y));
            let el = r.z.atan2(r.x.hypot(r.y));
            lo = lo.min(el);
            hi = hi.max(el);
        }
    }
    (lo, hi)
}

/// The compensated difference images as a field over directions: the mean over a window of
/// `max(d − threshold, 0)` in the view the direction projects onto.
pub struct DiffViews<'a> {
    pub views: &'a Views,
    pub diffs: &'a [Plane],
    pub threshold: f32,
    pub half_window: usize,
}

impl DiffField for DiffViews<'_> {
    fn value(&self, azimuth: f64, elevation: f64) -> f64 {
        let (se, ce) = elevation.sin_cos();
        let dir = Vector3::new(ce * azimuth.cos(), ce * azimuth.sin(), se);
        let Some((k, px)) = self.views.ray_to_view(&dir) else {
            return 0.0;
        };
        let Some(d) = self.diffs.get(k) else {
            return 0.0;
        };
        if d.width == 0 || d.height == 0 {
            return 0.0;
        }
        let (cx, cy) = (px.x.floor() as isize, px.y.floor() as isize);
        let r = self.half_window as isize;
        let (mut sum, mut n) = (0.0f64, 0u32);
        for y in cy - r..=cy + r {
            for x in cx - r..=cx + r {
                if x < 0 || y < 0 || x >= d.width as isize || y >= d.height as isize {
                    continue;
                }
                sum += f64::from((d.at(x as usize, y as usize) - self.threshold).max(0.0));
                n += 1;
            }
        }
        if n == 0 { 0.0 } else { sum / f64::from(n) }
    }
}

/// The caller's loss rule: lost when there is no estimate or its azimuth is farther than
/// `threshold_rad` from the true one (difference wrapped to (−π, π]).
pub fn is_lost(est_azimuth: Option<f64>, true_azimuth: f64, threshold_rad: f64) -> bool {
    match est_azimuth {
        None => true,
        Some(a) => a.is_nan() || wrap_angle(a - true_azimuth).abs() > threshold_rad,
    }
}

/// Frames and losses in one speed bin `[lo, hi)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedBin {
    pub lo: f64,
    pub hi: f64,
    pub frames: usize,
    pub lost: usize,
    /// `lost / frames`.
    pub rate: f64,
}

/// Loss rate per robot-speed bin of width `bin_width` (m/s) starting at 0: bins `[k·w,
/// (k+1)·w)`, in increasing speed, empty bins left out. Speeds are taken as magnitudes;
/// non-finite speeds are skipped. Empty when `bin_width` is not a positive number.
pub fn loss_by_speed(samples: &[(f64, bool)], bin_width: f64) -> Vec<SpeedBin> {
    if !(bin_width > 0.0 && bin_width.is_finite()) {
        return Vec::new();
    }
    let mut bins: std::collections::BTreeMap<u64, (usize, usize)> = Default::default();
    for &(speed, lost) in samples {
        if !speed.is_finite() {
            continue;
        }
        let k = (speed.abs() / bin_width).floor() as u64;
        let e = bins.entry(k).or_default();
        e.0 += 1;
        e.1 += usize::from(lost);
    }
    bins.into_iter()
        .map(|(k, (frames, lost))| SpeedBin {
            lo: k as f64 * bin_width,
            hi: (k + 1) as f64 * bin_width,
            frames,
            lost,
            rate: lost as f64 / frames as f64,
        })
        .collect()
}

#[cfg(test)]
mod tests;

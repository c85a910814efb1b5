//! Seed 001 §V's visual feature of a laser blob (Kobilarov et al.): the paracatadioptric
//! omni image unwarped onto a cylinder, the "spherical" region of interest of a blob lifted
//! to chest height, its hue–saturation histogram, the correlation of two histograms as
//! printed and the target-to-clutter likelihood ratio.
//!
//! - **Cylinder**: column = azimuth θ = atan2(y, x) of the camera frame over [−π, π), row =
//!   elevation φ = atan2(z, √(x² + y²)) from the smallest to the largest elevation the mirror
//!   ring holds (`r_max` → φ_min, `r_min` → φ_max, from r = f(√(tan²φ + 1) − tan φ)).
//!   [`CylinderMap::unwarp`] draws the whole cylinder (figures); the features sample only
//!   their region, through the same projection, so nothing is unwarped per frame.
//! - **ROI** (our reading, stated): the paper's centre ((θ_l + θ_r)/2, (φ_l + φ_r)/2) and width
//!   |θ_l − θ_r| of the blob's two edges lifted to height h. Its printed height |φ_l − φ_r| is
//!   close to zero for two points at the same height and range, so the region's elevation
//!   extent is that of the blob's middle lifted to h ± `half_height_m` instead.
//! - **Histogram** H: 8 hue × 8 saturation bins ([`ColorSpace::Hs`]) of the ring pixels in the
//!   ROI, normalised to sum 1, then its mean (1/64) subtracted from every bin, as printed.
//! - **corr** ([`CorrForm`]): the default is the normalised form Σ H_i H_j / √(Σ H_i² · Σ H_j²)
//!   ([`corr_normalised`], the correlation coefficient of the two mean-subtracted histograms,
//!   ≤ 1, and 1 for a histogram with itself). The paper's own text asks for it: "the highest
//!   correlation between two histograms is one", and its clutter density 1/(1 − corr_min) is
//!   uniform over [corr_min, 1]. The formula as printed, Σ H_i H_j / (Σ H_i² · Σ H_j²)
//!   ([`corr`], no square root), is kept as the named variant [`CorrForm::Printed`]: it is not
//!   bounded by 1 (identical histograms give 1 / Σ H²), so flat histograms — small Σ H² —
//!   score higher than peaked ones.
//! - **lr** = max(corr, 0) · (1 − corr_min): the paper's γ_T / γ_C with γ_C = 1 / (1 − corr_min).
//!
//! Written by hand: a handful of trigonometric samples per region, which no image crate does.

use image::RgbImage;
use nalgebra::{Isometry3, Point2, Point3};

use crate::geometry::camera::Paracatadioptric;
use crate::vision::colortrack::ColorSpace;

/// Number of bins of the hue–saturation histogram.
pub const HS_BINS: usize = 64;

/// Which form of the paper's histogram correlation (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CorrForm {
    /// Σ a·b / √(Σ a² · Σ b²), ≤ 1 (the paper's text; the default).
    #[default]
    Normalised,
    /// Σ a·b / (Σ a² · Σ b²), as printed (not bounded by 1).
    Printed,
}

impl CorrForm {
    /// The correlation of two histograms in this form.
    pub fn corr(self, a: &[f64], b: &[f64]) -> f64 {
        match self {
            CorrForm::Normalised => corr_normalised(a, b),
            CorrForm::Printed => corr(a, b),
        }
    }
}

/// Elevation (rad) of an image radius `r` on the mirror: the inverse of r = f(sec φ − tan φ).
pub fn elevation_of_radius(model: &Paracatadioptric, r: f64) -> f64 {
    ((model.f * model.f - r * r) / (2.0 * r * model.f)).atan()
}

/// The raw-image pixel of the direction (θ, φ) of the camera frame; `None` off the mirror.
pub fn pixel_of(model: &Paracatadioptric, theta: f64, phi: f64) -> Option<Point2<f64>> {
    let d = Point3::new(phi.cos() * theta.cos(), phi.cos() * theta.sin(), phi.sin());
    model.project(&d)
}

/// The cylinder's geometry for one omni camera.
#[derive(Debug, Clone, PartialEq)]
pub struct CylinderMap {
    pub model: Paracatadioptric,
    pub width: usize,
    pub height: usize,
    pub phi_min: f64,
    pub phi_max: f64,
}

impl CylinderMap {
    /// `width` columns over 2π, `height` rows over the ring's elevations.
    pub fn new(model: &Paracatadioptric, width: usize, height: usize) -> CylinderMap {
        let phi_min = elevation_of_radius(model, model.r_max);
        let phi_max = elevation_of_radius(model, model.r_min.max(1e-6));
        CylinderMap {
            model: model.clone(),
            width: width.max(1),
            height: height.max(1),
            phi_min,
            phi_max,
        }
    }

    /// Azimuth and elevation of the centre of cell (col, row).
    pub fn direction(&self, col: usize, row: usize) -> (f64, f64) {
        let theta =
            -std::f64::consts::PI + std::f64::consts::TAU * (col as f64 + 0.5) / self.width as f64;
        let phi =
            self.phi_min + (self.phi_max - self.phi_min) * (row as f64 + 0.5) / self.height as f64;
        (theta, phi)
    }

    /// The (fractional) column and row of a direction.
    pub fn cell(&self, theta: f64, phi: f64) -> (f64, f64) {
        let t = wrap(theta) + std::f64::consts::PI;
        let col = t / std::f64::consts::TAU * self.width as f64 - 0.5;
        let row = (phi - self.phi_min) / (self.phi_max - self.phi_min) * self.height as f64 - 0.5;
        (col, row)
    }

    /// The whole cylinder, nearest-pixel sampling; cells off the mirror are black.
    pub fn unwarp(&self, img: &RgbImage) -> RgbImage {
        let mut out = RgbImage::new(self.width as u32, self.height as u32);
        for row in 0..self.height {
            for col in 0..self.width {
                let (theta, phi) = self.direction(col, row);
                if let Some(rgb) = sample(img, &self.model, theta, phi) {
                    out.put_pixel(col as u32, row as u32, image::Rgb(rgb));
                }
            }
        }
        out
    }
}

fn wrap(a: f64) -> f64 {
    (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
}

/// The image colour in direction (θ, φ), nearest pixel; `None` off the mirror or the image.
fn sample(img: &RgbImage, model: &Paracatadioptric, theta: f64, phi: f64) -> Option<[u8; 3]> {
    let p = pixel_of(model, theta, phi)?;
    let (x, y) = (p.x.floor(), p.y.floor());
    if x < 0.0 || y < 0.0 || x >= f64::from(img.width()) || y >= f64::from(img.height()) {
        return None;
    }
    Some(img.get_pixel(x as u32, y as u32).0)
}

/// A region of the cylinder: centre and size in azimuth and elevation (rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphericalRoi {
    pub theta: f64,
    pub phi: f64,
    pub width: f64,
    pub height: f64,
}

/// Azimuth and elevation of a point of the camera frame; `None` on the axis.
pub fn spherical(p: &Point3<f64>) -> Option<(f64, f64)> {
    let rho = p.x.hypot(p.y);
    (rho > 1e-9).then(|| (p.y.atan2(p.x), p.z.atan2(rho)))
}

/// The ROI of a blob whose edges are `left` and `right` on the ground plane of the fixed
/// frame, lifted to height `h` (m); its elevation extent is the blob middle's at
/// h ± `half_height_m` (see the module doc). `camera_from_fixed` maps fixed-frame points into
/// the camera frame.
pub fn roi_from_edges(
    camera_from_fixed: &Isometry3<f64>,
    left: [f64; 2],
    right: [f64; 2],
    h: f64,
    half_height_m: f64,
) -> Option<SphericalRoi> {
    let at = |xy: [f64; 2], z: f64| spherical(&(camera_from_fixed * Point3::new(xy[0], xy[1], z)));
    let (tl, _) = at(left, h)?;
    let (tr, _) = at(right, h)?;
    let mid = [0.5 * (left[0] + right[0]), 0.5 * (left[1] + right[1])];
    let (_, p_lo) = at(mid, h - half_height_m)?;
    let (_, p_hi) = at(mid, h + half_height_m)?;
    let dtheta = wrap(tr - tl);
    Some(SphericalRoi {
        theta: wrap(tl + 0.5 * dtheta),
        phi: 0.5 * (p_lo + p_hi),
        width: dtheta.abs(),
        height: (p_lo - p_hi).abs(),
    })
}

/// The normalised, mean-subtracted hue–saturation histogram of the ROI, sampled on the
/// cylinder's grid (`map`'s angular steps, at least 3 × 3 samples); `None` when no sample
/// lies on the mirror.
pub fn hs_histogram(img: &RgbImage, map: &CylinderMap, roi: &SphericalRoi) -> Option<Vec<f64>> {
    let d_theta = std::f64::consts::TAU / map.width as f64;
    let d_phi = (map.phi_max - map.phi_min) / map.height as f64;
    let nt = ((roi.width / d_theta).round() as usize).clamp(3, 4 * map.width);
    let np = ((roi.height / d_phi.abs()).round() as usize).clamp(3, 4 * map.height);
    let mut h = vec![0.0; HS_BINS];
    let mut n = 0usize;
    for i in 0..nt {
        let theta = roi.theta - 0.5 * roi.width + roi.width * (i as f64 + 0.5) / nt as f64;
        for j in 0..np {
            let phi = roi.phi - 0.5 * roi.height + roi.height * (j as f64 + 0.5) / np as f64;
            if let Some([r, g, b]) = sample(img, &map.model, theta, phi) {
                h[usize::from(ColorSpace::Hs.bin(r, g, b))] += 1.0;
                n += 1;
            }
        }
    }
    (n > 0).then(|| normalise(h))
}

/// Counts → normalised to sum 1, then the mean subtracted from every bin (as printed).
pub fn normalise(mut h: Vec<f64>) -> Vec<f64> {
    let sum: f64 = h.iter().sum();
    if sum > 0.0 {
        h.iter_mut().for_each(|v| *v /= sum);
    }
    let mean = h.iter().sum::<f64>() / h.len().max(1) as f64;
    h.iter_mut().for_each(|v| *v -= mean);
    h
}

/// The paper's correlation as printed: Σ a·b / (Σ a² · Σ b²); 0 when either is flat.
pub fn corr(a: &[f64], b: &[f64]) -> f64 {
    let (ab, aa, bb) = sums(a, b);
    if aa <= 0.0 || bb <= 0.0 {
        return 0.0;
    }
    ab / (aa * bb)
}

/// The correlation coefficient Σ a·b / √(Σ a² · Σ b²) (≤ 1); 0 when either is flat.
pub fn corr_normalised(a: &[f64], b: &[f64]) -> f64 {
    let (ab, aa, bb) = sums(a, b);
    if aa <= 0.0 || bb <= 0.0 {
        return 0.0;
    }
    ab / (aa * bb).sqrt()
}

fn sums(a: &[f64], b: &[f64]) -> (f64, f64, f64) {
    a.iter()
        .zip(b)
        .fold((0.0, 0.0, 0.0), |(ab, aa, bb), (x, y)| {
            (ab + x * y, aa + x * x, bb + y * y)
        })
}

/// lr = max(corr, 0) · (1 − corr_min) (the paper's γ_T / γ_C).
pub fn likelihood_ratio(corr: f64, corr_min: f64) -> f64 {
    if corr.is_finite() {
        corr.max(0.0) * (1.0 - corr_min)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};

    fn model() -> Paracatadioptric {
        Paracatadioptric {
            width: 640,
            height: 480,
            xc: 320.0,
            yc: 240.0,
            f: 130.0,
            r_min: 28.0,
            r_max: 238.0,
        }
    }

    /// The paper's projection and its inverse round-trip to 1e-9 over the ring.
    #[test]
    fn projection_and_inverse_round_trip() {
        let m = model();
        let mut worst: f64 = 0.0;
        for i in 0..36 {
            for r in [30.0, 60.0, 100.0, 130.0, 180.0, 237.0] {
                let th = -3.0 + 0.17 * f64::from(i);
                let px = Point2::new(m.xc + r * th.cos(), m.yc + r * th.sin());
                let ray = m.ray(&px).expect("on the ring");
                for s in [0.5, 3.0, 20.0] {
                    let back = m.project(&Point3::from(ray.dir * s)).expect("projects");
                    worst = worst.max((back - px).norm());
                }
                // the closed forms agree: elevation of the radius → radius of the elevation
                let phi = elevation_of_radius(&m, r);
                let p = pixel_of(&m, th, phi).expect("on the ring");
                worst = worst.max((p - px).norm());
            }
        }
        assert!(worst < 1e-9, "round trip error {worst}");
    }

    #[test]
    fn cylinder_cells_and_directions_invert() {
        let map = CylinderMap::new(&model(), 720, 120);
        assert!(map.phi_min < 0.0 && map.phi_max > 1.0);
        for (col, row) in [(0usize, 0usize), (359, 60), (719, 119)] {
            let (t, p) = map.direction(col, row);
            let (c, r) = map.cell(t, p);
            assert!((c - col as f64).abs() < 1e-9 && (r - row as f64).abs() < 1e-9);
        }
    }

    /// A blob 3 m ahead on the x axis, 0.4 m wide, camera 1.25 m up and level: the ROI is
    /// centred on azimuth 0 with width 2·atan(0.2 / 3) and the elevation extent of ±0.3 m.
    #[test]
    fn roi_of_a_blob_straight_ahead() {
        let fixed_from_camera = Isometry3::from_parts(
            Translation3::new(0.0, 0.0, 1.25),
            UnitQuaternion::identity(),
        );
        let cam = fixed_from_camera.inverse();
        let roi = roi_from_edges(&cam, [3.0, 0.2], [3.0, -0.2], 1.25, 0.3).expect("roi");
        assert!(roi.theta.abs() < 1e-12);
        assert!((roi.width - 2.0 * (0.2f64 / 3.0).atan()).abs() < 1e-12);
        assert!((roi.height - 2.0 * (0.3f64 / 3.0).atan()).abs() < 1e-12);
        assert!(roi.phi.abs() < 1e-12);
        // across the ±π seam the centre stays behind the camera
        let roi = roi_from_edges(&cam, [-3.0, -0.2], [-3.0, 0.2], 1.25, 0.3).expect("roi");
        assert!((roi.theta.abs() - std::f64::consts::PI).abs() < 1e-12);
        assert!(roi.width < 0.2);
    }

    /// Hand-made histograms: corr as printed, its normalised form and lr.
    #[test]
    fn corr_and_likelihood_ratio_on_hand_made_histograms() {
        let mut a = vec![0.0; 4];
        a[0] = 2.0;
        a[1] = 2.0;
        let a = normalise(a); // [0.5, 0.5, 0, 0] - 0.25
        assert_eq!(a, vec![0.25, 0.25, -0.25, -0.25]);
        // identical: Σa² = 0.25, printed corr = 0.25 / 0.0625 = 4, normalised 1
        assert!((corr(&a, &a) - 4.0).abs() < 1e-12);
        assert!((corr_normalised(&a, &a) - 1.0).abs() < 1e-12);
        let b = normalise(vec![0.0, 0.0, 1.0, 1.0]);
        assert!((corr(&a, &b) + 4.0).abs() < 1e-12);
        assert!((corr_normalised(&a, &b) + 1.0).abs() < 1e-12);
        let c = normalise(vec![1.0, 0.0, 1.0, 0.0]); // orthogonal to a
        assert!(corr(&a, &c).abs() < 1e-12);
        assert_eq!(corr(&a, &[0.0; 4]), 0.0);
        // lr = max(corr, 0) (1 - corr_min)
        assert!((likelihood_ratio(4.0, -0.1) - 4.4).abs() < 1e-12);
        // the forms by name
        assert!((CorrForm::Normalised.corr(&a, &a) - 1.0).abs() < 1e-12);
        assert!((CorrForm::Printed.corr(&a, &a) - 4.0).abs() < 1e-12);
        // the printed form rewards flatness: the same shape at a fifth of the contrast scores
        // 20 against `a`, five times `a`'s match with itself; the normalised form says 1 to both
        let flat = normalise(vec![3.0, 3.0, 2.0, 2.0]);
        assert!((CorrForm::Printed.corr(&flat, &a) - 20.0).abs() < 1e-9);
        assert!((CorrForm::Normalised.corr(&flat, &a) - 1.0).abs() < 1e-12);
        assert_eq!(likelihood_ratio(-4.0, -0.1), 0.0);
        assert_eq!(likelihood_ratio(f64::NAN, -0.1), 0.0);
    }

    /// A red region in a grey image: its histogram puts all its mass in the red bin.
    #[test]
    fn histogram_of_a_painted_region() {
        let m = model();
        let map = CylinderMap::new(&m, 720, 120);
        let mut img = RgbImage::from_pixel(640, 480, image::Rgb([120, 120, 120]));
        let roi = SphericalRoi {
            theta: 0.5,
            phi: 0.1,
            width: 0.2,
            height: 0.15,
        };
        // paint the region's pixels (a little beyond it) red
        for y in 0..480u32 {
            for x in 0..640u32 {
                if let Some(ray) = m.ray(&Point2::new(f64::from(x) + 0.5, f64::from(y) + 0.5))
                    && let Some((t, p)) = spherical(&Point3::from(ray.dir))
                    && (wrap(t - roi.theta)).abs() < 0.12
                    && (p - roi.phi).abs() < 0.09
                {
                    img.put_pixel(x, y, image::Rgb([220, 20, 20]));
                }
            }
        }
        let h = hs_histogram(&img, &map, &roi).expect("histogram");
        let red = usize::from(ColorSpace::Hs.bin(220, 20, 20));
        let mean = 1.0 / HS_BINS as f64;
        assert!((h[red] - (1.0 - mean)).abs() < 1e-12, "{}", h[red]);
        assert!((h.iter().sum::<f64>()).abs() < 1e-12);
    }
}

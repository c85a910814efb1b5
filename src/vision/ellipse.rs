//! [`Ellipse`]: an image region summarised by its first two moments — a centre θ and a 2×2
//! covariance V in pixels² — the shape description shared by the blob moments
//! ([`super::blobs`]), the colour-histogram trackers ([`super::colortrack`], Zivkovic & Kröse,
//! CVPR 2004, eq. 16) and the local tracks ([`super::local`]).
//!
//! Pixel coordinates are the integer column and row of a pixel (the centre of pixel (x, y) is
//! at (x, y)), x to the right, y down. The k-σ region of an ellipse is the set of points with
//! squared Mahalanobis distance `(p − θ)ᵀ V⁻¹ (p − θ) ≤ k²`. A filled, uniform ellipse with
//! semi-axes a and b has second moments a²/4 and b²/4, so the 2σ region of the moments of a
//! uniform ellipse is that ellipse: [`Ellipse::overlap`] compares 2σ regions for that reason.
//!
//! Not here: drawing, fitting to contours, any image access.

use nalgebra::{Matrix2, Point2, Vector2};

/// Mahalanobis radius of the region [`Ellipse::overlap`] compares (the ellipse with the same
/// second moments as a uniform elliptical region).
pub const SHAPE_SIGMA: f64 = 2.0;

/// Sub-pixel sampling step of [`Ellipse::overlap`] (4 samples per pixel).
const OVERLAP_STEP_PX: f64 = 0.5;

/// A centre and a 2×2 covariance (pixels, pixels²).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ellipse {
    pub center: Point2<f64>,
    pub cov: Matrix2<f64>,
}

/// Principal axes of an ellipse: standard deviations along them and the angle of the major
/// axis (radians from +x towards +y, in (−π/2, π/2]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Axes {
    pub major_sigma: f64,
    pub minor_sigma: f64,
    pub angle: f64,
}

impl Ellipse {
    pub fn new(center: Point2<f64>, cov: Matrix2<f64>) -> Self {
        Self { center, cov }
    }

    /// An ellipse from its centre, its variances along x and y and their covariance.
    pub fn from_parts(cx: f64, cy: f64, vxx: f64, vxy: f64, vyy: f64) -> Self {
        Self::new(Point2::new(cx, cy), Matrix2::new(vxx, vxy, vxy, vyy))
    }

    /// The ellipse with major/minor standard deviations and major-axis angle (radians).
    pub fn from_axes(cx: f64, cy: f64, major_sigma: f64, minor_sigma: f64, angle: f64) -> Self {
        let (c, s) = (angle.cos(), angle.sin());
        let r = Matrix2::new(c, -s, s, c);
        let d = Matrix2::new(
            major_sigma * major_sigma,
            0.0,
            0.0,
            minor_sigma * minor_sigma,
        );
        let cov = r * d * r.transpose();
        // exact symmetry whatever the rounding
        let off = 0.5 * (cov[(0, 1)] + cov[(1, 0)]);
        Self::from_parts(cx, cy, cov[(0, 0)], off, cov[(1, 1)])
    }

    /// Finite, symmetric and positive definite.
    pub fn is_valid(&self) -> bool {
        let (a, b, c, d) = (
            self.cov[(0, 0)],
            self.cov[(0, 1)],
            self.cov[(1, 0)],
            self.cov[(1, 1)],
        );
        self.center.x.is_finite()
            && self.center.y.is_finite()
            && [a, b, c, d].iter().all(|v| v.is_finite())
            && b == c
            && a > 0.0
            && a * d - b * c > 0.0
    }

    /// V⁻¹, or `None` when V is singular or not finite.
    pub fn precision(&self) -> Option<Matrix2<f64>> {
        let det = self.cov.determinant();
        if !(det.is_finite() && det > 0.0) {
            return None;
        }
        self.cov.try_inverse()
    }

    /// Squared Mahalanobis distance of `p` from the centre (`None` for a singular V).
    pub fn mahalanobis2(&self, p: Point2<f64>) -> Option<f64> {
        let inv = self.precision()?;
        let d: Vector2<f64> = p - self.center;
        Some(d.dot(&(inv * d)))
    }

    /// Standard deviations along the principal axes and the major axis's angle (closed form
    /// for a symmetric 2×2 matrix).
    pub fn axes(&self) -> Axes {
        let (a, b, d) = (self.cov[(0, 0)], self.cov[(0, 1)], self.cov[(1, 1)]);
        let mean = 0.5 * (a + d);
        let r = (0.25 * (a - d) * (a - d) + b * b).sqrt();
        let (l1, l2) = (mean + r, (mean - r).max(0.0));
        let angle = if b == 0.0 && a >= d {
            0.0
        } else {
            0.5 * (2.0 * b).atan2(a - d)
        };
        Axes {
            major_sigma: l1.sqrt(),
            minor_sigma: l2.sqrt(),
            angle,
        }
    }

    /// Axis-aligned bounding box `[x0, y0, x1, y1]` of the k-σ region.
    pub fn bbox(&self, k: f64) -> [f64; 4] {
        let hx = k * self.cov[(0, 0)].max(0.0).sqrt();
        let hy = k * self.cov[(1, 1)].max(0.0).sqrt();
        [
            self.center.x - hx,
            self.center.y - hy,
            self.center.x + hx,
            self.center.y + hy,
        ]
    }

    /// Area of the k-σ region, `π k² √det V` (pixels²).
    pub fn area(&self, k: f64) -> f64 {
        std::f64::consts::PI * k * k * self.cov.determinant().max(0.0).sqrt()
    }

    /// The same ellipse with V multiplied by `s²` (axes scaled by `s`).
    pub fn scaled(&self, s: f64) -> Self {
        Self::new(self.center, self.cov * (s * s))
    }

    /// Intersection over union of the [`SHAPE_SIGMA`] (2σ) regions of two ellipses, counted on
    /// a half-pixel grid over their joint bounding box; 0 when either is degenerate.
    pub fn overlap(&self, other: &Ellipse) -> f64 {
        let (inter, _, union) = self.sampled_intersection(other);
        if union == 0 {
            0.0
        } else {
            inter as f64 / union as f64
        }
    }

    /// Fraction of this ellipse's 2σ region that lies inside `other`'s 2σ region (0 when
    /// degenerate), sampled as [`Self::overlap`]. Unlike the IoU it does not penalise `other`
    /// for being larger: a region that settles inside an object is fully covered by the
    /// object's moment ellipse.
    pub fn covered_by(&self, other: &Ellipse) -> f64 {
        let (inter, own, _) = self.sampled_intersection(other);
        if own == 0 {
            0.0
        } else {
            inter as f64 / own as f64
        }
    }

    /// Samples in both 2σ regions, in this one, and in either (grid of `OVERLAP_STEP_PX`).
    fn sampled_intersection(&self, other: &Ellipse) -> (u64, u64, u64) {
        let (Some(pa), Some(pb)) = (self.precision(), other.precision()) else {
            return (0, 0, 0);
        };
        let k2 = SHAPE_SIGMA * SHAPE_SIGMA;
        let (ba, bb) = (self.bbox(SHAPE_SIGMA), other.bbox(SHAPE_SIGMA));
        let x0 = (ba[0].min(bb[0]) / OVERLAP_STEP_PX).floor() as i64;
        let x1 = (ba[2].max(bb[2]) / OVERLAP_STEP_PX).ceil() as i64;
        let y0 = (ba[1].min(bb[1]) / OVERLAP_STEP_PX).floor() as i64;
        let y1 = (ba[3].max(bb[3]) / OVERLAP_STEP_PX).ceil() as i64;
        // guard against absurd sizes (a runaway covariance): at most 4096² samples
        if x1 - x0 > 4096 || y1 - y0 > 4096 {
            return (0, 0, 0);
        }
        let (mut inter, mut own, mut union) = (0u64, 0u64, 0u64);
        for j in y0..=y1 {
            let y = j as f64 * OVERLAP_STEP_PX;
            for i in x0..=x1 {
                let x = i as f64 * OVERLAP_STEP_PX;
                let da = Vector2::new(x - self.center.x, y - self.center.y);
                let db = Vector2::new(x - other.center.x, y - other.center.y);
                let ina = da.dot(&(pa * da)) <= k2;
                let inb = db.dot(&(pb * db)) <= k2;
                inter += u64::from(ina && inb);
                own += u64::from(ina);
                union += u64::from(ina || inb);
            }
        }
        (inter, own, union)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    #[test]
    fn axes_of_a_rotated_ellipse_round_trip() {
        for &angle in &[0.0, 0.3, -0.7, 1.2, std::f64::consts::FRAC_PI_2] {
            let e = Ellipse::from_axes(10.0, 20.0, 8.0, 3.0, angle);
            let ax = e.axes();
            assert!(close(ax.major_sigma, 8.0, 1e-9), "{ax:?}");
            assert!(close(ax.minor_sigma, 3.0, 1e-9), "{ax:?}");
            // angles are defined modulo π
            let d = (ax.angle - angle).rem_euclid(std::f64::consts::PI);
            assert!(
                d < 1e-9 || (std::f64::consts::PI - d) < 1e-9,
                "{angle} {ax:?}"
            );
            assert!(e.is_valid());
        }
    }

    #[test]
    fn mahalanobis_and_area() {
        let e = Ellipse::from_parts(0.0, 0.0, 4.0, 0.0, 1.0);
        assert_eq!(e.mahalanobis2(Point2::new(2.0, 0.0)), Some(1.0));
        assert_eq!(e.mahalanobis2(Point2::new(0.0, 2.0)), Some(4.0));
        assert!(close(e.area(2.0), std::f64::consts::PI * 4.0 * 2.0, 1e-12));
        assert_eq!(e.bbox(2.0), [-4.0, -2.0, 4.0, 2.0]);
        let singular = Ellipse::from_parts(0.0, 0.0, 1.0, 1.0, 1.0);
        assert_eq!(singular.mahalanobis2(Point2::new(1.0, 0.0)), None);
        assert!(!singular.is_valid());
    }

    #[test]
    fn overlap_of_identical_shifted_and_scaled_ellipses() {
        let e = Ellipse::from_axes(50.0, 50.0, 10.0, 5.0, 0.4);
        assert!(close(e.overlap(&e), 1.0, 1e-12));
        // a 2σ region of radius 20 inside one of radius 40: IoU = 1/4
        let small = Ellipse::from_parts(0.0, 0.0, 100.0, 0.0, 100.0);
        let big = small.scaled(2.0);
        assert!(
            close(small.overlap(&big), 0.25, 0.01),
            "{}",
            small.overlap(&big)
        );
        let far = Ellipse::from_parts(500.0, 0.0, 100.0, 0.0, 100.0);
        assert_eq!(small.overlap(&far), 0.0);
        // covered_by: all of the small one lies in the big one, a quarter of the big one in
        // the small one; disjoint: 0
        assert!(close(small.covered_by(&big), 1.0, 1e-12));
        assert!(close(big.covered_by(&small), 0.25, 0.01));
        assert_eq!(small.covered_by(&far), 0.0);
    }
}

//! Geometric features of one segment: the usual set of laser people detection (Arras,
//! Martínez Mozos & Burgard, "Using boosted features for the detection of people in 2D range
//! data", ICRA 2007), computed on the sensor-frame points `p_1 … p_n` of the segment.
//!
//! | # | feature | formula |
//! |---|---|---|
//! | 0 | `points` | `n` |
//! | 1 | `std_dev` | `√(Σ‖p_i − p̄‖² / (n − 1))`, `p̄` the centroid (0 when `n = 1`) |
//! | 2 | `width` | `‖p_n − p_1‖` |
//! | 3 | `linearity` | `Σ d_i²`, `d_i` the distance of `p_i` to the total-least-squares line (= the smallest eigenvalue of the scatter matrix `Σ (p_i − p̄)(p_i − p̄)ᵀ`) |
//! | 4 | `circularity` | `Σ (‖p_i − c‖ − r)²` for the fitted circle `(c, r)` ([`crate::laser::circle::fit`]); equals `linearity` when no circle fits (collinear points: a line is a circle of infinite radius) |
//! | 5 | `radius` | `r`, capped at [`RADIUS_CAP`]; [`RADIUS_CAP`] when no circle fits |
//! | 6 | `boundary_length` | `Σ ‖p_{i+1} − p_i‖` |
//! | 7 | `boundary_regularity` | standard deviation (population) of the `n − 1` distances `‖p_{i+1} − p_i‖` |
//! | 8 | `mean_curvature` | mean over `i = 2 … n−1` of the Menger curvature `4 A(p_{i−1}, p_i, p_{i+1}) / (‖p_i − p_{i−1}‖ ‖p_{i+1} − p_i‖ ‖p_{i+1} − p_{i−1}‖)` (unsigned; 0 when `n < 3` or a triple repeats a point) |
//! | 9 | `occluded_first` | 1 when the return on the beam just before the first beam is nearer to the sensor than `p_1` (the segment's start may be hidden), else 0 |
//! | 10 | `occluded_last` | the same for the beam just after the last beam |
//!
//! A neighbouring beam without a return does not occlude.

use nalgebra::{Matrix2, Point2};

use super::circle;
use super::points::ScanPoint;
use super::segment::Segment;

/// Fitted radii are capped here (m); a straight line gets exactly this.
pub const RADIUS_CAP: f64 = 1000.0;

/// Levenberg–Marquardt iterations after Kåsa's fit in the features' circle.
pub const CIRCLE_REFINE_ITERATIONS: usize = 10;

/// The features of one segment (see the module doc for each formula).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentFeatures {
    pub points: usize,
    pub std_dev: f64,
    pub width: f64,
    pub linearity: f64,
    pub circularity: f64,
    pub radius: f64,
    pub boundary_length: f64,
    pub boundary_regularity: f64,
    pub mean_curvature: f64,
    pub occluded_first: bool,
    pub occluded_last: bool,
    /// The fitted circle (sensor frame), when one fits.
    pub circle: Option<circle::Circle>,
}

/// Feature names in [`SegmentFeatures::to_vec`] order.
pub const FEATURE_NAMES: [&str; 11] = [
    "points",
    "std_dev",
    "width",
    "linearity",
    "circularity",
    "radius",
    "boundary_length",
    "boundary_regularity",
    "mean_curvature",
    "occluded_first",
    "occluded_last",
];

impl SegmentFeatures {
    /// The features in the fixed order of [`FEATURE_NAMES`] (flags as 0/1).
    pub fn to_vec(&self) -> Vec<f64> {
        vec![
            self.points as f64,
            self.std_dev,
            self.width,
            self.linearity,
            self.circularity,
            self.radius,
            self.boundary_length,
            self.boundary_regularity,
            self.mean_curvature,
            f64::from(u8::from(self.occluded_first)),
            f64::from(u8::from(self.occluded_last)),
        ]
    }
}

/// The features of `segment` over the scan's `points` (the full list, for the neighbours).
/// A segment whose range lies outside `points` gives the features of no points.
pub fn compute(points: &[ScanPoint], segment: &Segment) -> SegmentFeatures {
    let seg = points.get(segment.points.clone()).unwrap_or(&[]);
    let pts: Vec<Point2<f64>> = seg.iter().map(|p| p.sensor).collect();
    let n = pts.len();
    let centroid = if n > 0 {
        Point2::from(
            pts.iter()
                .fold(nalgebra::Vector2::zeros(), |a, p| a + p.coords)
                / n as f64,
        )
    } else {
        Point2::origin()
    };
    let scatter = pts.iter().fold(Matrix2::zeros(), |a, p| {
        let d = p - centroid;
        a + d * d.transpose()
    });
    let std_dev = if n > 1 {
        (scatter.trace() / (n - 1) as f64).sqrt()
    } else {
        0.0
    };
    let linearity = smallest_eigenvalue(&scatter);
    let circle = circle::fit(&pts, CIRCLE_REFINE_ITERATIONS);
    let (circularity, radius) = match circle {
        Some(c) => (c.sum_sq_residual(&pts), c.radius.min(RADIUS_CAP)),
        None => (linearity, RADIUS_CAP),
    };
    let steps: Vec<f64> = pts.windows(2).map(|w| (w[1] - w[0]).norm()).collect();
    let boundary_length: f64 = steps.iter().sum();
    let boundary_regularity = if steps.is_empty() {
        0.0
    } else {
        let m = boundary_length / steps.len() as f64;
        (steps.iter().map(|s| (s - m).powi(2)).sum::<f64>() / steps.len() as f64).sqrt()
    };
    let curvatures: Vec<f64> = pts.windows(3).map(|w| menger(w[0], w[1], w[2])).collect();
    let mean_curvature = if curvatures.is_empty() {
        0.0
    } else {
        curvatures.iter().sum::<f64>() / curvatures.len() as f64
    };
    let start = segment.points.start;
    let occluded_first = start > 0
        && start <= points.len()
        && seg.first().is_some_and(|f| {
            let nb = &points[start - 1];
            nb.beam + 1 == f.beam && nb.range < f.range
        });
    let end = segment.points.end;
    let occluded_last = seg.last().is_some_and(|l| {
        points
            .get(end)
            .is_some_and(|nb| nb.beam == l.beam + 1 && nb.range < l.range)
    });
    SegmentFeatures {
        points: n,
        std_dev,
        width: match (pts.first(), pts.last()) {
            (Some(a), Some(b)) => (b - a).norm(),
            _ => 0.0,
        },
        linearity,
        circularity,
        radius,
        boundary_length,
        boundary_regularity,
        mean_curvature,
        occluded_first,
        occluded_last,
        circle,
    }
}

/// The smallest eigenvalue of a symmetric 2×2 matrix (closed form, ≥ 0 for a scatter matrix).
fn smallest_eigenvalue(m: &Matrix2<f64>) -> f64 {
    let (a, b, d) = (m[(0, 0)], m[(0, 1)], m[(1, 1)]);
    let half_trace = (a + d) / 2.0;
    let disc = (((a - d) / 2.0).powi(2) + b * b).sqrt();
    (half_trace - disc).max(0.0)
}

/// Menger curvature of three points: `4·area / (product of side lengths)`.
fn menger(a: Point2<f64>, b: Point2<f64>, c: Point2<f64>) -> f64 {
    let (ab, bc, ac) = ((b - a).norm(), (c - b).norm(), (c - a).norm());
    let denom = ab * bc * ac;
    let positive = denom > 0.0; // false on NaN
    if !positive {
        return 0.0;
    }
    let cross = (b - a).x * (c - a).y - (b - a).y * (c - a).x;
    2.0 * cross.abs() / denom
}

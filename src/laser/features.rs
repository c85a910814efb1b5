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

/// Names of leg_tracker's 17 cluster features ([`leg_tracker_features`]), in its order.
pub const LEG_TRACKER_FEATURE_NAMES: [&str; 17] = [
    "points",
    "std_dev",
    "avg_median_dev",
    "width",
    "linearity",
    "circularity",
    "radius",
    "boundary_length",
    "boundary_regularity",
    "mean_curvature",
    "mean_angular_difference",
    "inscribed_angle_mean",
    "inscribed_angle_sd",
    "distance",
    "distance_per_point",
    "occluded_right",
    "occluded_left",
];

/// leg_tracker's cluster features (Leigh et al., ICRA 2015, `src/cluster_features.cpp`; read,
/// not copied), on a segment of at least 3 points, in [`LEG_TRACKER_FEATURE_NAMES`] order and
/// with its formulas, quirks included: `radius` is always 0 (it computes the fitted radius
/// and then stores 0), `boundary_regularity` divides by the point count `n` where the step
/// count is `n − 1`, `circularity` uses the plain algebraic (Kåsa) circle, the inscribed-angle
/// mean divides by `n`, and an end is **not occluded** (0) only when its neighbouring beam has
/// a return (`range_min < r < range_max`) that is farther than the end's range (or below
/// 1 cm); a missing neighbour, or the scan's first or last beam, leaves it 1. Angles `th` are
/// `atan2(B, A)` in `[0, 2π)`. `distance` is the norm of the median point (coordinate-wise
/// medians). Fewer than 3 points gives `None`.
pub fn leg_tracker_features(
    points: &[ScanPoint],
    segment: &Segment,
    geometry: &super::points::ScanGeometry,
    ranges: &[f32],
) -> Option<[f64; 17]> {
    let seg = points.get(segment.points.clone())?;
    let n = seg.len();
    if n < 3 {
        return None;
    }
    let nf = n as f64;
    let pts: Vec<Point2<f64>> = seg.iter().map(|p| p.sensor).collect();
    let mean = pts
        .iter()
        .fold(nalgebra::Vector2::zeros(), |a, p| a + p.coords)
        / nf;
    let median = |f: fn(&Point2<f64>) -> f64| {
        let mut v: Vec<f64> = pts.iter().map(f).collect();
        v.sort_by(f64::total_cmp);
        0.5 * (v[(n - 1) / 2] + v[n / 2])
    };
    let med = Point2::new(median(|p| p.x), median(|p| p.y));
    let distance = med.coords.norm();
    let sum_sq: f64 = pts.iter().map(|p| (p.coords - mean).norm_squared()).sum();
    let std_dev = (sum_sq / (nf - 1.0)).sqrt();
    let avg_median_dev = pts.iter().map(|p| (p - med).norm()).sum::<f64>() / nf;
    let width = (pts[n - 1] - pts[0]).norm();
    let scatter = pts.iter().fold(Matrix2::zeros(), |a, p| {
        let d = p.coords - mean;
        a + d * d.transpose()
    });
    let linearity = smallest_eigenvalue(&scatter);
    let circularity = match circle::kasa(&pts) {
        Some(c) => pts
            .iter()
            .map(|p| (c.radius - (p - c.centre).norm()).powi(2))
            .sum(),
        None => linearity, // collinear: a line is a circle of infinite radius
    };
    let angle = |a: Point2<f64>, m: Point2<f64>, b: Point2<f64>| {
        // leg_tracker: A = (ml·mr)/|mr|², B = (ml × mr)/|mr|², th = atan2(B, A) in [0, 2π)
        let (ml, mr) = (a - m, b - m);
        let l2 = mr.norm_squared();
        let th = ((ml.x * mr.y - ml.y * mr.x) / l2).atan2((ml.x * mr.x + ml.y * mr.y) / l2);
        if th < 0.0 {
            th + std::f64::consts::TAU
        } else {
            th
        }
    };
    let (mut boundary, mut sum_sq_steps, mut curvature, mut ang_diff) = (0.0, 0.0, 0.0, 0.0);
    let mut last_seg = 0.0;
    for w in pts.windows(3) {
        let (right, mid, left) = (w[0], w[1], w[2]);
        let (l_ml, l_mr, l_lr) = (
            (left - mid).norm(),
            (right - mid).norm(),
            (left - right).norm(),
        );
        boundary += l_mr;
        sum_sq_steps += l_mr * l_mr;
        last_seg = l_ml;
        let th = angle(left, mid, right);
        ang_diff += th / nf;
        let s = 0.5 * (l_ml + l_mr + l_lr);
        let area = (s * (s - l_ml) * (s - l_mr) * (s - l_lr)).max(0.0).sqrt();
        let k = 4.0 * area / (l_ml * l_mr * l_lr * nf);
        curvature += if th > 0.0 { k } else { -k };
    }
    boundary += last_seg;
    sum_sq_steps += last_seg * last_seg;
    let boundary_regularity = ((sum_sq_steps - boundary * boundary / nf) / (nf - 1.0)).sqrt();
    let (first, last) = (pts[0], pts[n - 1]);
    let (mut sum_iav, mut sum_iav_sq) = (0.0, 0.0);
    for &mid in &pts[1..n - 1] {
        let th = angle(first, mid, last);
        sum_iav += th;
        sum_iav_sq += th * th;
    }
    let iav = sum_iav / nf;
    let std_iav = ((sum_iav_sq - sum_iav * sum_iav / nf) / (nf - 1.0)).sqrt();
    let occluded = |end: &ScanPoint, nb: Option<usize>| -> f64 {
        let Some(k) = nb else { return 1.0 };
        let r = ranges.get(k).map_or(f64::NAN, |&r| f64::from(r));
        let present = r > geometry.range_min && r < geometry.range_max;
        if present && (end.range < r || r < 0.01) {
            0.0
        } else {
            1.0
        }
    };
    let (s0, s1) = (&seg[0], &seg[n - 1]);
    let occluded_left = occluded(s0, s0.beam.checked_sub(1));
    let occluded_right = occluded(s1, Some(s1.beam + 1).filter(|&k| k < ranges.len()));
    Some([
        nf,
        std_dev,
        avg_median_dev,
        width,
        linearity,
        circularity,
        0.0,
        boundary,
        boundary_regularity,
        curvature,
        ang_diff,
        iav,
        std_iav,
        distance,
        distance / nf,
        occluded_right,
        occluded_left,
    ])
}

//! The fundamental matrix between two views of a moving camera, estimated robustly: Hartley's
//! normalised eight-point algorithm with the rank-2 constraint, the Sampson distance as the
//! residual, and RANSAC. Seed 003 (Zajdel et al. §III) finds people moving against the static
//! scene seen from a moving robot as the outliers of such a fit.
//!
//! Written by hand on `nalgebra`'s SVD: the Rust vision crates at hand (`imageproc`) do not
//! estimate epipolar geometry. Draws come from a seeded stream, so results are reproducible.

use nalgebra::{DMatrix, Matrix3, Vector3};
use rand::RngExt;

use crate::rng;

/// A point correspondence `(x, x′)` in pixels: `x′ᵀ F x = 0`.
pub type Pair = ([f64; 2], [f64; 2]);

/// The similarity that moves points to their centroid with mean distance √2 (Hartley).
fn normaliser(pts: impl Iterator<Item = [f64; 2]> + Clone) -> Option<Matrix3<f64>> {
    let n = pts.clone().count() as f64;
    let (sx, sy) = pts
        .clone()
        .fold((0.0, 0.0), |a, p| (a.0 + p[0], a.1 + p[1]));
    let (cx, cy) = (sx / n, sy / n);
    let mean_d = pts.map(|p| (p[0] - cx).hypot(p[1] - cy)).sum::<f64>() / n;
    if !(mean_d > 1e-12 && mean_d.is_finite()) {
        return None;
    }
    let s = std::f64::consts::SQRT_2 / mean_d;
    Some(Matrix3::new(
        s,
        0.0,
        -s * cx,
        0.0,
        s,
        -s * cy,
        0.0,
        0.0,
        1.0,
    ))
}

/// The fundamental matrix through at least 8 correspondences (least squares beyond 8), rank 2,
/// scaled to unit Frobenius norm; `None` when the points are degenerate.
pub fn eight_point(pairs: &[Pair]) -> Option<Matrix3<f64>> {
    if pairs.len() < 8 {
        return None;
    }
    let t1 = normaliser(pairs.iter().map(|p| p.0))?;
    let t2 = normaliser(pairs.iter().map(|p| p.1))?;
    let mut a = DMatrix::zeros(pairs.len().max(9), 9);
    for (i, (x, y)) in pairs.iter().enumerate() {
        let p = t1 * Vector3::new(x[0], x[1], 1.0);
        let q = t2 * Vector3::new(y[0], y[1], 1.0);
        let row = [
            q.x * p.x,
            q.x * p.y,
            q.x,
            q.y * p.x,
            q.y * p.y,
            q.y,
            p.x,
            p.y,
            1.0,
        ];
        for (j, v) in row.iter().enumerate() {
            a[(i, j)] = *v;
        }
    }
    let svd = a.svd(false, true);
    let vt = svd.v_t?;
    // the right singular vector of the smallest singular value
    let (k, _) = svd
        .singular_values
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))?;
    let f = vt.row(k);
    let f = Matrix3::new(f[0], f[1], f[2], f[3], f[4], f[5], f[6], f[7], f[8]);
    // rank 2: zero the smallest singular value
    let svd = f.svd(true, true);
    let (u, vt) = (svd.u?, svd.v_t?);
    let mut s = svd.singular_values;
    let (k, _) = s.iter().enumerate().min_by(|a, b| a.1.total_cmp(b.1))?;
    s[k] = 0.0;
    let f = u * Matrix3::from_diagonal(&s) * vt;
    let f = t2.transpose() * f * t1;
    let norm = f.norm();
    (norm > 0.0 && norm.is_finite()).then(|| f / norm)
}

/// The Sampson distance of a correspondence to `f` (pixels², first-order geometric error).
pub fn sampson(f: &Matrix3<f64>, (x, y): &Pair) -> f64 {
    let p = Vector3::new(x[0], x[1], 1.0);
    let q = Vector3::new(y[0], y[1], 1.0);
    let fp = f * p;
    let ftq = f.transpose() * q;
    let e = q.dot(&fp);
    let d = fp.x * fp.x + fp.y * fp.y + ftq.x * ftq.x + ftq.y * ftq.y;
    if d > 0.0 { e * e / d } else { f64::INFINITY }
}

/// A robust fit: the model and which correspondences are its inliers.
#[derive(Debug, Clone, PartialEq)]
pub struct Fit {
    pub f: Matrix3<f64>,
    pub inliers: Vec<bool>,
}

/// RANSAC over 8-point samples: the model with the most correspondences within `threshold_px`
/// (Sampson distance below its square), refitted on all of them. `None` with fewer than 8
/// correspondences or no non-degenerate sample.
pub fn ransac(pairs: &[Pair], threshold_px: f64, iterations: usize, seed: u64) -> Option<Fit> {
    if pairs.len() < 8 {
        return None;
    }
    let t2 = threshold_px * threshold_px;
    let mut draws = rng::stream(seed, "fundamental ransac", pairs.len() as u64);
    let inliers_of =
        |f: &Matrix3<f64>| -> Vec<bool> { pairs.iter().map(|p| sampson(f, p) < t2).collect() };
    let mut best: Option<(usize, Vec<bool>)> = None;
    for _ in 0..iterations {
        let mut idx: Vec<usize> = Vec::with_capacity(8);
        while idx.len() < 8 {
            let i = draws.random_range(0..pairs.len());
            if !idx.contains(&i) {
                idx.push(i);
            }
        }
        let sample: Vec<Pair> = idx.iter().map(|&i| pairs[i]).collect();
        let Some(f) = eight_point(&sample) else {
            continue;
        };
        let inl = inliers_of(&f);
        let count = inl.iter().filter(|b| **b).count();
        if best.as_ref().is_none_or(|(c, _)| count > *c) {
            best = Some((count, inl));
        }
    }
    let (_, inl) = best?;
    let support: Vec<Pair> = pairs
        .iter()
        .zip(&inl)
        .filter(|(_, b)| **b)
        .map(|(p, _)| *p)
        .collect();
    let f = eight_point(&support)?;
    let inliers = inliers_of(&f);
    Some(Fit { f, inliers })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix3x4, Rotation3};

    /// Two pinhole views (f = 300 px, 320×240) of points 3–7.5 m ahead: the second camera moved
    /// 0.4 m sideways and 0.2 m forward and turned 5°.
    fn views() -> (Vec<Pair>, Matrix3<f64>, Matrix3x4<f64>) {
        let k = Matrix3::new(300.0, 0.0, 160.0, 0.0, 300.0, 120.0, 0.0, 0.0, 1.0);
        let r = Rotation3::from_euler_angles(0.0, 5f64.to_radians(), 0.0).into_inner();
        let t = Vector3::new(-0.4, 0.0, -0.2);
        let mut p2 = Matrix3x4::zeros();
        p2.fixed_view_mut::<3, 3>(0, 0).copy_from(&(k * r));
        p2.set_column(3, &(k * t));
        let mut pairs = Vec::new();
        for i in 0..40 {
            let (u, v) = ((i % 8) as f64, (i / 8) as f64);
            // depths scattered (not a plane: a planar scene leaves F undetermined)
            let z = 3.0 + 0.45 * ((i * 37) % 11) as f64;
            let x = Vector3::new((-2.0 + 0.55 * u) * z / 4.0, (-1.0 + 0.45 * v) * z / 4.0, z);
            let a = k * x;
            let b = p2 * x.push(1.0);
            pairs.push(([a.x / a.z, a.y / a.z], [b.x / b.z, b.y / b.z]));
        }
        (pairs, k, p2)
    }

    #[test]
    fn noise_free_correspondences_satisfy_the_epipolar_constraint() {
        let (pairs, ..) = views();
        let f = eight_point(&pairs).expect("fits");
        for p in &pairs {
            assert!(sampson(&f, p) < 1e-12, "{}", sampson(&f, p));
        }
        assert!(f.determinant().abs() < 1e-12, "rank 2");
        assert!(eight_point(&pairs[..7]).is_none());
    }

    #[test]
    fn ransac_flags_exactly_the_moving_points() {
        let (mut pairs, ..) = views();
        // twelve points that moved on their own between the views (people), across their
        // (near-horizontal) epipolar lines: motion along the line is undetectable by any F
        for (i, p) in pairs.iter_mut().enumerate().filter(|(i, _)| i % 10 < 3) {
            let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
            p.1[0] += 2.0 * sign;
            p.1[1] += sign * (5.0 + (i % 4) as f64);
        }
        let fit = ransac(&pairs, 0.5, 200, 7).expect("fits");
        let moving: Vec<usize> = (0..pairs.len()).filter(|&i| !fit.inliers[i]).collect();
        let want: Vec<usize> = (0..pairs.len()).filter(|i| i % 10 < 3).collect();
        assert_eq!(moving, want);
        // the same seed gives the same fit
        assert_eq!(ransac(&pairs, 0.5, 200, 7), Some(fit));
    }
}

//! Circle fits to 2-D points.
//!
//! [`kasa`]: the algebraic least-squares fit of Kåsa (1976, "A circle fitting procedure and
//! its error analysis"): minimise `Σ (x² + y² + D x + E y + F)²` over `(D, E, F)`, then centre
//! `(−D/2, −E/2)` and radius `√(D²/4 + E²/4 − F)`. The points are first centred on their mean
//! and scaled by their RMS distance to it, and the linear least-squares problem is solved by
//! SVD (not the normal equations), so that short arcs stay well conditioned. On noise-free
//! points of any arc the fit is exact. It is biased towards small radii on short noisy arcs;
//! [`refine`] removes that bias.
//!
//! [`refine`]: the geometric fit, minimising `Σ (‖p − c‖ − r)²` by Levenberg–Marquardt from a
//! start circle (steps only accepted when the cost falls, so it never gets worse).
//!
//! Degenerate input — fewer than 3 distinct points, collinear points (a line is a circle of
//! infinite radius), non-finite coordinates — gives `None`.

use nalgebra::{DMatrix, DVector, Matrix3, Point2, Vector3};

/// A fitted circle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Circle {
    pub centre: Point2<f64>,
    pub radius: f64,
}

impl Circle {
    /// `Σ (‖p − c‖ − r)²`: the geometric residual.
    pub fn sum_sq_residual(&self, points: &[Point2<f64>]) -> f64 {
        points
            .iter()
            .map(|p| ((p - self.centre).norm() - self.radius).powi(2))
            .sum()
    }
}

/// Ratio of smallest to largest singular value below which the points count as collinear.
const RANK_TOLERANCE: f64 = 1e-10;

/// Kåsa's algebraic fit (see the module doc).
pub fn kasa(points: &[Point2<f64>]) -> Option<Circle> {
    let n = points.len();
    if n < 3 || points.iter().any(|p| !(p.x.is_finite() && p.y.is_finite())) {
        return None;
    }
    let mean = points
        .iter()
        .fold(nalgebra::Vector2::zeros(), |a, p| a + p.coords)
        / n as f64;
    let scale = (points
        .iter()
        .map(|p| (p.coords - mean).norm_squared())
        .sum::<f64>()
        / n as f64)
        .sqrt();
    if !(scale > 0.0 && scale.is_finite()) {
        return None;
    }
    let mut a = DMatrix::<f64>::zeros(n, 3);
    let mut b = DVector::<f64>::zeros(n);
    for (i, p) in points.iter().enumerate() {
        let u = (p.coords - mean) / scale;
        a[(i, 0)] = u.x;
        a[(i, 1)] = u.y;
        a[(i, 2)] = 1.0;
        b[i] = -u.norm_squared();
    }
    let svd = a.svd(true, true);
    let (lo, hi) = svd
        .singular_values
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), &s| {
            (lo.min(s), hi.max(s))
        });
    let full_rank = lo > RANK_TOLERANCE * hi; // false on NaN
    if !full_rank {
        return None;
    }
    let sol = svd.solve(&b, 0.0).ok()?;
    let (d, e, f) = (sol[0], sol[1], sol[2]);
    let r2 = (d * d + e * e) / 4.0 - f;
    if !(r2 > 0.0 && r2.is_finite()) {
        return None;
    }
    Some(Circle {
        centre: Point2::new(mean.x - d / 2.0 * scale, mean.y - e / 2.0 * scale),
        radius: r2.sqrt() * scale,
    })
}

/// Geometric refinement of `start` (see the module doc); at most `iterations` steps.
pub fn refine(points: &[Point2<f64>], start: Circle, iterations: usize) -> Circle {
    let mut c = start;
    let mut cost = c.sum_sq_residual(points);
    let mut lambda = 1e-3;
    for _ in 0..iterations {
        let mut jtj = Matrix3::<f64>::zeros();
        let mut jtr = Vector3::<f64>::zeros();
        for p in points {
            let d = p - c.centre;
            let dist = d.norm();
            if dist <= 0.0 {
                continue;
            }
            let j = Vector3::new(-d.x / dist, -d.y / dist, -1.0);
            jtj += j * j.transpose();
            jtr += j * (dist - c.radius);
        }
        let damped = jtj + Matrix3::from_diagonal(&jtj.diagonal()) * lambda;
        let Some(step) = damped.lu().solve(&(-jtr)) else {
            break;
        };
        let next = Circle {
            centre: Point2::new(c.centre.x + step.x, c.centre.y + step.y),
            radius: c.radius + step.z,
        };
        let next_cost = next.sum_sq_residual(points);
        if next_cost.is_finite() && next_cost < cost && next.radius > 0.0 {
            let small = step.norm() <= 1e-12 * (1.0 + c.radius);
            c = next;
            cost = next_cost;
            lambda = (lambda / 10.0).max(1e-12);
            if small {
                break;
            }
        } else {
            lambda *= 10.0;
            if lambda > 1e12 {
                break;
            }
        }
    }
    c
}

/// Kåsa's fit followed by `iterations` of [`refine`] (0: Kåsa alone).
pub fn fit(points: &[Point2<f64>], iterations: usize) -> Option<Circle> {
    kasa(points).map(|c| refine(points, c, iterations))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arc(cx: f64, cy: f64, r: f64, from_deg: f64, span_deg: f64, n: usize) -> Vec<Point2<f64>> {
        (0..n)
            .map(|i| {
                let t = (from_deg + span_deg * i as f64 / (n - 1) as f64).to_radians();
                Point2::new(cx + r * t.cos(), cy + r * t.sin())
            })
            .collect()
    }

    #[test]
    fn kasa_is_exact_on_noise_free_arcs() {
        for (span, n) in [(30.0, 7), (90.0, 12), (180.0, 25)] {
            for (cx, cy, r) in [(2.5, -1.25, 0.08), (0.0, 0.0, 1.0), (-7.0, 3.0, 0.3)] {
                let c = kasa(&arc(cx, cy, r, 200.0, span, n)).expect("fit");
                assert!((c.centre.x - cx).abs() < 1e-9, "{span} {c:?}");
                assert!((c.centre.y - cy).abs() < 1e-9, "{span} {c:?}");
                assert!((c.radius - r).abs() < 1e-9, "{span} {c:?}");
                let refined = fit(&arc(cx, cy, r, 200.0, span, n), 10).expect("fit");
                assert!(
                    (refined.radius - r).abs() < 1e-9 && (refined.centre - c.centre).norm() < 1e-9
                );
            }
        }
    }

    #[test]
    fn three_points_give_their_circumcircle() {
        // (0,0), (2,0), (0,2): circumcentre (1,1), radius √2
        let c = kasa(&[
            Point2::new(0.0, 0.0),
            Point2::new(2.0, 0.0),
            Point2::new(0.0, 2.0),
        ])
        .expect("fit");
        assert!((c.centre - Point2::new(1.0, 1.0)).norm() < 1e-12);
        assert!((c.radius - 2f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn degenerate_input_gives_none() {
        let line: Vec<_> = (0..5)
            .map(|i| Point2::new(f64::from(i), 2.0 * f64::from(i)))
            .collect();
        assert_eq!(kasa(&line), None);
        assert_eq!(kasa(&line[..2]), None);
        assert_eq!(kasa(&[Point2::new(1.0, 1.0); 4]), None);
        let mut bad = arc(0.0, 0.0, 1.0, 0.0, 90.0, 5);
        bad[2].x = f64::NAN;
        assert_eq!(kasa(&bad), None);
    }

    #[test]
    fn refinement_lowers_the_geometric_cost_of_a_noisy_short_arc() {
        // an arc of radius 1 with alternating ±0.01 radial offsets: Kåsa underestimates
        let pts: Vec<_> = arc(0.0, 0.0, 1.0, 0.0, 40.0, 9)
            .into_iter()
            .enumerate()
            .map(|(i, p)| p * (1.0 + if i % 2 == 0 { 0.01 } else { -0.01 }))
            .collect();
        let k = kasa(&pts).expect("fit");
        let g = refine(&pts, k, 50);
        assert!(g.sum_sq_residual(&pts) < k.sum_sq_residual(&pts));
    }
}

//! The position Kalman filter of seed 000 (section 5, eq. 1–9): the state is the person's
//! position x ∈ R², the motion model `x_k = x_{k−1} + u_k + w_{k−1}` with a nominal displacement
//! `u_k` (the estimated velocity times the frame interval), the measurement `z_k = x_k + v_k`,
//! `w ~ N(0, Q)`, `v ~ N(0, R)`. Predict: `x⁻ = x + u`, `P⁻ = P + Q`; correct with
//! `K = P⁻ (P⁻ + R)⁻¹`, `x = x⁻ + K (z − x⁻)`, `P = (I − K) P⁻`.

use nalgebra::{Matrix2, Vector2};

#[derive(Debug, Clone, PartialEq)]
pub struct PositionKf {
    pub x: Vector2<f64>,
    pub p: Matrix2<f64>,
    pub q: Matrix2<f64>,
    pub r: Matrix2<f64>,
}

impl PositionKf {
    /// Start at the first measurement with covariance `R`.
    pub fn new(z0: Vector2<f64>, q: Matrix2<f64>, r: Matrix2<f64>) -> PositionKf {
        PositionKf { x: z0, p: r, q, r }
    }

    /// Eq. 5–6.
    pub fn predict(&mut self, u: Vector2<f64>) {
        self.x += u;
        self.p += self.q;
    }

    /// Eq. 7–9. A singular innovation covariance leaves the state unchanged.
    pub fn correct(&mut self, z: Vector2<f64>) {
        let Some(s_inv) = (self.p + self.r).try_inverse() else {
            return;
        };
        let k = self.p * s_inv;
        self.x += k * (z - self.x);
        self.p = (Matrix2::identity() - k) * self.p;
    }
}

/// Sample covariance of 2-vectors (divides by n − 1; zero with fewer than two).
pub fn covariance(v: &[Vector2<f64>]) -> Matrix2<f64> {
    if v.len() < 2 {
        return Matrix2::zeros();
    }
    let n = v.len() as f64;
    let mean = v.iter().sum::<Vector2<f64>>() / n;
    v.iter()
        .map(|d| (d - mean) * (d - mean).transpose())
        .sum::<Matrix2<f64>>()
        / (n - 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// With Q = 0 the filter is the information-form average of its prior and the
    /// measurements: P_n = 1 / (1/P₀ + n/R), x_n = P_n (x₀/P₀ + Σz/R) — the running mean when
    /// the prior is vague.
    #[test]
    fn static_case_equals_its_closed_form() {
        let (r, p0) = (0.04, 1e3);
        let mut kf = PositionKf {
            x: Vector2::new(0.5, -0.5),
            p: Matrix2::identity() * p0,
            q: Matrix2::zeros(),
            r: Matrix2::identity() * r,
        };
        let zs = [1.0, 1.4, 0.8, 1.2, 0.9, 1.05];
        for (i, z) in zs.iter().enumerate() {
            kf.predict(Vector2::zeros());
            kf.correct(Vector2::new(*z, -*z));
            let n = (i + 1) as f64;
            let pn = 1.0 / (1.0 / p0 + n / r);
            let xn = pn * (0.5 / p0 + zs[..=i].iter().sum::<f64>() / r);
            assert!(
                (kf.p[(0, 0)] - pn).abs() < 1e-12
                    && (kf.x.x - xn).abs() < 1e-12
                    && (kf.x.y + xn).abs() < 1e-12
            );
            let mean = zs[..=i].iter().sum::<f64>() / n;
            assert!((kf.x.x - mean).abs() < 1e-4, "close to the running mean");
        }
    }

    /// For a random walk the covariance converges to the closed-form steady state
    /// P = (−q + √(q² + 4qr)) / 2 of the scalar Riccati equation.
    #[test]
    fn random_walk_reaches_the_closed_form_steady_state() {
        let (q, r) = (0.024, 0.011);
        let mut kf = PositionKf::new(
            Vector2::zeros(),
            Matrix2::identity() * q,
            Matrix2::identity() * r,
        );
        for _ in 0..200 {
            kf.predict(Vector2::zeros());
            kf.correct(Vector2::zeros());
        }
        let steady = (-q + (q * q + 4.0 * q * r).sqrt()) / 2.0;
        assert!(
            (kf.p[(0, 0)] - steady).abs() < 1e-12,
            "{} vs {steady}",
            kf.p[(0, 0)]
        );
    }
}

//! A linear Kalman filter over fixed-size states (nalgebra), with the two motion models the
//! trackers use: constant velocity in 2-D (white-noise acceleration, the discretised model of
//! Bar-Shalom, *Estimation with Applications to Tracking*, §6.3.2) and a random walk for
//! slowly varying sizes. The covariance update uses the Joseph form, so it stays symmetric
//! and positive semi-definite.
//!
//! What it does not do: no extended or unscented variants, no gating (callers gate), no
//! smoothing backwards in time.

use nalgebra::{SMatrix, SVector};

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum KalmanError {
    #[error("the innovation covariance is singular")]
    Singular,
    #[error("a measurement is not finite")]
    NonFinite,
}

/// State `x` with covariance `p`.
#[derive(Debug, Clone, PartialEq)]
pub struct Kalman<const N: usize> {
    pub x: SVector<f64, N>,
    pub p: SMatrix<f64, N, N>,
}

impl<const N: usize> Kalman<N> {
    pub fn new(x: SVector<f64, N>, p: SMatrix<f64, N, N>) -> Self {
        Kalman { x, p }
    }

    /// `x ← F x`, `P ← F P Fᵀ + Q`.
    pub fn predict(&mut self, f: &SMatrix<f64, N, N>, q: &SMatrix<f64, N, N>) {
        self.x = f * self.x;
        self.p = f * self.p * f.transpose() + q;
        self.p = 0.5 * (self.p + self.p.transpose());
    }

    /// Update with measurement `z = H x + v`, `v ~ N(0, R)`.
    pub fn update<const M: usize>(
        &mut self,
        h: &SMatrix<f64, M, N>,
        r: &SMatrix<f64, M, M>,
        z: &SVector<f64, M>,
    ) -> Result<(), KalmanError> {
        if z.iter().any(|v| !v.is_finite()) {
            return Err(KalmanError::NonFinite);
        }
        let s = h * self.p * h.transpose() + r;
        let s_inv = s.try_inverse().ok_or(KalmanError::Singular)?;
        let k = self.p * h.transpose() * s_inv;
        self.x += k * (z - h * self.x);
        let i_kh = SMatrix::<f64, N, N>::identity() - k * h;
        self.p = i_kh * self.p * i_kh.transpose() + k * r * k.transpose();
        self.p = 0.5 * (self.p + self.p.transpose());
        Ok(())
    }
}

/// Constant-velocity model for state `[x, y, vx, vy]`: transition `F` and process noise `Q`
/// of a white-noise acceleration with standard deviation `accel_sigma` (units/s²).
pub fn constant_velocity_2d(
    dt_s: f64,
    accel_sigma: f64,
) -> (SMatrix<f64, 4, 4>, SMatrix<f64, 4, 4>) {
    let mut f = SMatrix::<f64, 4, 4>::identity();
    f[(0, 2)] = dt_s;
    f[(1, 3)] = dt_s;
    let q2 = accel_sigma * accel_sigma;
    let (a, b, c) = (dt_s.powi(4) / 4.0, dt_s.powi(3) / 2.0, dt_s.powi(2));
    let mut q = SMatrix::<f64, 4, 4>::zeros();
    for i in 0..2 {
        q[(i, i)] = a * q2;
        q[(i, i + 2)] = b * q2;
        q[(i + 2, i)] = b * q2;
        q[(i + 2, i + 2)] = c * q2;
    }
    (f, q)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix1, Matrix2x4, Vector1, Vector2, Vector4};

    fn is_psd_symmetric(p: &SMatrix<f64, 4, 4>) -> bool {
        (p - p.transpose()).norm() < 1e-12 && p.symmetric_eigenvalues().iter().all(|&e| e > -1e-12)
    }

    #[test]
    fn predict_with_zero_dt_and_zero_noise_is_the_identity() {
        let mut k = Kalman::new(Vector4::new(1.0, 2.0, 0.5, -0.5), SMatrix::identity() * 0.3);
        let before = k.clone();
        let (f, q) = constant_velocity_2d(0.0, 2.0);
        k.predict(&f, &q);
        assert_eq!(k, before);
    }

    #[test]
    fn constant_velocity_moves_the_state_and_grows_the_covariance() {
        let mut k = Kalman::new(Vector4::new(0.0, 0.0, 1.0, 2.0), SMatrix::identity() * 0.01);
        let (f, q) = constant_velocity_2d(0.5, 1.0);
        k.predict(&f, &q);
        assert!((k.x - Vector4::new(0.5, 1.0, 1.0, 2.0)).norm() < 1e-12);
        assert!(k.p[(0, 0)] > 0.01);
        assert!(is_psd_symmetric(&k.p));
    }

    #[test]
    fn scalar_update_matches_the_closed_form() {
        // prior N(0, 4), measurement 2 with variance 1: posterior mean 1.6, variance 0.8
        let mut k = Kalman::new(Vector1::new(0.0), Matrix1::new(4.0));
        k.update(&Matrix1::new(1.0), &Matrix1::new(1.0), &Vector1::new(2.0))
            .expect("update");
        assert!((k.x[0] - 1.6).abs() < 1e-12);
        assert!((k.p[(0, 0)] - 0.8).abs() < 1e-12);
    }

    #[test]
    fn tracking_a_constant_velocity_target_converges_and_stays_psd() {
        let mut k = Kalman::new(Vector4::zeros(), SMatrix::identity() * 10.0);
        let (f, q) = constant_velocity_2d(0.04, 0.5);
        let h = Matrix2x4::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0);
        let r = SMatrix::<f64, 2, 2>::identity() * 0.01;
        for i in 1..=300 {
            let t = f64::from(i) * 0.04;
            k.predict(&f, &q);
            k.update(&h, &r, &Vector2::new(1.0 + 0.8 * t, 2.0 - 0.3 * t))
                .expect("update");
            assert!(is_psd_symmetric(&k.p));
        }
        assert!((k.x[2] - 0.8).abs() < 1e-3 && (k.x[3] + 0.3).abs() < 1e-3);
        assert_eq!(
            k.update(&h, &r, &Vector2::new(f64::NAN, 0.0)),
            Err(KalmanError::NonFinite)
        );
    }
}

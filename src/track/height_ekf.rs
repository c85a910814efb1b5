//! The extended Kalman filter of seed 002 §5 (Brooks & Williams): one person as the state
//! (x, y, h) — position on the floor and height — with constant position plus Gaussian noise
//! (no velocity, as the paper argues) and the height a constant the filter learns (`q_height`
//! = 0: the paper adds noise to the position only; a height random walk, `q_height` > 0, is a
//! variant). With `q_height` = 0 the height variance only shrinks; the Joseph-form update keeps
//! it non-negative, so no floor is applied (a test runs 10 000 updates). Fused from
//!
//! - laser range–bearing observations of the leg-pair midpoint from a laser at `(lx, ly)` with
//!   heading `lyaw`: r = ‖(x − lx, y − ly)‖, b = atan2(y − ly, x − lx) − lyaw;
//! - camera bearing + elevation of the head top from a camera centre `(cx, cy, cz)` (its
//!   measured height; the tilt enters when the pixel is turned into a world ray):
//!   β = atan2(y − cy, x − cx), ε = atan2(h − cz, ρ), ρ = ‖(x − cx, y − cy)‖.
//!
//! Each observation passes the standard 3σ innovation gate (Mahalanobis distance ≤ `gate_sigma`,
//! so a camera observation that would imply an unrealistic height is ignored). The
//! constant-velocity variant (state (x, y, h, vx, vy), white-noise acceleration) is our
//! addition to test the paper's argument against velocity. Hand-written: the EKF is a few
//! lines of nalgebra and the paper's models are specific. No data association (one person).

use nalgebra::{DMatrix, DVector};

/// Motion model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Motion {
    /// Seed 002: (x, y, h), constant position plus noise.
    ConstantPosition,
    /// Our addition: (x, y, h, vx, vy), constant velocity plus acceleration noise.
    ConstantVelocity,
}

/// Noise and gate (seed 002 gives none of these numbers; chosen on the quick profile).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EkfParams {
    pub motion: Motion,
    /// Position random walk, m²/s (constant position) or acceleration spectral density,
    /// m²/s³ (constant velocity).
    pub q_pos: f64,
    /// Height random walk, m²/s: 0 in the paper's model (height a constant the filter
    /// learns); > 0 only in the random-walk variant.
    pub q_height: f64,
    /// Laser range and bearing σ (m, rad).
    pub sigma_range_m: f64,
    pub sigma_bearing_rad: f64,
    /// Camera bearing and elevation σ (rad).
    pub sigma_cam_bearing_rad: f64,
    pub sigma_cam_elevation_rad: f64,
    /// Initial height (the paper: 1.0 m) and its σ ("very large").
    pub h0_m: f64,
    pub sigma_h0_m: f64,
    /// Initial position σ around the first observation's position, m.
    pub sigma_pos0_m: f64,
    /// Innovation gate in standard deviations (Mahalanobis distance), the paper: 3.
    pub gate_sigma: f64,
}

/// A sensor pose on the floor plan (laser) or in 3-D (camera centre, yaw unused).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorAt {
    pub x: f64,
    pub y: f64,
    pub z: f64,
    pub yaw: f64,
}

/// What one update did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Update {
    /// Squared Mahalanobis distance of the innovation.
    pub d2: f64,
    pub accepted: bool,
}

/// Wrap an angle to (−π, π].
pub fn wrap(a: f64) -> f64 {
    let mut a = a % std::f64::consts::TAU;
    if a > std::f64::consts::PI {
        a -= std::f64::consts::TAU;
    } else if a <= -std::f64::consts::PI {
        a += std::f64::consts::TAU;
    }
    a
}

/// Camera model: (β, ε) of the head top `(x, y, h)` seen from `cam`, and its 2×3 Jacobian.
pub fn camera_model(x: f64, y: f64, h: f64, cam: &SensorAt) -> ([f64; 2], [[f64; 3]; 2]) {
    let (dx, dy, dz) = (x - cam.x, y - cam.y, h - cam.z);
    let rho2 = dx * dx + dy * dy;
    let rho = rho2.sqrt().max(1e-9);
    let r2 = rho2 + dz * dz;
    let z = [dy.atan2(dx), dz.atan2(rho)];
    let jac = [
        [-dy / rho2.max(1e-18), dx / rho2.max(1e-18), 0.0],
        [-dz * dx / (rho * r2), -dz * dy / (rho * r2), rho / r2],
    ];
    (z, jac)
}

/// Head height that elevation `elevation` implies at floor range `range_m` from a camera at
/// height `cam_z` (level ground): the inverse of the elevation model.
pub fn height_from_elevation(elevation: f64, range_m: f64, cam_z: f64) -> f64 {
    cam_z + range_m * elevation.tan()
}

/// How far the floor range moves per radian of elevation for a head top `dz_m` above (< 0:
/// below) the camera at floor range `range_m`: |dρ/dε| = (ρ² + Δz²) / |Δz|, from
/// ε = atan2(Δz, ρ). The camera's range information falls as the head nears the camera's
/// height; infinite at Δz = 0 (the elevation then says nothing about the range).
pub fn range_per_elevation(range_m: f64, dz_m: f64) -> f64 {
    (range_m * range_m + dz_m * dz_m) / dz_m.abs()
}

/// Laser model: (r, b) of `(x, y)` from `laser`, and its 2×2 Jacobian.
pub fn laser_model(x: f64, y: f64, laser: &SensorAt) -> ([f64; 2], [[f64; 2]; 2]) {
    let (dx, dy) = (x - laser.x, y - laser.y);
    let r2 = (dx * dx + dy * dy).max(1e-18);
    let r = r2.sqrt();
    (
        [r, wrap(dy.atan2(dx) - laser.yaw)],
        [[dx / r, dy / r], [-dy / r2, dx / r2]],
    )
}

/// The filter.
#[derive(Debug, Clone)]
pub struct HeightEkf {
    pub params: EkfParams,
    pub x: DVector<f64>,
    pub p: DMatrix<f64>,
    /// Time of the state, s.
    pub t_s: f64,
}

impl HeightEkf {
    fn dim(motion: Motion) -> usize {
        match motion {
            Motion::ConstantPosition => 3,
            Motion::ConstantVelocity => 5,
        }
    }

    /// Start at `(x, y)` (σ `sigma_pos0_m`) with height `h0` (σ `sigma_h0`), at rest.
    pub fn new(params: EkfParams, xy: [f64; 2], h0: f64, sigma_h0: f64, t_s: f64) -> HeightEkf {
        let n = Self::dim(params.motion);
        let mut x = DVector::zeros(n);
        x[0] = xy[0];
        x[1] = xy[1];
        x[2] = h0;
        let mut p = DMatrix::zeros(n, n);
        p[(0, 0)] = params.sigma_pos0_m.powi(2);
        p[(1, 1)] = params.sigma_pos0_m.powi(2);
        p[(2, 2)] = sigma_h0.powi(2);
        if n == 5 {
            p[(3, 3)] = 1.0; // walking speeds: σ 1 m/s
            p[(4, 4)] = 1.0;
        }
        HeightEkf { params, x, p, t_s }
    }

    /// Predict to time `t_s` (never backwards).
    pub fn predict(&mut self, t_s: f64) {
        let dt = (t_s - self.t_s).max(0.0);
        self.t_s = self.t_s.max(t_s);
        let q = self.params.q_pos;
        match self.params.motion {
            Motion::ConstantPosition => {
                self.p[(0, 0)] += q * dt;
                self.p[(1, 1)] += q * dt;
            }
            Motion::ConstantVelocity => {
                let mut f = DMatrix::identity(5, 5);
                f[(0, 3)] = dt;
                f[(1, 4)] = dt;
                self.x = &f * &self.x;
                let mut qm = DMatrix::zeros(5, 5);
                for (i, v) in [(0, 3), (1, 4)] {
                    qm[(i, i)] = q * dt.powi(3) / 3.0;
                    qm[(i, v)] = q * dt.powi(2) / 2.0;
                    qm[(v, i)] = q * dt.powi(2) / 2.0;
                    qm[(v, v)] = q * dt;
                }
                self.p = &f * &self.p * f.transpose() + qm;
            }
        }
        self.p[(2, 2)] += self.params.q_height * dt;
    }

    /// Gated EKF update with innovation `nu`, Jacobian `h` (2 × n) and noise `r`.
    fn update(&mut self, nu: [f64; 2], h: DMatrix<f64>, r: [f64; 2]) -> Update {
        let s = &h * &self.p * h.transpose() + DMatrix::from_diagonal(&DVector::from_row_slice(&r));
        let Some(s_inv) = s.clone().try_inverse() else {
            return Update {
                d2: f64::INFINITY,
                accepted: false,
            };
        };
        let nu = DVector::from_row_slice(&nu);
        let d2 = (nu.transpose() * &s_inv * &nu)[(0, 0)];
        if d2 > self.params.gate_sigma.powi(2) {
            return Update {
                d2,
                accepted: false,
            };
        }
        let k = &self.p * h.transpose() * &s_inv;
        self.x += &k * nu;
        let n = self.x.len();
        // Joseph form keeps P symmetric positive semi-definite
        let ikh = DMatrix::identity(n, n) - &k * &h;
        let rm = DMatrix::from_diagonal(&DVector::from_row_slice(&r));
        self.p = &ikh * &self.p * ikh.transpose() + &k * rm * k.transpose();
        Update { d2, accepted: true }
    }

    /// Laser range–bearing of the leg-pair midpoint.
    pub fn update_laser(&mut self, range_m: f64, bearing: f64, laser: &SensorAt) -> Update {
        let (z, j) = laser_model(self.x[0], self.x[1], laser);
        let n = self.x.len();
        let mut h = DMatrix::zeros(2, n);
        for r in 0..2 {
            h[(r, 0)] = j[r][0];
            h[(r, 1)] = j[r][1];
        }
        let sr = self.params.sigma_range_m.powi(2);
        let sb = self.params.sigma_bearing_rad.powi(2);
        self.update([range_m - z[0], wrap(bearing - z[1])], h, [sr, sb])
    }

    /// Camera bearing + elevation of the head top (world-frame angles from the camera centre).
    pub fn update_camera(&mut self, bearing: f64, elevation: f64, cam: &SensorAt) -> Update {
        let (z, j) = camera_model(self.x[0], self.x[1], self.x[2], cam);
        let n = self.x.len();
        let mut h = DMatrix::zeros(2, n);
        for r in 0..2 {
            for c in 0..3 {
                h[(r, c)] = j[r][c];
            }
        }
        let sb = self.params.sigma_cam_bearing_rad.powi(2);
        let se = self.params.sigma_cam_elevation_rad.powi(2);
        self.update([wrap(bearing - z[0]), elevation - z[1]], h, [sb, se])
    }

    pub fn xy(&self) -> [f64; 2] {
        [self.x[0], self.x[1]]
    }

    pub fn height(&self) -> f64 {
        self.x[2]
    }

    pub fn sigma_height(&self) -> f64 {
        self.p[(2, 2)].max(0.0).sqrt()
    }

    /// 2×2 position covariance `[[xx, xy], [xy, yy]]`.
    pub fn pos_cov(&self) -> [[f64; 2]; 2] {
        [
            [self.p[(0, 0)], self.p[(0, 1)]],
            [self.p[(1, 0)], self.p[(1, 1)]],
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> SensorAt {
        SensorAt {
            x: 7.85,
            y: 3.0,
            z: 2.2,
            yaw: 0.0,
        }
    }

    #[test]
    fn camera_jacobian_matches_finite_differences() {
        for &(x, y, h) in &[
            (3.0, 3.5, 1.84),
            (5.0, 1.2, 1.0),
            (2.0, 4.8, 2.5),
            (7.0, 3.1, 1.7),
        ] {
            let (_, j) = camera_model(x, y, h, &cam());
            let eps = 1e-6;
            let s = [x, y, h];
            for c in 0..3 {
                let (mut a, mut b) = (s, s);
                a[c] += eps;
                b[c] -= eps;
                let (za, _) = camera_model(a[0], a[1], a[2], &cam());
                let (zb, _) = camera_model(b[0], b[1], b[2], &cam());
                for r in 0..2 {
                    let fd = (za[r] - zb[r]) / (2.0 * eps);
                    assert!(
                        (fd - j[r][c]).abs() < 1e-7,
                        "({x},{y},{h}) d z{r}/d s{c}: {fd} vs {}",
                        j[r][c]
                    );
                }
            }
        }
    }

    #[test]
    fn the_elevation_model_inverts_a_known_head_height_at_a_known_range() {
        // head top 1.84 m, 4 m from a camera at 2.2 m: ε = atan2(−0.36, 4)
        let c = cam();
        let (z, _) = camera_model(c.x - 4.0, c.y, 1.84, &c);
        assert!((z[1] - (-0.36f64).atan2(4.0)).abs() < 1e-15);
        assert!(
            (z[0].abs() - std::f64::consts::PI).abs() < 1e-15,
            "facing −x: β = π"
        );
        let h = height_from_elevation(z[1], 4.0, c.z);
        assert!((h - 1.84).abs() < 1e-12, "{h}");
    }

    #[test]
    fn range_per_elevation_is_the_inverse_slope_of_the_elevation_model() {
        // finite differences of ε(ρ) from the camera model; the numbers: a 1.84 m head
        // under a 2.2 m camera at 5 m is 70 m/rad (0.26 m per 3.76 mrad pixel of a 266 px
        // focal length), under a 2.8 m camera 27 m/rad, and a head at the camera's height gives no
        // range
        for &(rho, dz) in &[
            (5.0, -0.36),
            (8.0, -0.36),
            (3.0, 0.64),
            (5.0, -0.96),
            (1.5, 0.1),
        ] {
            let c = SensorAt {
                x: 0.0,
                y: 0.0,
                z: 2.0,
                yaw: 0.0,
            };
            let eps = |r: f64| camera_model(r, 0.0, 2.0 + dz, &c).0[1];
            let slope = (eps(rho + 1e-6) - eps(rho - 1e-6)) / 2e-6;
            let want = range_per_elevation(rho, dz);
            assert!((1.0 / slope.abs() - want).abs() < 1e-6 * want, "{rho} {dz}");
        }
        assert!((range_per_elevation(5.0, -0.36) - 69.804).abs() < 1e-3);
        assert!((range_per_elevation(5.0, -0.96) - 27.001).abs() < 1e-3);
        assert!(range_per_elevation(5.0, 0.0).is_infinite());
    }

    fn params(motion: Motion) -> EkfParams {
        EkfParams {
            motion,
            q_pos: 0.1,
            q_height: 1e-6,
            sigma_range_m: 0.05,
            sigma_bearing_rad: 0.01,
            sigma_cam_bearing_rad: 0.01,
            sigma_cam_elevation_rad: 0.01,
            h0_m: 1.0,
            sigma_h0_m: 10.0,
            sigma_pos0_m: 1.0,
            gate_sigma: 3.0,
        }
    }

    #[test]
    fn noise_free_laser_and_camera_learn_the_height_and_the_gate_rejects_an_outlier() {
        let laser = SensorAt {
            x: 0.15,
            y: 3.0,
            z: 0.3,
            yaw: 0.0,
        };
        let truth = (3.5, 3.4, 1.84);
        for motion in [Motion::ConstantPosition, Motion::ConstantVelocity] {
            let mut f = HeightEkf::new(params(motion), [3.0, 3.0], 1.0, 10.0, 0.0);
            for k in 1..=50 {
                let t = 0.2 * f64::from(k);
                f.predict(t);
                let (zl, _) = laser_model(truth.0, truth.1, &laser);
                assert!(f.update_laser(zl[0], zl[1], &laser).accepted || k == 1);
                let (zc, _) = camera_model(truth.0, truth.1, truth.2, &cam());
                f.update_camera(zc[0], zc[1], &cam());
            }
            assert!(
                (f.height() - 1.84).abs() < 1e-3,
                "{motion:?}: {}",
                f.height()
            );
            assert!((f.xy()[0] - 3.5).abs() < 1e-3 && (f.xy()[1] - 3.4).abs() < 1e-3);
            // an observation implying a 3 m tall person is outside the 3σ gate
            let (zc, _) = camera_model(truth.0, truth.1, 3.0, &cam());
            let before = f.x.clone();
            let u = f.update_camera(zc[0], zc[1], &cam());
            assert!(!u.accepted && u.d2 > 9.0);
            assert_eq!(f.x, before);
        }
    }

    #[test]
    fn a_constant_height_keeps_its_value_and_variance_through_predict() {
        // q_height = 0: predict adds q_pos dt to the position variances and nothing to the
        // height's; with the random walk the height variance grows by q_height dt
        for motion in [Motion::ConstantPosition, Motion::ConstantVelocity] {
            let mut pc = params(motion);
            pc.q_height = 0.0;
            let mut f = HeightEkf::new(pc, [1.0, 2.0], 1.84, 0.05, 0.0);
            f.predict(7.5);
            assert_eq!((f.height(), f.p[(2, 2)]), (1.84, 0.05f64.powi(2)));
            assert!(f.p[(0, 0)] > 1.0, "the position variance grows");
            pc.q_height = 1e-4;
            let mut f = HeightEkf::new(pc, [1.0, 2.0], 1.84, 0.05, 0.0);
            f.predict(7.5);
            assert!((f.p[(2, 2)] - (0.05f64.powi(2) + 7.5e-4)).abs() < 1e-15);
        }
    }

    #[test]
    fn a_long_constant_height_run_keeps_the_covariance_positive_definite_without_a_floor() {
        // 10 000 laser + camera updates (about 17 min at 10 Hz) with q_height = 0: the height
        // variance never grows and stays positive, P stays symmetric with positive eigenvalues,
        // and the noise-free height is learned
        let laser = SensorAt {
            x: 0.15,
            y: 3.0,
            z: 0.3,
            yaw: 0.0,
        };
        let mut pc = params(Motion::ConstantPosition);
        pc.q_height = 0.0;
        let mut f = HeightEkf::new(pc, [3.0, 3.0], 1.0, 10.0, 0.0);
        let mut last_var = f64::INFINITY;
        for k in 1..=10_000 {
            let t = 0.1 * f64::from(k);
            let (x, y) = (3.0 + (0.01 * t).sin(), 3.0 + (0.013 * t).cos());
            f.predict(t);
            let (zl, _) = laser_model(x, y, &laser);
            f.update_laser(zl[0], zl[1], &laser);
            let (zc, _) = camera_model(x, y, 1.84, &cam());
            assert!(f.update_camera(zc[0], zc[1], &cam()).accepted);
            assert!(f.p[(2, 2)] > 0.0 && f.p[(2, 2)] <= last_var * (1.0 + 1e-9));
            last_var = f.p[(2, 2)];
        }
        let sym = (&f.p - f.p.transpose()).abs().max();
        let eig = f.p.clone().symmetric_eigen().eigenvalues;
        assert!(sym < 1e-15 && eig.min() > 0.0, "{sym} {eig}");
        // what remains of the first, far-off linearisations: 3 µm (σ_h 0.46 mm)
        assert!(
            (f.height() - 1.84).abs() < 1e-4 && f.sigma_height() < 1e-3,
            "{} {}",
            f.height(),
            f.sigma_height()
        );
    }

    #[test]
    fn predict_with_zero_dt_is_the_identity_and_angles_wrap() {
        let mut f = HeightEkf::new(params(Motion::ConstantVelocity), [1.0, 2.0], 1.0, 10.0, 5.0);
        let (x, p) = (f.x.clone(), f.p.clone());
        f.predict(5.0);
        assert_eq!((f.x.clone(), f.p.clone()), (x, p));
        assert!((wrap(3.0 * std::f64::consts::PI) - std::f64::consts::PI).abs() < 1e-12);
        assert!((wrap(-0.5) + 0.5).abs() < 1e-15);
    }
}

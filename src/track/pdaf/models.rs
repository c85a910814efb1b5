//! The two motion models of the target filter, both written in the 5-D state
//! `(x, y, vx, vy, ω)` of the fixed (odom) frame (m, m/s, rad/s).
//!
//! - **CV** (constant velocity, continuous white-noise acceleration; Bar-Shalom, Li &
//!   Kirubarajan, *Estimation with Applications to Tracking and Navigation*, §6.2.2): per axis
//!   `F = [1 T; 0 1]`, `Q = q̃ [T³/3 T²/2; T²/2 T]` with `q̃` = `accel_noise`, the power spectral
//!   density of the acceleration (m²/s³). The ω block is **held at zero**: the transition's ω row
//!   is zero and `Q_ωω = 0`, so after a CV prediction `ω = 0` with zero variance and zero
//!   cross-covariance. The kinematics never read ω, so the 4-D part is exactly the 4-D CV
//!   filter; inside the IMM the CT mode's turn rate enters the CV mode only through mixing,
//!   where the spread term `(ω_CT − ω̄)²` gives the mixed estimate its ω variance back.
//! - **CT** (coordinated turn with unknown turn rate, *ibid.* §11.7.1): the exact solution of
//!   `ṗ = v`, `v̇ = ω · rot90(v)`, `ω̇ = 0` over `T`, with `θ = ωT`,
//!
//!   ```text
//!   x' = x + (sin θ/ω) vx − ((1 − cos θ)/ω) vy      vx' = cos θ vx − sin θ vy
//!   y' = y + ((1 − cos θ)/ω) vx + (sin θ/ω) vy      vy' = sin θ vx + cos θ vy      ω' = ω
//!   ```
//!
//!   propagated with an EKF (Jacobian [`ct_jacobian`]). `sin θ/ω = T·f₁(θ)` and
//!   `(1 − cos θ)/ω = T·f₂(θ)` and their ω-derivatives are evaluated through `f₁ = sin θ/θ`,
//!   `f₂ = (1 − cos θ)/θ = 2 sin²(θ/2)/θ` and their θ-derivatives, with Taylor series for
//!   `|θ| < 0.1`, so nothing divides by ω and `ω = 0` gives the CV transition exactly. Process
//!   noise: the same CWNA block on (position, velocity) as CV (acceleration noise in the fixed
//!   frame) and a random walk on ω with PSD `turn_noise` (rad²/s³): `Q_ωω = q_ω T`.
//!
//! What it does not do: no range–bearing measurements (the filter measures (x, y)), no
//! acceleration state, no turn-rate-dependent noise.

use nalgebra::{SMatrix, SVector};

/// The filter state `(x, y, vx, vy, ω)`.
pub(crate) type State = SVector<f64, 5>;
/// Its covariance.
pub(crate) type Cov = SMatrix<f64, 5, 5>;

/// The two motion models.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Motion {
    Cv,
    Ct,
}

/// Below this `|θ| = |ω T|` the CT coefficients come from their Taylor series (truncation
/// error below 1e-17 relative; above it the closed forms lose at most ~1e-13 to cancellation).
const SERIES_BELOW: f64 = 0.1;

/// `(f₁, f₂, f₁', f₂')` of `θ`: `f₁ = sin θ/θ`, `f₂ = (1 − cos θ)/θ` and their derivatives.
pub(super) fn turn_coefficients(theta: f64) -> (f64, f64, f64, f64) {
    if theta.abs() < SERIES_BELOW {
        let t2 = theta * theta;
        let f1 = 1.0
            - t2 / 6.0
                * (1.0 - t2 / 20.0 * (1.0 - t2 / 42.0 * (1.0 - t2 / 72.0 * (1.0 - t2 / 110.0))));
        let f2 = theta / 2.0
            * (1.0 - t2 / 12.0 * (1.0 - t2 / 30.0 * (1.0 - t2 / 56.0 * (1.0 - t2 / 90.0))));
        let d1 = -theta / 3.0
            * (1.0 - t2 / 10.0 * (1.0 - t2 / 28.0 * (1.0 - t2 / 54.0 * (1.0 - t2 / 88.0))));
        let d2 = 0.5
            * (1.0
                - t2 / 4.0
                    * (1.0
                        - t2 / 18.0 * (1.0 - t2 / 40.0 * (1.0 - t2 / 70.0 * (1.0 - t2 / 108.0)))));
        (f1, f2, d1, d2)
    } else {
        let (sin, cos) = theta.sin_cos();
        let one_minus_cos = 2.0 * (0.5 * theta).sin().powi(2);
        let f1 = sin / theta;
        let f2 = one_minus_cos / theta;
        let d1 = (theta * cos - sin) / (theta * theta);
        let d2 = (theta * sin - one_minus_cos) / (theta * theta);
        (f1, f2, d1, d2)
    }
}

/// The state after `dt_s` under `motion` (noise-free).
pub(crate) fn transition(motion: Motion, x: &State, dt_s: f64) -> State {
    let (px, py, vx, vy, w) = (x[0], x[1], x[2], x[3], x[4]);
    match motion {
        Motion::Cv => State::new(px + dt_s * vx, py + dt_s * vy, vx, vy, 0.0),
        Motion::Ct => {
            let theta = w * dt_s;
            let (f1, f2, _, _) = turn_coefficients(theta);
            let (s, c) = (dt_s * f1, dt_s * f2);
            let (sin, cos) = theta.sin_cos();
            State::new(
                px + s * vx - c * vy,
                py + c * vx + s * vy,
                cos * vx - sin * vy,
                sin * vx + cos * vy,
                w,
            )
        }
    }
}

/// The Jacobian `∂f/∂x` of [`transition`] at `x` (for CV the transition matrix itself).
pub(crate) fn jacobian(motion: Motion, x: &State, dt_s: f64) -> Cov {
    match motion {
        Motion::Cv => {
            let mut f = Cov::identity();
            f[(0, 2)] = dt_s;
            f[(1, 3)] = dt_s;
            f[(4, 4)] = 0.0;
            f
        }
        Motion::Ct => ct_jacobian(x, dt_s),
    }
}

/// The Jacobian of the coordinated-turn transition, the ω column included
/// (`∂(sin θ/ω)/∂ω = T² f₁'(θ)`, `∂((1 − cos θ)/ω)/∂ω = T² f₂'(θ)`).
pub(crate) fn ct_jacobian(x: &State, dt_s: f64) -> Cov {
    let (vx, vy, w) = (x[2], x[3], x[4]);
    let theta = w * dt_s;
    let (f1, f2, d1, d2) = turn_coefficients(theta);
    let (s, c) = (dt_s * f1, dt_s * f2);
    let (ds, dc) = (dt_s * dt_s * d1, dt_s * dt_s * d2);
    let (sin, cos) = theta.sin_cos();
    let mut f = Cov::identity();
    f[(0, 2)] = s;
    f[(0, 3)] = -c;
    f[(0, 4)] = ds * vx - dc * vy;
    f[(1, 2)] = c;
    f[(1, 3)] = s;
    f[(1, 4)] = dc * vx + ds * vy;
    f[(2, 2)] = cos;
    f[(2, 3)] = -sin;
    f[(2, 4)] = -dt_s * (sin * vx + cos * vy);
    f[(3, 2)] = sin;
    f[(3, 3)] = cos;
    f[(3, 4)] = dt_s * (cos * vx - sin * vy);
    f
}

/// Process noise over `dt_s`: the CWNA block with PSD `accel_noise` on each axis and, for CT,
/// `turn_noise · dt_s` on ω.
pub(crate) fn process_noise(motion: Motion, dt_s: f64, accel_noise: f64, turn_noise: f64) -> Cov {
    let mut q = Cov::zeros();
    let (a, b, c) = (dt_s.powi(3) / 3.0, dt_s.powi(2) / 2.0, dt_s);
    for i in 0..2 {
        q[(i, i)] = a * accel_noise;
        q[(i, i + 2)] = b * accel_noise;
        q[(i + 2, i)] = b * accel_noise;
        q[(i + 2, i + 2)] = c * accel_noise;
    }
    if motion == Motion::Ct {
        q[(4, 4)] = turn_noise * dt_s;
    }
    q
}

/// One EKF prediction: `x ← f(x)`, `P ← F P Fᵀ + Q` (symmetrised).
pub(crate) fn predict(
    motion: Motion,
    x: &mut State,
    p: &mut Cov,
    dt_s: f64,
    accel_noise: f64,
    turn_noise: f64,
) {
    let f = jacobian(motion, x, dt_s);
    *x = transition(motion, x, dt_s);
    let q = process_noise(motion, dt_s, accel_noise, turn_noise);
    let fp = f * *p * f.transpose() + q;
    *p = 0.5 * (fp + fp.transpose());
}

//! The interacting-multiple-model steps (Bar-Shalom, Li & Kirubarajan, *Estimation with
//! Applications to Tracking and Navigation*, §11.6.6): Markov mode switching, mixing, mode
//! probabilities from the mode likelihoods, and the combined estimate. Written for any number
//! of modes; one mode makes every step the identity, so the single-model filters run through
//! the same code.
//!
//! **Switching.** `imm_switch` is the probability of leaving a mode within one second. Read as
//! a constant hazard, the probability of leaving within a step of `Δt` seconds is
//! `1 − (1 − imm_switch)^Δt`, spread evenly over the other modes (with two modes: to the
//! other one). `Δt = 0` gives the identity.

use super::models::{Cov, State};

/// The mode transition matrix `π[i][j] = P(mode j at k+1 | mode i at k)` over `dt_s`.
pub(crate) fn switch_matrix(modes: usize, imm_switch: f64, dt_s: f64) -> Vec<Vec<f64>> {
    let leave = if modes < 2 {
        0.0
    } else {
        1.0 - (1.0 - imm_switch).powf(dt_s)
    };
    let other = if modes < 2 {
        0.0
    } else {
        leave / (modes - 1) as f64
    };
    (0..modes)
        .map(|i| {
            (0..modes)
                .map(|j| if i == j { 1.0 - leave } else { other })
                .collect()
        })
        .collect()
}

/// Mixing: the predicted mode probabilities `c_j = Σ_i π_ij μ_i` and the mixed initial
/// estimate of each mode, `x0_j = Σ_i μ_{i|j} x_i`,
/// `P0_j = Σ_i μ_{i|j} (P_i + (x_i − x0_j)(x_i − x0_j)ᵀ)` with `μ_{i|j} = π_ij μ_i / c_j`.
/// A mode with `c_j = 0` keeps its own estimate.
pub(crate) fn mix(
    est: &[(State, Cov)],
    mu: &[f64],
    pi: &[Vec<f64>],
) -> (Vec<(State, Cov)>, Vec<f64>) {
    let n = est.len();
    let c: Vec<f64> = (0..n)
        .map(|j| (0..n).map(|i| pi[i][j] * mu[i]).sum())
        .collect();
    let mixed = (0..n)
        .map(|j| {
            if c[j] <= 0.0 || !c[j].is_finite() {
                return est[j];
            }
            let w: Vec<f64> = (0..n).map(|i| pi[i][j] * mu[i] / c[j]).collect();
            combine(est, &w)
        })
        .collect();
    (mixed, c)
}

/// The moment-matched combination `x = Σ w_i x_i`, `P = Σ w_i (P_i + (x_i − x)(x_i − x)ᵀ)`
/// (symmetrised).
pub(crate) fn combine(est: &[(State, Cov)], w: &[f64]) -> (State, Cov) {
    let mut x = State::zeros();
    for ((xi, _), wi) in est.iter().zip(w) {
        x += *wi * xi;
    }
    let mut p = Cov::zeros();
    for ((xi, pi), wi) in est.iter().zip(w) {
        let d = xi - x;
        p += *wi * (pi + d * d.transpose());
    }
    (x, 0.5 * (p + p.transpose()))
}

/// Posterior mode probabilities `μ_j ∝ Λ_j c_j`; when every product is zero (or not finite)
/// the measurements say nothing about the mode and the predicted `c` is kept.
pub(crate) fn posterior(c: &[f64], likelihood: &[f64]) -> Vec<f64> {
    let prod: Vec<f64> = c.iter().zip(likelihood).map(|(a, b)| a * b).collect();
    let total: f64 = prod.iter().sum();
    if total > 0.0 && total.is_finite() {
        prod.iter().map(|v| v / total).collect()
    } else {
        c.to_vec()
    }
}

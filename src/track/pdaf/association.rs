//! Gates and association weights of the target filter: the elliptical (χ²) gate, the maneuver
//! gate, the PDAF weights with feature likelihood ratios (seed 001 §V, Bar-Shalom & Li,
//! *Multitarget-Multisensor Tracking*, §3.4) and the nearest-neighbour choice.
//!
//! **Weights.** For the gated measurements with squared Mahalanobis distances `d²_j` and
//! likelihood ratios `lr_j`: `p_j = P_D · exp(−d²_j/2) · lr_j`,
//! `b = λ · |2πS|^{1/2} · (1 − P_D P_G)`, `β_j = p_j / (b + Σp)`, `β₀ = b / (b + Σp)`. When
//! `b + Σp` is zero (no clutter, `P_D P_G = 1`, every `p_j` zero) nothing can be said and
//! `β₀ = 1` (prediction only). The same numbers give the likelihood of the measurement set
//! under the filter's (mode's) prediction, up to a factor common to all modes,
//! `Λ = (b + Σp) / |2πS|^{1/2} = λ (1 − P_D P_G) + P_D Σ_j N(z_j; ẑ, S) lr_j`, which the IMM
//! uses as its mode likelihood.

use nalgebra::{Matrix2, Vector2};

/// Squared Mahalanobis distance `νᵀ S⁻¹ ν`.
pub(crate) fn mahalanobis2(nu: &Vector2<f64>, s_inv: &Matrix2<f64>) -> f64 {
    (nu.transpose() * s_inv * nu)[(0, 0)]
}

/// The inverse of a 2×2 innovation covariance and its determinant; `None` when it is not
/// positive definite or not finite.
pub(crate) fn invert(s: &Matrix2<f64>) -> Option<(Matrix2<f64>, f64)> {
    let det = s[(0, 0)] * s[(1, 1)] - s[(0, 1)] * s[(1, 0)];
    if !(det > 0.0 && det.is_finite() && s[(0, 0)] > 0.0) {
        return None;
    }
    let inv = Matrix2::new(s[(1, 1)], -s[(0, 1)], -s[(1, 0)], s[(0, 0)]) / det;
    Some((inv, det))
}

/// The maneuver gate's radius (m): the farthest a person can have moved in `dt_s` seconds
/// from the last updated position, `v_max Δt + ½ a_max Δt² + 3 σ_r`.
pub(crate) fn maneuver_radius(v_max: f64, a_max: f64, sigma_r: f64, dt_s: f64) -> f64 {
    // Δt = 0 reaches 3σ_r even with an infinite v_max or a_max (∞ · 0 would be NaN)
    let reach = if dt_s > 0.0 {
        v_max * dt_s + 0.5 * a_max * dt_s * dt_s
    } else {
        0.0
    };
    reach + 3.0 * sigma_r
}

/// PDAF weights of one filter (or IMM mode) over its gated measurements.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Weights {
    /// `β_j`, one per gated measurement.
    pub beta: Vec<f64>,
    /// `β₀`.
    pub beta0: f64,
    /// `Λ`, the likelihood of the measurement set (see the module doc).
    pub likelihood: f64,
}

/// The PDAF weights of the module doc from the squared distances `d2`, the likelihood ratios
/// `lr` (same length), `det S`, `P_D`, `P_G` and the clutter density `λ` (1/m²).
pub(crate) fn pdaf_weights(
    d2: &[f64],
    lr: &[f64],
    det_s: f64,
    p_d: f64,
    p_g: f64,
    lambda: f64,
) -> Weights {
    let norm = 2.0 * std::f64::consts::PI * det_s.sqrt();
    let p: Vec<f64> = d2
        .iter()
        .zip(lr)
        .map(|(d, l)| p_d * (-0.5 * d).exp() * l)
        .collect();
    let b = lambda * norm * (1.0 - p_d * p_g).max(0.0);
    let total = b + p.iter().sum::<f64>();
    if !(total > 0.0 && total.is_finite()) {
        return Weights {
            beta: vec![0.0; p.len()],
            beta0: 1.0,
            likelihood: 0.0,
        };
    }
    Weights {
        beta: p.iter().map(|v| v / total).collect(),
        beta0: b / total,
        likelihood: total / norm,
    }
}

/// The nearest neighbour: the measurement with the largest `exp(−d²/2) · lr` (with `lr = 1`
/// for all: the smallest Mahalanobis distance), ties to the lowest index; those with
/// `lr = 0` are never chosen. Compared in the log domain, so distant measurements do not
/// underflow into ties.
pub(crate) fn nearest(d2: &[f64], lr: &[f64]) -> Option<usize> {
    let mut best: Option<(usize, f64)> = None;
    for (k, (d, l)) in d2.iter().zip(lr).enumerate() {
        if *l <= 0.0 {
            continue;
        }
        let score = -0.5 * d + l.ln();
        if best.is_none_or(|(_, s)| score > s) {
            best = Some((k, score));
        }
    }
    best.map(|(k, _)| k)
}

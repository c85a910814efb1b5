//! Joint probabilistic data association (JPDA) for linear Kalman filters: gated clusters,
//! exact enumeration of the feasible joint events of a cluster, the marginal association
//! probabilities, and the PDAF combined-innovation update with its spread-of-innovations term
//! (Bar-Shalom & Li, *Multitarget-Multisensor Tracking*, §6.2 (JPDA) and §3.4 (PDAF);
//! Fortmann, Bar-Shalom & Scheffe, IEEE J. Oceanic Eng. 8(3), 1983).
//!
//! **Joint events.** A feasible joint event θ gives each track of a cluster at most one of the
//! measurements inside its gate and each measurement at most one track. With detection
//! probability `P_D`, gate probability `P_G` and a Poisson clutter of spatial density `λ`, the
//! parametric JPDA (Bar-Shalom & Li eq. 6.2.4-4) gives
//!
//! ```text
//! P(θ | Z) ∝ Π_{(t, j) ∈ θ} (P_D · N(z_j; ẑ_t, S_t) / λ) · Π_{t missed in θ} (1 − P_D · P_G)
//! ```
//!
//! Multiplied by the constant `λ^T` (T tracks in the cluster), an assigned pair weighs
//! `w_tj = P_D · N(z_j; ẑ_t, S_t)` and a missed track `m_t = λ · (1 − P_D · P_G)`; this form is
//! what [`joint_marginals`] takes, and it stays defined at `λ = 0`. The marginals are
//! `β_tj = Σ_{θ ∋ (t, j)} P(θ)` and `β_t0 = 1 − Σ_j β_tj`. With one track this is the PDAF:
//! `β_j = e_j / (b + Σ_k e_k)`, `β_0 = b / (b + Σ_k e_k)`, `e_j = exp(−d_j²/2)`,
//! `b = λ · |2π S|^{1/2} · (1 − P_D P_G) / P_D`.
//!
//! **Cluster size limit.** The number of joint events grows combinatorially (6 tracks × 6
//! measurements all gated: 13,327 events). [`joint_marginals`] enumerates exactly (depth
//! first, in track and measurement order, so deterministic) and gives up with `None` once a
//! cluster has more than `max_events` events, or when every event has zero weight; the caller
//! decides what to do then (the laser tracker falls back to global nearest neighbour for that
//! cluster and counts it). The same pass returns the most probable joint event, which the
//! laser tracker uses for track management (hits, initiation).
//!
//! **Update** ([`combined_update`], Bar-Shalom & Li eq. 3.4.2-7 … 3.4.2-12): with the gain
//! `K = P Hᵀ S⁻¹`, the innovations `ν_j = z_j − H x`, `ν = Σ_j β_j ν_j`,
//!
//! ```text
//! x⁺ = x + K ν
//! P⁺ = β_0 P + (1 − β_0) (P − K S Kᵀ) + K (Σ_j β_j ν_j ν_jᵀ − ν νᵀ) Kᵀ
//! ```
//!
//! Hand-written (no well-kept Rust crate implements JPDA over nalgebra filters; the
//! enumeration is 40 lines). What it does not do: no track-oriented or Monte-Carlo
//! approximations for large clusters, no JIPDA (track existence), no coupled (JPDA-C) update.

use nalgebra::{SMatrix, SVector};

use super::kalman::{Kalman, KalmanError};

/// Marginal association probabilities of one cluster.
#[derive(Debug, Clone, PartialEq)]
pub struct Marginals {
    /// `beta[t][j]`: probability that track `t` produced measurement `j` (0 outside its gate).
    pub beta: Vec<Vec<f64>>,
    /// `beta0[t]`: probability that track `t` produced none.
    pub beta0: Vec<f64>,
    /// The most probable joint event: per track its measurement, `None` = missed.
    pub best: Vec<Option<usize>>,
    /// Joint events enumerated.
    pub events: usize,
}

/// Joint events of a cluster with pair weights `w[t][j]` (`w_tj = P_D · N(z_j; ẑ_t, S_t)`;
/// 0, negative or NaN: outside the gate) and missed-track weights `miss[t]`
/// (`λ · (1 − P_D P_G)`), see the module doc. `None` when there are more than `max_events`
/// joint events or when all of them have zero weight.
pub fn joint_marginals(w: &[Vec<f64>], miss: &[f64], max_events: usize) -> Option<Marginals> {
    let tracks = w.len();
    let meas = w.iter().map(Vec::len).max().unwrap_or(0);
    let gated: Vec<Vec<usize>> = w
        .iter()
        .map(|row| (0..row.len()).filter(|&j| row[j] > 0.0).collect())
        .collect();
    let mut e = Enumeration {
        w,
        miss,
        gated: &gated,
        max_events,
        used: vec![false; meas],
        current: vec![None; tracks],
        sum: vec![vec![0.0; meas]; tracks],
        sum0: vec![0.0; tracks],
        total: 0.0,
        best: (f64::NEG_INFINITY, vec![None; tracks]),
        events: 0,
    };
    if !e.walk(0, 1.0) {
        return None;
    }
    if !(e.total > 0.0 && e.total.is_finite()) {
        return None;
    }
    let beta = e
        .sum
        .iter()
        .map(|row| row.iter().map(|v| v / e.total).collect())
        .collect();
    let beta0 = e.sum0.iter().map(|v| v / e.total).collect();
    Some(Marginals {
        beta,
        beta0,
        best: e.best.1,
        events: e.events,
    })
}

/// Depth-first enumeration state of [`joint_marginals`].
struct Enumeration<'a> {
    w: &'a [Vec<f64>],
    miss: &'a [f64],
    gated: &'a [Vec<usize>],
    max_events: usize,
    used: Vec<bool>,
    current: Vec<Option<usize>>,
    sum: Vec<Vec<f64>>,
    sum0: Vec<f64>,
    total: f64,
    best: (f64, Vec<Option<usize>>),
    events: usize,
}

impl Enumeration<'_> {
    /// Events from track `t` on, given the weight `acc` so far; false once over the limit.
    fn walk(&mut self, t: usize, acc: f64) -> bool {
        if t == self.current.len() {
            self.events += 1;
            if self.events > self.max_events {
                return false;
            }
            self.total += acc;
            for (k, c) in self.current.iter().enumerate() {
                match c {
                    Some(j) => self.sum[k][*j] += acc,
                    None => self.sum0[k] += acc,
                }
            }
            if acc > self.best.0 {
                self.best = (acc, self.current.clone());
            }
            return true;
        }
        self.current[t] = None;
        if !self.walk(t + 1, acc * self.miss[t].max(0.0)) {
            return false;
        }
        for &j in &self.gated[t] {
            if self.used[j] {
                continue;
            }
            self.used[j] = true;
            self.current[t] = Some(j);
            let ok = self.walk(t + 1, acc * self.w[t][j]);
            self.used[j] = false;
            self.current[t] = None;
            if !ok {
                return false;
            }
        }
        true
    }
}

/// Connected components of the gate graph `gated(track, measurement)`: each as (tracks,
/// measurements), both ascending, in order of their first track. Tracks without a gated
/// measurement and measurements in no gate belong to no cluster.
pub fn clusters(
    tracks: usize,
    meas: usize,
    gated: impl Fn(usize, usize) -> bool,
) -> Vec<(Vec<usize>, Vec<usize>)> {
    let mut parent: Vec<usize> = (0..tracks + meas).collect();
    fn find(parent: &mut [usize], mut x: usize) -> usize {
        while parent[x] != x {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        x
    }
    let mut in_gate = vec![false; tracks + meas];
    for t in 0..tracks {
        for j in 0..meas {
            if gated(t, j) {
                in_gate[t] = true;
                in_gate[tracks + j] = true;
                let (a, b) = (find(&mut parent, t), find(&mut parent, tracks + j));
                if a != b {
                    parent[a.max(b)] = a.min(b);
                }
            }
        }
    }
    let mut out: Vec<(usize, Vec<usize>, Vec<usize>)> = Vec::new();
    for (v, _) in in_gate.iter().enumerate().filter(|(_, g)| **g) {
        let root = find(&mut parent, v);
        let k = match out.iter().position(|c| c.0 == root) {
            Some(k) => k,
            None => {
                out.push((root, Vec::new(), Vec::new()));
                out.len() - 1
            }
        };
        if v < tracks {
            out[k].1.push(v);
        } else {
            out[k].2.push(v - tracks);
        }
    }
    out.into_iter().map(|(_, t, m)| (t, m)).collect()
}

/// Probability that a measurement of an M-dimensional Gaussian falls inside the gate
/// `d² ≤ gate` (χ² with M degrees of freedom); exact for M = 2 (`1 − e^{−gate/2}`), which is
/// the only dimension the trackers use; other M return `None`.
pub fn gate_probability(dims: usize, gate: f64) -> Option<f64> {
    (dims == 2).then(|| 1.0 - (-0.5 * gate.max(0.0)).exp())
}

/// `N(z; ẑ, S)` of an innovation with squared Mahalanobis distance `d2` and innovation
/// covariance determinant `det_s`, in M = 2 dimensions.
pub fn gaussian_2d(d2: f64, det_s: f64) -> f64 {
    (-0.5 * d2).exp() / (2.0 * std::f64::consts::PI * det_s.sqrt())
}

/// The combined-innovation (PDAF) update of one track with its gated measurements and their
/// association probabilities (`beta[j]`, `beta0`; see the module doc). With `beta0 = 1` the
/// filter is unchanged.
pub fn combined_update<const N: usize, const M: usize>(
    k: &mut Kalman<N>,
    h: &SMatrix<f64, M, N>,
    r: &SMatrix<f64, M, M>,
    z: &[SVector<f64, M>],
    beta: &[f64],
    beta0: f64,
) -> Result<(), KalmanError> {
    if z.iter().any(|v| v.iter().any(|c| !c.is_finite())) {
        return Err(KalmanError::NonFinite);
    }
    let s = h * k.p * h.transpose() + r;
    let s_inv = s.try_inverse().ok_or(KalmanError::Singular)?;
    let gain = k.p * h.transpose() * s_inv;
    let pred = h * k.x;
    let mut nu = SVector::<f64, M>::zeros();
    let mut spread = SMatrix::<f64, M, M>::zeros();
    for (zj, &b) in z.iter().zip(beta) {
        let v = zj - pred;
        nu += b * v;
        spread += b * v * v.transpose();
    }
    spread -= nu * nu.transpose();
    let p_c = k.p - gain * s * gain.transpose();
    k.x += gain * nu;
    k.p = beta0 * k.p + (1.0 - beta0) * p_c + gain * spread * gain.transpose();
    k.p = 0.5 * (k.p + k.p.transpose());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Matrix2x4, Matrix4, Vector2, Vector4};

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12 * (1.0 + a.abs().max(b.abs()))
    }

    /// Two tracks, two measurements, every pair gated: the seven feasible events by hand.
    #[test]
    fn two_tracks_two_measurements_match_the_hand_enumeration() {
        let w = vec![vec![0.7, 0.2], vec![0.3, 0.9]];
        let miss = vec![0.1, 0.05];
        let m = joint_marginals(&w, &miss, 100).expect("marginals");
        // events (track 0's, track 1's measurement; 0 = missed) and their weights
        let e00 = 0.1 * 0.05;
        let e10 = 0.7 * 0.05;
        let e20 = 0.2 * 0.05;
        let e01 = 0.1 * 0.3;
        let e02 = 0.1 * 0.9;
        let e12 = 0.7 * 0.9;
        let e21 = 0.2 * 0.3;
        let total = e00 + e10 + e20 + e01 + e02 + e12 + e21;
        assert_eq!(m.events, 7);
        assert!(close(m.beta[0][0], (e10 + e12) / total));
        assert!(close(m.beta[0][1], (e20 + e21) / total));
        assert!(close(m.beta0[0], (e00 + e01 + e02) / total));
        assert!(close(m.beta[1][0], (e01 + e21) / total));
        assert!(close(m.beta[1][1], (e02 + e12) / total));
        assert!(close(m.beta0[1], (e00 + e10 + e20) / total));
        assert_eq!(m.best, vec![Some(0), Some(1)]);
        for t in 0..2 {
            assert!(close(m.beta0[t] + m.beta[t].iter().sum::<f64>(), 1.0));
        }
    }

    #[test]
    fn ungated_pairs_are_not_events_and_the_limit_gives_up() {
        // track 1 sees only measurement 1: (missed, missed), (0, missed), (1, missed),
        // (missed, 1), (0, 1); (1, 1) is infeasible
        let w = vec![vec![0.5, 0.5], vec![0.0, 0.4]];
        let m = joint_marginals(&w, &[0.2, 0.2], 100).expect("marginals");
        assert_eq!(m.events, 5);
        assert_eq!(m.beta[1][0], 0.0);
        assert!(joint_marginals(&w, &[0.2, 0.2], 4).is_none());
        // λ = 0 and a track that must miss: every event weighs 0
        assert!(joint_marginals(&[vec![1.0], vec![1.0]], &[0.0, 0.0], 100).is_none());
    }

    #[test]
    fn one_track_is_the_pdaf_weight_formula() {
        let (pd, lambda, gate) = (0.8, 0.3, 9.0);
        let pg = gate_probability(2, gate).expect("2-D");
        let det_s = 0.04f64;
        let d2 = [0.5, 2.0, 7.0];
        let w = vec![d2.iter().map(|&d| pd * gaussian_2d(d, det_s)).collect()];
        let m = joint_marginals(&w, &[lambda * (1.0 - pd * pg)], 100).expect("marginals");
        let e: Vec<f64> = d2.iter().map(|d| (-0.5 * d).exp()).collect();
        let b = lambda * (2.0 * std::f64::consts::PI * det_s.sqrt()) * (1.0 - pd * pg) / pd;
        let sum = b + e.iter().sum::<f64>();
        for (j, ej) in e.iter().enumerate() {
            assert!(close(m.beta[0][j], ej / sum), "{m:?}");
        }
        assert!(close(m.beta0[0], b / sum));
    }

    #[test]
    fn clusters_are_the_connected_components() {
        // tracks 0,1 share measurement 1; track 2 alone with 3; track 3 gates nothing
        let g = [(0, 0), (0, 1), (1, 1), (2, 3)];
        let c = clusters(4, 5, |t, j| g.contains(&(t, j)));
        assert_eq!(c, vec![(vec![0, 1], vec![0, 1]), (vec![2], vec![3])]);
    }

    #[test]
    fn a_sure_single_measurement_is_the_kalman_update() {
        let p0 = Matrix4::from_diagonal(&Vector4::new(0.04, 0.09, 1.0, 2.0));
        let x0 = Vector4::new(1.0, 2.0, 0.3, -0.1);
        let h = Matrix2x4::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0);
        let r = Matrix2::identity() * 0.01;
        let z = Vector2::new(1.1, 1.8);
        let mut kf = Kalman::new(x0, p0);
        kf.update(&h, &r, &z).expect("kf");
        let mut jp = Kalman::new(x0, p0);
        combined_update(&mut jp, &h, &r, &[z], &[1.0], 0.0).expect("jpda");
        assert!((kf.x - jp.x).norm() < 1e-12 && (kf.p - jp.p).norm() < 1e-12);
        // β0 = 1: nothing changes
        let mut none = Kalman::new(x0, p0);
        combined_update(&mut none, &h, &r, &[z], &[0.0], 1.0).expect("jpda");
        assert_eq!((none.x, none.p), (x0, p0));
    }

    #[test]
    fn the_spread_term_is_the_weighted_innovation_covariance() {
        // scalar: P = 1, R = 1, S = 2, K = 1/2; innovations −1 and +1 with β = 0.5 each:
        // ν = 0, spread = 1, P⁺ = (1 − 1/2) + K² · 1 = 0.75
        let mut k = Kalman::new(SVector::<f64, 1>::new(0.0), SMatrix::<f64, 1, 1>::new(1.0));
        let one = SMatrix::<f64, 1, 1>::new(1.0);
        let z = [SVector::<f64, 1>::new(-1.0), SVector::<f64, 1>::new(1.0)];
        combined_update(&mut k, &one, &one, &z, &[0.5, 0.5], 0.0).expect("update");
        assert!(close(k.x[0], 0.0) && close(k.p[(0, 0)], 0.75), "{k:?}");
    }
}

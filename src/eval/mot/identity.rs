//! Identity metrics IDF1, IDP, IDR (Ristani et al., "Performance Measures and a Data Set for
//! Multi-Target, Multi-Camera Tracking", ECCV Workshops 2016, eq. 6–8), as py-motmetrics
//! `id_global_assignment`.
//!
//! A ground-truth trajectory and a hypothesis trajectory "agree" in a frame when both are
//! present and their pair is allowed by the match rule (whatever CLEAR MOT matched there).
//! One global one-to-one matching of trajectories maximises the total agreement (IDTP);
//! that is the matching that minimises IDFN + IDFP, because
//! IDFN = GT − IDTP and IDFP = predictions − IDTP.

use std::collections::HashMap;

use super::Frames;
use crate::assign::max_count_pairs;

/// IDF1 and its parts. Ratios are NaN where their denominator is zero.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct IdMetrics {
    /// Observations of matched trajectory pairs that agree.
    pub idtp: u64,
    /// Hypothesis observations not covered by IDTP.
    pub idfp: u64,
    /// Ground-truth observations not covered by IDTP.
    pub idfn: u64,
    /// 2 · IDTP / (GT + predictions).
    pub idf1: f64,
    /// IDTP / (IDTP + IDFP).
    pub idp: f64,
    /// IDTP / (IDTP + IDFN).
    pub idr: f64,
}

impl IdMetrics {
    fn from_counts(idtp: u64, idfp: u64, idfn: u64) -> Self {
        let tp = idtp as f64;
        IdMetrics {
            idtp,
            idfp,
            idfn,
            idf1: 2.0 * tp / (2.0 * tp + idfp as f64 + idfn as f64),
            idp: tp / (tp + idfp as f64),
            idr: tp / (tp + idfn as f64),
        }
    }

    /// Several sequences: counts summed, ratios from the sums (motmetrics `OVERALL`).
    pub fn merge(parts: &[&IdMetrics]) -> IdMetrics {
        IdMetrics::from_counts(
            parts.iter().map(|p| p.idtp).sum(),
            parts.iter().map(|p| p.idfp).sum(),
            parts.iter().map(|p| p.idfn).sum(),
        )
    }
}

pub(super) fn compute(frames: &dyn Frames, n_gt: usize, n_hyp: usize) -> IdMetrics {
    let mut agree: HashMap<(usize, usize), u64> = HashMap::new();
    let (mut num_gt, mut num_hyp) = (0u64, 0u64);
    frames.each(&mut |f| {
        let nh = f.hyp.len();
        num_gt += f.gt.len() as u64;
        num_hyp += nh as u64;
        for (i, &o) in f.gt.iter().enumerate() {
            for (j, &h) in f.hyp.iter().enumerate() {
                if f.dist[i * nh + j].is_finite() {
                    *agree.entry((o, h)).or_default() += 1;
                }
            }
        }
    });
    let mut edges: Vec<(usize, usize, u64)> = agree.iter().map(|(&(o, h), &n)| (o, h, n)).collect();
    // Sorted, so ties between equally good matchings break the same way on every run.
    edges.sort_unstable();
    let idtp: u64 = max_count_pairs(n_gt, n_hyp, &edges)
        .iter()
        .map(|p| agree.get(p).copied().unwrap_or(0))
        .sum();
    // `frames` hold every observation once, so the totals are GT and predictions.
    IdMetrics::from_counts(idtp, num_hyp - idtp, num_gt - idtp)
}

#[cfg(test)]
mod tests {
    use super::super::tests::bx;
    use super::super::{MatchRule, Sequence};

    #[test]
    fn one_switch_halfway_splits_the_identity() {
        // One person for 10 frames; the tracker calls them 7 for frames 0..6 and 8 after.
        let gt: Vec<_> = (0..10).map(|k| bx(k, 1, 0.0, 0.0, 10.0, 10.0)).collect();
        let hyp: Vec<_> = (0..10)
            .map(|k| bx(k, if k < 6 { 7 } else { 8 }, 0.0, 0.0, 10.0, 10.0))
            .collect();
        let id = Sequence::new(&gt, &hyp, MatchRule::Iou { min_iou: 0.5 })
            .expect("valid test input")
            .identity();
        assert_eq!((id.idtp, id.idfp, id.idfn), (6, 4, 4));
        assert!((id.idf1 - 0.6).abs() < 1e-12);
    }

    #[test]
    fn agreement_counts_pairs_that_clear_mot_did_not_match() {
        // Two overlapping people, one hypothesis covering both at IoU ≥ 0.5: CLEAR MOT can
        // match it once per frame, but the identity matching picks whichever agrees longer.
        let gt = [
            bx(0, 1, 0.0, 0.0, 10.0, 10.0),
            bx(0, 2, 1.0, 0.0, 10.0, 10.0),
            bx(1, 2, 1.0, 0.0, 10.0, 10.0),
        ];
        let hyp = [
            bx(0, 5, 0.5, 0.0, 10.0, 10.0),
            bx(1, 5, 0.5, 0.0, 10.0, 10.0),
        ];
        let id = Sequence::new(&gt, &hyp, MatchRule::Iou { min_iou: 0.5 })
            .expect("valid test input")
            .identity();
        assert_eq!((id.idtp, id.idfp, id.idfn), (2, 0, 1));
    }
}

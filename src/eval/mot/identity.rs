//! Identity metrics IDF1, IDP, IDR (Ristani et al., "Performance Measures and a Data Set for
//! Multi-Target, Multi-Camera Tracking", ECCV Workshops 2016, eq. 6–8), as py-motmetrics
//! `id_global_assignment`.
//!
//! A ground-truth trajectory and a hypothesis trajectory "agree" in a frame when both are
//! present and their pair is allowed by the match rule (whatever CLEAR MOT matched there).
//! One global one-to-one matching of trajectories maximises the total agreement (IDTP);
//! that is the matching that minimises IDFN + IDFP, because
//! IDFN = GT − IDTP and IDFP = predictions − IDTP.

use super::AllowedFrames;
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

pub(super) fn compute(frames: &dyn AllowedFrames, n_gt: usize, n_hyp: usize) -> IdMetrics {
    // Frames in which each (object, hypothesis) pair agrees, per object: an object meets
    // few hypotheses, and the one of its previous frame most often, so a short list searched
    // from its end beats a map.
    let mut agree: Vec<Vec<(u32, u64)>> = vec![Vec::new(); n_gt];
    let (mut num_gt, mut num_hyp) = (0u64, 0u64);
    frames.each_allowed(&mut |f| {
        num_gt += f.gt.len() as u64;
        num_hyp += f.hyp.len() as u64;
        for p in f.pairs {
            let (o, h) = (f.gt[p.i as usize] as usize, f.hyp[p.j as usize]);
            let list = &mut agree[o];
            match list.iter_mut().rev().find(|e| e.0 == h) {
                Some(e) => e.1 += 1,
                None => list.push((h, 1)),
            }
        }
    });
    // Sorted by (object, hypothesis), so ties between equally good matchings break the same
    // way on every run.
    let mut edges: Vec<(usize, usize, u64)> = Vec::new();
    for (o, list) in agree.iter_mut().enumerate() {
        list.sort_unstable();
        edges.extend(list.iter().map(|&(h, n)| (o, h as usize, n)));
    }
    let count = |(o, h): (usize, usize)| {
        agree[o]
            .binary_search_by_key(&(h as u32), |e| e.0)
            .map_or(0, |k| agree[o][k].1)
    };
    let idtp: u64 = max_count_pairs(n_gt, n_hyp, &edges)
        .into_iter()
        .map(count)
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

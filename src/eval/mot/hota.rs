//! HOTA (Luiten et al., "HOTA: A Higher Order Metric for Evaluating Multi-Object Tracking",
//! IJCV 129, 2021), computed as TrackEval's `metrics/hota.py` (`eval_sequence`,
//! `combine_sequences`).
//!
//! 1. Global alignment between every ground-truth id g and hypothesis id t:
//!    A(g, t) = Σ_frames S'(g, t) / (|g| + |t| − Σ_frames S'(g, t)), where S' is the frame's
//!    similarity normalised by its row and column sums (TrackEval's `sim_iou`).
//! 2. Per frame, the assignment maximising Σ A(g, t) · S(g, t) (Hungarian).
//! 3. For each α in 0.05, 0.10, …, 0.95, assigned pairs with S ≥ α are true positives (TP);
//!    the other objects are FN, the other hypotheses FP. DetA = TP / (TP + FN + FP).
//!    AssA = Σ_TP Ass-IoU(g, t) / TP with Ass-IoU = TPA / (TPA + FNA + FPA) over the pair's
//!    matches (eq. 9–10); LocA = mean S over TP; HOTA_α = √(DetA_α · AssA_α).
//! 4. Reported values are means over the 19 α. With no hypotheses (or no ground truth) at
//!    all, HOTA, DetA and AssA are 0 and LocA 1, as in TrackEval.
//!
//! Not included: HOTA(0), LocA(0), OWTA; class averaging; TrackEval's MOTChallenge
//! preprocessing (distractor classes, zero-marked ground truth).

use std::collections::HashMap;

use super::Frames;
use crate::assign::max_score_pairs;

/// Number of localisation thresholds α.
pub const HOTA_ALPHAS: usize = 19;

/// The k-th threshold, α_k = 0.05 + 0.05 k, bit for bit as `np.arange(0.05, 0.99, 0.05)`.
pub fn hota_alpha(k: usize) -> f64 {
    0.05 + k as f64 * 0.05
}

/// TrackEval compares `similarity >= alpha - eps` with numpy's float64 machine epsilon.
const ALPHA_EPS: f64 = f64::EPSILON;

/// HOTA and its sub-metrics at one threshold α.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct HotaAtAlpha {
    pub alpha: f64,
    pub num_tp: u64,
    pub num_fn: u64,
    pub num_fp: u64,
    pub hota: f64,
    pub det_a: f64,
    pub ass_a: f64,
    pub loc_a: f64,
    pub det_re: f64,
    pub det_pr: f64,
    pub ass_re: f64,
    pub ass_pr: f64,
}

/// HOTA and its sub-metrics, averaged over α, with the per-α values.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Hota {
    pub hota: f64,
    pub det_a: f64,
    pub ass_a: f64,
    pub loc_a: f64,
    pub det_re: f64,
    pub det_pr: f64,
    pub ass_re: f64,
    pub ass_pr: f64,
    pub per_alpha: Vec<HotaAtAlpha>,
}

impl HotaAtAlpha {
    fn zero(k: usize) -> Self {
        HotaAtAlpha {
            alpha: hota_alpha(k),
            num_tp: 0,
            num_fn: 0,
            num_fp: 0,
            hota: 0.0,
            det_a: 0.0,
            ass_a: 0.0,
            loc_a: 0.0,
            det_re: 0.0,
            det_pr: 0.0,
            ass_re: 0.0,
            ass_pr: 0.0,
        }
    }

    /// TrackEval `_compute_final_fields`.
    fn finish(mut self) -> Self {
        let tp = self.num_tp as f64;
        self.det_re = tp / (tp + self.num_fn as f64).max(1.0);
        self.det_pr = tp / (tp + self.num_fp as f64).max(1.0);
        self.det_a = tp / (tp + (self.num_fn + self.num_fp) as f64).max(1.0);
        self.hota = (self.det_a * self.ass_a).sqrt();
        self
    }
}

impl Hota {
    fn from_alphas(per_alpha: Vec<HotaAtAlpha>) -> Self {
        let mean = |f: fn(&HotaAtAlpha) -> f64| {
            per_alpha.iter().map(f).sum::<f64>() / per_alpha.len() as f64
        };
        Hota {
            hota: mean(|a| a.hota),
            det_a: mean(|a| a.det_a),
            ass_a: mean(|a| a.ass_a),
            loc_a: mean(|a| a.loc_a),
            det_re: mean(|a| a.det_re),
            det_pr: mean(|a| a.det_pr),
            ass_re: mean(|a| a.ass_re),
            ass_pr: mean(|a| a.ass_pr),
            per_alpha,
        }
    }

    /// Several sequences, as TrackEval `combine_sequences`: counts summed, AssA/AssRe/AssPr
    /// and LocA averaged with weights TP.
    pub fn merge(parts: &[&Hota]) -> Hota {
        let per_alpha = (0..HOTA_ALPHAS)
            .map(|k| {
                let at = |p: &&Hota| p.per_alpha.get(k).cloned().unwrap_or(HotaAtAlpha::zero(k));
                let all: Vec<HotaAtAlpha> = parts.iter().map(at).collect();
                let mut r = HotaAtAlpha::zero(k);
                r.num_tp = all.iter().map(|a| a.num_tp).sum();
                r.num_fn = all.iter().map(|a| a.num_fn).sum();
                r.num_fp = all.iter().map(|a| a.num_fp).sum();
                let tp = r.num_tp as f64;
                let weighted = |f: fn(&HotaAtAlpha) -> f64| {
                    all.iter().map(|a| f(a) * a.num_tp as f64).sum::<f64>()
                };
                r.ass_a = weighted(|a| a.ass_a) / tp.max(1.0);
                r.ass_re = weighted(|a| a.ass_re) / tp.max(1.0);
                r.ass_pr = weighted(|a| a.ass_pr) / tp.max(1.0);
                r.loc_a = weighted(|a| a.loc_a).max(1e-10) / tp.max(1e-10);
                r.finish()
            })
            .collect();
        Hota::from_alphas(per_alpha)
    }
}

pub(super) fn compute(frames: &dyn Frames, n_gt: usize, n_hyp: usize) -> Hota {
    let (mut num_gt, mut num_hyp) = (0usize, 0usize);
    frames.each(&mut |f| {
        num_gt += f.gt.len();
        num_hyp += f.hyp.len();
    });
    if num_gt == 0 || num_hyp == 0 {
        // TrackEval returns early: everything FN (or FP), LocA 1, the rest 0.
        let per_alpha = (0..HOTA_ALPHAS)
            .map(|k| HotaAtAlpha {
                num_fn: num_gt as u64,
                num_fp: num_hyp as u64,
                loc_a: 1.0,
                ..HotaAtAlpha::zero(k)
            })
            .collect();
        return Hota::from_alphas(per_alpha);
    }

    // 1. Global alignment A(g, t), for the pairs that ever overlap. Each such pair gets a
    //    dense index (`pair_of`); the second pass looks it up again for each overlapping
    //    entry of its frame (`entries`), so no per-entry index is kept for the whole sequence.
    const NO_PAIR: u32 = u32::MAX;
    let mut pair_of: HashMap<(usize, usize), u32> = HashMap::new();
    let mut pairs: Vec<(usize, usize)> = Vec::new();
    let mut potential: Vec<f64> = Vec::new();
    let mut gt_count = vec![0u64; n_gt];
    let mut hyp_count = vec![0u64; n_hyp];
    let mut row_sum = Vec::new();
    let mut col_sum = Vec::new();
    frames.each(&mut |f| {
        let nh = f.hyp.len();
        let rows = || f.sim.chunks(nh.max(1)).take(f.gt.len());
        row_sum.clear();
        row_sum.extend(rows().map(|r| r.iter().sum::<f64>()));
        col_sum.clear();
        col_sum.resize(nh, 0.0);
        for row in rows() {
            for (sum, s) in col_sum.iter_mut().zip(row) {
                *sum += s;
            }
        }
        for (i, &g) in f.gt.iter().enumerate() {
            for (j, &t) in f.hyp.iter().enumerate() {
                let s = f.sim[i * nh + j];
                if s <= 0.0 {
                    continue;
                }
                let p = *pair_of.entry((g, t)).or_insert_with(|| {
                    pairs.push((g, t));
                    potential.push(0.0);
                    (pairs.len() - 1) as u32
                });
                let denom = col_sum[j] + row_sum[i] - s;
                if denom > f64::EPSILON {
                    potential[p as usize] += s / denom;
                }
            }
        }
        for &g in &f.gt {
            gt_count[g] += 1;
        }
        for &t in &f.hyp {
            hyp_count[t] += 1;
        }
    });
    let alignment: Vec<f64> = pairs
        .iter()
        .zip(&potential)
        .map(|(&(g, t), &p)| p / (gt_count[g] as f64 + hyp_count[t] as f64 - p))
        .collect();

    // 2–3. Per-frame matching, scored at every α.
    let mut per_alpha: Vec<HotaAtAlpha> = (0..HOTA_ALPHAS).map(HotaAtAlpha::zero).collect();
    let mut loc_sum = [0.0f64; HOTA_ALPHAS];
    let mut matches: Vec<Vec<u64>> = vec![vec![0; pairs.len()]; HOTA_ALPHAS];
    let mut entries: Vec<u32> = Vec::new();
    frames.each(&mut |f| {
        let (ng, nh) = (f.gt.len(), f.hyp.len());
        if ng == 0 || nh == 0 {
            for a in per_alpha.iter_mut() {
                a.num_fp += nh as u64;
                a.num_fn += ng as u64;
            }
            return;
        }
        entries.clear();
        for (i, &g) in f.gt.iter().enumerate() {
            for (j, &t) in f.hyp.iter().enumerate() {
                entries.push(if f.sim[i * nh + j] > 0.0 {
                    pair_of.get(&(g, t)).copied().unwrap_or(NO_PAIR)
                } else {
                    NO_PAIR
                });
            }
        }
        let assigned = max_score_pairs(ng, nh, |i, j| match entries[i * nh + j] {
            NO_PAIR => 0.0,
            p => alignment[p as usize] * f.sim[i * nh + j],
        });
        for (k, a) in per_alpha.iter_mut().enumerate() {
            let alpha = hota_alpha(k);
            let mut n = 0u64;
            for &(i, j) in &assigned {
                let s = f.sim[i * nh + j];
                if s >= alpha - ALPHA_EPS {
                    n += 1;
                    loc_sum[k] += s;
                    // s ≥ α > 0, so the pair has an index.
                    if let Some(m) = matches[k].get_mut(entries[i * nh + j] as usize) {
                        *m += 1;
                    }
                }
            }
            a.num_tp += n;
            a.num_fn += ng as u64 - n;
            a.num_fp += nh as u64 - n;
        }
    });

    // Association scores per α, then the final fields.
    let per_alpha = per_alpha
        .into_iter()
        .enumerate()
        .map(|(k, mut a)| {
            let tp = (a.num_tp as f64).max(1.0);
            let (mut ass_a, mut ass_re, mut ass_pr) = (0.0, 0.0, 0.0);
            for (&(g, t), &m) in pairs.iter().zip(&matches[k]).filter(|(_, m)| **m > 0) {
                let (m, gc, tc) = (m as f64, gt_count[g] as f64, hyp_count[t] as f64);
                ass_a += m * m / (gc + tc - m).max(1.0);
                ass_re += m * m / gc.max(1.0);
                ass_pr += m * m / tc.max(1.0);
            }
            a.ass_a = ass_a / tp;
            a.ass_re = ass_re / tp;
            a.ass_pr = ass_pr / tp;
            a.loc_a = loc_sum[k].max(1e-10) / (a.num_tp as f64).max(1e-10);
            a.finish()
        })
        .collect();
    Hota::from_alphas(per_alpha)
}

#[cfg(test)]
mod tests {
    use super::super::tests::bx;
    use super::super::{MatchRule, Observation, Sequence};
    use super::*;

    fn hota(gt: &[Observation], hyp: &[Observation]) -> Hota {
        Sequence::new(gt, hyp, MatchRule::Iou { min_iou: 0.5 })
            .expect("valid test input")
            .hota()
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    #[test]
    fn alphas_are_numpys() {
        assert_eq!(hota_alpha(0), 0.05);
        assert_eq!(hota_alpha(2), 0.15000000000000002);
        assert_eq!(hota_alpha(18), 0.9500000000000001);
    }

    #[test]
    fn perfect_tracking_scores_one() {
        let gt: Vec<_> = (0..5)
            .flat_map(|k| {
                [
                    bx(k, 1, 0.0, 0.0, 10.0, 10.0),
                    bx(k, 2, 50.0, 0.0, 10.0, 10.0),
                ]
            })
            .collect();
        let h = hota(&gt, &gt);
        assert!(close(h.hota, 1.0) && close(h.det_a, 1.0) && close(h.ass_a, 1.0));
        assert!(close(h.loc_a, 1.0));
    }

    /// Hand-computed: one object for 4 frames, hypothesis with IoU 0.6 in all of them.
    /// For α ≤ 0.6 every frame is a TP (DetA = AssA = 1); above, all FN + FP (DetA = 0).
    /// That is 12 of the 19 α: α_11 = 0.6000000000000001 still counts, because TrackEval
    /// compares S ≥ α − ε.
    #[test]
    fn constant_overlap_hand_case() {
        let gt: Vec<_> = (0..4).map(|k| bx(k, 1, 0.0, 0.0, 10.0, 10.0)).collect();
        // IoU = 75 / 125 = 0.6 (box shifted by 2.5 px).
        let hyp: Vec<_> = (0..4).map(|k| bx(k, 9, 2.5, 0.0, 10.0, 10.0)).collect();
        let h = hota(&gt, &hyp);
        let at = &h.per_alpha;
        let iou = 75.0 / 125.0;
        let above = (0..HOTA_ALPHAS)
            .filter(|&k| iou >= hota_alpha(k) - f64::EPSILON)
            .count();
        assert_eq!(above, 12);
        assert_eq!((at[0].num_tp, at[0].num_fn, at[0].num_fp), (4, 0, 0));
        assert_eq!((at[18].num_tp, at[18].num_fn, at[18].num_fp), (0, 4, 4));
        assert!(close(h.det_a, 12.0 / 19.0));
        assert!(close(h.ass_a, 12.0 / 19.0));
        assert!(close(h.hota, 12.0 / 19.0));
        // LocA: 0.6 where matched; 1e-10 / 1e-10 = 1 where no TP (TrackEval's convention).
        assert!(close(h.loc_a, (12.0 * iou + 7.0) / 19.0));
    }

    /// Hand-computed: one object for 4 frames, tracked perfectly but with an id switch after
    /// frame 2 (ids 7, 7, 8, 8). DetA = 1 at every α. Each TP's Ass-IoU = 2 / (4 + 2 − 2)
    /// = 0.5, so AssA = 0.5 and HOTA = √0.5.
    #[test]
    fn id_switch_hand_case() {
        let gt: Vec<_> = (0..4).map(|k| bx(k, 1, 0.0, 0.0, 10.0, 10.0)).collect();
        let hyp: Vec<_> = (0..4)
            .map(|k| bx(k, if k < 2 { 7 } else { 8 }, 0.0, 0.0, 10.0, 10.0))
            .collect();
        let h = hota(&gt, &hyp);
        assert!(close(h.det_a, 1.0));
        assert!(close(h.ass_a, 0.5));
        assert!(close(h.hota, 0.5f64.sqrt()));
        assert!(close(h.per_alpha[3].ass_re, 0.5) && close(h.per_alpha[3].ass_pr, 1.0));
    }

    /// Hand-computed: 2 objects × 2 frames; the hypothesis finds only object 1, perfectly,
    /// and adds one FP in frame 0. TP = 2, FN = 2, FP = 1 → DetA = 2/5; AssA = 1.
    #[test]
    fn misses_and_false_positives_hand_case() {
        let gt = [
            bx(0, 1, 0.0, 0.0, 10.0, 10.0),
            bx(0, 2, 50.0, 0.0, 10.0, 10.0),
            bx(1, 1, 0.0, 0.0, 10.0, 10.0),
            bx(1, 2, 50.0, 0.0, 10.0, 10.0),
        ];
        let hyp = [
            bx(0, 5, 0.0, 0.0, 10.0, 10.0),
            bx(0, 6, 200.0, 0.0, 10.0, 10.0),
            bx(1, 5, 0.0, 0.0, 10.0, 10.0),
        ];
        let h = hota(&gt, &hyp);
        assert!(close(h.det_a, 0.4) && close(h.ass_a, 1.0));
        assert!(close(h.hota, 0.4f64.sqrt()));
        assert!(close(h.det_re, 0.5) && close(h.det_pr, 2.0 / 3.0));
    }

    #[test]
    fn merge_of_one_is_identity_and_weights_by_tp() {
        let gt: Vec<_> = (0..4).map(|k| bx(k, 1, 0.0, 0.0, 10.0, 10.0)).collect();
        let hyp: Vec<_> = (0..4)
            .map(|k| bx(k, if k < 2 { 7 } else { 8 }, 0.0, 0.0, 10.0, 10.0))
            .collect();
        let a = hota(&gt, &hyp);
        let m = Hota::merge(&[&a]);
        assert!(close(m.hota, a.hota) && close(m.loc_a, a.loc_a));
        let b = hota(&gt, &gt);
        let m = Hota::merge(&[&a, &b]);
        // Both have 4 TP at every α: AssA = (0.5 · 4 + 1 · 4) / 8.
        assert!(close(m.ass_a, 0.75) && close(m.det_a, 1.0));
    }
}

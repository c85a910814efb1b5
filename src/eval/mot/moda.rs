//! Multi-view detection scores on the ground plane: MODA and MODP (Kasturi et al., PAMI 2009),
//! as the WILDTRACK / POM literature reports them (Chavdarova et al. 2018; MVDet's
//! `evaluateDetection`): per frame, an optimal matching of detections to ground-truth points
//! within `max_m` (most pairs, then least total distance: [`assign::min_cost_max_pairs`]);
//! no identities, so no continuity rule and no switches.
//!
//! `MODA = 1 − (FN + FP) / GT` and `MODP = Σ_matches (1 − d / max_m) / TP` (1 = every match
//! exactly on its person, 0 = all at the threshold). Precision and recall are `TP / (TP + FP)`
//! and `TP / GT`.

use super::assign;

/// MODA / MODP with their counts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Moda {
    pub gt: usize,
    pub tp: usize,
    pub fp: usize,
    pub fn_: usize,
    pub moda: f64,
    pub modp: f64,
    pub precision: f64,
    pub recall: f64,
}

/// One frame: ground-truth points and detected points `(x, y)` (m).
pub type PointFrame = (Vec<[f64; 2]>, Vec<[f64; 2]>);

/// Score frames of `(ground truth, detections)` points at `max_m`.
pub fn moda_modp(frames: &[PointFrame], max_m: f64) -> Moda {
    let (mut gt, mut tp, mut fp, mut sum) = (0usize, 0usize, 0usize, 0.0);
    for (g, h) in frames {
        let dist = |i: usize, j: usize| {
            let d = (g[i][0] - h[j][0]).hypot(g[i][1] - h[j][1]);
            if d <= max_m { d } else { f64::INFINITY }
        };
        let pairs = assign::min_cost_max_pairs(g.len(), h.len(), dist);
        gt += g.len();
        tp += pairs.len();
        fp += h.len() - pairs.len();
        sum += pairs
            .iter()
            .map(|&(i, j)| 1.0 - dist(i, j) / max_m)
            .sum::<f64>();
    }
    let fn_ = gt - tp;
    let ratio = |a: f64, b: usize| if b == 0 { f64::NAN } else { a / b as f64 };
    Moda {
        gt,
        tp,
        fp,
        fn_,
        moda: 1.0 - ratio((fn_ + fp) as f64, gt),
        modp: ratio(sum, tp),
        precision: ratio(tp as f64, tp + fp),
        recall: ratio(tp as f64, gt),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hand_counted_frames() {
        // frame 1: two people, one detection 0.1 m off, one 0.3 m off;
        // frame 2: one person missed, one false detection 2 m away;
        // frame 3: a detection between two people 0.4 m from each goes to one of them
        let frames = vec![
            (vec![[0.0, 0.0], [5.0, 5.0]], vec![[0.1, 0.0], [5.0, 5.3]]),
            (vec![[1.0, 1.0]], vec![[3.0, 1.0]]),
            (vec![[0.0, 0.0], [0.8, 0.0]], vec![[0.4, 0.0]]),
        ];
        let m = moda_modp(&frames, 0.5);
        assert_eq!((m.gt, m.tp, m.fp, m.fn_), (5, 3, 1, 2));
        assert!((m.moda - (1.0 - 3.0 / 5.0)).abs() < 1e-12, "{m:?}");
        // (1 − 0.2) + (1 − 0.6) + (1 − 0.8) over 3
        assert!((m.modp - (0.8 + 0.4 + 0.2) / 3.0).abs() < 1e-12, "{m:?}");
        assert!((m.precision - 0.75).abs() < 1e-12 && (m.recall - 0.6).abs() < 1e-12);
    }

    #[test]
    fn most_pairs_beat_the_closest_pair() {
        // the closest pairing (a–x) would leave b unmatched; two pairs win
        let frames = vec![(vec![[0.0, 0.0], [0.9, 0.0]], vec![[0.45, 0.0], [-0.4, 0.0]])];
        let m = moda_modp(&frames, 0.5);
        assert_eq!((m.tp, m.fp, m.fn_), (2, 0, 0));
        assert!((m.moda - 1.0).abs() < 1e-12);
    }

    #[test]
    fn no_ground_truth_gives_nan_not_a_panic() {
        let m = moda_modp(&[(vec![], vec![[0.0, 0.0]])], 0.5);
        assert_eq!((m.gt, m.fp), (0, 1));
        assert!(m.moda.is_nan() && m.modp.is_nan());
    }
}

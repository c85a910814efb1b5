//! What the associations share: step 2's greedy selection of disjoint hypotheses, and step 3's
//! half where a hypothesis continues a candidate or starts one, and a candidate seen
//! in N_app frames becomes a person. The paper's search and the ground association differ only in
//! how they pair candidates with this frame's hypotheses.

use super::{Candidate, CylinderTracker, Hypothesis, Object3d, StepStats};

impl CylinderTracker {
    /// `h` continues candidate `prev` (already predicted to this frame) or starts one; a
    /// candidate seen in N_app frames becomes an object, otherwise it is returned to wait.
    pub(super) fn advance_candidate(
        &mut self,
        prev: Option<Candidate>,
        h: Hypothesis,
        stats: &mut StepStats,
    ) -> Option<Candidate> {
        let cand = match prev {
            Some(mut c) => {
                self.measure(&mut c.kf, &h);
                c.count += 1;
                c.support = h.support.clone();
                c.last = h;
                c
            }
            None => Candidate {
                support: h.support.clone(),
                count: 1,
                kf: self.new_filter(&h),
                last: h,
            },
        };
        if cand.count < self.params.n_app {
            return Some(cand);
        }
        let id = self.next_id;
        self.next_id += 1;
        stats.promoted += 1;
        self.objects.push(Object3d {
            id,
            kf: cand.kf,
            support: cand.support,
            misses: 0,
            age: 0,
            measured: Some(cand.last),
        });
        None
    }
}

/// Greedy selection by score: hypotheses `(score, boxes, hypothesis)` taken best first (ties by
/// their box lists), each kept only when none of its boxes is `used` yet, so every 2-D box
/// supports at most one person; the boxes of the kept ones are marked `used`.
pub(super) fn select_disjoint(
    mut valid: Vec<(f64, Vec<usize>, Hypothesis)>,
    used: &mut [bool],
) -> Vec<Hypothesis> {
    valid.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut selected = Vec::new();
    for (_, combo, h) in valid {
        if combo.iter().any(|&i| used[i]) {
            continue;
        }
        for &i in &combo {
            used[i] = true;
        }
        selected.push(h);
    }
    selected
}

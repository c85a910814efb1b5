//! The `scalable` association ([`super::Association::Scalable`]): the paper's search for new
//! objects, without enumerating every combination, for crowds seen by many cameras.
//!
//! The paper (§5) enumerates every combination of one-or-no 2-D object per camera — `Π(n_c+1)`
//! of them, 10¹⁰ for 7 cameras and 25 people — and keeps the best disjoint ones by `E_c`.
//! Here the same selection runs over a candidate set that grows with the number of coherent
//! pairs instead:
//!
//! 1. **Pairwise ray consistency (heads).** Every pair of free 2-D objects in different
//!    cameras is triangulated; a pair within `p_Th` (and the head-height and room checks of
//!    [`super::CylinderTracker`]) is a seed.
//! 2. **Growth.** A seed is extended one camera at a time: its head is projected into each
//!    camera it lacks, the free objects whose head lies within `p_Th` of that projection are
//!    tried, and the one giving the lowest `E_c` is added while the combination stays valid;
//!    it stops when no camera adds a valid object. Seeds that grow into the same combination
//!    are merged.
//! 3. **Selection** — greedy by `E_c`, each 2-D object in at most one person, exactly the rule
//!    the paper applies to its exhaustive list. Why greedy rather than min-cost flow or an
//!    ILP: a person is a *hyperedge* over up to seven cameras, so choosing disjoint
//!    hyperedges is set packing — not a flow problem (flows solve two-sided matching) and
//!    NP-hard in general; an ILP would need a solver dependency and a weight that trades
//!    cameras against pixels, which eq. 5 already fixes by ranking (`10^N_c`). Greedy by `E_c`
//!    keeps the paper's semantics, so on small scenes both variants choose the same people
//!    whenever the best combination of each person is among the grown ones (tested on the
//!    office rig).
//! 4. **Ground points.** The 2-D objects still free are persons seen by one camera only (or
//!    views the other cameras could not confirm): each becomes a single-camera hypothesis at
//!    the point where its box bottom's ray meets the ground (z = 0), with the height where its
//!    head ray passes over that point. Its selection error is `p_Th / 10` — the worst a
//!    one-camera combination could score by eq. 5 — so it always ranks after every valid
//!    multi-camera combination; it is dropped when its ground point lies within
//!    `ground_separation_m` of a person already selected or tracked (a view of someone
//!    already explained).
//!
//! Existing objects are updated as in the paper (best combination differing from their
//! support in at most one 2-D object), where a one-object support is now valid through its
//! ground point, so a person who walks out of all but one camera keeps being tracked.
//! `N_app` / `N_dis` are unchanged.

use std::collections::BTreeSet;

use nalgebra::Point3;

use super::candidate::select_disjoint;
use super::{CylinderTracker, Hypothesis, Prepared, StepStats, cylinder_radius};

impl CylinderTracker {
    /// A single-camera hypothesis from the ground point of 2-D object `i` (its box bottom on
    /// z = 0), `None` without a ground point or outside the room and head-height range.
    pub(super) fn ground_hypothesis(&self, prepared: &[Prepared], i: usize) -> Option<Hypothesis> {
        let p = &self.params;
        let o = &prepared[i];
        let g = o.ground?;
        if !self.in_room(g.x, g.y) {
            return None;
        }
        // height: where the head ray passes over the ground point
        let dxy = o.dir.x * o.dir.x + o.dir.y * o.dir.y;
        if dxy < 1e-12 {
            return None;
        }
        let s = ((g.x - o.origin.x) * o.dir.x + (g.y - o.origin.y) * o.dir.y) / dxy;
        let z = o.origin.z + s * o.dir.z;
        if s <= 0.0 || !(z >= p.head_height_m.0 && z <= p.head_height_m.1) {
            return None;
        }
        let head = Point3::new(g.x, g.y, z);
        let view = &self.views[o.camera];
        let seen = view.project_ideal(&head)?;
        let e_m = (seen - o.ideal).norm();
        Some(Hypothesis {
            support: vec![(o.camera, o.id)],
            head_m: head,
            e_m_px: e_m,
            e_c: p.p_th_px / 10.0,
            radius_m: cylinder_radius(&head, &[(view, o.head_px, o.width_px)]),
        })
    }

    /// Grow a valid combination camera by camera (see the module doc); returns the final
    /// combination and its hypothesis.
    fn grow(
        &self,
        prepared: &[Prepared],
        free_by_cam: &[Vec<usize>],
        mut combo: Vec<usize>,
        mut best: Hypothesis,
        stats: &mut StepStats,
    ) -> (Vec<usize>, Hypothesis) {
        let sel = self.params.selection;
        loop {
            let mut step: Option<(f64, Vec<usize>, Hypothesis)> = None;
            for (cam, objs) in free_by_cam.iter().enumerate() {
                if combo.iter().any(|&i| prepared[i].camera == cam) {
                    continue;
                }
                let Some(at) = self.views[cam].project_ideal(&best.head_m) else {
                    continue;
                };
                for &j in objs {
                    if (prepared[j].ideal - at).norm() > self.params.p_th_px {
                        continue;
                    }
                    let mut c = combo.clone();
                    c.push(j);
                    c.sort_by_key(|&i| prepared[i].camera);
                    stats.combinations += 1;
                    if let Some(h) = self.evaluate(prepared, &c) {
                        let s = h.score(sel);
                        if step.as_ref().is_none_or(|b| (s, &c) < (b.0, &b.1)) {
                            step = Some((s, c, h));
                        }
                    }
                }
            }
            match step {
                Some((s, c, h)) if s < best.score(sel) => {
                    combo = c;
                    best = h;
                }
                _ => return (combo, best),
            }
        }
    }

    /// Step 2 of [`CylinderTracker::step`] for the scalable association: seeds, growth,
    /// greedy selection by `E_c`, then ground points for what is left.
    pub(super) fn select_new_scalable(
        &self,
        prepared: &[Prepared],
        used: &mut [bool],
        stats: &mut StepStats,
    ) -> Vec<Hypothesis> {
        let sel = self.params.selection;
        let free: Vec<usize> = (0..prepared.len()).filter(|&i| !used[i]).collect();
        let mut free_by_cam: Vec<Vec<usize>> = vec![Vec::new(); self.views.len()];
        for &i in &free {
            free_by_cam[prepared[i].camera].push(i);
        }
        let mut seen: BTreeSet<Vec<usize>> = BTreeSet::new();
        let mut valid: Vec<(f64, Vec<usize>, Hypothesis)> = Vec::new();
        for (a, &i) in free.iter().enumerate() {
            for &j in &free[a + 1..] {
                if prepared[i].camera == prepared[j].camera {
                    continue;
                }
                stats.combinations += 1;
                let Some(h) = self.evaluate(prepared, &[i, j]) else {
                    continue;
                };
                let (c, h) = self.grow(prepared, &free_by_cam, vec![i, j], h, stats);
                if seen.insert(c.clone()) {
                    valid.push((h.score(sel), c, h));
                }
            }
        }
        let mut selected = select_disjoint(valid, used);
        // ground points of what is left, best (lowest head reprojection error) first
        let mut singles: Vec<(f64, usize, Hypothesis)> = free
            .iter()
            .filter(|&&i| !used[i])
            .filter_map(|&i| {
                self.ground_hypothesis(prepared, i)
                    .map(|h| (h.e_m_px, i, h))
            })
            .collect();
        singles.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let sep = self.params.ground_separation_m;
        let mut taken: Vec<(f64, f64)> = selected
            .iter()
            .map(|h| (h.head_m.x, h.head_m.y))
            .chain(self.objects.iter().map(|o| (o.kf.x[0], o.kf.x[1])))
            .collect();
        for (_, i, h) in singles {
            let (x, y) = (h.head_m.x, h.head_m.y);
            if taken.iter().any(|&(tx, ty)| (tx - x).hypot(ty - y) < sep) {
                continue;
            }
            used[i] = true;
            taken.push((x, y));
            selected.push(h);
        }
        selected
    }
}

#[cfg(test)]
mod tests;

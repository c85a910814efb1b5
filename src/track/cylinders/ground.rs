//! The `ground` association ([`super::Association::Ground`]): people found anew every frame on
//! the ground plane from their boxes' feet and heads, then tracked on the ground by
//! assignment — for crowds seen by many cameras at a low frame rate.
//!
//! **Why not the 2-D tracks.** The paper carries a 3-D object from frame to frame through its
//! supporting 2-D tracks (the next combination may differ in at most one 2-D object). At
//! WILDTRACK's 2 fps people move up to a metre between frames and the 2-D graph matching
//! (IoU between boxes 0.5 s apart) breaks most 2-D tracks, so objects lose their support and
//! are created again. Here the 2-D ids only label the support; nothing depends on them.
//!
//! **A person is a vertical segment** from `(x, y, 0)` to `(x, y, h)`. A box gives two image
//! points of it: the bottom centre (the feet, on the ground) and the head point (the top row
//! on the image of the vertical, [`super::box_head_px`]). A combination — at most one box per
//! camera — is fitted by Gauss–Newton on `(x, y, h)`, minimising the squared reprojection
//! errors of both points in ideal pixels. Its `E_m` is the mean over cameras of the mean of
//! the two errors (eq. 4 with the feet as a second cue), `E_c = E_m / 10^N_c` (eq. 5); a
//! combination is valid when `E_m ≤ p_Th`, `h` is a head height and the segment stands in the
//! room in front of every supporting camera. One camera already fixes `(x, y)` by its foot
//! ray on the ground and `h` by its head ray, so a person seen by one camera is placed by its
//! ground point; two cameras give eight equations for three unknowns, so a wrong pair is
//! rejected by the feet *and* by the box heights (range), unlike two head rays alone.
//!
//! **Per frame** (`detect_ground`): (1) every pair of boxes in different cameras whose
//! one-camera segments project near each other (within `PAIR_GATE · p_Th`, either way) is
//! fitted; a valid pair is a seed. (2) Seeds, best `E_c` first, grow camera by camera (a seed
//! whose two boxes already lie in one grown combination is skipped: it grows into it): the
//! boxes of a camera it lacks
//! whose feet lie within `2·p_Th` of its projected feet are tried and the one with the lowest
//! `E_c` is added while the combination stays valid (as in [`super::scalable`]). (3) The grown
//! combinations are selected greedily by `E_c`, each box in at most one person — set packing,
//! see [`super::scalable`] for why greedy rather than flow or an ILP. (4) Each box still free
//! is a one-camera person placed by its ground point, ranked after every multi-camera one
//! (`E_c = p_Th / 10`), unless a person already selected explains it: its projection in that
//! camera lies within `p_Th` of the box (a second box of someone, or someone hidden behind).
//!
//! **Over time** (`step_ground`): every object's Kalman filter (the tracker's, constant
//! velocity on the ground) is predicted; this frame's people are assigned to objects by the
//! Hungarian algorithm on ground distance ([`crate::assign::min_cost_max_pairs`]), pairs
//! farther than `gate_m` forbidden; an object without a person for `N_dis` consecutive frames
//! is discarded. The people left are assigned the same way to the candidates of the last
//! frame; a candidate continued for `N_app` consecutive frames becomes an object, one not
//! continued is dropped — the paper's `N_app` / `N_dis` with "the same person" meaning
//! "within the gate on the ground" instead of "differs in at most one 2-D object".

use nalgebra::{Matrix3, Point3, Vector2, Vector3};

use super::candidate::select_disjoint;
use super::{
    Association, Cylinder, CylinderTracker, Hypothesis, Object2d, Prepared, StepStats,
    cylinder_radius,
};
use crate::assign::min_cost_max_pairs;

/// Gauss–Newton iterations of one fit (it converges in 3–5 from the mean ground point).
const FIT_ITERATIONS: usize = 12;
/// The pair test's gate in units of `p_Th`: a box's one-camera segment carries its errors
/// along the foot ray (depth), which another camera sees foreshortened or not; 4 `p_Th` only
/// keeps pairs from being fitted at all when they are metres apart.
const PAIR_GATE: f64 = 4.0;
/// Step of the numerical Jacobian (m).
const JACOBIAN_STEP_M: f64 = 1e-6;

/// Steps 1–2's output (see [`CylinderTracker::ground_candidates`]).
pub(super) struct GroundCandidates {
    /// `(E_c, boxes, hypothesis)` of every valid multi-camera combination kept.
    pub multi: Vec<(f64, Vec<usize>, Hypothesis)>,
    /// Each box's one-camera fit (indexed like the prepared boxes).
    pub single: Vec<Option<Hypothesis>>,
    /// The boxes with a ground point and a foot point.
    pub usable: Vec<usize>,
}

/// A pixel difference with its coordinates multiplied by a box's residual weights (exact when
/// they are 1).
fn weighted(d: Vector2<f64>, w: [f64; 2]) -> Vector2<f64> {
    Vector2::new(d.x * w[0], d.y * w[1])
}

impl CylinderTracker {
    /// The foot and head residuals (ideal px) of segment `(x, y, h)` in the boxes of `combo`,
    /// `None` when a point does not project.
    fn residuals(
        &self,
        prepared: &[Prepared],
        combo: &[usize],
        s: &Vector3<f64>,
    ) -> Option<Vec<f64>> {
        let mut r = Vec::with_capacity(4 * combo.len());
        for &i in combo {
            let o = &prepared[i];
            let view = &self.views[o.camera];
            let foot = view.project_ideal(&Point3::new(s.x, s.y, 0.0))? - o.foot_ideal?;
            let head = view.project_ideal(&Point3::new(s.x, s.y, s.z))? - o.ideal;
            // the weights are 1 but under `Occupancy` (box uncertainty)
            r.extend([
                foot.x * o.w_foot[0],
                foot.y * o.w_foot[1],
                head.x * o.w_head[0],
                head.y * o.w_head[1],
            ]);
        }
        Some(r)
    }

    /// Fit one combination (see the module doc); `None` when invalid.
    fn fit_segment(&self, prepared: &[Prepared], combo: &[usize]) -> Option<Hypothesis> {
        let p = &self.params;
        let n = combo.len() as f64;
        let (mut gx, mut gy) = (0.0, 0.0);
        for &i in combo {
            let g = prepared[i].ground?;
            gx += g.x;
            gy += g.y;
        }
        let mid = 0.5 * (p.head_height_m.0 + p.head_height_m.1);
        let mut s = Vector3::new(gx / n, gy / n, mid);
        let mut r = self.residuals(prepared, combo, &s)?;
        for _ in 0..FIT_ITERATIONS {
            let mut jtj = Matrix3::zeros();
            let mut jtr = Vector3::zeros();
            let mut cols = Vec::with_capacity(3);
            for k in 0..3 {
                let mut t = s;
                t[k] += JACOBIAN_STEP_M;
                let rk = self.residuals(prepared, combo, &t)?;
                cols.push(
                    rk.iter()
                        .zip(&r)
                        .map(|(a, b)| (a - b) / JACOBIAN_STEP_M)
                        .collect::<Vec<f64>>(),
                );
            }
            for a in 0..3 {
                jtr[a] = cols[a].iter().zip(&r).map(|(j, e)| j * e).sum();
                for b in 0..3 {
                    jtj[(a, b)] = cols[a].iter().zip(&cols[b]).map(|(u, v)| u * v).sum();
                }
            }
            let step = jtj.lu().solve(&(-jtr))?;
            s += step;
            r = self.residuals(prepared, combo, &s)?;
            if step.norm() < 1e-9 {
                break;
            }
        }
        if !(s.iter().all(|v| v.is_finite())
            && s.z >= p.head_height_m.0
            && s.z <= p.head_height_m.1
            && self.in_room(s.x, s.y))
        {
            return None;
        }
        let head = Point3::new(s.x, s.y, s.z);
        let mut sum = 0.0;
        for (k, &i) in combo.iter().enumerate() {
            let view = &self.views[prepared[i].camera];
            // in front of every supporting camera, feet and head
            for z in [0.0, s.z] {
                if (view.world_from_camera.inverse() * Point3::new(s.x, s.y, z)).z <= 0.0 {
                    return None;
                }
            }
            let q = &r[4 * k..4 * k + 4];
            sum += 0.5 * (q[0].hypot(q[1]) + q[2].hypot(q[3]));
        }
        let e_m = sum / n;
        if e_m.is_nan() || e_m > p.p_th_px {
            return None;
        }
        let support3: Vec<_> = combo
            .iter()
            .map(|&i| {
                let o = &prepared[i];
                (&self.views[o.camera], o.head_px, o.width_px)
            })
            .collect();
        let e_c = if combo.len() == 1 {
            p.p_th_px / 10.0
        } else {
            e_m.max(super::E_M_FLOOR_PX) / 10f64.powi(combo.len() as i32)
        };
        Some(Hypothesis {
            support: combo
                .iter()
                .map(|&i| (prepared[i].camera, prepared[i].id))
                .collect(),
            head_m: head,
            e_m_px: e_m,
            e_c,
            radius_m: cylinder_radius(&head, &support3),
        })
    }

    /// Grow a valid combination camera by camera while `E_c` falls; with a `trail`, every
    /// combination passed through (the seed included) is pushed onto it.
    fn grow_segment(
        &self,
        prepared: &[Prepared],
        by_cam: &[Vec<usize>],
        (mut combo, mut best): (Vec<usize>, Hypothesis),
        stats: &mut StepStats,
        mut trail: Option<&mut Vec<(Vec<usize>, Hypothesis)>>,
    ) -> (Vec<usize>, Hypothesis) {
        let gate = 2.0 * self.params.p_th_px;
        loop {
            let mut step: Option<(f64, Vec<usize>, Hypothesis)> = None;
            let foot = Point3::new(best.head_m.x, best.head_m.y, 0.0);
            for (cam, objs) in by_cam.iter().enumerate() {
                if combo.iter().any(|&i| prepared[i].camera == cam) {
                    continue;
                }
                let Some(at) = self.views[cam].project_ideal(&foot) else {
                    continue;
                };
                for &j in objs {
                    let Some(f) = prepared[j].foot_ideal else {
                        continue;
                    };
                    if weighted(f - at, prepared[j].w_foot).norm() > gate {
                        continue;
                    }
                    let mut c = combo.clone();
                    c.push(j);
                    c.sort_by_key(|&i| prepared[i].camera);
                    stats.combinations += 1;
                    if let Some(h) = self.fit_segment(prepared, &c)
                        && step.as_ref().is_none_or(|b| (h.e_c, &c) < (b.0, &b.1))
                    {
                        step = Some((h.e_c, c, h));
                    }
                }
            }
            match step {
                Some((s, c, h)) if s < best.e_c => {
                    if let Some(t) = trail.as_deref_mut() {
                        t.push((
                            std::mem::replace(&mut combo, c),
                            std::mem::replace(&mut best, h),
                        ));
                    } else {
                        combo = c;
                        best = h;
                    }
                }
                _ => return (combo, best),
            }
        }
    }

    /// This frame's people from all its boxes (steps 1–4 of the module doc), sorted by `E_c`.
    pub(super) fn detect_ground(
        &self,
        prepared: &[Prepared],
        stats: &mut StepStats,
    ) -> Vec<Hypothesis> {
        let c = self.ground_candidates(prepared, stats);
        let mut used = vec![false; prepared.len()];
        let selected = select_disjoint(c.multi, &mut used);
        self.with_leftovers(prepared, &c.single, &c.usable, &used, selected)
    }

    /// Steps 1–2 of the module doc: every valid multi-camera combination a seed grew (with
    /// `occupancy`, every step of each growth too), and each box's one-camera fit.
    pub(super) fn ground_candidates(
        &self,
        prepared: &[Prepared],
        stats: &mut StepStats,
    ) -> GroundCandidates {
        let usable: Vec<usize> = (0..prepared.len())
            .filter(|&i| prepared[i].ground.is_some() && prepared[i].foot_ideal.is_some())
            .collect();
        let mut by_cam: Vec<Vec<usize>> = vec![Vec::new(); self.views.len()];
        for &i in &usable {
            by_cam[prepared[i].camera].push(i);
        }
        // one-camera fits: each box's own segment, for the pair test and step 4
        let single: Vec<Option<Hypothesis>> = (0..prepared.len())
            .map(|i| {
                (prepared[i].ground.is_some() && prepared[i].foot_ideal.is_some())
                    .then(|| self.fit_segment(prepared, &[i]))
                    .flatten()
            })
            .collect();
        let mut seeds: Vec<(f64, [usize; 2], Hypothesis)> = Vec::new();
        for (a, &i) in usable.iter().enumerate() {
            for &j in &usable[a + 1..] {
                if prepared[i].camera == prepared[j].camera
                    || !self.near_pair(prepared, &single, i, j)
                {
                    continue;
                }
                stats.combinations += 1;
                if let Some(h) = self.fit_segment(prepared, &[i, j]) {
                    seeds.push((h.e_c, [i, j], h));
                }
            }
        }
        seeds.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut seen = std::collections::BTreeSet::new();
        let mut in_grown: Vec<Vec<usize>> = vec![Vec::new(); prepared.len()];
        let mut valid: Vec<(f64, Vec<usize>, Hypothesis)> = Vec::new();
        // `occupancy` keeps every seed and growth step as a candidate too (its module doc)
        let keep_steps = self.params.association == Association::Occupancy;
        let mut grown = 0;
        for (_, [i, j], h) in seeds {
            // both boxes already in one grown combination: this seed grows into it too
            if in_grown[i].iter().any(|g| in_grown[j].contains(g)) {
                if keep_steps && seen.insert(vec![i, j]) {
                    valid.push((h.e_c, vec![i, j], h));
                }
                continue;
            }
            let mut trail = Vec::new();
            let (c, h) = self.grow_segment(
                prepared,
                &by_cam,
                (vec![i, j], h),
                stats,
                keep_steps.then_some(&mut trail),
            );
            for (tc, th) in trail {
                if seen.insert(tc.clone()) {
                    valid.push((th.e_c, tc, th));
                }
            }
            if seen.insert(c.clone()) {
                for &k in &c {
                    in_grown[k].push(grown);
                }
                grown += 1;
                valid.push((h.e_c, c, h));
            }
        }
        GroundCandidates {
            multi: valid,
            single,
            usable,
        }
    }

    /// Step 4 of the module doc: `selected` (the multi-camera people), then each usable box
    /// not `used` as a one-camera person unless one of `selected` explains it.
    pub(super) fn with_leftovers(
        &self,
        prepared: &[Prepared],
        single: &[Option<Hypothesis>],
        usable: &[usize],
        used: &[bool],
        mut selected: Vec<Hypothesis>,
    ) -> Vec<Hypothesis> {
        let multi = selected.len();
        for &i in usable.iter().filter(|&&i| !used[i]) {
            if self.explained(&prepared[i], &selected[..multi]) {
                continue;
            }
            if let Some(h) = single[i].clone() {
                selected.push(h);
            }
        }
        selected
    }

    /// The pair test before a fit: the one-camera segment of either box projects into the
    /// other's camera within [`PAIR_GATE`]` · p_Th` of that box (feet and head).
    fn near_pair(
        &self,
        prepared: &[Prepared],
        single: &[Option<Hypothesis>],
        i: usize,
        j: usize,
    ) -> bool {
        let ok = |a: usize, b: usize| {
            single[a].as_ref().is_some_and(|h| {
                self.explained_within(&prepared[b], std::slice::from_ref(h), PAIR_GATE)
            })
        };
        ok(i, j) || ok(j, i)
    }

    /// Whether a person of `people` projects within `p_Th` of box `o` (feet and head).
    fn explained(&self, o: &Prepared, people: &[Hypothesis]) -> bool {
        self.explained_within(o, people, 1.0)
    }

    /// [`Self::explained`] within `factor · p_Th`.
    fn explained_within(&self, o: &Prepared, people: &[Hypothesis], factor: f64) -> bool {
        let view = &self.views[o.camera];
        let Some(f) = o.foot_ideal else { return false };
        people.iter().any(|h| {
            let foot = view.project_ideal(&Point3::new(h.head_m.x, h.head_m.y, 0.0));
            let head = view.project_ideal(&h.head_m);
            match (foot, head) {
                (Some(a), Some(b)) => {
                    0.5 * (weighted(a - f, o.w_foot).norm()
                        + weighted(b - o.ideal, o.w_head).norm())
                        <= factor * self.params.p_th_px
                }
                _ => false,
            }
        })
    }

    /// [`CylinderTracker::step`] for the ground association (see the module doc).
    pub(super) fn step_ground(&mut self, objects: &[Object2d]) -> (Vec<Cylinder>, StepStats) {
        let mut stats = StepStats::default();
        let prepared = self.prepare(objects);
        let people = self.detect_ground(&prepared, &mut stats);
        let (f, q) = self.transition();
        for obj in self.objects.iter_mut() {
            obj.kf.predict(&f, &q);
            obj.age += 1;
        }
        let gate = self.params.gate_m;
        let dist = |x: f64, y: f64, h: &Hypothesis| {
            let d = (h.head_m.x - x).hypot(h.head_m.y - y);
            if d <= gate { d } else { f64::INFINITY }
        };
        let pairs = min_cost_max_pairs(self.objects.len(), people.len(), |k, j| {
            dist(self.objects[k].kf.x[0], self.objects[k].kf.x[1], &people[j])
        });
        let mut taken = vec![false; people.len()];
        let mut update: Vec<Option<usize>> = vec![None; self.objects.len()];
        for &(k, j) in &pairs {
            update[k] = Some(j);
            taken[j] = true;
        }
        let objects = std::mem::take(&mut self.objects);
        for (mut obj, upd) in objects.into_iter().zip(update) {
            match upd {
                Some(j) => {
                    let h = &people[j];
                    self.measure(&mut obj.kf, h);
                    obj.support = h.support.clone();
                    obj.misses = 0;
                    obj.measured = Some(h.clone());
                }
                None => {
                    obj.misses += 1;
                    obj.measured = None;
                }
            }
            if obj.misses >= self.params.n_dis || !self.in_room(obj.kf.x[0], obj.kf.x[1]) {
                stats.discarded += 1;
            } else {
                self.objects.push(obj);
            }
        }
        let left: Vec<Hypothesis> = people
            .into_iter()
            .zip(taken)
            .filter(|(_, t)| !t)
            .map(|(h, _)| h)
            .collect();
        self.continue_ground_candidates(left, (&f, &q), &mut stats);
        (self.cylinders(), stats)
    }

    /// Candidates continued by assignment on the ground within the gate; promoted after
    /// `N_app` consecutive frames, dropped when not continued.
    fn continue_ground_candidates(
        &mut self,
        people: Vec<Hypothesis>,
        (f, q): (&nalgebra::Matrix6<f64>, &nalgebra::Matrix6<f64>),
        stats: &mut StepStats,
    ) {
        let mut old = std::mem::take(&mut self.candidates);
        for c in old.iter_mut() {
            c.kf.predict(f, q);
        }
        let gate = self.params.gate_m;
        let pairs = min_cost_max_pairs(old.len(), people.len(), |k, j| {
            let d =
                (people[j].head_m.x - old[k].kf.x[0]).hypot(people[j].head_m.y - old[k].kf.x[1]);
            if d <= gate { d } else { f64::INFINITY }
        });
        let mut of_person: Vec<Option<usize>> = vec![None; people.len()];
        for &(k, j) in &pairs {
            of_person[j] = Some(k);
        }
        for (h, k) in people.into_iter().zip(of_person) {
            let prev = k.map(|k| old[k].clone());
            if let Some(c) = self.advance_candidate(prev, h, stats) {
                self.candidates.push(c);
            }
        }
    }
}

#[cfg(test)]
pub(super) mod tests;

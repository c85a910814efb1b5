//! leg_tracker's joint leg tracker (Leigh et al., "Person Tracking and Following with 2D Laser
//! Scanners", ICRA 2015; `scripts/joint_leg_tracker.py` at commit c7ff1e4, the one
//! `leg_tracker_benchmarks` pins; read, not copied): every cluster of the scan is tracked on
//! its own, two tracked clusters that move together through free space become a person, and a
//! person is then tracked from its two legs. Per scan ([`JointTracker::step`]), in the fixed
//! frame:
//!
//! 1. **Clusters** ([`Cluster`]) arrive with the detector's confidence that each is a leg
//!    (leg_tracker runs with `detection_threshold = −1`: every cluster within 10 m, whatever
//!    its confidence) and the occupancy of the local grid around it
//!    ([`crate::laser::occupancy::LocalGrid::occupancy_around`]); a cluster is *in free space*
//!    when that is below `free_threshold`.
//! 2. **Prediction**: every track (object or person) is a constant-velocity Kalman filter on
//!    `[x, y, vx, vy]` with leg_tracker's hand-set noise: `Q = σ² I₄` with `σ = 0.5 · Δt`
//!    (leg_tracker's 0.0667 / 0.05 / 0.0333 at 7.5 / 10 / 15 Hz), `R = 0.1² I₂`, initial
//!    covariance `0.5 I₄`.
//! 3. **Association** (global nearest neighbour, [`crate::assign::min_cost_max_pairs`], which
//!    is scipy's `linear_sum_assignment` with forbidden pairs made expensive): the cost of a
//!    cluster and a track is `d = ‖z − x‖ / √(P₀₀ + (σ_obs + 0.4)²)`, allowed when
//!    `d < gate` (`norm.ppf(0.95)` = 1.645 for leg_tracker's `confidence_percentile` 0.9);
//!    every person is offered twice (one slot per leg), and people take only clusters in free
//!    space ("ignore possible matchings between people and detections not in freespace").
//! 4. **Update**: a person matched to two clusters is updated with their midpoint, to one with
//!    the midpoint of that cluster and its own prediction; a track's confidence follows
//!    `c ← 0.95 c + 0.05 c_z` and its free-space value `f ← 0.8 f + 0.2 f_z`. Each step of the
//!    filtered position longer than `min_step_m` adds to the distance the track travelled
//!    (coasting steps included, as leg_tracker's).
//! 5. **Deletion**: a person whose confidence fell below `min_confidence`; any track whose
//!    `P₀₀ + (σ_obs + 0.4)²` exceeds `max_sd_m²`. Unmatched clusters start object tracks.
//! 6. **Leg pairs**: two tracks (not both people) within `max_pair_m` of each other, both of
//!    confidence ≥ `min_confidence`, form a candidate pair, which remembers how far each had
//!    travelled when it formed; it dissolves as soon as one of those conditions fails. A pair
//!    whose two tracks were both matched on this scan **becomes a person** when each has
//!    travelled more than `min_travel_m` since the pair formed and at least one of them is in
//!    free space (its `f` below `free_threshold`); a pair of a person and an object track
//!    deletes the object track instead (the person takes that leg on the next scan).
//!
//! **Quick confirmation** (ours, [`QuickConfirm`]; off in [`JointParams::leg_tracker`]): a pair
//! also becomes a person, before its legs travelled `min_travel_m`, when its midpoint moved
//! at least `min_displacement_m` (straight-line, since the pair formed), the sum of the two
//! tracks' running confidences `Σ min(c₁, c₂)` over the scans both were matched reaches
//! `min_confidence_sum`,
//! and **both** tracks are in free space. leg_tracker's 0.5 m of travel per leg costs a person
//! seen for only a second or two most of its scans; a static leg-like object does not move
//! its midpoint, and a path length (leg_tracker's measure) counts a static object's jitter
//! where a displacement does not.
//!
//! **Lone-cluster confirmation** (ours, [`LoneConfirm`]; off by default): an object track
//! matched on this scan, in no candidate pair and farther than `max_pair_m` from every
//! person, with running confidence ≥ `min_confidence`, in free space, that travelled
//! `min_travel_m` since it started (and moved `min_displacement_m` from where it started)
//! becomes a person in place — for people whose legs show as one cluster (on
//! `general_tracking_moving_1` the largest reason people go unreported). On the synthetic
//! quick sessions it added more false positives than it removed misses (pooled MOTA 0.752 →
//! 0.704, `examples/laser_confirm_probe`), so it stays off.
//!
//! Reported people ([`JointTracker::confirmed`]): every person track, or only those matched on
//! this scan when `publish_occluded` is false (leg_tracker's option). Ids are 1, 2, … in
//! order of creation, shared by object and person tracks, so the same input gives the same
//! ids. No I/O; non-finite clusters are ignored.

use std::collections::BTreeMap;

use nalgebra::{Matrix2, Matrix2x4, Matrix4, Point2, Vector2, Vector4};

use crate::assign::min_cost_max_pairs;
use crate::track::kalman::Kalman;

/// One cluster of a scan as the tracker sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cluster {
    /// Fixed frame (m).
    pub position: Point2<f64>,
    /// The detector's confidence that it is a leg, in `[0, 1]`.
    pub confidence: f64,
    /// Mean occupancy probability of the grid around it (0 = free).
    pub occupancy: f64,
}

/// Our quick confirmation (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuickConfirm {
    /// Straight-line displacement (m) of the pair's midpoint since it formed.
    pub min_displacement_m: f64,
    /// Least `Σ min(c₁, c₂)` over the scans both legs were matched.
    pub min_confidence_sum: f64,
}

/// Our lone-cluster confirmation (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoneConfirm {
    /// Least running confidence of the lone track.
    pub min_confidence: f64,
    /// Least straight-line displacement (m) of the track from where it started; 0: none.
    pub min_displacement_m: f64,
}

/// Parameters (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointParams {
    /// Most distance (m) between the two legs of a pair (`max_leg_pairing_dist`).
    pub max_pair_m: f64,
    /// Least confidence of a pair's legs and of a person (`confidence_threshold_to_maintain_track`).
    pub min_confidence: f64,
    /// Distance (m) each leg must travel, once paired, to make a person
    /// (`dist_travelled_together_to_initiate_leg_pair`).
    pub min_travel_m: f64,
    /// Steps of the filtered position shorter than this (m) are not counted as travel.
    pub min_step_m: f64,
    /// Below this occupancy a cluster or track is in free space (`in_free_space_threshold`).
    pub free_threshold: f64,
    /// Gate on the association distance `d` (module doc).
    pub gate: f64,
    /// A track is deleted when `√(P₀₀ + (σ_obs + 0.4)²)` exceeds this (m; `max_std`).
    pub max_sd_m: f64,
    /// σ_obs: observation standard deviation of the Kalman update (m).
    pub obs_sd_m: f64,
    /// Added to σ_obs in the association distance (m).
    pub association_extra_sd_m: f64,
    /// σ of the process noise per second of Δt (`σ = this · Δt`, m and m/s).
    pub process_sd_per_s: f64,
    /// Initial state variance (each of x, y, vx, vy).
    pub initial_variance: f64,
    /// Weight of a new observation in a track's confidence.
    pub confidence_rate: f64,
    /// Weight of a new observation in a track's free-space value.
    pub free_rate: f64,
    /// Report people that were not matched on the current scan.
    pub publish_occluded: bool,
    /// Our quick confirmation; `None`: leg_tracker's rule alone.
    pub quick: Option<QuickConfirm>,
    /// Our lone-cluster confirmation; `None`: people come only from leg pairs.
    pub lone: Option<LoneConfirm>,
}

impl JointParams {
    /// leg_tracker's values (`joint_leg_tracker.py` defaults, which the benchmark launch files
    /// keep): pairs within 0.8 m, confidence 0.1, 0.5 m of travel, steps > 0.01 m, free below
    /// 0.06, gate `norm.ppf(0.95)`, `max_std` 0.9 m, σ_obs 0.1 m (+ 0.4 m when associating),
    /// `σ = 0.5 Δt`, initial covariance 0.5, confidence and free-space weights 0.05 and 0.2,
    /// occluded people reported (the node's default); no quick confirmation.
    pub fn leg_tracker() -> Self {
        JointParams {
            max_pair_m: 0.8,
            min_confidence: 0.1,
            min_travel_m: 0.5,
            min_step_m: 0.01,
            free_threshold: 0.06,
            gate: 1.644_853_626_951_472_2,
            max_sd_m: 0.9,
            obs_sd_m: 0.1,
            association_extra_sd_m: 0.4,
            process_sd_per_s: 0.5,
            initial_variance: 0.5,
            confidence_rate: 0.05,
            free_rate: 0.2,
            publish_occluded: true,
            quick: None,
            lone: None,
        }
    }
}

/// The quick confirmation's values: see [`JointParams::default`].
pub const QUICK: QuickConfirm = QuickConfirm {
    min_displacement_m: 0.25,
    min_confidence_sum: 3.0,
};

/// The lone-cluster confirmation's value: a running confidence of at least 0.5 (the detector
/// calls the cluster a leg more often than not), a priori; travel and free space are
/// leg_tracker's (module doc).
pub const LONE: LoneConfirm = LoneConfirm {
    min_confidence: 0.5,
    min_displacement_m: 0.0,
};

impl Default for JointParams {
    /// leg_tracker's values ([`JointParams::leg_tracker`]) with our quick confirmation
    /// [`QUICK`]: a midpoint displacement of 0.25 m (half leg_tracker's travel; static objects
    /// hold their midpoint to a few cm) and a confidence sum of 3 (three scans of a confident
    /// pair), a priori; kept after the synthetic comparison in `docs/laser_people.md`.
    fn default() -> Self {
        JointParams {
            quick: Some(QUICK),
            ..JointParams::leg_tracker()
        }
    }
}

/// A tracked object (a cluster, usually a leg) or person.
#[derive(Debug, Clone, PartialEq)]
pub struct Track {
    pub id: u64,
    /// A person (made from a leg pair), else an object.
    pub person: bool,
    pub filter: Kalman<4>,
    /// Running confidence (module doc).
    pub confidence: f64,
    /// Running free-space value (occupancy; low = free).
    pub free: f64,
    /// Distance travelled (m).
    pub travelled_m: f64,
    /// Where the track started (fixed frame, m).
    pub origin: Point2<f64>,
    /// Matched on the last scan.
    pub seen: bool,
}

impl Track {
    pub fn position(&self) -> Point2<f64> {
        Point2::new(self.filter.x[0], self.filter.x[1])
    }

    pub fn velocity(&self) -> Vector2<f64> {
        Vector2::new(self.filter.x[2], self.filter.x[3])
    }
}

/// A candidate leg pair: what each track had travelled when it formed, its midpoint then, and
/// the confidence summed since.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Pair {
    travelled: (f64, f64),
    midpoint: Point2<f64>,
    confidence_sum: f64,
}

/// The tracker's state (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct JointTracker {
    pub params: JointParams,
    tracks: Vec<Track>,
    /// Keyed by (newer id, older id).
    pairs: BTreeMap<(u64, u64), Pair>,
    next_id: u64,
    last_time: Option<f64>,
}

fn h() -> Matrix2x4<f64> {
    Matrix2x4::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0)
}

fn finite(c: &Cluster) -> bool {
    c.position.x.is_finite() && c.position.y.is_finite()
}

/// Which track (index into the tracker's list) each cluster was matched to on a scan.
pub type Matches = Vec<Option<usize>>;

impl JointTracker {
    pub fn new(params: JointParams) -> Self {
        JointTracker {
            params,
            tracks: Vec::new(),
            pairs: BTreeMap::new(),
            next_id: 1,
            last_time: None,
        }
    }

    /// Every live track, objects and people, in order of creation.
    pub fn tracks(&self) -> &[Track] {
        &self.tracks
    }

    /// The reported people (module doc).
    pub fn confirmed(&self) -> impl Iterator<Item = &Track> {
        let all = self.params.publish_occluded;
        self.tracks
            .iter()
            .filter(move |t| t.person && (all || t.seen))
    }

    fn association_variance(&self) -> f64 {
        (self.params.obs_sd_m + self.params.association_extra_sd_m).powi(2)
    }

    /// One scan at `time_s` (s, any origin). Returns, per cluster, whether it was matched to
    /// a person on this scan (leg_tracker's "leg clusters": the grid maps every other
    /// cluster as an obstacle).
    pub fn step(&mut self, time_s: f64, clusters: &[Cluster]) -> Vec<bool> {
        let p = self.params;
        let dt = match self.last_time {
            Some(t0) if (time_s - t0).is_finite() && time_s > t0 => time_s - t0,
            _ => 0.0,
        };
        if time_s.is_finite() {
            self.last_time = Some(self.last_time.map_or(time_s, |t0| t0.max(time_s)));
        }
        let before: Vec<Point2<f64>> = self.tracks.iter().map(Track::position).collect();
        let mut f = Matrix4::identity();
        f[(0, 2)] = dt;
        f[(1, 3)] = dt;
        let q = Matrix4::identity() * (p.process_sd_per_s * dt).powi(2);
        for t in &mut self.tracks {
            t.filter.predict(&f, &q);
        }
        // slots: every track, then every person a second time
        let slots: Vec<usize> = (0..self.tracks.len())
            .chain((0..self.tracks.len()).filter(|&i| self.tracks[i].person))
            .collect();
        let var_obs = self.association_variance();
        let pairs = min_cost_max_pairs(clusters.len(), slots.len(), |ci, si| {
            let (c, t) = (&clusters[ci], &self.tracks[slots[si]]);
            if !finite(c) || (t.person && c.occupancy >= p.free_threshold) {
                return f64::NAN;
            }
            let d = (c.position - t.position()).norm() / (t.filter.p[(0, 0)] + var_obs).sqrt();
            if d < p.gate { d } else { f64::NAN }
        });
        let mut by_track: Vec<Vec<usize>> = vec![Vec::new(); self.tracks.len()];
        let mut matched: Matches = vec![None; clusters.len()];
        for &(ci, si) in &pairs {
            by_track[slots[si]].push(ci);
            matched[ci] = Some(slots[si]);
        }
        let leg_clusters: Vec<bool> = matched
            .iter()
            .map(|m| m.is_some_and(|ti| self.tracks[ti].person))
            .collect();
        self.update(clusters, &by_track, &before);
        self.delete_and_start(clusters, &matched);
        let seen: BTreeMap<u64, f64> = self
            .tracks
            .iter()
            .filter(|t| t.seen)
            .map(|t| (t.id, t.confidence))
            .collect();
        self.pair_and_confirm(&seen);
        leg_clusters
    }

    /// Step 4 of the module doc.
    fn update(&mut self, clusters: &[Cluster], by_track: &[Vec<usize>], before: &[Point2<f64>]) {
        let p = self.params;
        let r = Matrix2::identity() * p.obs_sd_m.powi(2);
        for (ti, t) in self.tracks.iter_mut().enumerate() {
            let obs: Option<(Point2<f64>, f64, f64)> = match by_track[ti].as_slice() {
                [] => None,
                [a] if t.person => {
                    let c = &clusters[*a];
                    Some((
                        nalgebra::center(&c.position, &t.position()),
                        c.confidence,
                        c.occupancy,
                    ))
                }
                [a] => {
                    let c = &clusters[*a];
                    Some((c.position, c.confidence, c.occupancy))
                }
                [a, b, ..] => {
                    let (c, d) = (&clusters[*a], &clusters[*b]);
                    Some((
                        nalgebra::center(&c.position, &d.position),
                        (c.confidence + d.confidence) / 2.0,
                        (c.occupancy + d.occupancy) / 2.0,
                    ))
                }
            };
            t.seen = false;
            if let Some((z, conf, occ)) = obs
                && t.filter.update(&h(), &r, &z.coords).is_ok()
            {
                t.free = (1.0 - p.free_rate) * t.free + p.free_rate * occ;
                t.confidence = (1.0 - p.confidence_rate) * t.confidence + p.confidence_rate * conf;
                t.seen = true;
            }
            let step = (t.position() - before[ti]).norm();
            if step > p.min_step_m && step.is_finite() {
                t.travelled_m += step;
            }
        }
    }

    /// Step 5 of the module doc.
    fn delete_and_start(&mut self, clusters: &[Cluster], matched: &Matches) {
        let p = self.params;
        let var_obs = self.association_variance();
        let max_var = p.max_sd_m.powi(2);
        self.tracks.retain(|t| {
            !(t.person && t.confidence < p.min_confidence)
                && t.filter.p[(0, 0)] + var_obs <= max_var
        });
        for (ci, c) in clusters.iter().enumerate() {
            if matched[ci].is_none() && finite(c) {
                self.start(c, false);
            }
        }
    }

    fn start(&mut self, c: &Cluster, person: bool) {
        let at = c.position;
        let cov = Matrix4::identity() * self.params.initial_variance;
        self.tracks.push(Track {
            id: self.next_id,
            person,
            filter: Kalman::new(Vector4::new(at.x, at.y, 0.0, 0.0), cov),
            confidence: c.confidence,
            free: c.occupancy,
            travelled_m: 0.0,
            origin: at,
            seen: true,
        });
        self.next_id += 1;
    }

    /// Step 6 and the quick confirmation (module doc). `seen_with` holds the running
    /// confidence of every track matched on this scan (new tracks count as matched, as in
    /// leg_tracker).
    fn pair_and_confirm(&mut self, seen_with: &BTreeMap<u64, f64>) {
        let p = self.params;
        let index: BTreeMap<u64, usize> = self
            .tracks
            .iter()
            .enumerate()
            .map(|(i, t)| (t.id, i))
            .collect();
        let ok = |t: &Track| t.confidence >= p.min_confidence;
        // form the new pairs
        for (i, a) in self.tracks.iter().enumerate() {
            for b in &self.tracks[..i] {
                let key = (a.id.max(b.id), a.id.min(b.id));
                if (a.person && b.person)
                    || !(ok(a) && ok(b))
                    || (a.position() - b.position()).norm() > p.max_pair_m
                    || self.pairs.contains_key(&key)
                {
                    continue;
                }
                let (n, o) = if a.id > b.id { (a, b) } else { (b, a) };
                self.pairs.insert(
                    key,
                    Pair {
                        travelled: (n.travelled_m, o.travelled_m),
                        midpoint: nalgebra::center(&a.position(), &b.position()),
                        confidence_sum: 0.0,
                    },
                );
            }
        }
        let mut gone: Vec<u64> = Vec::new();
        let mut born: Vec<Cluster> = Vec::new();
        let keys: Vec<(u64, u64)> = self.pairs.keys().copied().collect();
        for key in keys {
            let (Some(&i), Some(&j)) = (index.get(&key.0), index.get(&key.1)) else {
                self.pairs.remove(&key);
                continue;
            };
            let (a, b) = (&self.tracks[i], &self.tracks[j]);
            if gone.contains(&a.id)
                || gone.contains(&b.id)
                || (a.person && b.person)
                || !(ok(a) && ok(b))
                || (a.position() - b.position()).norm() > p.max_pair_m
            {
                self.pairs.remove(&key);
                continue;
            }
            let (Some(ca), Some(cb)) = (seen_with.get(&a.id), seen_with.get(&b.id)) else {
                continue;
            };
            let Some(pair) = self.pairs.get_mut(&key) else {
                continue;
            };
            pair.confidence_sum += ca.min(*cb).max(0.0);
            let travel = (a.travelled_m - pair.travelled.0).min(b.travelled_m - pair.travelled.1);
            let free_one = a.free < p.free_threshold || b.free < p.free_threshold;
            let free_both = a.free < p.free_threshold && b.free < p.free_threshold;
            let mid = nalgebra::center(&a.position(), &b.position());
            let quick = p.quick.is_some_and(|q| {
                free_both
                    && (mid - pair.midpoint).norm() >= q.min_displacement_m
                    && pair.confidence_sum >= q.min_confidence_sum
            });
            if !((travel > p.min_travel_m && free_one) || quick) {
                continue;
            }
            match (a.person, b.person) {
                (false, false) => {
                    born.push(Cluster {
                        position: mid,
                        confidence: (a.confidence + b.confidence) / 2.0,
                        occupancy: 0.0,
                    });
                    gone.extend([a.id, b.id]);
                }
                (true, _) => gone.push(b.id),
                (_, true) => gone.push(a.id),
            }
            self.pairs.remove(&key);
        }
        self.tracks.retain(|t| !gone.contains(&t.id));
        self.pairs
            .retain(|k, _| !gone.contains(&k.0) && !gone.contains(&k.1));
        for c in born {
            self.start(&c, true);
        }
        self.confirm_lone();
    }

    /// Our lone-cluster confirmation (module doc): an object track matched on this scan, in no
    /// candidate pair and farther than `max_pair_m` from every person (else it is that
    /// person's other leg), confident and in free space, that travelled `min_travel_m` since
    /// it started becomes a person in place (its id and filter kept).
    fn confirm_lone(&mut self) {
        let p = self.params;
        let Some(lone) = p.lone else {
            return;
        };
        let paired: std::collections::BTreeSet<u64> =
            self.pairs.keys().flat_map(|&(a, b)| [a, b]).collect();
        let mut people: Vec<Point2<f64>> = self
            .tracks
            .iter()
            .filter(|t| t.person)
            .map(Track::position)
            .collect();
        for t in &mut self.tracks {
            let beside_a_person = people
                .iter()
                .any(|q| (t.position() - q).norm() <= p.max_pair_m);
            if !t.person
                && t.seen
                && !beside_a_person
                && !paired.contains(&t.id)
                && t.confidence >= lone.min_confidence
                && t.free < p.free_threshold
                && t.travelled_m > p.min_travel_m
                && (t.position() - t.origin).norm() >= lone.min_displacement_m
            {
                t.person = true;
                t.free = 0.0;
                people.push(t.position());
            }
        }
    }
}

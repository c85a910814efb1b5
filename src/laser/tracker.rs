//! Multi-person tracking from leg detections, in the fixed frame.
//!
//! One track per person: a constant-velocity Kalman filter on `[x, y, vx, vy]`
//! ([`crate::track::kalman::constant_velocity_2d`], white-noise acceleration) observed in
//! position (`H = [I₂ 0]`). Each scan ([`PeopleTracker::step`]):
//!
//! 1. every track is predicted to the scan's time (`dt` = time since the previous scan; a
//!    negative or non-finite `dt` counts as 0);
//! 2. **global nearest neighbour**: people observations (leg-pair midpoints) are assigned to
//!    tracks by the Hungarian algorithm ([`crate::assign::max_score_pairs`]) maximising
//!    `Σ (gate − d²)` over pairs inside the gate, `d²` the Mahalanobis distance of the
//!    innovation (`yᵀ S⁻¹ y`, `S = H P Hᵀ + R`); equivalently the assignment of least
//!    `Σ d² + gate · (unassigned tracks)`;
//! 3. tracks left unassigned are offered the **unpaired legs** the same way, with the larger
//!    covariance `R_leg` (a leg lies up to half a step from the person's centre): a person one
//!    of whose legs is hidden behind the other keeps being updated;
//!    With `max_leg_only_scans = Some(k)` only tracks updated by a leg pair within their last
//!    `k` scans are offered legs (off by default): without it, one static leg-like object
//!    (a pole, a table leg) can keep a track alive indefinitely;
//! 4. people observations left unassigned start tentative tracks (single legs never do);
//! 5. **M-of-N**: a tentative track is confirmed once it was updated in `confirm_m` of its last
//!    `confirm_n` scans, and deleted once it has missed more than `confirm_n − confirm_m` scans
//!    before that; a confirmed track is deleted when it was updated in fewer than `delete_m`
//!    of its last `delete_n` scans.
//!
//! **Motion confirmation** ([`Confirmation::Motion`], instead of step 5's M-of-N; leg_tracker's
//! rule, Leigh et al. ICRA 2015, `joint_leg_tracker.py`): observations carry the detector's
//! confidence and the occupancy of the space around them ([`Observation`], from
//! [`crate::laser::occupancy`]). A tentative track is reported as a person once it has
//! travelled `min_travel_m` through free space — the sum of its filtered position's steps
//! between updates (each from the position after the previous update) longer than
//! `min_step_m`, counted on updates whose observation had occupancy below `free_threshold` —
//! and the mean confidence of its observations reaches `min_confidence`. Confirmed tracks
//! take no observation (pair or single leg) whose occupancy is at or above `free_threshold`
//! (leg_tracker: "ignore possible matchings between people and detections not in free space"),
//! so a person's track cannot pass on to a static leg-like object. Tentative tracks are deleted
//! by the confirmed tracks' rule (`delete_m` of `delete_n`), not by the early-miss count, so a
//! person whose legs are paired only now and then keeps a track while it moves. With JPDA the
//! free-space gate applies to the single legs only.
//!
//! Ids are 1, 2, 3, … in order of creation; within a scan new tracks are created in
//! observation order, so the same input gives the same ids.
//!
//! **JPDA** ([`Association::Jpda`], instead of step 2): tracks and people observations are
//! split into clusters of shared gates, the feasible joint events of each cluster are
//! enumerated exactly ([`crate::track::jpda`]: detection probability `P_D`, Poisson clutter of
//! density `λ`) and every track of a cluster gets the combined-innovation update with its
//! marginal association probabilities. Track management stays that of GNN, on the **most
//! probable joint event**: a track assigned a measurement in it counts as updated (M-of-N);
//! measurements it leaves unassigned start tentative tracks. Tracks that had a gated
//! observation but were left unassigned are not offered single legs (their state already
//! had its soft update). A cluster with more than `max_events` joint events (or whose events
//! all weigh zero) is associated by GNN instead and counted ([`PeopleTracker::jpda_fallbacks`]).

use std::collections::VecDeque;

use nalgebra::{Matrix2, Matrix2x4, Matrix4, Point2, Vector2, Vector4};

use crate::assign::max_score_pairs;
use crate::track::jpda::{
    clusters, combined_update, gate_probability, gaussian_2d, joint_marginals,
};
use crate::track::kalman::{Kalman, constant_velocity_2d};

/// How people observations are associated with tracks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Association {
    /// Global nearest neighbour: one observation per track, Hungarian algorithm.
    Gnn,
    /// Joint probabilistic data association (see the module doc).
    Jpda(JpdaParams),
}

/// Parameters of [`Association::Jpda`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JpdaParams {
    /// `P_D`: probability that a person is detected as a leg pair on a scan.
    pub detection_probability: f64,
    /// `λ`: false people observations per m² per scan (Poisson clutter).
    pub clutter_density: f64,
    /// Most joint events enumerated in one cluster before it falls back to GNN.
    pub max_events: usize,
}

impl Default for JpdaParams {
    /// - `detection_probability` 0.9 and `clutter_density` 0.05 m⁻²: chosen on the synthetic
    ///   `segway_park` and `office_network` logs (`examples/laser_jpda_sweep.rs`, MOTA over
    ///   P_D ∈ {0.6, 0.75, 0.9, 0.99} × λ ∈ {0.005, 0.05, 0.5, 2}); never on the real logs.
    /// - `max_events` 20,000: every cluster of up to 6 people and 6 observations (13,327
    ///   events) is exact; a few milliseconds at most per cluster.
    fn default() -> Self {
        JpdaParams {
            detection_probability: 0.9,
            clutter_density: 0.05,
            max_events: 20_000,
        }
    }
}

/// A value for [`TrackerParams::max_leg_only_scans`] (2 s at 10 Hz): chosen on the synthetic
/// `segway_park` and `office_network` logs (`examples/laser_jpda_sweep.rs`: MOTA 0.937, 0.931,
/// 0.948, 0.954 for 3, 5, 10, 20 scans against 0.953 without a limit), never on the real logs.
pub const LEG_ONLY_SCANS: usize = 20;

/// How a tentative track becomes a reported person (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Confirmation {
    /// `confirm_m` of the last `confirm_n` scans updated (the default).
    MofN,
    /// Travelled far enough through free space, with enough detector confidence.
    Motion(MotionParams),
}

/// Parameters of [`Confirmation::Motion`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionParams {
    /// Distance (m) travelled through free space before a track is reported.
    pub min_travel_m: f64,
    /// Steps of the filtered position shorter than this (m) are not counted.
    pub min_step_m: f64,
    /// An observation lies in free space when its occupancy is below this.
    pub free_threshold: f64,
    /// Least mean detector confidence of a track's observations to be reported.
    pub min_confidence: f64,
}

impl Default for MotionParams {
    /// leg_tracker's values (`joint_leg_tracker.py` defaults, kept by the benchmark launch
    /// files): `min_travel_m` 0.5 (`dist_travelled_together_to_initiate_leg_pair`),
    /// `min_step_m` 0.01 (its `delta_dist_travelled > 0.01`), `free_threshold` 0.06
    /// (`in_free_space_threshold`); `min_confidence` 0 (off: the leg model has no confidence).
    fn default() -> Self {
        MotionParams {
            min_travel_m: 0.5,
            min_step_m: 0.01,
            free_threshold: 0.06,
            min_confidence: 0.0,
        }
    }
}

/// One observation with what the detector and the occupancy grid say of it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observation {
    /// Fixed frame (m).
    pub position: Point2<f64>,
    /// Detector confidence in `[0, 1]` (1 for the leg model).
    pub confidence: f64,
    /// Occupancy of the space around it (0: free; [`crate::laser::occupancy::LocalGrid::occupancy_around`]).
    pub occupancy: f64,
}

impl Observation {
    /// A position with confidence 1 in free space (what [`PeopleTracker::step`] assumes).
    pub fn certain(position: Point2<f64>) -> Self {
        Observation {
            position,
            confidence: 1.0,
            occupancy: 0.0,
        }
    }
}

/// Tracker parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackerParams {
    /// White-noise acceleration standard deviation of the CV model (m/s²).
    pub accel_sigma: f64,
    /// Standard deviation of a person observation, per axis (m).
    pub person_sigma: f64,
    /// Standard deviation of a single-leg observation of the person's centre, per axis (m).
    pub leg_sigma: f64,
    /// Gate on the squared Mahalanobis distance of the innovation.
    pub gate: f64,
    /// Standard deviation of the initial velocity, per axis (m/s).
    pub init_velocity_sigma: f64,
    pub confirm_m: usize,
    pub confirm_n: usize,
    pub delete_m: usize,
    pub delete_n: usize,
    /// Data association of people observations.
    pub association: Association,
    /// Single legs are offered only to tracks that had a leg-pair update within their last
    /// this many scans; `None`: always (the default).
    pub max_leg_only_scans: Option<usize>,
    /// How tentative tracks are confirmed (M-of-N by default).
    pub confirmation: Confirmation,
}

impl Default for TrackerParams {
    /// - `gate` 9: seed 002 §5, "the standard three-sigma innovation gate" (`d ≤ 3`).
    /// - `accel_sigma` 2 m/s²: people reach walking speed (≈ 1.4 m/s) in under a second;
    ///   chosen on synthetic data.
    /// - `person_sigma` 0.1 m: the midpoint of two legs wanders about that far from the
    ///   body's centre over a stride; chosen on synthetic data.
    /// - `leg_sigma` 0.3 m: half the default leg pair distance (0.6 m), the farthest a leg
    ///   lies from the person's centre; chosen.
    /// - `init_velocity_sigma` 1.5 m/s: about a brisk walking speed; chosen.
    /// - `confirm_m`/`confirm_n` 3 of 5 and `delete_m`/`delete_n` 1 of 10 (deleted after
    ///   10 scans without an update, 1 s at 10 Hz): common M-of-N choices (Blackman &
    ///   Popoli, *Design and Analysis of Modern Tracking Systems*, §3.2); chosen.
    /// - `association`: GNN (seed 002's choice).
    fn default() -> Self {
        TrackerParams {
            accel_sigma: 2.0,
            person_sigma: 0.1,
            leg_sigma: 0.3,
            gate: 9.0,
            init_velocity_sigma: 1.5,
            confirm_m: 3,
            confirm_n: 5,
            delete_m: 1,
            delete_n: 10,
            association: Association::Gnn,
            max_leg_only_scans: None,
            confirmation: Confirmation::MofN,
        }
    }
}

/// What updated a track in the last scan.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Update {
    /// People observation of this index.
    Person(usize),
    /// Single leg of this index.
    Leg(usize),
    /// Nothing: the track coasted on its prediction.
    Missed,
}

/// A track's state after a scan.
#[derive(Debug, Clone, PartialEq)]
pub struct Track {
    pub id: u64,
    pub confirmed: bool,
    pub filter: Kalman<4>,
    /// Updates of the recent scans, newest last (`true`: updated).
    pub history: VecDeque<bool>,
    /// Scans missed before confirmation.
    pub early_misses: usize,
    /// Scans since the last leg-pair (people observation) update.
    pub since_pair: usize,
    pub last: Update,
    /// Distance travelled through free space (m; counted under [`Confirmation::Motion`]).
    pub travelled_m: f64,
    /// Sum of the confidences of its observations and their count.
    pub confidence_sum: f64,
    pub observations: usize,
    /// Position after the last scan that updated it.
    previous: Point2<f64>,
    /// Occupancy of the observation that last updated it.
    last_occupancy: f64,
}

impl Track {
    pub fn position(&self) -> Point2<f64> {
        Point2::new(self.filter.x[0], self.filter.x[1])
    }

    pub fn velocity(&self) -> Vector2<f64> {
        Vector2::new(self.filter.x[2], self.filter.x[3])
    }

    /// Mean detector confidence of its observations.
    pub fn mean_confidence(&self) -> f64 {
        if self.observations == 0 {
            0.0
        } else {
            self.confidence_sum / self.observations as f64
        }
    }

    fn hits(&self, last_n: usize) -> usize {
        self.history
            .iter()
            .rev()
            .take(last_n)
            .filter(|&&h| h)
            .count()
    }
}

/// Count an observation that updated `t`: its confidence, and under motion confirmation the
/// step of the filtered position when the observation lies in free space (module doc).
fn note_observation(t: &mut Track, z: &Observation) {
    t.confidence_sum += z.confidence;
    t.observations += 1;
    t.last_occupancy = z.occupancy;
}

/// The tracker's state (see the module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct PeopleTracker {
    pub params: TrackerParams,
    tracks: Vec<Track>,
    next_id: u64,
    last_time: Option<f64>,
    jpda_fallbacks: u64,
}

fn h() -> Matrix2x4<f64> {
    Matrix2x4::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0)
}

/// Squared Mahalanobis distance of `z` from the filter's predicted position with noise `r`.
pub fn mahalanobis2(k: &Kalman<4>, r: &Matrix2<f64>, z: &Point2<f64>) -> f64 {
    let h = h();
    let s = h * k.p * h.transpose() + r;
    let y = z.coords - h * k.x;
    match s.try_inverse() {
        Some(si) => {
            let d = (y.transpose() * si * y)[(0, 0)];
            if d.is_finite() { d } else { f64::INFINITY }
        }
        None => f64::INFINITY,
    }
}

impl PeopleTracker {
    pub fn new(params: TrackerParams) -> Self {
        PeopleTracker {
            params,
            tracks: Vec::new(),
            next_id: 1,
            last_time: None,
            jpda_fallbacks: 0,
        }
    }

    /// All live tracks, tentative ones included, in order of creation.
    pub fn tracks(&self) -> &[Track] {
        &self.tracks
    }

    /// JPDA clusters associated by GNN because they had too many joint events (see the
    /// module doc); 0 under GNN.
    pub fn jpda_fallbacks(&self) -> u64 {
        self.jpda_fallbacks
    }

    /// The confirmed tracks.
    pub fn confirmed(&self) -> impl Iterator<Item = &Track> {
        self.tracks.iter().filter(|t| t.confirmed)
    }

    /// One scan at `time_s` (seconds, any origin) with its people observations and unpaired
    /// legs, both in the fixed frame. Non-finite observations are ignored.
    pub fn step(&mut self, time_s: f64, people: &[Point2<f64>], legs: &[Point2<f64>]) {
        let people: Vec<Observation> = people.iter().map(|&p| Observation::certain(p)).collect();
        let legs: Vec<Observation> = legs.iter().map(|&p| Observation::certain(p)).collect();
        self.step_observed(time_s, &people, &legs);
    }

    /// [`Self::step`] with each observation's confidence and occupancy (used by
    /// [`Confirmation::Motion`]; the M-of-N tracker ignores them).
    pub fn step_observed(&mut self, time_s: f64, people: &[Observation], legs: &[Observation]) {
        let dt = match self.last_time {
            Some(t0) if (time_s - t0).is_finite() && time_s > t0 => time_s - t0,
            _ => 0.0,
        };
        if time_s.is_finite() {
            self.last_time = Some(self.last_time.map_or(time_s, |t0| t0.max(time_s)));
        }
        let p = self.params;
        let (f, q) = constant_velocity_2d(dt, p.accel_sigma);
        for t in &mut self.tracks {
            t.filter.predict(&f, &q);
            t.last = Update::Missed;
        }
        let finite = |z: &Point2<f64>| z.x.is_finite() && z.y.is_finite();
        let r_person = Matrix2::identity() * p.person_sigma.powi(2);
        let r_leg = Matrix2::identity() * p.leg_sigma.powi(2);
        let people_at: Vec<Point2<f64>> = people.iter().map(|o| o.position).collect();
        let legs_at: Vec<Point2<f64>> = legs.iter().map(|o| o.position).collect();

        let all: Vec<usize> = (0..self.tracks.len()).collect();
        let mut person_used = vec![false; people.len()];
        let mut soft = vec![false; self.tracks.len()];
        match p.association {
            Association::Gnn => {
                for (ti, zi) in self.associate(&all, &people_at, people, &r_person) {
                    person_used[zi] = true;
                    self.apply(ti, &r_person, &people[zi], Update::Person(zi));
                }
            }
            Association::Jpda(j) => {
                self.jpda(&people_at, &r_person, &j, &mut person_used, &mut soft);
                for (ti, t) in self.tracks.iter_mut().enumerate() {
                    if let (true, Update::Person(zi)) = (soft[ti], t.last) {
                        note_observation(t, &people[zi]);
                    }
                }
            }
        }
        let unmatched: Vec<usize> = all
            .iter()
            .copied()
            .filter(|&ti| self.tracks[ti].last == Update::Missed && !soft[ti])
            .filter(|&ti| {
                p.max_leg_only_scans
                    .is_none_or(|k| self.tracks[ti].since_pair < k)
            })
            .collect();
        for (ti, zi) in self.associate(&unmatched, &legs_at, legs, &r_leg) {
            self.apply(ti, &r_leg, &legs[zi], Update::Leg(zi));
        }
        self.book_keep();
        for (zi, z) in people.iter().enumerate() {
            if !person_used[zi] && finite(&z.position) {
                self.start(zi, z);
            }
        }
    }

    /// Whether a confirmed track may take an observation of this occupancy (the free-space
    /// gate of [`Confirmation::Motion`]).
    fn may_take(&self, ti: usize, occupancy: f64) -> bool {
        match self.params.confirmation {
            Confirmation::MofN => true,
            Confirmation::Motion(m) => !self.tracks[ti].confirmed || occupancy < m.free_threshold,
        }
    }

    /// GNN pairs (track index, observation index) among `candidates`.
    fn associate(
        &self,
        candidates: &[usize],
        obs: &[Point2<f64>],
        meta: &[Observation],
        r: &Matrix2<f64>,
    ) -> Vec<(usize, usize)> {
        let gate = self.params.gate;
        max_score_pairs(candidates.len(), obs.len(), |i, j| {
            let z = &obs[j];
            if !(z.x.is_finite()
                && z.y.is_finite()
                && self.may_take(candidates[i], meta[j].occupancy))
            {
                return f64::NAN;
            }
            let d2 = mahalanobis2(&self.tracks[candidates[i]].filter, r, z);
            if d2 <= gate { gate - d2 } else { f64::NAN }
        })
        .into_iter()
        .map(|(i, j)| (candidates[i], j))
        .collect()
    }

    /// JPDA of the people observations (module doc): per cluster the combined update of every
    /// track, `used` and `Update::Person` from the most probable joint event; `soft` marks the
    /// tracks that were in a cluster.
    fn jpda(
        &mut self,
        people: &[Point2<f64>],
        r: &Matrix2<f64>,
        j: &JpdaParams,
        used: &mut [bool],
        soft: &mut [bool],
    ) {
        let gate = self.params.gate;
        let h = h();
        let d2: Vec<Vec<f64>> = self
            .tracks
            .iter()
            .map(|t| {
                people
                    .iter()
                    .map(|z| mahalanobis2(&t.filter, r, z))
                    .collect()
            })
            .collect();
        let det: Vec<f64> = self
            .tracks
            .iter()
            .map(|t| (h * t.filter.p * h.transpose() + r).determinant())
            .collect();
        let pd = j.detection_probability;
        let pg = gate_probability(2, gate).unwrap_or(1.0);
        let miss = j.clutter_density * (1.0 - pd * pg);
        let gated = |t: usize, z: usize| d2[t][z] <= gate;
        for (ts, zs) in clusters(self.tracks.len(), people.len(), gated) {
            let w: Vec<Vec<f64>> = ts
                .iter()
                .map(|&t| {
                    zs.iter()
                        .map(|&z| {
                            if gated(t, z) {
                                pd * gaussian_2d(d2[t][z], det[t])
                            } else {
                                0.0
                            }
                        })
                        .collect()
                })
                .collect();
            let sub: Vec<Point2<f64>> = zs.iter().map(|&z| people[z]).collect();
            let Some(m) = joint_marginals(&w, &vec![miss; ts.len()], j.max_events) else {
                self.jpda_fallbacks += 1;
                let meta: Vec<Observation> = sub.iter().map(|&z| Observation::certain(z)).collect();
                for (ti, k) in self.associate(&ts, &sub, &meta, r) {
                    used[zs[k]] = true;
                    self.apply(ti, r, &meta[k], Update::Person(zs[k]));
                }
                continue;
            };
            let coords: Vec<Vector2<f64>> = sub.iter().map(|z| z.coords).collect();
            for (k, &ti) in ts.iter().enumerate() {
                soft[ti] = true;
                let t = &mut self.tracks[ti];
                let ok = combined_update(&mut t.filter, &h, r, &coords, &m.beta[k], m.beta0[k]);
                if let (Ok(()), Some(b)) = (ok, m.best[k]) {
                    used[zs[b]] = true;
                    t.last = Update::Person(zs[b]);
                }
            }
        }
    }

    fn apply(&mut self, ti: usize, r: &Matrix2<f64>, z: &Observation, how: Update) {
        let t = &mut self.tracks[ti];
        if t.filter.update(&h(), r, &z.position.coords).is_ok() {
            t.last = how;
            note_observation(t, z);
        }
    }

    /// Histories, confirmation and deletion.
    fn book_keep(&mut self) {
        let p = self.params;
        let keep = p.confirm_n.max(p.delete_n).max(1);
        for t in &mut self.tracks {
            let hit = t.last != Update::Missed;
            t.since_pair = match t.last {
                Update::Person(_) => 0,
                _ => t.since_pair + 1,
            };
            t.history.push_back(hit);
            while t.history.len() > keep {
                t.history.pop_front();
            }
            let now = t.position();
            if let Confirmation::Motion(m) = p.confirmation {
                let step = (now - t.previous).norm();
                if hit && t.last_occupancy < m.free_threshold && step > m.min_step_m {
                    t.travelled_m += step;
                }
            }
            if !t.confirmed {
                if !hit {
                    t.early_misses += 1;
                }
                t.confirmed = match p.confirmation {
                    Confirmation::MofN => t.hits(p.confirm_n) >= p.confirm_m,
                    Confirmation::Motion(m) => {
                        t.travelled_m >= m.min_travel_m && t.mean_confidence() >= m.min_confidence
                    }
                };
            }
            if hit {
                t.previous = now;
            }
        }
        let motion = matches!(p.confirmation, Confirmation::Motion(_));
        self.tracks.retain(|t| {
            if t.confirmed || motion {
                t.history.len() < p.delete_n || t.hits(p.delete_n) >= p.delete_m
            } else {
                t.early_misses <= p.confirm_n.saturating_sub(p.confirm_m)
            }
        });
    }

    fn start(&mut self, zi: usize, z: &Observation) {
        let p = self.params;
        let pos = p.person_sigma.powi(2);
        let vel = p.init_velocity_sigma.powi(2);
        let cov = Matrix4::from_diagonal(&Vector4::new(pos, pos, vel, vel));
        let mut history = VecDeque::new();
        history.push_back(true);
        let confirmed = match p.confirmation {
            Confirmation::MofN => p.confirm_m <= 1,
            Confirmation::Motion(m) => m.min_travel_m <= 0.0 && z.confidence >= m.min_confidence,
        };
        let at = z.position;
        self.tracks.push(Track {
            id: self.next_id,
            confirmed,
            filter: Kalman::new(Vector4::new(at.x, at.y, 0.0, 0.0), cov),
            history,
            early_misses: 0,
            since_pair: 0,
            last: Update::Person(zi),
            travelled_m: 0.0,
            confidence_sum: z.confidence,
            observations: 1,
            previous: at,
            last_occupancy: z.occupancy,
        });
        self.next_id += 1;
    }
}

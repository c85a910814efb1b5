//! Several people for the EKF of seed 002 — our addition: the paper tracks one person and
//! leaves data association out, though it notes that "the height model is also used for
//! distinguishing between targets" (§5). One [`HeightEkf`] over (x, y, h) per person:
//!
//! - **Association: global nearest neighbour (GNN) inside the 3σ gate.** Every observation of
//!   one sensor event (the leg pairs of one scan, or the head tops of one camera frame) is
//!   tried on every track; a pair is allowed when its squared Mahalanobis distance is inside
//!   the track's gate (`gate_sigma`², the paper's three-sigma gate), and the pairs are chosen
//!   one to one, most pairs first and then least total squared distance
//!   ([`crate::assign::min_cost_max_pairs`]). One to one, because one scan's leg pairs (one
//!   frame's head tops) come from different people: nearest-in-Mahalanobis per track would let
//!   two tracks of people walking side by side take the same observation and merge. Camera
//!   head tops are associated through the height too (a 1.62 m head and a 1.84 m head at the
//!   same bearing differ in elevation).
//! - **Birth** from a laser leg pair that no track took, farther than `birth_clearance_m` from
//!   every track (and from the other births of the same scan), at h0 with σ h0 as in the
//!   single-person filter. Cameras never start a track (bearing and elevation do not place a
//!   head of unknown height).
//! - **Deletion** of a track that no leg pair updated for `delete_after_s`. Head tops alone do
//!   not keep a track alive: bearing + elevation do not hold its range (§5: "absolute range
//!   observations, as provided by the laser, are required"), and a track fed only by a
//!   camera drifts along the camera's ray while the laser starts a new track for the person.
//! - **Ambiguous head tops are skipped** (`skip_ambiguous_camera`): a head top inside the
//!   gates of two or more tracks updates none. Two people of similar height at similar
//!   bearings from a camera cannot be told apart by bearing + elevation (1.84 vs 1.75 m at
//!   4 m differ by 0.022 rad, about one σ), and a wrong pick pulls the track along the ray;
//!   leg pairs are precise enough not to need this.
//! - A track is reported once `confirm_hits` laser pairs updated it (one stray leg pair does
//!   not become a person).
//!
//! Also [`triangulate_head`]: the closed-form head top from two cameras' bearing + elevation
//! (the floor-plane intersection of the bearings, then the height from the elevations).
//! Pure state machine: no I/O, no clocks.

use super::height_ekf::{EkfParams, HeightEkf, SensorAt, Update};
use crate::assign;

/// Parameters of the multi-person tracker.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackerParams {
    pub ekf: EkfParams,
    /// A track that no leg pair updated for this long (s) is deleted.
    pub delete_after_s: f64,
    /// An unassociated leg pair nearer than this (m) to a track or to another birth of the
    /// same scan starts no track.
    pub birth_clearance_m: f64,
    /// Laser updates (the birth included) before a track is reported.
    pub confirm_hits: u32,
    /// A camera observation inside the gates of two or more tracks updates none.
    pub skip_ambiguous_camera: bool,
}

/// One observation of a sensor event.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Observation {
    /// Range–bearing of a leg-pair midpoint from `laser` (bearing in the laser frame).
    Laser {
        range_m: f64,
        bearing_rad: f64,
        laser: SensorAt,
    },
    /// Bearing + elevation of a head top (world-frame angles from the camera centre).
    Camera {
        bearing_rad: f64,
        elevation_rad: f64,
        camera: SensorAt,
    },
}

impl Observation {
    /// Floor position of a laser observation (map frame); `None` for a camera.
    pub fn laser_xy(&self) -> Option<[f64; 2]> {
        match *self {
            Observation::Laser {
                range_m,
                bearing_rad,
                laser,
            } => {
                let a = laser.yaw + bearing_rad;
                Some([laser.x + range_m * a.cos(), laser.y + range_m * a.sin()])
            }
            Observation::Camera { .. } => None,
        }
    }

    fn apply(&self, f: &mut HeightEkf) -> Update {
        match *self {
            Observation::Laser {
                range_m,
                bearing_rad,
                laser,
            } => f.update_laser(range_m, bearing_rad, &laser),
            Observation::Camera {
                bearing_rad,
                elevation_rad,
                camera,
            } => f.update_camera(bearing_rad, elevation_rad, &camera),
        }
    }
}

/// One person's track.
#[derive(Debug, Clone)]
pub struct Track {
    /// Sequential from 1, never reused.
    pub id: u64,
    pub ekf: HeightEkf,
    pub born_s: f64,
    /// Time of the last accepted observation (the birth counts).
    pub last_update_s: f64,
    /// Time of the last accepted leg pair (the birth counts).
    pub last_laser_s: f64,
    pub laser_hits: u32,
    pub camera_hits: u32,
}

/// What one [`MultiTracker::step`] did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StepReport {
    /// `(track id, observation index)` of every accepted association.
    pub assigned: Vec<(u64, usize)>,
    /// Observations that no track took (births included).
    pub unassigned: Vec<usize>,
    pub born: Vec<u64>,
    pub deleted: Vec<u64>,
}

/// The set of tracks.
#[derive(Debug, Clone)]
pub struct MultiTracker {
    pub params: TrackerParams,
    tracks: Vec<Track>,
    next_id: u64,
}

impl MultiTracker {
    pub fn new(params: TrackerParams) -> MultiTracker {
        MultiTracker {
            params,
            tracks: Vec::new(),
            next_id: 1,
        }
    }

    /// Every live track, oldest first.
    pub fn tracks(&self) -> &[Track] {
        &self.tracks
    }

    /// Whether `t` is reported (see `confirm_hits`).
    pub fn confirmed(&self, t: &Track) -> bool {
        t.laser_hits >= self.params.confirm_hits
    }

    /// One sensor event at `t_s` (never earlier than the last): predict every track, associate
    /// `obs` by GNN inside the gate and update, start tracks from unassociated leg pairs when
    /// `allow_birth`, and delete tracks no leg pair updated for `delete_after_s`.
    pub fn step(&mut self, t_s: f64, obs: &[Observation], allow_birth: bool) -> StepReport {
        for t in &mut self.tracks {
            t.ekf.predict(t_s);
        }
        // every allowed (track, observation) pair with its updated filter
        let mut trials: Vec<Vec<Option<(f64, HeightEkf)>>> = Vec::with_capacity(self.tracks.len());
        for t in &self.tracks {
            let row = obs
                .iter()
                .map(|o| {
                    let mut f = t.ekf.clone();
                    let u = o.apply(&mut f);
                    (u.accepted && u.d2.is_finite()).then_some((u.d2, f))
                })
                .collect();
            trials.push(row);
        }
        if self.params.skip_ambiguous_camera {
            for (c, o) in obs.iter().enumerate() {
                let gated = trials.iter().filter(|row| row[c].is_some()).count();
                if matches!(o, Observation::Camera { .. }) && gated > 1 {
                    for row in &mut trials {
                        row[c] = None;
                    }
                }
            }
        }
        let pairs = assign::min_cost_max_pairs(self.tracks.len(), obs.len(), |r, c| {
            trials[r][c].as_ref().map_or(f64::INFINITY, |(d2, _)| *d2)
        });
        let mut report = StepReport::default();
        let mut taken = vec![false; obs.len()];
        for (r, c) in pairs {
            let Some((_, f)) = trials[r][c].take() else {
                continue;
            };
            let track = &mut self.tracks[r];
            track.ekf = f;
            track.last_update_s = t_s;
            match obs[c] {
                Observation::Laser { .. } => {
                    track.laser_hits += 1;
                    track.last_laser_s = t_s;
                }
                Observation::Camera { .. } => track.camera_hits += 1,
            }
            taken[c] = true;
            report.assigned.push((track.id, c));
        }
        report.assigned.sort_unstable();
        report.unassigned = (0..obs.len()).filter(|&c| !taken[c]).collect();
        if allow_birth {
            self.births(t_s, obs, &report.unassigned.clone(), &mut report);
        }
        let limit = self.params.delete_after_s;
        self.tracks.retain(|t| {
            let keep = t_s - t.last_laser_s <= limit;
            if !keep {
                report.deleted.push(t.id);
            }
            keep
        });
        report
    }

    fn births(&mut self, t_s: f64, obs: &[Observation], free: &[usize], report: &mut StepReport) {
        let clear = self.params.birth_clearance_m;
        for &c in free {
            let Some(xy) = obs[c].laser_xy() else {
                continue;
            };
            let near = self.tracks.iter().any(|t| {
                let p = t.ekf.xy();
                (p[0] - xy[0]).hypot(p[1] - xy[1]) < clear
            });
            if near {
                continue;
            }
            let e = self.params.ekf;
            let id = self.next_id;
            self.next_id += 1;
            self.tracks.push(Track {
                id,
                ekf: HeightEkf::new(e, xy, e.h0_m, e.sigma_h0_m, t_s),
                born_s: t_s,
                last_update_s: t_s,
                last_laser_s: t_s,
                laser_hits: 1,
                camera_hits: 0,
            });
            report.born.push(id);
        }
    }
}

/// Head top `[x, y, h]` from two cameras' bearing + elevation `(bearing, elevation, camera)`:
/// the bearings' rays intersected on the floor plan, then the height from each camera's
/// elevation at its floor range, averaged. `None` when the bearings are (nearly) parallel or
/// meet behind a camera.
pub fn triangulate_head(a: (f64, f64, SensorAt), b: (f64, f64, SensorAt)) -> Option<[f64; 3]> {
    let (da, db) = ([a.0.cos(), a.0.sin()], [b.0.cos(), b.0.sin()]);
    // a + s da = b + u db  ⇔  s da − u db = b − a
    let det = -da[0] * db[1] + db[0] * da[1];
    if det.abs() < 1e-9 {
        return None;
    }
    let (rx, ry) = (b.2.x - a.2.x, b.2.y - a.2.y);
    let s = (-rx * db[1] + db[0] * ry) / det;
    let u = (da[0] * ry - da[1] * rx) / det;
    if !(s > 0.0 && u > 0.0) {
        return None;
    }
    let ha = a.2.z + s * a.1.tan();
    let hb = b.2.z + u * b.1.tan();
    Some([a.2.x + s * da[0], a.2.y + s * da[1], 0.5 * (ha + hb)])
}

#[cfg(test)]
mod tests;

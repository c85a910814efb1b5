//! The placeholder baseline estimator of the closed loop (not a paper method): the cluster
//! of leg-sized laser segments (at most [`LEG_MAX_WIDTH_M`] wide) nearest to the last
//! estimate's prediction, within a gate. It starts on
//! the cluster nearest to a given point (where a person points the robot at its target),
//! coasts on its velocity while nothing is in the gate, and after [`LOST_AFTER_S`] without
//! a return declares the target lost (`rst`): it then answers `None` until a cluster appears
//! within [`REACQUIRE_M`] (growing by [`REACQUIRE_GROWTH_MPS`] per second since the loss) of
//! where the last estimate would have walked to; the first search, around the initial point,
//! grows the same way from t = 0. No appearance, no motion model beyond a
//! smoothed velocity, no data association beyond "nearest": a crosser or a tree can capture
//! it, which is what the real tracker (seed 001's PDAF) is for.

use nalgebra::Point2;

use super::{Estimate, Follower, FollowerOutput, ScanInput};
use crate::laser::points::project;
use crate::laser::segment::{SegmentOptions, Threshold, segment};

/// Radius of the gate around the predicted position (m).
pub const GATE_M: f64 = 0.8;
/// Leg candidates within this distance of the nearest one form the target: both legs (m).
pub const CLUSTER_M: f64 = 0.45;
/// Consecutive returns farther apart than this start a new segment (m).
pub const SEGMENT_JUMP_M: f64 = 0.1;
/// Segments wider than this (first to last return) are not legs (m): a leg is 0.11–0.15 m
/// across, with room for a slanted view; two legs seen as one segment drop out (the track
/// coasts for that scan).
pub const LEG_MAX_WIDTH_M: f64 = 0.25;
/// Time without a return in the gate after which the target is lost (s).
pub const LOST_AFTER_S: f64 = 1.0;
/// Radius around the initial point, and around the last estimate once lost, in which a
/// cluster (re)starts the track (m).
pub const REACQUIRE_M: f64 = 1.5;
/// Growth of the reacquisition radius per second since the target was lost (m/s): about a
/// walker's speed, as the person walks on while the robot stops.
pub const REACQUIRE_GROWTH_MPS: f64 = 1.5;
/// Largest reacquisition radius (m).
pub const REACQUIRE_MAX_M: f64 = 6.0;
/// Standard deviation of a fresh estimate (m), and its growth per second of coasting (m/s).
const SIGMA_M: f64 = 0.05;
const SIGMA_GROWTH_MPS: f64 = 1.0;
/// Weight of the newest velocity measurement in the smoothed velocity.
const VELOCITY_GAIN: f64 = 0.3;

struct TrackState {
    position: [f64; 2],
    velocity: [f64; 2],
    /// Time of the last update (s) and of the last return in the gate.
    t_last: f64,
    t_seen: f64,
}

/// See the module doc.
pub struct NearestBlobFollower {
    track: Option<TrackState>,
    /// Where a lost (or not yet found) target is searched for: its last position and velocity
    /// and the time it was lost (the initial point counts as lost at t = 0).
    anchor: ([f64; 2], [f64; 2], f64),
}

impl NearestBlobFollower {
    pub fn new(init: [f64; 2]) -> Self {
        NearestBlobFollower {
            track: None,
            anchor: (init, [0.0, 0.0], 0.0),
        }
    }

    /// Centre and radius of the search for a lost (or not yet found) target at `t`.
    fn search(&self, t: f64) -> ([f64; 2], f64) {
        let (p, v, t0) = self.anchor;
        let h = (t - t0).max(0.0);
        let r = (REACQUIRE_M + REACQUIRE_GROWTH_MPS * h).min(REACQUIRE_MAX_M);
        let h = h.min(LOST_AFTER_S);
        ([p[0] + v[0] * h, p[1] + v[1] * h], r)
    }
}

/// Leg-sized pieces of a scan: the centroids (in the pose's frame) of the jump-distance
/// segments no wider than [`LEG_MAX_WIDTH_M`]. Bushes, walls and the ground line a pitched
/// laser draws are wider, and are not candidates.
fn leg_candidates(input: &ScanInput<'_>) -> Vec<Point2<f64>> {
    let points = project(input.ranges, &input.geometry, Some(&input.laser_pose));
    let options = SegmentOptions {
        threshold: Threshold::Fixed(SEGMENT_JUMP_M),
        min_points: 1,
    };
    segment(&points, &options)
        .into_iter()
        .filter_map(|seg| {
            let pts = &points[seg.points];
            let (first, last) = (pts.first()?, pts.last()?);
            if (last.sensor - first.sensor).norm() > LEG_MAX_WIDTH_M {
                return None;
            }
            let n = pts.len() as f64;
            let (sx, sy) = pts
                .iter()
                .fold((0.0, 0.0), |(x, y), p| (x + p.fixed.x, y + p.fixed.y));
            Some(Point2::new(sx / n, sy / n))
        })
        .collect()
}

/// Mean of the candidates within [`CLUSTER_M`] of the candidate nearest to `at`, when that
/// one is within `gate` of `at` (both legs of a person).
fn nearest_cluster(points: &[Point2<f64>], at: [f64; 2], gate: f64) -> Option<[f64; 2]> {
    let at = Point2::new(at[0], at[1]);
    let nearest = points
        .iter()
        .map(|p| ((p - at).norm(), p))
        .filter(|(d, _)| *d <= gate)
        .min_by(|a, b| a.0.total_cmp(&b.0))?
        .1;
    let (mut sx, mut sy, mut n) = (0.0, 0.0, 0.0);
    for p in points.iter().filter(|p| (*p - nearest).norm() <= CLUSTER_M) {
        sx += p.x;
        sy += p.y;
        n += 1.0;
    }
    Some([sx / n, sy / n])
}

fn estimate(track: &TrackState, t: f64) -> Estimate {
    let sigma = SIGMA_M + SIGMA_GROWTH_MPS * (t - track.t_seen).max(0.0);
    Estimate {
        position: track.position,
        velocity: track.velocity,
        covariance: [[sigma * sigma, 0.0], [0.0, sigma * sigma]],
    }
}

impl Follower for NearestBlobFollower {
    fn on_scan(&mut self, input: &ScanInput<'_>) -> FollowerOutput {
        let t = input.t;
        let points = leg_candidates(input);
        let Some(tr) = self.track.as_mut() else {
            // (re)initialise on the cluster nearest to the anchor
            let (centre, radius) = self.search(t);
            let Some(c) = nearest_cluster(&points, centre, radius) else {
                return FollowerOutput {
                    estimate: None,
                    reset: false,
                    look_at: None,
                };
            };
            let tr = TrackState {
                position: c,
                velocity: [0.0, 0.0],
                t_last: t,
                t_seen: t,
            };
            let e = estimate(&tr, t);
            self.track = Some(tr);
            return FollowerOutput {
                estimate: Some(e),
                reset: false,
                look_at: None,
            };
        };
        let dt = (t - tr.t_last).max(0.0);
        let predicted = [
            tr.position[0] + tr.velocity[0] * dt,
            tr.position[1] + tr.velocity[1] * dt,
        ];
        match nearest_cluster(&points, predicted, GATE_M) {
            Some(c) if dt > 0.0 => {
                for ((v, ck), pk) in tr.velocity.iter_mut().zip(c).zip(tr.position) {
                    *v += VELOCITY_GAIN * ((ck - pk) / dt - *v);
                }
                tr.position = c;
                tr.t_seen = t;
            }
            Some(_) => tr.t_seen = t,
            None if t - tr.t_seen > LOST_AFTER_S => {
                self.anchor = (tr.position, tr.velocity, t);
                self.track = None;
                return FollowerOutput {
                    estimate: None,
                    reset: true,
                    look_at: None,
                };
            }
            None => tr.position = predicted,
        }
        tr.t_last = t;
        FollowerOutput {
            estimate: Some(estimate(tr, t)),
            reset: false,
            look_at: None,
        }
    }

    fn uses_omni(&self) -> bool {
        false
    }
}

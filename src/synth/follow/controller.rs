//! The two following controllers of seed 001 §VI, as pure functions of the robot's odometry
//! pose and speed, the target's estimate and (pure pursuit) the trail of past estimates:
//!
//! - [`direct`]: turn to null the relative bearing `β` (`ω = K_β·β`) and drive to null the
//!   range error (`v = K_r·(r − d) + max(0, v_t·u)`, `u` the line of sight, `v_t` the target's
//!   estimated velocity), slowed when the target is off the nose.
//! - [`pursuit`]: pure pursuit on the person's estimated path: aim at the first trail point at
//!   least [`LOOKAHEAD_M`] away, `ω = κ·v` with the curvature `κ = 2·y/L²` of the arc through
//!   it (`y` its lateral offset, `L` its distance); drive to null the error of the distance
//!   *along the path* to the target (the straight range once that is below `d`), no faster
//!   than the arc is drivable at the turn-rate limit (`v ≤ ω_max/|κ|`; a goal beside or
//!   behind is turned to at `v ≤ ω_max·L/2`; issue 30, round 12).
//!
//! Both keep the desired following distance `d = d_follow + v²/(2·a_min)` (`v` the robot's
//! speed, `a_min` its largest deceleration: the term seed 001's `E_follow` subtracts, so the
//! robot can always stop short of the person), and the speed and turn-rate limits. The loop
//! applies the acceleration and deceleration limits when it tracks the commanded speed;
//! without an estimate the command is a stop, which it reaches at `a_min`, turning towards the
//! target's last prediction when the follower gives one ([`stop`]; seed 001 §VI: `rst` "will
//! cause the robot to stop, and reinitiate the track"), or, with `lost = "search"` (our
//! addition, issue 30, round 14), drives to that prediction and turns in place there
//! ([`search`]).

use super::Estimate;
use crate::synth::robot::wrap;
use crate::synth::scenario::Follow;

/// Range-error gain `K_r` (1/s).
pub const K_RANGE: f64 = 1.2;
/// Bearing gain `K_β` (1/s).
pub const K_BEARING: f64 = 2.0;
/// Pure pursuit's look-ahead distance (m).
pub const LOOKAHEAD_M: f64 = 1.0;
/// Smallest speed pure pursuit turns with (m/s): it still faces a target it need not approach.
pub const PURSUIT_MIN_TURN_SPEED: f64 = 0.5;
/// Top speed of [`search`] (m/s): Table I's mean following speed `v_avg` (a priori).
pub const SEARCH_SPEED_MPS: f64 = 1.5;
/// Trail points closer together than this are not kept (m).
pub const TRAIL_SPACING_M: f64 = 0.1;
/// A trail point the robot came this close to is passed (m).
pub const TRAIL_REACHED_M: f64 = 0.6;

/// The robot's kinematic and dynamic limits and its following distance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// `d_follow` (m).
    pub following_distance: f64,
    pub max_speed: f64,
    pub max_accel: f64,
    /// `a_min`, the largest deceleration (m/s²).
    pub max_decel: f64,
    /// Turn-rate limit (rad/s).
    pub max_turn_rate: f64,
}

impl Limits {
    pub fn of(f: &Follow) -> Self {
        Limits {
            following_distance: f.distance,
            max_speed: f.max_speed,
            max_accel: f.max_accel,
            max_decel: f.decel(),
            max_turn_rate: f.max_turn_rate,
        }
    }

    /// `d = d_follow + v²/(2·a_min)` at speed `v`.
    pub fn desired_distance(&self, v: f64) -> f64 {
        self.following_distance + v * v / (2.0 * self.max_decel)
    }
}

/// The robot as odometry gives it: pose in `odom` and measured forward speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OdomPose {
    pub x: f64,
    pub y: f64,
    pub yaw: f64,
    pub v: f64,
}

/// A command: forward speed and yaw rate, and the desired distance it was computed for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Command {
    pub v: f64,
    pub w: f64,
    pub desired_distance: f64,
}

/// Speed factor for a target `bearing` off the nose: full ahead, 40 % at a radian or more.
fn heading_factor(bearing: f64) -> f64 {
    1.0 - 0.6 * bearing.abs().min(1.0)
}

/// Stop: the loop decelerates at `a_min` to a standstill; with `look_at` (the target's last
/// prediction, `odom`) the robot turns towards it (`ω = K_β·β`, turn-rate limited), so the
/// laser's 180° keeps the place the target was lost in view while the follower looks for it.
pub fn stop(robot: &OdomPose, look_at: Option<[f64; 2]>, lim: &Limits) -> Command {
    let w = look_at.map_or(0.0, |p| {
        let bearing = wrap((p[1] - robot.y).atan2(p[0] - robot.x) - robot.yaw);
        (K_BEARING * bearing).clamp(-lim.max_turn_rate, lim.max_turn_rate)
    });
    Command {
        v: 0.0,
        w,
        desired_distance: lim.desired_distance(robot.v),
    }
}

/// Search (our addition; issue 30, round 14): drive towards `look_at`, the target's last
/// prediction (`odom`), turning to it as [`direct`] does (`ω = K_β·β`, slowed off the nose),
/// at `K_r·ρ` but no faster than [`SEARCH_SPEED_MPS`]; within `ρ₀` = [`TRAIL_REACHED_M`] of
/// it (reached in finite time: the speed law aims at the point itself), turn in place at half
/// the turn-rate limit, to the left, so the laser's 180° sweeps round the place the target was
/// lost at. The obstacle check applies to it as to every command. Seed 001 stops instead
/// ([`stop`]): a robot that stops behind the trunk that hid the person may not see them again
/// (the second full run's run 03 stood for 163 s). Not the default: it did not gain on the
/// dev split (docs/s001_kobilarov_following.md, round 14).
pub fn search(robot: &OdomPose, look_at: [f64; 2], lim: &Limits) -> Command {
    let desired_distance = lim.desired_distance(robot.v);
    let (dx, dy) = (look_at[0] - robot.x, look_at[1] - robot.y);
    let range = dx.hypot(dy);
    if range <= TRAIL_REACHED_M {
        return Command {
            v: 0.0,
            w: 0.5 * lim.max_turn_rate,
            desired_distance,
        };
    }
    let bearing = wrap(dy.atan2(dx) - robot.yaw);
    let v = (K_RANGE * range).min(SEARCH_SPEED_MPS).min(lim.max_speed);
    Command {
        v: v * heading_factor(bearing),
        w: (K_BEARING * bearing).clamp(-lim.max_turn_rate, lim.max_turn_rate),
        desired_distance,
    }
}

/// Direct following (see the module doc).
pub fn direct(robot: &OdomPose, est: &Estimate, lim: &Limits) -> Command {
    let d = lim.desired_distance(robot.v);
    let (dx, dy) = (est.position[0] - robot.x, est.position[1] - robot.y);
    let range = dx.hypot(dy);
    let bearing = wrap(dy.atan2(dx) - robot.yaw);
    let receding = if range > 0.0 {
        ((est.velocity[0] * dx + est.velocity[1] * dy) / range).max(0.0)
    } else {
        0.0
    };
    let v = (K_RANGE * (range - d) + receding) * heading_factor(bearing);
    Command {
        v: v.clamp(0.0, lim.max_speed),
        w: (K_BEARING * bearing).clamp(-lim.max_turn_rate, lim.max_turn_rate),
        desired_distance: d,
    }
}

/// Curvature `κ = 2·y/L²` of the arc from the robot (at the origin, heading +x) through a
/// point at `(x, y)` in the robot's frame, `L² = x² + y²`; 0 at the robot itself.
pub fn pursuit_curvature(x: f64, y: f64) -> f64 {
    let l2 = x * x + y * y;
    if l2 > 0.0 { 2.0 * y / l2 } else { 0.0 }
}

/// The highest speed at which the arc of curvature `k` (1/m) is drivable at the turn-rate
/// limit, `ω_max / |k|` (seed 001 §VI: the controllers "account for the dynamic and kinematic
/// constraints of the robot"); unbounded on a straight line.
pub fn drivable_speed(k: f64, lim: &Limits) -> f64 {
    if k == 0.0 {
        f64::INFINITY
    } else {
        lim.max_turn_rate / k.abs()
    }
}

/// The person's estimated path: past estimates at least [`TRAIL_SPACING_M`] apart, and how
/// far along it the robot has come.
#[derive(Debug, Clone, Default)]
pub struct Trail {
    points: Vec<[f64; 2]>,
    progress: usize,
}

impl Trail {
    /// Add an estimate (kept when it moved at least [`TRAIL_SPACING_M`]).
    pub fn push(&mut self, p: [f64; 2]) {
        if self
            .points
            .last()
            .is_none_or(|l| (l[0] - p[0]).hypot(l[1] - p[1]) >= TRAIL_SPACING_M)
        {
            self.points.push(p);
        }
    }

    /// Pass the points the robot at `(x, y)` came within [`TRAIL_REACHED_M`] of, and those
    /// whose successor is nearer to it (the robot is already beyond them).
    pub fn advance(&mut self, x: f64, y: f64) {
        let dist = |p: [f64; 2]| (p[0] - x).hypot(p[1] - y);
        while self.progress + 1 < self.points.len() {
            let (p, q) = (self.points[self.progress], self.points[self.progress + 1]);
            if dist(p) >= TRAIL_REACHED_M && dist(q) > dist(p) {
                break;
            }
            self.progress += 1;
        }
        // bounded memory: forget what is well behind
        if self.progress > 512 {
            self.points.drain(..self.progress);
            self.progress = 0;
        }
    }

    pub fn clear(&mut self) {
        self.points.clear();
        self.progress = 0;
    }

    /// The points ahead of the robot, oldest first.
    pub fn ahead(&self) -> &[[f64; 2]] {
        self.points.get(self.progress..).unwrap_or(&[])
    }
}

/// Pure pursuit along `trail` towards the estimate (see the module doc).
pub fn pursuit(robot: &OdomPose, est: &Estimate, trail: &Trail, lim: &Limits) -> Command {
    let d = lim.desired_distance(robot.v);
    let ahead = trail.ahead();
    let target = est.position;
    let dist = |p: [f64; 2], q: [f64; 2]| (p[0] - q[0]).hypot(p[1] - q[1]);
    let here = [robot.x, robot.y];
    // distance to the target along the path: robot -> trail points -> target
    let mut along = 0.0;
    let mut from = here;
    for &p in ahead {
        along += dist(from, p);
        from = p;
    }
    along += dist(from, target);
    // never close in below the following distance, however long the path
    let range = dist(here, target);
    let gap = if range <= d { range - d } else { along - d };
    let goal = ahead
        .iter()
        .copied()
        .find(|&p| dist(here, p) >= LOOKAHEAD_M)
        .unwrap_or(target);
    let (c, s) = (robot.yaw.cos(), robot.yaw.sin());
    let (gx, gy) = (goal[0] - robot.x, goal[1] - robot.y);
    let (x, y) = (c * gx + s * gy, -s * gx + c * gy);
    let bearing = y.atan2(x);
    let speed_t = est.velocity[0].hypot(est.velocity[1]);
    let v = ((K_RANGE * gap + speed_t) * heading_factor(bearing)).clamp(0.0, lim.max_speed);
    let (v, w) = if x > 0.0 {
        let k = pursuit_curvature(x, y);
        let v = v.min(drivable_speed(k, lim));
        (v, k * v.max(PURSUIT_MIN_TURN_SPEED))
    } else {
        // the goal is beside or behind: turn towards it as fast as allowed, on a circle no
        // wider than its distance
        let v = v.min(lim.max_turn_rate * x.hypot(y) / 2.0);
        (v, lim.max_turn_rate * if y >= 0.0 { 1.0 } else { -1.0 })
    };
    Command {
        v,
        w: w.clamp(-lim.max_turn_rate, lim.max_turn_rate),
        desired_distance: d,
    }
}

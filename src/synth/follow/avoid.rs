//! The platform under the following controllers: a footprint that cannot pass through trees
//! and bushes, and a local obstacle check on the robot's own laser (our addition; seed 001 is
//! silent on both — its Segway RMP has "a human-size footprint" and drove 12 runs among
//! "scattered trees and small bushes", so it did not drive through them).
//!
//! - **Footprint** ([`Platform::radius_m`]): a disc. The closed loop stops the robot where a
//!   step would put the disc inside an obstacle's footprint (`synth::world::Obstacle`) and
//!   logs the contact (a bumper's report); the controllers know nothing of it.
//! - **Obstacle check** ([`apply`]), on by default (`avoid = false` is the controllers as
//!   printed): the scan's returns — without ground hits (below [`GROUND_Z_M`] in `odom` with
//!   the IMU's pitch) and without the target's own returns (within [`TARGET_CLEAR_M`] of its
//!   estimate) — with the earlier returns within [`MEMORY_RANGE_M`] that the laser, 0.25 m
//!   ahead of the base with a 180° view, no longer sees (beside and behind it:
//!   [`Surroundings`]) and the places of earlier contacts (a front bumper's report, kept
//!   within the same range whether the laser sees them or not: an obstacle whose widest
//!   section lies below the scan plane; issue 30, round 12), in the robot's planar frame; for the commanded arc, the path length before the disc grown by
//!   `margin_m` touches one ([`free_length`], closed form on the arc). The command stands when
//!   that length covers its stopping distance `v²/(2·a_min)` and one scan period of travel;
//!   else the nearest yaw rate of a fan that does, at the same
//!   speed; else the fan's arc allowing the highest speed, at that speed (its curvature kept);
//!   else — boxed in: no arc of the fan has `margin_m` of free path (issue 30, round 13; before,
//!   only no arc at all, and the robot crept at a few cm/s on the least-blocked arc, held
//!   against the obstacle while the person ran on) — a turn in place away from what blocks it
//!   ([`turn_away`]; its side held from scan to scan until the robot is free). A
//!   command to stand or turn in place is never changed (a disc turns in place) — unless the
//!   robot is still moving: a command slower than the robot's measured speed (a stop
//!   included) is judged at the speed the robot has, since it brakes along the commanded
//!   yaw rate's arc for its whole stopping distance; when no arc of the fan is clear for that
//!   distance, it brakes along the freest one (issue 30, round 14: before, a lost robot's stop
//!   turning towards the last prediction was never checked and braked into the trunk that
//!   had hidden the person).
//!
//! Written by hand: a dynamic-window style admissibility test on one scan, a few dozen lines
//! with no crate that fits (navigation stacks are frameworks, not functions).

use super::ScanInput;
use super::controller::{Command, Limits, OdomPose};
pub use crate::synth::scenario::Platform;
use nalgebra::{Isometry3, Point3};

/// Returns below this height in `odom` (m) are the ground (the pitched laser's ground hits).
pub const GROUND_Z_M: f64 = 0.1;
/// Returns within this distance of the target's estimate (m) are the target.
pub const TARGET_CLEAR_M: f64 = 0.6;
/// Below this measured speed (m/s) the robot stands: a stop is not checked (odometry noise).
pub const STANDING_MPS: f64 = 0.1;
/// One scan period (s): the command holds until the next scan.
pub const REACTION_S: f64 = 0.1;
/// Yaw rates in the fan, spread evenly over `±max_turn_rate`.
pub const FAN: usize = 31;
/// Returns are remembered where the laser no longer sees them while within this range (m).
pub const MEMORY_RANGE_M: f64 = 2.0;

/// The scan's obstacle returns in `odom` (see the module doc). `target`: the target's
/// estimate in `odom`.
pub fn obstacle_points(input: &ScanInput<'_>, target: Option<[f64; 2]>) -> Vec<[f64; 2]> {
    let g = &input.geometry;
    let mut out = Vec::new();
    for (k, &r) in input.ranges.iter().enumerate() {
        let r = f64::from(r);
        if !(r.is_finite() && r >= g.range_min && r < g.range_max) {
            continue;
        }
        let a = g.angle_min + k as f64 * g.angle_increment;
        let p = input.laser_pose * Point3::new(r * a.cos(), r * a.sin(), 0.0);
        if p.z < GROUND_Z_M {
            continue;
        }
        if target.is_some_and(|t| (p.x - t[0]).hypot(p.y - t[1]) < TARGET_CLEAR_M) {
            continue;
        }
        out.push([p.x, p.y]);
    }
    out
}

/// The returns the check looks at (all in `odom`): the current scan's, and earlier returns
/// within [`MEMORY_RANGE_M`] of the robot that the laser no longer sees (beside and behind it;
/// where the laser looks, its current scan replaces them, so a person who walked on leaves no
/// trail in view).
#[derive(Debug, Default)]
pub struct Surroundings {
    memory: Vec<[f64; 2]>,
    /// Where contacts were ([`Surroundings::bump`]), kept within [`MEMORY_RANGE_M`] whether
    /// the laser sees them or not.
    bumps: Vec<[f64; 2]>,
    /// The side of the boxed-in turn at the scan before (left: true), held while boxed in.
    boxed_left: Option<bool>,
}

impl Surroundings {
    /// The current scan's returns (`odom`) with the remembered ones the laser at `laser_pose`
    /// (`odom <- laser`) does not see, in the planar frame of `robot`; then `scan` joins the
    /// memory.
    pub fn around(
        &mut self,
        scan: Vec<[f64; 2]>,
        laser_pose: &Isometry3<f64>,
        robot: &OdomPose,
    ) -> Vec<[f64; 2]> {
        let to_laser = laser_pose.inverse();
        let z = laser_pose.translation.z;
        let near = |q: &[f64; 2]| (q[0] - robot.x).hypot(q[1] - robot.y) <= MEMORY_RANGE_M;
        self.memory
            .retain(|q| near(q) && (to_laser * Point3::new(q[0], q[1], z)).x <= 0.0);
        self.bumps.retain(near);
        let (s, c) = robot.yaw.sin_cos();
        let local = scan
            .iter()
            .chain(&self.memory)
            .chain(&self.bumps)
            .map(|q| {
                let (dx, dy) = (q[0] - robot.x, q[1] - robot.y);
                [c * dx + s * dy, -s * dx + c * dy]
            })
            .collect();
        self.memory.extend(scan.into_iter().filter(near));
        local
    }
}

impl Surroundings {
    /// A contact of the footprint of `radius` at `robot`: the obstacle is marked at the
    /// footprint's front, on the heading (a front bumper's report; issue 30, round 12), and
    /// stays among the returns the check looks at while within [`MEMORY_RANGE_M`].
    pub fn bump(&mut self, robot: &OdomPose, radius: f64) {
        let (s, c) = robot.yaw.sin_cos();
        self.bumps
            .push([robot.x + radius * c, robot.y + radius * s]);
    }
}

/// Path length (m) along the arc of curvature `k` (1/m, left positive) from the origin heading
/// +x before a disc of radius `radius` touches `p`, capped at `cap`; a point the disc already
/// covers blocks (0) when it lies ahead (`x > 0`) and is ignored behind.
pub fn point_free_length(p: [f64; 2], k: f64, radius: f64, cap: f64) -> f64 {
    let [x, y] = p;
    if x.hypot(y) <= radius {
        return if x > 0.0 { 0.0 } else { cap };
    }
    if k.abs() < 1e-9 {
        if x <= 0.0 || y.abs() > radius {
            return cap;
        }
        return (x - (radius * radius - y * y).sqrt()).clamp(0.0, cap);
    }
    // turning right is turning left in the mirror image
    let (y, rho) = if k > 0.0 {
        (y, 1.0 / k)
    } else {
        (-y, -1.0 / k)
    };
    // centre (0, rho); the robot starts at angle 0 measured from -y towards +x
    let (rx, ry) = (x, y - rho);
    let d = rx.hypot(ry);
    if (d - rho).abs() > radius {
        return cap;
    }
    let phi = rx.atan2(-ry).rem_euclid(std::f64::consts::TAU);
    let cos_alpha = ((rho * rho + d * d - radius * radius) / (2.0 * rho * d)).clamp(-1.0, 1.0);
    (rho * (phi - cos_alpha.acos()).max(0.0)).min(cap)
}

/// The least [`point_free_length`] over `points` for the footprint's `radius` grown by
/// `margin`; a point already inside the margin counts against the footprint alone (the margin
/// is kept where it can be, so a robot that came too close can still leave).
pub fn free_length(points: &[[f64; 2]], k: f64, radius: f64, margin: f64, cap: f64) -> f64 {
    let grown = radius + margin;
    points
        .iter()
        .map(|&p| {
            let r = if p[0].hypot(p[1]) <= grown {
                radius
            } else {
                grown
            };
            point_free_length(p, k, r, cap)
        })
        .fold(cap, f64::min)
}

/// The path a command at speed `v` needs clear: stopping distance and one scan of travel.
fn needed(v: f64, lim: &Limits) -> f64 {
    v * v / (2.0 * lim.max_decel) + v * REACTION_S
}

/// The highest speed whose [`needed`] length fits in `free`.
fn speed_for(free: f64, lim: &Limits) -> f64 {
    let a = lim.max_decel;
    a * (-REACTION_S + (REACTION_S * REACTION_S + 2.0 * free.max(0.0) / a).sqrt())
}

/// Boxed in: the turn in place, at least half the turn-rate limit, and whether it is to the
/// left: `keep`'s side when the robot was boxed in at the scan before (issue 30, round 14: the
/// side is held until the robot is free, since turning brings returns onto the side it turns
/// to, and choosing afresh at each scan made a dev run's robot wobble in place for 70 s);
/// otherwise away from the side the blocking returns (ahead, within the grown footprint) lie
/// on; towards the command's turn when they are balanced, left when that is nought too.
fn turn_away(
    w_cmd: f64,
    points: &[[f64; 2]],
    p: &Platform,
    lim: &Limits,
    keep: Option<bool>,
) -> (f64, bool) {
    let grown = p.radius_m + p.margin_m;
    let lateral: f64 = points
        .iter()
        .filter(|q| q[0] > 0.0 && q[0].hypot(q[1]) <= grown)
        .map(|q| q[1])
        .sum();
    let left = keep.unwrap_or(if lateral.abs() > 1e-9 {
        lateral < 0.0
    } else if w_cmd != 0.0 {
        w_cmd > 0.0
    } else {
        true
    });
    let w = w_cmd.abs().max(0.5 * lim.max_turn_rate);
    (if left { w } else { -w }, left)
}

impl Surroundings {
    /// [`apply`], holding a boxed-in turn's side from one scan to the next until the robot is
    /// no longer boxed in ([`turn_away`]).
    pub fn check(
        &mut self,
        cmd: Command,
        v_now: f64,
        points: &[[f64; 2]],
        lim: &Limits,
        p: &Platform,
    ) -> (Command, bool) {
        let (out, changed, boxed) = check(cmd, v_now, points, lim, p, self.boxed_left);
        self.boxed_left = boxed;
        (out, changed)
    }
}

/// The checked command and whether the check changed it (see the module doc), each scan on
/// its own (no boxed-in side held: [`Surroundings::check`] holds it). `v_now`: the robot's
/// measured forward speed.
pub fn apply(
    cmd: Command,
    v_now: f64,
    points: &[[f64; 2]],
    lim: &Limits,
    p: &Platform,
) -> (Command, bool) {
    let (out, changed, _) = check(cmd, v_now, points, lim, p, None);
    (out, changed)
}

/// [`apply`] with the side of the boxed-in turn at the scan before (`keep`); also returns the
/// side of this scan's boxed-in turn (`None`: not boxed in).
fn check(
    cmd: Command,
    v_now: f64,
    points: &[[f64; 2]],
    lim: &Limits,
    p: &Platform,
    keep: Option<bool>,
) -> (Command, bool, Option<bool>) {
    // the speed the arc is travelled at: the command's, or the robot's while it brakes
    let braking = v_now > cmd.v && v_now >= STANDING_MPS;
    let u = if braking { v_now } else { cmd.v };
    if !p.avoid || u <= 0.0 || points.is_empty() {
        return (cmd, false, None);
    }
    let need = needed(u, lim);
    // capped at no less than the margin, so a slow command's arcs can be told from a box
    let cap = need.max(p.margin_m);
    let free = |w: f64| free_length(points, w / u, p.radius_m, p.margin_m, cap);
    if free(cmd.w) >= need {
        return (cmd, false, None);
    }
    let fan: Vec<f64> = (0..FAN)
        .map(|i| lim.max_turn_rate * (2.0 * i as f64 / (FAN - 1) as f64 - 1.0))
        .collect();
    let frees: Vec<f64> = fan.iter().map(|&w| free(w)).collect();
    let closest = |ok: &dyn Fn(usize) -> bool| {
        (0..FAN)
            .filter(|&i| ok(i))
            .min_by(|&a, &b| (fan[a] - cmd.w).abs().total_cmp(&(fan[b] - cmd.w).abs()))
    };
    if let Some(i) = closest(&|i| frees[i] >= need) {
        return (Command { w: fan[i], ..cmd }, true, None);
    }
    // nothing clear at this speed: the arc allowing the highest speed, nearest the command
    let speeds: Vec<f64> = frees
        .iter()
        .map(|&f| speed_for(f, lim).min(cmd.v))
        .collect();
    let best = speeds.iter().copied().fold(0.0, f64::max);
    let most_free = frees.iter().copied().fold(0.0, f64::max);
    if most_free < p.margin_m || (!braking && best <= 1e-3) {
        let (w, left) = turn_away(cmd.w, points, p, lim, keep);
        return (Command { v: 0.0, w, ..cmd }, true, Some(left));
    }
    if braking {
        // it cannot stop sooner: brake along the arc with the most room
        let i = closest(&|i| frees[i] >= most_free).expect("the most room is one of them");
        return (
            Command {
                v: speeds[i],
                w: fan[i],
                ..cmd
            },
            true,
            None,
        );
    }
    let i = closest(&|i| speeds[i] >= best).expect("the best speed is one of them");
    let v = speeds[i];
    (
        Command {
            v,
            w: fan[i] / cmd.v * v,
            ..cmd
        },
        true,
        None,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Returns every 5° on a circle of `radius` round the robot.
    fn ring(radius: f64) -> Vec<[f64; 2]> {
        (0..72)
            .map(|i| {
                let a = i as f64 * 5f64.to_radians();
                [radius * a.cos(), radius * a.sin()]
            })
            .collect()
    }

    fn lim() -> Limits {
        Limits {
            following_distance: 3.2,
            max_speed: 3.5,
            max_accel: 1.4,
            max_decel: 1.4,
            max_turn_rate: 1.5,
        }
    }

    /// The arc's free length by walking it in 0.1 mm steps.
    fn walked(p: [f64; 2], k: f64, radius: f64, cap: f64) -> f64 {
        let step = 1e-4;
        let mut s = 0.0;
        while s < cap {
            let (x, y) = if k.abs() < 1e-9 {
                (s, 0.0)
            } else {
                ((k * s).sin() / k, (1.0 - (k * s).cos()) / k)
            };
            if (x - p[0]).hypot(y - p[1]) <= radius {
                return s;
            }
            s += step;
        }
        cap
    }

    #[test]
    fn free_length_on_a_line_and_on_a_circle_in_closed_form() {
        let r = 0.35;
        // straight: the disc's front reaches a point 0.2 m off the line
        let got = point_free_length([3.0, 0.2], 0.0, r, 10.0);
        assert!((got - (3.0 - (r * r - 0.04_f64).sqrt())).abs() < 1e-12);
        assert_eq!(point_free_length([3.0, 0.4], 0.0, r, 10.0), 10.0);
        // a point on a circle of radius 2 a quarter turn on: rho (pi/2 - 2 asin(r / 2 rho))
        let want = 2.0 * (std::f64::consts::FRAC_PI_2 - 2.0 * (r / 4.0).asin());
        for (p, k) in [([2.0, 2.0], 0.5), ([2.0, -2.0], -0.5)] {
            let got = point_free_length(p, k, r, 10.0);
            assert!((got - want).abs() < 1e-12, "{p:?} {k}: {got} vs {want}");
        }
        // already covered: blocks ahead, ignored behind
        assert_eq!(point_free_length([0.2, 0.1], 0.3, r, 5.0), 0.0);
        assert_eq!(point_free_length([-0.2, 0.1], 0.3, r, 5.0), 5.0);
    }

    #[test]
    fn free_length_agrees_with_walking_the_arc() {
        let mut worst: f64 = 0.0;
        for i in 0..12 {
            for j in 0..12 {
                let p = [-1.0 + 0.37 * i as f64, -2.2 + 0.41 * j as f64];
                if p[0].hypot(p[1]) <= 0.35 {
                    continue; // covered at the start: the rule above, not a walk
                }
                for k in [-1.3, -0.4, 0.0, 0.25, 0.9] {
                    let (a, b) = (point_free_length(p, k, 0.35, 4.0), walked(p, k, 0.35, 4.0));
                    worst = worst.max((a - b).abs());
                }
            }
        }
        assert!(worst < 2e-4, "worst {worst}");
    }

    #[test]
    fn memory_keeps_what_the_laser_no_longer_sees_nearby() {
        let at = |x: f64| OdomPose {
            x,
            y: 0.0,
            yaw: 0.0,
            v: 1.0,
        };
        // the laser 0.25 m ahead of the base, level, facing +x
        let laser = |x: f64| Isometry3::translation(x + 0.25, 0.0, 0.45);
        let mut s = Surroundings::default();
        // first scan at x = 0: a trunk point ahead-left, a walker ahead, something far ahead
        let first = vec![[1.0, 0.6], [1.5, 0.0], [3.0, 0.0]];
        assert_eq!(s.around(first, &laser(0.0), &at(0.0)).len(), 3);
        // at x = 1.2: the trunk point is beside and behind the laser (kept), the walker has
        // gone from the place the laser still sees (dropped), the far point is in view (dropped)
        let got = s.around(vec![[4.0, 0.0]], &laser(1.2), &at(1.2));
        assert_eq!(got.len(), 2, "{got:?}");
        assert!((got[1][0] - -0.2).abs() < 1e-12 && (got[1][1] - 0.6).abs() < 1e-12);
        // standing still, it stays remembered (memory is by place, not by time)
        for _ in 0..50 {
            assert_eq!(s.around(vec![], &laser(1.2), &at(1.2)).len(), 1);
        }
        // 2.5 m on, the trunk point is out of range
        assert_eq!(s.around(vec![], &laser(3.3), &at(3.3)).len(), 0);
    }

    #[test]
    fn a_contact_is_remembered_where_the_laser_looks_and_turns_the_robot_away() {
        let robot = OdomPose {
            x: 1.0,
            y: 2.0,
            yaw: std::f64::consts::FRAC_PI_2,
            v: 0.0,
        };
        // the laser 0.25 m ahead of the base (+y here), level
        let laser = |r: &OdomPose| {
            Isometry3::from_parts(
                nalgebra::Translation3::new(r.x, r.y + 0.25, 0.45),
                nalgebra::UnitQuaternion::from_euler_angles(0.0, 0.0, r.yaw),
            )
        };
        let p = Platform::default();
        let mut s = Surroundings::default();
        s.bump(&robot, p.radius_m);
        // in the robot's frame the bump is the footprint's front, though the laser looks there
        // and sees nothing; scan after scan it stays
        for _ in 0..3 {
            let got = s.around(vec![], &laser(&robot), &robot);
            assert_eq!(got.len(), 1, "{got:?}");
            assert!((got[0][0] - 0.35).abs() < 1e-12 && got[0][1].abs() < 1e-12);
        }
        // it blocks every arc ahead: a command to drive becomes a turn in place, at least half
        // the turn-rate limit, towards the command's turn (the bump is dead ahead)
        let cmd = Command {
            v: 2.0,
            w: 0.2,
            desired_distance: 4.6,
        };
        let points = s.around(vec![], &laser(&robot), &robot);
        let (got, changed) = apply(cmd, 0.0, &points, &lim(), &p);
        assert!(changed);
        assert_eq!((got.v, got.w), (0.0, 0.5 * lim().max_turn_rate));
        // 2 m away it is forgotten
        let away = OdomPose { y: -0.1, ..robot };
        assert_eq!(s.around(vec![], &laser(&away), &away).len(), 0);
    }

    #[test]
    fn a_clear_command_stands_and_standing_is_never_changed() {
        let cmd = Command {
            v: 2.0,
            w: 0.3,
            desired_distance: 4.6,
        };
        let far = [[20.0, 0.0], [0.0, 5.0]];
        assert_eq!(
            apply(cmd, 0.0, &far, &lim(), &Platform::default()),
            (cmd, false)
        );
        let turn = Command { v: 0.0, ..cmd };
        let wall = [[0.5, 0.0]];
        assert_eq!(
            apply(turn, 0.0, &wall, &lim(), &Platform::default()),
            (turn, false)
        );
        let off = Platform {
            avoid: false,
            ..Platform::default()
        };
        assert_eq!(apply(cmd, 0.0, &wall, &lim(), &off), (cmd, false));
    }

    /// A trunk on the right, clear of the straight path: a stop turning right at 0.73 rad/s
    /// from 2.5 m/s brakes along the arc of curvature −0.73/2.5 for 2.5²/2.8 + 0.25 m and
    /// meets it at 2.2 m; the check turns the braking onto the nearest clear yaw rate of the
    /// fan, still a stop. Standing (below 0.1 m/s), the same stop is not checked.
    #[test]
    fn a_stop_at_speed_is_judged_along_its_braking_arc() {
        let p = Platform::default();
        let stop = Command {
            v: 0.0,
            w: -0.73,
            desired_distance: 3.2,
        };
        let (u, k): (f64, f64) = (2.5, -0.73 / 2.5);
        let (rho, theta) = (-1.0 / k, 2.2 * -k);
        let centre = [rho * theta.sin(), -rho * (1.0 - theta.cos())];
        let trunk: Vec<[f64; 2]> = (0..36)
            .map(|i| {
                let a = i as f64 * 10f64.to_radians();
                [centre[0] + 0.15 * a.cos(), centre[1] + 0.15 * a.sin()]
            })
            .collect();
        let (r, m) = (p.radius_m, p.margin_m);
        let need = u * u / 2.8 + u * REACTION_S;
        assert!(free_length(&trunk, k, r, m, 10.0) < need);
        assert!(free_length(&trunk, 0.0, r, m, 10.0) >= need);
        let (got, changed) = apply(stop, u, &trunk, &lim(), &p);
        assert!(changed);
        assert_eq!(got.v, 0.0);
        assert!(free_length(&trunk, got.w / u, r, m, 10.0) >= need);
        // every yaw rate of the fan nearer the command's is blocked
        let fan = (0..FAN).map(|i| 1.5 * (2.0 * i as f64 / (FAN - 1) as f64 - 1.0));
        for w in fan.filter(|w| (w - stop.w).abs() < (got.w - stop.w).abs() - 1e-12) {
            assert!(free_length(&trunk, w / u, r, m, 10.0) < need, "{w}");
        }
        assert_eq!(apply(stop, 0.05, &trunk, &lim(), &p), (stop, false));
        // slowing from 2.5 to 1 m/s is judged at 2.5 m/s too (at its own 1 m/s it would
        // stand: the tighter arc passes inside the trunk)
        let slow = Command { v: 1.0, ..stop };
        assert!(free_length(&trunk, slow.w / slow.v, r, m, 10.0) >= needed(1.0, &lim()));
        let (got, _) = apply(slow, u, &trunk, &lim(), &p);
        assert!(
            free_length(&trunk, got.w / u, r, m, 10.0) >= need,
            "{got:?}"
        );
        // nothing clear for the braking distance (a ring 1.5 m round): it brakes along the
        // arc with the most room, still a stop
        let ring = ring(1.5);
        let (got, changed) = apply(stop, u, &ring, &lim(), &p);
        assert!(changed);
        assert_eq!(got.v, 0.0);
        let most = (0..FAN)
            .map(|i| 1.5 * (2.0 * i as f64 / (FAN - 1) as f64 - 1.0))
            .map(|w| free_length(&ring, w / u, r, m, need))
            .fold(0.0, f64::max);
        assert_eq!(free_length(&ring, got.w / u, r, m, need), most);
    }

    /// Boxed in, the side of the turn is held while the robot stays boxed in (the returns
    /// ahead moving to the other side as it turns would flip it), and chosen afresh once it
    /// was free.
    #[test]
    fn a_boxed_in_turn_keeps_its_side_until_the_robot_is_free() {
        let p = Platform::default();
        let cmd = Command {
            v: 3.0,
            w: 0.0,
            desired_distance: 6.4,
        };
        let (left, right) = ([[0.3, 0.1]], [[0.3, -0.1]]);
        assert_eq!(apply(cmd, 0.0, &left, &lim(), &p).0.w, -0.75);
        assert_eq!(apply(cmd, 0.0, &right, &lim(), &p).0.w, 0.75);
        let mut s = Surroundings::default();
        assert_eq!(s.check(cmd, 0.0, &left, &lim(), &p).0.w, -0.75);
        // turned right, the return is now on the right: still right
        assert_eq!(s.check(cmd, 0.0, &right, &lim(), &p).0.w, -0.75);
        // free for a scan: the side is forgotten
        let far = [[20.0, 0.0]];
        assert_eq!(s.check(cmd, 0.0, &far, &lim(), &p), (cmd, false));
        assert_eq!(s.check(cmd, 0.0, &right, &lim(), &p).0.w, 0.75);
    }

    #[test]
    fn a_bush_ahead_turns_the_command_onto_the_nearest_clear_arc() {
        let p = Platform::default();
        let cmd = Command {
            v: 2.0,
            w: 0.0,
            desired_distance: 4.6,
        };
        // a bush 2 m ahead, slightly left of the nose: returns on its near half
        let bush: Vec<[f64; 2]> = (0..20)
            .map(|i| {
                let a = std::f64::consts::PI * (0.5 + i as f64 / 19.0);
                [2.6 + 0.5 * a.cos(), 0.1 + 0.5 * a.sin()]
            })
            .collect();
        let need = 4.0 / 2.8 + 0.2;
        let (r, m) = (p.radius_m, p.margin_m);
        assert!(free_length(&bush, 0.0, r, m, 10.0) < need);
        let (got, changed) = apply(cmd, 0.0, &bush, &lim(), &p);
        assert!(changed);
        assert_eq!(got.v, cmd.v);
        // the nearest yaw rate of the fan that is clear, and it turns away (right)
        assert!(got.w < 0.0, "{got:?}");
        assert!(free_length(&bush, got.w / got.v, r, m, 10.0) >= need);
        let step = 2.0 * 1.5 / (FAN - 1) as f64;
        let nearer = got.w + step;
        assert!(free_length(&bush, nearer / got.v, r, m, 10.0) < need);
    }

    #[test]
    fn boxed_in_it_slows_to_what_the_room_allows_or_turns_in_place() {
        let p = Platform::default();
        let cmd = Command {
            v: 3.0,
            w: 0.0,
            desired_distance: 6.4,
        };
        // a ring of returns 1.5 m around the robot: every arc meets it within 1 m
        let ring = ring(1.5);
        let (got, changed) = apply(cmd, 0.0, &ring, &lim(), &p);
        assert!(changed);
        let free = free_length(&ring, got.w / got.v, p.radius_m, p.margin_m, 10.0);
        assert!(got.v > 0.0 && got.v < 3.0, "{got:?}");
        assert!((needed(got.v, &lim()) - free).abs() < 1e-9);
        // a ring 0.75 m round: 0.25 m of free path straight on (more than the margin), more
        // on the curved arcs; it slows to what the freest arc allows
        let mid: Vec<[f64; 2]> = ring.iter().map(|q| [q[0] * 0.5, q[1] * 0.5]).collect();
        let (got, _) = apply(cmd, 0.0, &mid, &lim(), &p);
        let free = free_length(&mid, got.w / got.v, p.radius_m, p.margin_m, 10.0);
        assert!(got.v >= speed_for(0.25, &lim()) - 1e-12, "{got:?}");
        assert!(
            (needed(got.v, &lim()) - free).abs() < 1e-9,
            "{got:?} {free}"
        );
        // inside the margin the footprint alone counts, and no arc has the margin's 0.15 m
        // free: boxed in, it turns in place rather than creeping against the ring
        let near: Vec<[f64; 2]> = ring.iter().map(|q| [q[0] * 0.3, q[1] * 0.3]).collect();
        let (got, _) = apply(cmd, 0.0, &near, &lim(), &p);
        assert_eq!((got.v, got.w.abs()), (0.0, 0.75), "{got:?}");
        // a trunk of 0.15 m radius just ahead and a little left: 0.1 m to it straight on, and
        // no arc of the fan clears the margin; turn in place, right, away from it
        let trunk: Vec<[f64; 2]> = (0..36)
            .map(|i| {
                let a = i as f64 * 10f64.to_radians();
                [0.60 + 0.15 * a.cos(), 0.05 + 0.15 * a.sin()]
            })
            .collect();
        let (got, _) = apply(cmd, 0.0, &trunk, &lim(), &p);
        assert_eq!((got.v, got.w), (0.0, -0.75), "{got:?}");
        // touching ahead: stop and turn in place away from the touch, left when balanced
        let (got, _) = apply(cmd, 0.0, &[[0.3, 0.1]], &lim(), &p);
        assert_eq!((got.v, got.w), (0.0, -0.75));
        let (got, _) = apply(cmd, 0.0, &[[0.3, 0.1], [0.3, -0.1]], &lim(), &p);
        assert_eq!((got.v, got.w), (0.0, 0.75));
    }
}

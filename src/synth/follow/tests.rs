//! Known answers of the controllers, the placeholder follower on hand-made scans, and the
//! closed loop on an analytic laser (a disc for the person) — no renderer, so it is fast.

use std::convert::Infallible;

use nalgebra::{Isometry3, Point3};

use super::avoid::Platform;
use super::closed_loop::{self, CaptureEvent, ClosedLoop, LoopSpec, Sensed, Sensors};
use super::controller::{self, Limits, OdomPose, SEARCH_SPEED_MPS, TRAIL_REACHED_M, Trail};
use super::nearest_blob::{LOST_AFTER_S, NearestBlobFollower};
use super::{Estimate, Follower, FollowerOutput, ScanInput};
use crate::laser::points::ScanGeometry;
use crate::synth::motion::DT;
use crate::synth::robot;
use crate::synth::scenario::{Controller, Estimator, Follow, Lost, Robot, RobotMode};
use crate::synth::world::Obstacle;
use crate::time::Nanos;

fn limits() -> Limits {
    Limits {
        following_distance: 1.8,
        max_speed: 2.4,
        max_accel: 1.4,
        max_decel: 2.0,
        max_turn_rate: 1.5,
    }
}

fn still(x: f64, y: f64) -> Estimate {
    Estimate {
        position: [x, y],
        velocity: [0.0, 0.0],
        covariance: [[0.01, 0.0], [0.0, 0.01]],
    }
}

fn at_origin(v: f64) -> OdomPose {
    OdomPose {
        x: 0.0,
        y: 0.0,
        yaw: 0.0,
        v,
    }
}

#[test]
fn desired_distance_adds_the_stopping_distance() {
    // d = 1.8 + v²/(2·a_min) = 1.8 + 4/4
    assert_eq!(limits().desired_distance(2.0), 2.8);
    assert_eq!(limits().desired_distance(0.0), 1.8);
}

#[test]
fn a_still_target_straight_ahead_at_the_desired_distance_needs_no_command() {
    let lim = limits();
    for v in [0.0, 1.0] {
        let robot = at_origin(v);
        let d = lim.desired_distance(v);
        let est = still(d, 0.0);
        let c = controller::direct(&robot, &est, &lim);
        assert_eq!((c.v, c.w, c.desired_distance), (0.0, 0.0, d));
        let c = controller::pursuit(&robot, &est, &Trail::default(), &lim);
        assert_eq!((c.v, c.w), (0.0, 0.0), "pursuit at v = {v}");
    }
    // farther: drive; nearer: stand
    assert!(controller::direct(&at_origin(0.0), &still(3.0, 0.0), &lim).v > 0.0);
    assert_eq!(
        controller::direct(&at_origin(0.0), &still(1.0, 0.0), &lim).v,
        0.0
    );
}

#[test]
fn the_turn_has_the_sign_of_the_bearing_error() {
    let lim = limits();
    let robot = at_origin(1.0);
    for (y, sign) in [(1.0, 1.0), (-1.0, -1.0)] {
        let est = still(3.0, y);
        let c = controller::direct(&robot, &est, &lim);
        assert_eq!(c.w.signum(), sign, "direct, target at y = {y}");
        let c = controller::pursuit(&robot, &est, &Trail::default(), &lim);
        assert_eq!(c.w.signum(), sign, "pursuit, target at y = {y}");
    }
    // saturates at the turn-rate limit
    let c = controller::direct(&robot, &still(-3.0, 0.1), &lim);
    assert_eq!(c.w, lim.max_turn_rate);
}

/// `search`: `v = min(K_r·ρ, 1.5)·(1 − 0.6·min(|β|, 1))`, `ω = K_β·β` clamped; at
/// the point, a turn in place at half the turn-rate limit.
#[test]
fn search_drives_to_the_point_at_its_top_speed_and_turns_in_place_there() {
    let lim = limits();
    let robot = at_origin(0.0);
    let ahead = controller::search(&robot, [5.0, 0.0], &lim);
    assert_eq!((ahead.v, ahead.w), (1.5, 0.0));
    let near = controller::search(&robot, [0.8, 0.0], &lim);
    assert!((near.v - 1.2 * 0.8).abs() < 1e-12, "{near:?}");
    let left = controller::search(&robot, [0.0, 5.0], &lim);
    assert!((left.v - 1.5 * 0.4).abs() < 1e-12, "{left:?}");
    assert_eq!(left.w, lim.max_turn_rate);
    let right = controller::search(&robot, [5.0, -0.5], &lim);
    let beta = (-0.5f64).atan2(5.0);
    assert!((right.w - 2.0 * beta).abs() < 1e-12);
    assert!((right.v - 1.5 * (1.0 - 0.6 * beta.abs())).abs() < 1e-12);
    let there = controller::search(&robot, [0.3, 0.2], &lim);
    assert_eq!((there.v, there.w), (0.0, 0.5 * lim.max_turn_rate));
}

#[test]
fn pure_pursuit_curvature_of_a_point_on_a_circle_is_its_inverse_radius() {
    // circle of radius R through the robot, tangent to its heading: centre (0, R)
    for r in [0.5_f64, 2.0, -3.0] {
        for phi in [0.1_f64, 0.7, 1.5] {
            let (x, y) = (r.abs() * phi.sin(), r * (1.0 - phi.cos()));
            let k = controller::pursuit_curvature(x, y);
            assert!((k - 1.0 / r).abs() < 1e-12, "R {r} phi {phi}: {k}");
            assert_eq!(k, 2.0 * y / (x * x + y * y));
        }
    }
    assert_eq!(controller::pursuit_curvature(0.0, 0.0), 0.0);
}

#[test]
fn pursuit_aims_along_the_trail_not_at_the_target() {
    // the person walked up the y axis then turned right: the robot (at the origin, facing +y)
    // aims at the trail point ahead, straight on, though the target is off to the right
    let lim = limits();
    let robot = OdomPose {
        x: 0.0,
        y: 0.0,
        yaw: std::f64::consts::FRAC_PI_2,
        v: 0.0,
    };
    let mut trail = Trail::default();
    for k in 0..=30 {
        trail.push([0.0, f64::from(k) * 0.1]);
    }
    trail.push([1.0, 3.0]);
    trail.advance(0.0, 0.0);
    let est = still(1.5, 3.0);
    let c = controller::pursuit(&robot, &est, &trail, &lim);
    assert!(c.w.abs() < 1e-9, "w {}", c.w);
    // distance along the path 3 + 1.5 = 4.5 m > 1.8 m: drive at K_r·2.7, capped
    assert_eq!(c.v, lim.max_speed);
    // direct following turns right, towards the target
    assert!(controller::direct(&robot, &est, &lim).w < 0.0);
}

#[test]
fn pursuit_drives_no_faster_than_its_arc_allows_at_the_turn_rate_limit() {
    // the goal (the only trail point, 1.03 m off) lies on an arc of curvature
    // 2·0.9/(0.5² + 0.9²) = 1.698 /m; the target is far along the path, so the range term
    // alone would command the speed limit (2.4 m/s), on which the arc needs 4.1 rad/s: the
    // speed is cut to ω_max/κ and the turn is the limit, so the robot drives the arc
    let lim = limits();
    let robot = at_origin(1.0);
    let mut trail = Trail::default();
    trail.push([0.5, 0.9]);
    trail.advance(0.0, 0.0);
    let est = still(10.0, 10.0);
    let c = controller::pursuit(&robot, &est, &trail, &lim);
    let k = 2.0 * 0.9 / (0.5 * 0.5 + 0.9 * 0.9);
    assert!((c.v - lim.max_turn_rate / k).abs() < 1e-12, "v {}", c.v);
    assert!((c.w - lim.max_turn_rate).abs() < 1e-12, "w {}", c.w);
    assert!((c.w / c.v - k).abs() < 1e-12);
    assert_eq!(controller::drivable_speed(0.0, &lim), f64::INFINITY);
    assert_eq!(controller::drivable_speed(-2.0, &lim), 0.75);
    // a goal behind (-1, -0.5), 1.118 m off: full turn to the right, on a circle no wider
    // than that distance: v = 1.5 · 1.118 / 2
    let mut trail = Trail::default();
    trail.push([-1.0, -0.5]);
    trail.advance(0.0, 0.0);
    let c = controller::pursuit(&robot, &est, &trail, &lim);
    assert_eq!(c.w, -lim.max_turn_rate);
    assert!(
        (c.v - lim.max_turn_rate * 1.25_f64.sqrt() / 2.0).abs() < 1e-12,
        "v {}",
        c.v
    );
}

/// A scan of discs (centres in the laser frame, radius) from a laser at the identity pose.
fn disc_scan(discs: &[([f64; 2], f64)]) -> (Vec<f32>, ScanGeometry) {
    let g = ScanGeometry {
        angle_min: -std::f64::consts::FRAC_PI_2,
        angle_increment: 0.5_f64.to_radians(),
        range_min: 0.05,
        range_max: 20.0,
    };
    let ranges = (0..361)
        .map(|k| {
            let a = g.angle(k);
            let (dx, dy) = (a.cos(), a.sin());
            discs
                .iter()
                .filter_map(|&([cx, cy], r)| {
                    let along = cx * dx + cy * dy;
                    let off2 = cx * cx + cy * cy - along * along;
                    (off2 <= r * r && along > 0.0).then(|| along - (r * r - off2).sqrt())
                })
                .fold(f64::INFINITY, f64::min) as f32
        })
        .collect();
    (ranges, g)
}

fn input<'a>(t: f64, ranges: &'a [f32], geometry: ScanGeometry) -> ScanInput<'a> {
    ScanInput {
        t,
        stamp: Nanos((t * 1e9) as u64),
        ranges,
        geometry,
        laser_pose: Isometry3::identity(),
        robot_pose: Isometry3::identity(),
        omni: None,
    }
}

#[test]
fn nearest_blob_starts_on_the_nearest_cluster_follows_it_and_loses_it() {
    let legs = |x: f64| [([x, 0.12], 0.06), ([x, -0.12], 0.06)];
    let tree = ([2.0, 1.5], 0.2);
    let mut f = NearestBlobFollower::new([2.2, 0.3]);
    let (r, g) = disc_scan(&[legs(2.0)[0], legs(2.0)[1], tree]);
    let out = f.on_scan(&input(0.0, &r, g));
    let e = out.estimate.expect("initialised");
    // the legs' front surfaces: a little in front of x = 2, between them in y
    assert!(
        (e.position[0] - 1.96).abs() < 0.04 && e.position[1].abs() < 0.02,
        "{e:?}"
    );
    // walking away at 1 m/s, seen every 0.1 s
    let mut last = e;
    for k in 1..=10 {
        let x = 2.0 + 0.1 * f64::from(k);
        let (r, g) = disc_scan(&[legs(x)[0], legs(x)[1], tree]);
        last = f
            .on_scan(&input(0.1 * f64::from(k), &r, g))
            .estimate
            .expect("tracked");
    }
    assert!((last.position[0] - 2.96).abs() < 0.04, "{last:?}");
    assert!(last.velocity[0] > 0.5 && last.velocity[0] < 1.1, "{last:?}");
    // gone: coasts, then `rst` once after LOST_AFTER_S, then nothing
    let (r, g) = disc_scan(&[tree]);
    let mut resets = Vec::new();
    for k in 11..=30 {
        let t = 0.1 * f64::from(k);
        let out = f.on_scan(&input(t, &r, g));
        if out.reset {
            resets.push(t);
        }
        if t <= 1.0 + LOST_AFTER_S - 1e-9 {
            let e = out.estimate.expect("coasting");
            assert!(e.covariance[0][0] > last.covariance[0][0]);
        }
    }
    assert_eq!(resets.len(), 1, "{resets:?}");
    assert!(
        (resets[0] - (1.0 + LOST_AFTER_S + 0.1)).abs() < 1e-9,
        "{resets:?}"
    );
    assert_eq!(f.on_scan(&input(3.1, &r, g)).estimate, None);
}

fn follow_spec() -> Follow {
    Follow {
        target: 1,
        distance: 1.8,
        max_speed: 2.4,
        max_accel: 1.4,
        pitch_deg_per_mps2: 7.0,
        pitch_tau_s: 0.3,
        closed_loop: true,
        controllers: vec![Controller::Pursuit],
        max_decel: Some(2.0),
        max_turn_rate: 1.5,
        estimator: Estimator::NearestBlob,
        pdaf: Default::default(),
        platform: Default::default(),
        lost: Default::default(),
    }
}

fn robot_spec() -> Robot {
    Robot {
        mode: RobotMode::Follow,
        pose: [0.0, 0.0, 0.0],
        follow: Some(follow_spec()),
        tour: None,
        odom_noise: [0.02, 0.01],
        odom_rate_hz: 50.0,
        imu_rate_hz: 100.0,
    }
}

/// An analytic 10 Hz laser at 0.4 m on the robot that sees one person's legs (discs) walking
/// along +x at `speed` from (3, 0.5), then a turn to +y at x = 12.
struct DiscWorld {
    speed: f64,
    base_from_laser: Isometry3<f64>,
    /// Static discs (trunks) in `map`: `(centre, radius)`.
    statics: Vec<([f64; 2], f64)>,
}

impl DiscWorld {
    fn person(&self, t: f64) -> [f64; 2] {
        let s = self.speed * t;
        if s < 9.0 {
            [3.0 + s, 0.5]
        } else {
            [12.0, 0.5 + s - 9.0]
        }
    }
}

impl Sensors for DiscWorld {
    type Error = Infallible;

    fn events(&self, _omni: bool) -> Vec<CaptureEvent> {
        (0..150)
            .map(|n| CaptureEvent {
                t_ns: 3_000_000 + n * 100_000_000,
                sensor: 0,
                n,
                omni: false,
            })
            .collect()
    }

    fn capture(
        &mut self,
        ev: &CaptureEvent,
        map_from_base: &Isometry3<f64>,
    ) -> Result<Sensed, Infallible> {
        let t = ev.t_ns as f64 * 1e-9;
        let p = self.person(t);
        let laser_from_map = (map_from_base * self.base_from_laser).inverse();
        let legs = [0.12, -0.12].iter().map(|dy| ([p[0], p[1] + dy], 0.06));
        let discs: Vec<([f64; 2], f64)> = legs
            .chain(self.statics.iter().copied())
            .map(|(c, r)| {
                let q = laser_from_map * Point3::new(c[0], c[1], 0.4);
                ([q.x, q.y], r)
            })
            .collect();
        let (ranges, geometry) = disc_scan(&discs);
        Ok(Sensed::Scan {
            stamp: Nanos(ev.t_ns),
            ranges,
            geometry,
            base_from_laser: self.base_from_laser,
        })
    }
}

fn run_disc_world(controller: Controller, follower: &mut dyn Follower) -> ClosedLoop {
    run_among(controller, follower, &[], Platform::default())
}

/// [`run_disc_world`] among `trunks` (footprints, and discs on the scan) on `platform`.
fn run_among(
    controller: Controller,
    follower: &mut dyn Follower,
    trunks: &[Obstacle],
    platform: Platform,
) -> ClosedLoop {
    let follow = Follow {
        platform,
        ..follow_spec()
    };
    run_follow(controller, follower, trunks, &follow)
}

/// [`run_among`] with the robot's whole `[robot.follow]` table.
fn run_follow(
    controller: Controller,
    follower: &mut dyn Follower,
    trunks: &[Obstacle],
    follow: &Follow,
) -> ClosedLoop {
    let robot = robot_spec();
    let spec = LoopSpec {
        robot: &robot,
        follow,
        controller,
        duration: 15.0,
        seed: 7,
        session: 0,
        obstacles: trunks,
    };
    let mut world = DiscWorld {
        speed: 1.2,
        base_from_laser: Isometry3::translation(0.25, 0.0, 0.4),
        statics: trunks.iter().map(|o| ([o.x, o.y], o.hx)).collect(),
    };
    match closed_loop::run(&spec, &mut world, follower) {
        Ok(r) => r,
        Err(e) => match e {},
    }
}

#[test]
fn the_closed_loop_follows_a_walker_with_both_controllers() {
    let world = DiscWorld {
        speed: 1.2,
        base_from_laser: Isometry3::identity(),
        statics: Vec::new(),
    };
    for controller in [Controller::Pursuit, Controller::Direct] {
        let mut f = NearestBlobFollower::new([3.0, 0.5]);
        let run = run_disc_world(controller, &mut f);
        assert_eq!(run.scans.len(), 150);
        assert!(
            run.scans.iter().all(|s| s.output.estimate.is_some()),
            "{controller:?} lost it"
        );
        // after the start-up, the range stays near the following distance and the robot
        // moves at the walker's speed
        for t in [6.0, 10.0, 14.0] {
            let s = run.track.state(t);
            let p = world.person(t);
            let range = (p[0] - s.x).hypot(p[1] - s.y);
            assert!(
                range > 1.5 && range < 3.5,
                "{controller:?} t {t}: range {range}"
            );
        }
        let s = run.track.state(14.0);
        assert!((s.v - 1.2).abs() < 0.4, "{controller:?}: v {}", s.v);
        // it pitched while accelerating
        let max_pitch = run
            .track
            .samples
            .iter()
            .map(|s| s.pitch)
            .fold(0.0, f64::max);
        assert!(max_pitch.to_degrees() > 3.0);
        // the loop's odometry is the one the log gets
        let odo = robot::odometry(&run.track, [0.02, 0.01], 50.0, 15.0, 7, 0);
        assert!(odo == run.odometry);
    }
}

/// Sees the target straight ahead 3 m away until `lost_at`, then nothing; with `look`, it
/// then gives that point (`odom`) as the target's last prediction.
struct LosesAt {
    lost_at: f64,
    look: Option<[f64; 2]>,
}

impl Follower for LosesAt {
    fn on_scan(&mut self, input: &ScanInput<'_>) -> FollowerOutput {
        let ahead = input.robot_pose * Point3::new(3.0, 0.0, 0.0);
        let seen = input.t < self.lost_at;
        FollowerOutput {
            estimate: seen.then(|| still(ahead.x, ahead.y)),
            reset: (input.t - self.lost_at).abs() < 0.05,
            look_at: if seen { None } else { self.look },
        }
    }
}

#[test]
fn a_lost_target_stops_the_robot_at_its_deceleration_limit() {
    let lost_at = 5.0;
    let run = run_disc_world(
        Controller::Direct,
        &mut LosesAt {
            lost_at,
            look: None,
        },
    );
    let first_none = run
        .scans
        .iter()
        .find(|s| s.output.estimate.is_none())
        .expect("lost");
    assert!(first_none.output.reset);
    assert_eq!(first_none.command.v, 0.0);
    let v0 = run.track.state(first_none.t).v;
    assert!(v0 > 1.0, "moving when lost: {v0}");
    let stopped_by = first_none.t + v0 / 2.0 + 2.0 * DT;
    let i = (stopped_by / DT).ceil() as usize;
    assert_eq!(run.track.samples[i].v, 0.0, "still moving at {stopped_by}");
    // and not before the deceleration limit allows
    let early = ((first_none.t + v0 / 2.0 - 3.0 * DT) / DT) as usize;
    assert!(run.track.samples[early].v > 0.0);
    // it pitches backwards while braking
    let min_pitch = run.track.samples[i - 60..i]
        .iter()
        .map(|s| s.pitch)
        .fold(0.0, f64::min);
    assert!(min_pitch.to_degrees() < -3.0, "{}", min_pitch.to_degrees());
    // without a last prediction it does not turn
    assert!(
        run.scans
            .iter()
            .filter(|s| s.t > lost_at)
            .all(|s| s.command.w == 0.0)
    );
}

/// Lost with a last prediction to its left: the robot stops and turns in place until it
/// faces that point (yaw = its bearing), at most at the turn-rate limit.
#[test]
fn a_lost_target_turns_the_stopped_robot_towards_its_last_prediction() {
    let lost_at = 3.0;
    // the robot starts at the origin heading +x (`robot_spec`); look far to its left
    let run = run_disc_world(
        Controller::Direct,
        &mut LosesAt {
            lost_at,
            look: Some([0.0, 40.0]),
        },
    );
    let end = run.track.samples.last().expect("samples");
    assert_eq!(end.v, 0.0);
    let bearing = (40.0 - end.y).atan2(-end.x);
    let err = crate::synth::robot::wrap(bearing - end.yaw);
    assert!(err.abs() < 0.05, "still {err} rad off the last prediction");
    let lim = limits();
    assert!(
        run.scans
            .iter()
            .all(|s| s.command.w.abs() <= lim.max_turn_rate)
    );
    assert!(run.scans.iter().any(|s| s.t > lost_at && s.command.w > 0.5));
}

/// With `lost = "search"` the lost robot drives to the last prediction instead of stopping,
/// and turns in place once there (our addition; issue 30, round 14).
#[test]
fn a_searching_robot_drives_to_the_last_prediction_and_turns_there() {
    let look = [6.0, 5.0];
    let follow = Follow {
        lost: Lost::Search,
        ..follow_spec()
    };
    let mut lose = LosesAt {
        lost_at: 3.0,
        look: Some(look),
    };
    let run = run_follow(Controller::Direct, &mut lose, &[], &follow);
    // where odometry puts it (the look point is in `odom`)
    let last = run.scans.last().expect("scans");
    let left = (look[0] - last.robot[0]).hypot(look[1] - last.robot[1]);
    assert!(
        left <= TRAIL_REACHED_M,
        "{left} m short at {:?}",
        last.robot
    );
    assert_eq!(last.command.v, 0.0);
    assert_eq!(last.command.w, 0.5 * limits().max_turn_rate);
    let top = run
        .scans
        .iter()
        .filter(|s| s.t > 3.0)
        .map(|s| s.command.v)
        .fold(0.0, f64::max);
    assert!(top > 1.0 && top <= SEARCH_SPEED_MPS, "{top}");
    // the paper's stop, for the same loss, stands where it braked
    let mut lose = LosesAt {
        lost_at: 3.0,
        look: Some(look),
    };
    let stopped = run_follow(Controller::Direct, &mut lose, &[], &follow_spec());
    let end = stopped.track.samples.last().expect("samples");
    assert!((look[0] - end.x).hypot(look[1] - end.y) > 3.0, "{end:?}");
}

/// A trunk 0.2 m off the robot's straight path to a still target 20 m ahead: the footprint's
/// 0.35 m cannot pass it.
fn trunk_on_the_way() -> Obstacle {
    Obstacle::disc(5.0, 0.2, 0.3)
}

/// Gives a still target at `at` (`odom`) at every scan.
struct Still {
    at: [f64; 2],
}

impl Follower for Still {
    fn on_scan(&mut self, _input: &ScanInput<'_>) -> FollowerOutput {
        FollowerOutput {
            estimate: Some(still(self.at[0], self.at[1])),
            reset: false,
            look_at: None,
        }
    }
}

fn closest_approach(run: &ClosedLoop, o: &Obstacle) -> f64 {
    run.track
        .samples
        .iter()
        .map(|s| o.distance(s.x, s.y))
        .fold(f64::INFINITY, f64::min)
}

/// Without the obstacle check the robot drives into the trunk: every step that would overlap it
/// deeper is refused (it stops there, and the next scan reports the contact) until turning
/// towards the target lets it slide off; it never gets closer than its footprint.
#[test]
fn the_footprint_cannot_pass_through_a_trunk() {
    let trunk = trunk_on_the_way();
    let blind = Platform {
        avoid: false,
        ..Platform::default()
    };
    let mut goal = Still { at: [20.0, 0.0] };
    let run = run_among(Controller::Direct, &mut goal, &[trunk], blind);
    let closest = closest_approach(&run, &trunk);
    assert!(closest >= blind.radius_m, "{closest}");
    assert!(
        closest < blind.radius_m + 0.05,
        "never reached it: {closest}"
    );
    let held: Vec<f64> = run
        .scans
        .iter()
        .filter(|s| s.contact)
        .map(|s| s.t)
        .collect();
    assert!(held.len() >= 3, "{held:?}");
    assert!(held.iter().all(|&t| run.track.state(t).v < 0.2));
    assert!(run.scans.iter().all(|s| !s.avoided));
}

/// With the check (the default) the laser sees the trunk, the command turns onto a clear arc,
/// and the robot passes it without touching, keeping the margin.
#[test]
fn the_obstacle_check_steers_the_robot_around_the_trunk() {
    let trunk = trunk_on_the_way();
    let p = Platform::default();
    let mut goal = Still { at: [20.0, 0.0] };
    let run = run_among(Controller::Direct, &mut goal, &[trunk], p);
    assert!(run.scans.iter().all(|s| !s.contact));
    assert!(run.scans.iter().any(|s| s.avoided));
    let closest = closest_approach(&run, &trunk);
    assert!(closest >= p.radius_m + 0.5 * p.margin_m, "{closest}");
    let end = run.track.samples.last().expect("samples");
    assert!(end.x > trunk.x + 5.0 && end.y.abs() < 1.0, "{end:?}");
}

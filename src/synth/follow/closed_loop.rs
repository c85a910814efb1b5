//! The closed loop: the robot stepped at [`DT`] with the balancing pitch of
//! [`robot::balance_and_drive`] and its jitter (the same random stream as the open-loop
//! follower), its odometry integrated tick by tick ([`Odometer`]), and at every capture of
//! the follower's laser (and, when the follower reads it, of the omni camera) the sensor
//! captured through [`Sensors`] at the robot's current true pose. The follower's output at a
//! scan sets the command until the next scan; the robot tracks the commanded speed within
//! its acceleration and deceleration (`a_min`) limits. Under the controllers sits the platform
//! ([`avoid`](super::avoid)): each command is checked against the scan, and a step that would
//! put the footprint inside an obstacle is not taken (the robot stops there; the next scan's
//! record says so, as a bumper would).
//!
//! Timing: a capture at `t` is processed once the track holds the samples on both sides of
//! `t` ([`RobotTrack::holds`]), so the true pose it sees is exactly what the finished track
//! gives the capture stage later — the scan the follower reads is bit for bit the one logged;
//! its command takes effect from the next step (at most one [`DT`] of latency).

use image::RgbImage;
use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use rand_distr::{Distribution, Normal};

use super::avoid;
use super::controller::{self, Command, Limits, OdomPose, Trail};
use super::{Follower, FollowerOutput, OmniInput, ScanInput};
use crate::geometry::camera::CameraModel;
use crate::laser::points::ScanGeometry;
use crate::rng;
use crate::synth::motion::DT;
use crate::synth::robot::{
    self, Odometer, OdometrySample, PITCH_JITTER_RAD, RobotState, RobotTrack,
};
use crate::synth::scenario::{Controller, Follow, Lost, Robot};
use crate::synth::world::Obstacle;
use crate::time::Nanos;

/// One capture the loop needs: time (ns since the session start), the sensor's index in the
/// rig and its frame number (as the capture schedule numbers them), and whether it is the
/// omni camera (else the follower's laser).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CaptureEvent {
    pub t_ns: u64,
    pub sensor: usize,
    pub n: u64,
    pub omni: bool,
}

/// What one capture gave.
pub enum Sensed {
    Scan {
        stamp: Nanos,
        ranges: Vec<f32>,
        geometry: ScanGeometry,
        base_from_laser: Isometry3<f64>,
    },
    Omni {
        stamp: Nanos,
        image: RgbImage,
        base_from_camera: Isometry3<f64>,
        model: CameraModel,
    },
}

/// The session's sensors as the loop sees them (the session implements it over its rig).
pub trait Sensors {
    type Error;
    /// The follower laser's captures and, when `omni`, the omni camera's, in time order.
    fn events(&self, omni: bool) -> Vec<CaptureEvent>;
    /// Capture `event` with the robot at `map_from_base` (its true pose).
    fn capture(
        &mut self,
        event: &CaptureEvent,
        map_from_base: &Isometry3<f64>,
    ) -> Result<Sensed, Self::Error>;
}

/// What the loop runs.
#[derive(Debug, Clone, Copy)]
pub struct LoopSpec<'a> {
    pub robot: &'a Robot,
    pub follow: &'a Follow,
    pub controller: Controller,
    pub duration: f64,
    /// The scenario seed (the robot's and the odometry's random streams) and session index.
    pub seed: u64,
    pub session: u64,
    /// The footprints the robot cannot enter (`map`, where the robot's true pose lives).
    pub obstacles: &'a [Obstacle],
}

/// The loop's answer at one scan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanRecord {
    pub t: f64,
    pub stamp: Nanos,
    pub output: FollowerOutput,
    pub command: Command,
    pub controller: Controller,
    /// The robot's odometry pose `[x, y, yaw]` in `odom` at the scan.
    pub robot: [f64; 3],
    /// The platform's obstacle check changed the controller's command.
    pub avoided: bool,
    /// The footprint touched an obstacle since the previous scan (a step was refused).
    pub contact: bool,
}

/// The closed-loop run: the robot's true track and every scan's record.
pub struct ClosedLoop {
    pub track: RobotTrack,
    pub scans: Vec<ScanRecord>,
    /// The odometry the loop integrated (equal to `robot::odometry` of `track`).
    pub odometry: Vec<OdometrySample>,
}

/// `odom <- base_link` from an odometry pose and the true pitch.
fn odom_from_base(pose: [f64; 3], pitch: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(pose[0], pose[1], 0.0),
        UnitQuaternion::from_euler_angles(0.0, pitch, pose[2]),
    )
}

/// The latest omni frame, posed in `odom`.
struct OmniFrame {
    stamp: Nanos,
    image: RgbImage,
    camera_pose: Isometry3<f64>,
    model: CameraModel,
}

/// Run the closed loop (see the module doc).
pub fn run<S: Sensors>(
    spec: &LoopSpec,
    sensors: &mut S,
    follower: &mut dyn Follower,
) -> Result<ClosedLoop, S::Error> {
    let f = spec.follow;
    let lim = Limits::of(f);
    let n = (spec.duration / DT).ceil() as usize + 2;
    let mut track = RobotTrack {
        samples: Vec::with_capacity(n),
    };
    let mut s = RobotState {
        x: spec.robot.pose[0],
        y: spec.robot.pose[1],
        yaw: spec.robot.pose[2].to_radians(),
        ..Default::default()
    };
    let mut r = rng::stream(spec.seed, "robot", spec.session);
    let jitter = Normal::new(0.0, PITCH_JITTER_RAD).expect("valid sigma");
    let mut odo = Odometer::new(
        spec.robot.odom_noise,
        spec.robot.odom_rate_hz,
        spec.duration,
        spec.seed,
        spec.session,
    );
    let events = sensors.events(follower.uses_omni());
    let mut next = 0;
    let mut omni: Option<OmniFrame> = None;
    let mut trail = Trail::default();
    let mut cmd = Command {
        v: 0.0,
        w: 0.0,
        desired_distance: lim.desired_distance(0.0),
    };
    let mut scans = Vec::new();
    let mut contact = false;
    let mut around = avoid::Surroundings::default();
    for _ in 0..n {
        track.samples.push(s);
        odo.advance(&track);
        while let Some(ev) = events.get(next) {
            let t = ev.t_ns as f64 * 1e-9;
            if !track.holds(t) {
                break;
            }
            next += 1;
            let truth = track.state(t);
            let Some((pose, v_odo)) = odo.pose_at(t) else {
                continue;
            };
            let odom_base = odom_from_base(pose, truth.pitch);
            match sensors.capture(ev, &truth.pose())? {
                Sensed::Omni {
                    stamp,
                    image,
                    base_from_camera,
                    model,
                } => {
                    omni = Some(OmniFrame {
                        stamp,
                        image,
                        camera_pose: odom_base * base_from_camera,
                        model,
                    });
                }
                Sensed::Scan {
                    stamp,
                    ranges,
                    geometry,
                    base_from_laser,
                } => {
                    let input = ScanInput {
                        t,
                        stamp,
                        ranges: &ranges,
                        geometry,
                        laser_pose: odom_base * base_from_laser,
                        robot_pose: odom_base,
                        omni: omni.as_ref().map(|o| OmniInput {
                            image: &o.image,
                            camera_pose: o.camera_pose,
                            model: &o.model,
                            stamp: o.stamp,
                        }),
                    };
                    let output = follower.on_scan(&input);
                    let robot = OdomPose {
                        x: pose[0],
                        y: pose[1],
                        yaw: pose[2],
                        v: v_odo,
                    };
                    let plain =
                        command((spec.controller, f.lost), &robot, &output, &mut trail, &lim);
                    let avoided;
                    (cmd, avoided) = if f.platform.avoid {
                        if contact {
                            around.bump(&robot, f.platform.radius_m);
                        }
                        let target = output.estimate.map(|e| e.position);
                        let scan = avoid::obstacle_points(&input, target);
                        let points = around.around(scan, &input.laser_pose, &robot);
                        around.check(plain, robot.v, &points, &lim, &f.platform)
                    } else {
                        (plain, false)
                    };
                    scans.push(ScanRecord {
                        t,
                        stamp,
                        output,
                        command: cmd,
                        controller: spec.controller,
                        robot: pose,
                        avoided,
                        contact,
                    });
                    contact = false;
                }
            }
        }
        let prev_v = s.v;
        s.v += (cmd.v - s.v).clamp(-lim.max_decel * DT, lim.max_accel * DT);
        s.w = cmd.w;
        let before = (s.x, s.y);
        robot::balance_and_drive(&mut s, prev_v, f, jitter.sample(&mut r));
        if blocked(spec.obstacles, f.platform.radius_m, before, (s.x, s.y)) {
            (s.x, s.y) = before;
            s.v = 0.0;
            contact = true;
        }
    }
    Ok(ClosedLoop {
        track,
        scans,
        odometry: odo.samples,
    })
}

/// Whether a step of a footprint of `radius` from `from` to `to` runs into an obstacle: it
/// ends overlapping one, deeper than it started (a footprint set down overlapping can leave).
pub fn blocked(obstacles: &[Obstacle], radius: f64, from: (f64, f64), to: (f64, f64)) -> bool {
    radius > 0.0
        && obstacles.iter().any(|o| {
            let d = o.distance(to.0, to.1);
            d < radius && d < o.distance(from.0, from.1)
        })
}

/// The controller's command for one scan's output (and, while the target is lost, what
/// `lost` says); keeps the trail of estimates.
fn command(
    (controller, lost): (Controller, Lost),
    robot: &OdomPose,
    output: &FollowerOutput,
    trail: &mut Trail,
    lim: &Limits,
) -> Command {
    if output.reset {
        trail.clear();
    }
    let Some(est) = &output.estimate else {
        trail.clear();
        return match (lost, output.look_at) {
            (Lost::Search, Some(p)) => controller::search(robot, p, lim),
            _ => controller::stop(robot, output.look_at, lim),
        };
    };
    trail.push(est.position);
    trail.advance(robot.x, robot.y);
    match controller {
        Controller::Direct => controller::direct(robot, est, lim),
        Controller::Pursuit => controller::pursuit(robot, est, trail, lim),
    }
}

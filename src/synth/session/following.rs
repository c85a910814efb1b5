//! The closed following loop of a session (`[robot.follow] closed_loop = true`): the rig's
//! follower laser and omni camera as the loop's [`Sensors`] (the same scenes, noise keys and
//! schedule as the capture stage, so the loop reads exactly what is logged), the follower the
//! scenario names, and the follower's per-scan state on `/follower/state`. The robot starts
//! in front of its target, facing it (the scenario's `[robot] pose` gives the direction it
//! comes from); the crowd's crossers are still planned against the open-loop robot.

use image::RgbImage;
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion};

use super::capture::schedule;
use super::rig::{Channels, Rig, SensorRuntime};
use super::types::{Session, SynthError};
use crate::geometry::camera::CameraModel;
use crate::groundtruth::FollowerState;
use crate::laser::points::ScanGeometry;
use crate::log::SessionWriter;
use crate::synth::follow::closed_loop::{
    self, CaptureEvent, ClosedLoop, LoopSpec, Sensed, Sensors,
};
use crate::synth::follow::make_follower;
use crate::synth::world::Primitive;

/// A closed loop starts the robot at most this far (m) beyond the following distance from
/// its target, facing it.
const START_GAP_M: f64 = 1.0;

/// The rig's sensors that feed the follower.
struct LoopSensors<'a> {
    ses: &'a Session<'a>,
    rig: &'a Rig,
    /// The first robot-mounted laser, and the first robot-mounted omni camera.
    laser: usize,
    omni: Option<usize>,
    dynamic: Vec<Primitive>,
}

impl Sensors for LoopSensors<'_> {
    type Error = SynthError;

    fn events(&self, omni: bool) -> Vec<CaptureEvent> {
        schedule(
            &self.rig.sensors,
            self.ses.seed,
            self.ses.s.scenario.duration_s,
        )
        .into_iter()
        .filter_map(|(t_ns, sensor, n)| {
            let is_omni = omni && Some(sensor) == self.omni;
            (sensor == self.laser || is_omni).then_some(CaptureEvent {
                t_ns,
                sensor,
                n,
                omni: is_omni,
            })
        })
        .collect()
    }

    fn capture(
        &mut self,
        ev: &CaptureEvent,
        map_from_base: &Isometry3<f64>,
    ) -> Result<Sensed, SynthError> {
        let t = ev.t_ns as f64 * 1e-9;
        let scene = self.ses.scene(t, *map_from_base, &mut self.dynamic);
        match &self.rig.sensors[ev.sensor] {
            SensorRuntime::Laser(l) => {
                let (ranges, _) = self.ses.cast_scan(l, (ev.sensor, ev.n), &scene);
                let spec = &l.spec;
                // the geometry as a reader decodes it from the logged f32 fields
                let geometry = ScanGeometry {
                    angle_min: f64::from(spec.angle_min() as f32),
                    angle_increment: f64::from(spec.increment as f32),
                    range_min: f64::from(spec.range_min as f32),
                    range_max: f64::from(spec.range_max as f32),
                };
                Ok(Sensed::Scan {
                    stamp: scene.stamp,
                    ranges,
                    geometry,
                    base_from_laser: l.mount,
                })
            }
            SensorRuntime::Camera(c) => {
                let (frame, _) = self.ses.render_camera(c, (ev.sensor, ev.n), &scene);
                let image =
                    RgbImage::from_raw(frame.width, frame.height, frame.rgb).ok_or_else(|| {
                        SynthError::Encode {
                            camera: c.frame_id.clone(),
                            reason: "frame size".into(),
                        }
                    })?;
                Ok(Sensed::Omni {
                    stamp: scene.stamp,
                    image,
                    base_from_camera: c.mount,
                    model: c.cam.model.clone(),
                })
            }
        }
    }
}

/// Run the closed loop of session `session` when the scenario asks for one: `None` for an
/// open-loop scenario. `ses` is the session with the nominal (open-loop) robot track.
pub(super) fn run(
    ses: &Session,
    rig: &Rig,
    session: u64,
) -> Result<Option<ClosedLoop>, SynthError> {
    let s = ses.s;
    let Some(f) = s.robot.follow.as_ref().filter(|f| f.closed_loop) else {
        return Ok(None);
    };
    let laser = rig
        .sensors
        .iter()
        .position(|x| matches!(x, SensorRuntime::Laser(l) if l.on_robot));
    let Some(laser) = laser else {
        return Err(SynthError::Scenario(
            "robot.follow.closed_loop needs a laser on the robot".into(),
        ));
    };
    let omni = rig.sensors.iter().position(|x| {
        matches!(x, SensorRuntime::Camera(c) if c.on_robot && !matches!(c.cam.model, CameraModel::Pinhole(_)))
    });
    // a person points the robot at its target: its true position where it first appears,
    // in odom (odom starts at the robot's start pose)
    let target = ses
        .people
        .iter()
        .find(|a| a.body.id == f.target)
        .and_then(|a| a.track.position(a.track.start))
        .ok_or_else(|| SynthError::Scenario("robot.follow.target is never present".into()))?;
    // ... standing in front of it, as the paper's runs start: the robot starts facing the
    // target, at most START_GAP_M beyond the following distance from it on the line from the
    // scenario's start position (a 180° laser with a 20 m range sees nothing behind or far)
    let mut robot = s.robot.clone();
    let (dx, dy) = (target.0 - robot.pose[0], target.1 - robot.pose[1]);
    let dist = dx.hypot(dy);
    let gap = dist.min(f.distance + START_GAP_M);
    if dist > 0.0 {
        robot.pose = [
            target.0 - dx / dist * gap,
            target.1 - dy / dist * gap,
            dy.atan2(dx).to_degrees(),
        ];
    }
    let start = Isometry3::from_parts(
        Translation3::new(robot.pose[0], robot.pose[1], 0.0),
        UnitQuaternion::from_euler_angles(0.0, 0.0, robot.pose[2].to_radians()),
    );
    let init = start.inverse() * Point3::new(target.0, target.1, 0.0);
    let mut follower = make_follower(f, [init.x, init.y]);
    let controller = f.controllers[session as usize % f.controllers.len().max(1)];
    let spec = LoopSpec {
        robot: &robot,
        follow: f,
        controller,
        duration: s.scenario.duration_s,
        seed: s.scenario.seed,
        session,
        obstacles: &ses.world.obstacles,
    };
    let mut sensors = LoopSensors {
        ses,
        rig,
        laser,
        omni,
        dynamic: Vec::new(),
    };
    closed_loop::run(&spec, &mut sensors, follower.as_mut()).map(Some)
}

/// Write every scan's follower state on `/follower/state` (frame `odom`), logged at its stamp.
pub(super) fn write_states(
    w: &mut SessionWriter,
    ch: &Channels,
    run: &ClosedLoop,
) -> Result<(), SynthError> {
    let Some(channel) = ch.follower else {
        return Ok(());
    };
    for rec in &run.scans {
        let e = rec.output.estimate;
        w.write_json(
            channel,
            rec.stamp,
            &FollowerState {
                stamp_ns: rec.stamp.0,
                frame_id: "odom".into(),
                position: e.map(|e| e.position),
                velocity: e.map(|e| e.velocity),
                covariance: e.map(|e| e.covariance),
                reset: rec.output.reset,
                controller: rec.controller.name().into(),
                command_v: rec.command.v,
                command_w: rec.command.w,
                desired_distance: rec.command.desired_distance,
                robot: rec.robot,
                look_at: rec.output.look_at,
                avoided: rec.avoided,
                contact: rec.contact,
            },
        )?;
    }
    Ok(())
}

//! The robot's own streams: wheel odometry with the `odom -> base_link` and `map -> odom`
//! transforms (perfect localisation), and the IMU.

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use rand::RngExt;

use super::rig::{Channels, quat, tf};
use super::types::{Clock, SynthError};
use crate::log::SessionWriter;
use crate::log::msgs::{Header, Imu, Odometry, Pose, TfMessage};
use crate::rng;
use crate::synth::robot::{self, RobotTrack};
use crate::synth::scenario::Scenario;
use crate::time::Nanos;

/// Odometry (with its TF) at the robot's odometry rate, logged 1 ms after the stamp.
pub(super) fn write_odometry(
    w: &mut SessionWriter,
    ch: &Channels,
    s: &Scenario,
    robot_track: &RobotTrack,
    session: u64,
    clock: Clock,
) -> Result<(), SynthError> {
    let dur = s.scenario.duration_s;
    let odo = robot::odometry(
        robot_track,
        s.robot.odom_noise,
        s.robot.odom_rate_hz,
        dur,
        s.scenario.seed,
        session,
    );
    for (t, [x, y, yaw], v, wz) in &odo {
        let stamp = clock.at(*t);
        let log = Nanos(stamp.0 + 1_000_000);
        let odom_from_base = Isometry3::from_parts(
            Translation3::new(*x, *y, 0.0),
            UnitQuaternion::from_euler_angles(0.0, 0.0, *yaw),
        );
        let truth = robot_track.state(*t).pose();
        // perfect localisation: map -> odom makes map -> base_link equal the true pose
        let map_from_odom = truth * odom_from_base.inverse();
        w.write(
            ch.odom,
            log,
            &Odometry {
                header: Header::new(stamp, "odom"),
                child_frame_id: "base_link".into(),
                pose: Pose {
                    position: Point3::new(*x, *y, 0.0),
                    orientation: quat(&odom_from_base.rotation),
                },
                pose_covariance: [0.0; 36],
                linear: Vector3::new(*v, 0.0, 0.0),
                angular: Vector3::new(0.0, 0.0, *wz),
                twist_covariance: [0.0; 36],
            },
        )?;
        w.write(
            ch.tf,
            log,
            &TfMessage {
                transforms: vec![
                    tf("odom", "base_link", stamp, &odom_from_base),
                    tf("map", "odom", stamp, &map_from_odom),
                ],
            },
        )?;
    }
    Ok(())
}

/// The IMU at its rate, logged 0.5 ms after the stamp: orientation, angular rates and the
/// specific force, with uniform noise.
pub(super) fn write_imu(
    w: &mut SessionWriter,
    ch: &Channels,
    s: &Scenario,
    robot_track: &RobotTrack,
    session: u64,
    clock: Clock,
) -> Result<(), SynthError> {
    let dur = s.scenario.duration_s;
    let imu_dt = 1.0 / s.robot.imu_rate_hz;
    let mut imu_rng = rng::stream(s.scenario.seed, "imu", session);
    let mut k = 0u64;
    loop {
        let t = k as f64 * imu_dt;
        if t >= dur {
            break;
        }
        let st = robot_track.state(t);
        let q = UnitQuaternion::from_euler_angles(0.0, st.pitch, st.yaw);
        let a_world = Vector3::new(st.accel * st.yaw.cos(), st.accel * st.yaw.sin(), 9.81);
        let f = q.inverse() * a_world;
        let n = |r: &mut rand_chacha::ChaCha8Rng, s: f64| s * (r.random::<f64>() - 0.5) * 3.46;
        let stamp = clock.at(t);
        w.write(
            ch.imu,
            Nanos(stamp.0 + 500_000),
            &Imu {
                header: Header::new(stamp, "base_link"),
                orientation: quat(&q),
                orientation_covariance: [0.0; 9],
                angular_velocity: Vector3::new(
                    n(&mut imu_rng, 0.002),
                    st.pitch_rate + n(&mut imu_rng, 0.002),
                    st.w + n(&mut imu_rng, 0.002),
                ),
                angular_velocity_covariance: [0.0; 9],
                linear_acceleration: f + Vector3::new(
                    n(&mut imu_rng, 0.02),
                    n(&mut imu_rng, 0.02),
                    n(&mut imu_rng, 0.02),
                ),
                linear_acceleration_covariance: [0.0; 9],
            },
        )?;
        k += 1;
    }
    Ok(())
}

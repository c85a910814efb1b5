//! The closed following loop of seed 001 §VI: the synthesizer's robot driven by a tracker's
//! estimate at every scan instead of by the target's true track, so a lost target makes the
//! robot stop (and, decelerating, pitch), as on the paper's Segway RMP.
//!
//! - The estimator interface: a [`Follower`] gets at every scan of the robot's laser exactly
//!   the ranges `/scan` will carry, the robot's odometry pose (what `/odom` will say at that
//!   time) with the true pitch an IMU reads, and the latest omni frame; it returns an
//!   [`Estimate`] in `odom` or `None` (target lost). [`make_follower`] builds the one a
//!   scenario names; the PDAF tracker of `laser` plugs in there (`laser` is a lower layer: the
//!   synthesizer calls it, never the reverse).
//! - [`nearest_blob`]: the placeholder baseline estimator (nearest return cluster in a gate).
//! - [`pdaf`]: the paper's estimator, `laser::follow` in its paper configuration
//!   (coordinated-turn PDAF with the colour likelihood).
//! - [`controller`]: direct following and pure pursuit on the estimated path, at the desired
//!   following distance `d_follow + v²/(2·a_min)` (the term seed 001's `E_follow` subtracts).
//! - [`avoid`]: the platform under the controllers — a footprint that cannot pass through
//!   obstacles and a check of each command against the scan (our addition).
//! - [`closed_loop`]: steps the robot at [`crate::synth::motion::DT`] with the balancing pitch,
//!   captures the follower's sensors at the capture schedule's instants through a
//!   [`closed_loop::Sensors`] the session provides, and records every scan's output.
//!
//! Not modelled: the crowd that crosses between the robot and the target
//! (`[crowd] cross_between_robot_and`) is planned against the *nominal* open-loop track
//! (`robot::simulate`), because the closed-loop track does not exist when the crowd is cast;
//! crossers therefore cross where the open-loop robot would have been, which is near, not on,
//! the line to the closed-loop robot.

pub mod avoid;
pub mod closed_loop;
pub mod controller;
pub mod nearest_blob;
pub mod pdaf;
#[cfg(test)]
mod tests;

use image::RgbImage;
use nalgebra::Isometry3;

use crate::geometry::camera::CameraModel;
use crate::laser::points::ScanGeometry;
use crate::synth::scenario::{Estimator, Follow};
use crate::time::Nanos;

/// One omni camera frame as the follower sees it.
pub struct OmniInput<'a> {
    pub image: &'a RgbImage,
    /// `odom <- camera` at the frame's capture time (odometry pose, true pitch, the mount).
    pub camera_pose: Isometry3<f64>,
    pub model: &'a CameraModel,
    pub stamp: Nanos,
}

/// What the follower gets at one scan.
pub struct ScanInput<'a> {
    /// Seconds since the session start (capture time).
    pub t: f64,
    /// Header stamp as written to the log.
    pub stamp: Nanos,
    /// Exactly the ranges written to `/scan`.
    pub ranges: &'a [f32],
    pub geometry: ScanGeometry,
    /// `odom <- laser`: the robot's odometry pose (x, y, yaw as integrated, what `/odom`
    /// says at this time) with the true pitch and roll (an IMU reads those) and the mount.
    pub laser_pose: Isometry3<f64>,
    /// `odom <- base_link`, same source.
    pub robot_pose: Isometry3<f64>,
    /// The latest omni frame captured at or before `t` (`None` before the first, or when
    /// the follower does not use it: [`Follower::uses_omni`]).
    pub omni: Option<OmniInput<'a>>,
}

/// The target's estimate in `odom`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    pub position: [f64; 2],
    pub velocity: [f64; 2],
    pub covariance: [[f64; 2]; 2],
}

/// The follower's answer to one scan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FollowerOutput {
    /// `None`: target lost, the robot stops.
    pub estimate: Option<Estimate>,
    /// `rst` fired at this scan (the track was dropped to be re-initialised).
    pub reset: bool,
    /// While lost: where the target was last predicted (`odom`); the robot stops and turns
    /// towards it. `None`: stop without turning.
    pub look_at: Option<[f64; 2]>,
}

/// A target estimator fed scan by scan, in time order.
pub trait Follower {
    fn on_scan(&mut self, input: &ScanInput<'_>) -> FollowerOutput;

    /// Whether [`Follower::on_scan`] reads the omni frame. When false the loop renders no
    /// omni frame (the capture stage still renders and logs every one), which keeps a
    /// laser-only estimator from doubling a session's rendering time.
    fn uses_omni(&self) -> bool {
        true
    }
}

/// The estimator `spec.estimator` names, initialised on the target near `init` (`odom`).
pub fn make_follower(spec: &Follow, init: [f64; 2]) -> Box<dyn Follower> {
    match spec.estimator {
        Estimator::NearestBlob => Box::new(nearest_blob::NearestBlobFollower::new(init)),
        Estimator::Pdaf => Box::new(pdaf::PdafFollower::new(&spec.pdaf, init)),
    }
}

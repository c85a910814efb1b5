//! The types the stages of a session share: the synthesizer's error, the actors (a person's
//! body and motion), the preview of one instant, the session's clock, what the capture reads
//! ([`Session`]) and the scene at one instant ([`Scene`]).

use image::RgbImage;
use nalgebra::Isometry3;

use crate::groundtruth::{CameraView, PersonTruth};
use crate::log::LogError;
use crate::synth::motion::Track;
use crate::synth::person::{Body, PersonState};
use crate::synth::robot::RobotTrack;
use crate::synth::scenario::Scenario;
use crate::synth::world::{Primitive, World};
use crate::time::Nanos;

#[derive(Debug, thiserror::Error)]
pub enum SynthError {
    #[error(transparent)]
    Log(#[from] LogError),
    #[error("{0}")]
    Scenario(String),
    #[error("encoding a frame of {camera}: {reason}")]
    Encode { camera: String, reason: String },
}

/// A person in a session: body and motion.
pub struct Actor {
    pub body: Body,
    pub track: Track,
}

/// One camera's frame for the preview and what it saw of each person `(id, view)`.
pub type PreviewCamera = (String, RgbImage, Vec<(u32, CameraView)>);

/// What the preview sheet shows: one instant of the session.
pub struct PreviewData {
    pub t: f64,
    pub cameras: Vec<PreviewCamera>,
    /// Laser returns in the map frame.
    pub scan_points: Vec<[f64; 2]>,
    pub people: Vec<PersonTruth>,
    pub robot: [f64; 3],
    pub sensors: Vec<(String, [f64; 3])>,
    pub world: World,
}

/// Log time of session time `t` (s): the session's epoch plus `t`, rounded to the nanosecond.
#[derive(Debug, Clone, Copy)]
pub(super) struct Clock {
    pub t0: Nanos,
}

impl Clock {
    pub fn at(&self, t: f64) -> Nanos {
        Nanos(self.t0.0 + (t * 1e9).round() as u64)
    }
}

/// What the capture of a session reads.
pub(super) struct Session<'a> {
    pub s: &'a Scenario,
    pub world: &'a World,
    pub people: &'a [Actor],
    pub robot_track: &'a RobotTrack,
    /// The session's seed (noise keys, latencies, laser phases).
    pub seed: u64,
    pub clock: Clock,
    /// Height of the laser plane where the ground truth measures legs (m).
    pub laser_height: f64,
}

/// What every sensor sees at one instant.
pub(super) struct Scene<'a> {
    pub t: f64,
    pub stamp: Nanos,
    /// `map_from_base_link` of the robot.
    pub base: Isometry3<f64>,
    /// `(index in people, state)` of everyone present.
    pub states: Vec<(usize, PersonState)>,
    /// Moving background, then every present person's primitives.
    pub dynamic: &'a [Primitive],
    /// Each present person's primitives, in the order of `states`.
    pub per_person: Vec<Vec<Primitive>>,
    /// Floor shadows `[x, y, r]`, in the order of `states`.
    pub shadows: Vec<[f64; 3]>,
}

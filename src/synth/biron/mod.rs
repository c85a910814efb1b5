//! The BIRON dataset (`biron_home`, seed 003, issue 33): one session of a home-like room
//! where BIRON — a standing robot with a laser at 30 cm, two microphones 28.1 cm apart at
//! 106 cm and a pan-tilt colour camera at 141 cm (seed 003 §III) — watches visitors come,
//! stand, turn their heads and talk ([`script`]); the audio of every condition of the
//! acoustic grid is rendered first ([`audio`]), then the session runs in closed loop
//! ([`closed_loop`]): at each camera frame the attention system of [`crate::anchoring`] sees
//! exactly the logged scans, image and sound, and its output turns the pan-tilt unit for the
//! next frame (as E2's robot is driven by its tracker). Ground truth per step ([`truth`]).
//!
//! Channels: `/scan`, `/camera/image_raw/compressed` (JPEG) + `/camera/camera_info`,
//! `/ptu/joint_states` and the camera's pose on `/tf`, `/audio` (`audio_common_msgs`
//! AudioDataStamped, S16LE, 2 channels, 16 kHz, 1024-frame chunks) + `/audio_info` (once) at
//! the nominal condition, and `/audio_grid/rt60_<ms>ms_snr_<dB>db/audio` (+ `audio_info`) for
//! every cell of the grid (the nominal one again), `/attention/state`, `/ground_truth/{people,biron,utterances}`.

pub mod audio;
mod closed_loop;
pub mod gaze;
pub mod noise;
pub mod room;
pub mod script;
pub mod speech;
mod truth;

use std::collections::BTreeMap;
use std::path::Path;

use nalgebra::{Isometry3, Quaternion, UnitQuaternion};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::log::msgs::{Header, Transform, TransformStamped};
use crate::log::{SessionWriter, WriterOptions};
use crate::progress::Progress;
use crate::rng;
use crate::synth::scenario::{BironSpec, Scenario};
use crate::synth::session::{GENERATOR_VERSION, PreviewData, SynthError};
use crate::synth::world::World;
use crate::time::Nanos;

/// Epoch of session 0 (s), as the other datasets; each session starts 10 000 s later.
const EPOCH_S: u64 = 1_700_000_000;
/// Laser mount on the robot `[x, z]` (m): "at the front at a height of approximately 30 cm".
pub const LASER_XZ: [f64; 2] = [0.15, 0.30];
/// Microphones in front of the robot's centre (m).
pub const MIC_FORWARD_M: f64 = 0.10;

/// Topic of an acoustic condition's audio (the nominal one is `/audio`).
pub fn grid_topic(rt60_s: f64, snr_db: f64) -> String {
    format!(
        "/audio_grid/rt60_{}ms_snr_{}db/audio",
        (rt60_s * 1000.0).round() as i64,
        snr_db.round() as i64
    )
}

/// The `audio_info` topic beside an audio topic.
pub fn info_topic(audio_topic: &str) -> String {
    match audio_topic.strip_suffix("audio") {
        Some(prefix) => format!("{prefix}audio_info"),
        None => format!("{audio_topic}_info"),
    }
}

fn tf(parent: &str, child: &str, stamp: Nanos, pose: &Isometry3<f64>) -> TransformStamped {
    let q: Quaternion<f64> = *pose.rotation.quaternion();
    TransformStamped {
        header: Header::new(stamp, parent),
        child_frame_id: child.to_string(),
        transform: Transform {
            translation: pose.translation.vector,
            rotation: q,
        },
    }
}

fn pose(x: f64, y: f64, z: f64, yaw: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        nalgebra::Translation3::new(x, y, z),
        UnitQuaternion::from_euler_angles(0.0, 0.0, yaw),
    )
}

/// Write session `index` of a BIRON scenario to `path`.
pub fn write_session(
    s: &Scenario,
    spec: &BironSpec,
    scenario_text: &str,
    profile: &str,
    index: u32,
    path: &Path,
    bar: &dyn Progress,
) -> Result<PreviewData, SynthError> {
    let seed = rng::hash(s.scenario.seed, &[u64::from(index)]);
    let session = u64::from(index);
    let world = World::build(s, session);
    let t0 = Nanos((EPOCH_S + 10_000 * session) * Nanos::NANOS_PER_SEC);
    let robot = [spec.robot[0], spec.robot[1], spec.robot[2].to_radians()];
    let stage = script::Stage {
        robot,
        camera: [robot[0], robot[1], crate::anchoring::ptu::CAMERA_HEIGHT_M],
        door: spec.door,
        room: s.world.size,
        duration: s.scenario.duration_s,
    };
    let mut r = ChaCha8Rng::seed_from_u64(rng::hash(seed, &[0xb140]));
    let mut script = script::draw(&stage, spec.visitors, &mut r);
    gaze::plan_heads(&mut script, &stage, &mut r);
    let setup = audio::AudioSetup {
        sample_rate: 16_000,
        spacing_m: crate::audio::doa::BIRON_SPACING_M,
        height_m: crate::audio::doa::BIRON_MIC_HEIGHT_M,
        forward_m: MIC_FORWARD_M,
        room: [s.world.size[0], s.world.size[1], s.world.wall_height],
        rt60_s: spec.rt60_s.clone(),
        snr_db: spec.snr_db.clone(),
    };
    let conditions = audio::render(&script, &stage, &setup, seed);

    let mut w = SessionWriter::create(path, &WriterOptions::default())?;
    let mut meta = BTreeMap::new();
    meta.insert("scenario".to_string(), s.scenario.name.clone());
    meta.insert("seed".to_string(), s.scenario.seed.to_string());
    meta.insert("session_seed".to_string(), seed.to_string());
    meta.insert("session".to_string(), index.to_string());
    meta.insert("profile".to_string(), profile.to_string());
    meta.insert("generator".to_string(), GENERATOR_VERSION.to_string());
    meta.insert("paper".to_string(), s.scenario.paper.clone());
    meta.insert("scenario_toml".to_string(), scenario_text.to_string());
    let clipped: u64 = conditions.iter().map(|c| c.clipped).sum();
    meta.insert("audio_clipped_samples".to_string(), clipped.to_string());
    w.metadata("peopletrack.scenario", meta)?;

    let run = closed_loop::Run {
        spec,
        world: &world,
        script: &script,
        stage: &stage,
        setup: &setup,
        conditions: &conditions,
        seed,
        t0,
    };
    let preview = run.write(&mut w, bar)?;
    w.finish()?;
    Ok(preview)
}

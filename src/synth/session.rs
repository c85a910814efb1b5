//! One synthetic session, end to end: people and robot trajectories, then every sensor at its
//! own rate in time order — images (raw or JPEG) with `CameraInfo`, exact person masks, laser
//! scans, odometry, IMU, TF — plus ground truth, written as a ROS 2 MCAP like a real recording.
//!
//! Clocks: a sensor's header stamp is its capture time; the log time adds a small transport
//! latency (cameras 8–25 ms, laser 3–8 ms), so logs show the stamp-vs-log offsets real logs
//! do. Ground truth is stamped and logged at capture time.

use std::collections::BTreeMap;
use std::path::Path;

use crate::log::msgs::TfMessage;
use crate::log::{SessionWriter, WriterOptions};
use crate::progress::Progress;
use crate::rng;
use crate::synth::scenario::Scenario;
use crate::synth::world::World;
use crate::time::Nanos;

mod capture;
mod cast;
mod following;
mod odometry;
mod rig;
mod truth;
mod types;

pub use types::{Actor, PreviewCamera, PreviewData, SynthError};
use types::{Clock, Session};

/// Version of the generator, recorded in every log's metadata; `synth --if-absent` renders a
/// log again when it differs. The counter in brackets is bumped by hand whenever a change
/// alters what a render writes — the closed loops' estimators (`laser::follow`,
/// `anchoring`) included, since they drive the robot while rendering. (2): issue 33's
/// round 7 changed the BIRON loop; (1) was never bumped before that. (3): issue 30 round 14
/// judges a braking robot's stop by its braking arc (`synth::follow::avoid`).
pub const GENERATOR_VERSION: &str =
    concat!("peopletrack-synth ", env!("CARGO_PKG_VERSION"), " (3)");

/// Epoch of session 0 (s); each session starts 10 000 s later.
const EPOCH_S: u64 = 1_700_000_000;

/// Simulate session `index` of a scenario and write it to `path`. Returns what the preview needs.
///
/// Stages, in the order they write: the scenario metadata; the sensors (their channels, then
/// the cameras' true poses as metadata); the TF, odometry, IMU and ground-truth channels and
/// the static transforms; the robot's odometry and IMU streams; the follower's states (closed
/// loop only); then every sensor capture in time order, each instant followed by its ground
/// truth. A closed-loop session runs its following loop (`synth::follow`) after installing the
/// rig, and everything from the odometry on uses the loop's robot track.
pub fn write_session(
    s: &Scenario,
    scenario_text: &str,
    profile: &str,
    base: &Path,
    index: u32,
    path: &Path,
    bar: &dyn Progress,
) -> Result<PreviewData, SynthError> {
    let seed = rng::hash(s.scenario.seed, &[u64::from(index)]);
    let session = u64::from(index);
    let world = World::build(s, session);
    let clock = Clock {
        t0: Nanos((EPOCH_S + 10_000 * session) * Nanos::NANOS_PER_SEC),
    };
    let (people, nominal_track) = cast::people_and_robot(s, &world, base, session)?;

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
    w.metadata("peopletrack.scenario", meta)?;

    // the rig reads the robot's track only for cameras on a static robot
    let mut rig = rig::install(&mut w, s, &world, &nominal_track, clock)?;
    let ch = rig::Channels::add(&mut w, s)?;
    let closed = following::run(
        &Session {
            s,
            world: &world,
            people: &people,
            robot_track: &nominal_track,
            seed,
            clock,
            laser_height: rig.laser_height,
        },
        &rig,
        session,
    )?;
    let robot_track = match &closed {
        Some(c) => c.track.clone(),
        None => nominal_track,
    };
    w.write(
        ch.tf_static,
        clock.at(0.0),
        &TfMessage {
            transforms: std::mem::take(&mut rig.statics),
        },
    )?;
    odometry::write_odometry(&mut w, &ch, s, &robot_track, session, clock)?;
    odometry::write_imu(&mut w, &ch, s, &robot_track, session, clock)?;
    if let Some(c) = &closed {
        following::write_states(&mut w, &ch, c)?;
    }

    let ses = Session {
        s,
        world: &world,
        people: &people,
        robot_track: &robot_track,
        seed,
        clock,
        laser_height: rig.laser_height,
    };
    let preview = capture::capture_all(&mut w, &ses, &rig, &ch, bar)?;
    w.finish()?;
    Ok(preview)
}

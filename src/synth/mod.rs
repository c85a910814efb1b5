//! Synthetic sessions that follow each paper's set-up, rendered from a scenario file
//! (`datasets/<name>/scenario.toml`) into ROS 2 MCAP logs that go through the same reader as
//! real ones. Everything is deterministic from the scenario seed, whatever the thread count.
//!
//! - [`scenario`]: the file format (world, people, robot, sensors, profiles).
//! - [`world`]: static scene, moving background, materials and light; [`shapes`]: primitives.
//! - [`person`]: articulated people; [`motion`]: how they move; [`robot`]: the robot;
//!   [`follow`]: the closed following loop (the robot driven by a tracker's estimate).
//! - [`render`]: per-pixel ray casting for every camera model; [`laser`]: scans.
//! - [`session`]: one session written as a log, returning what its preview sheet shows
//!   ([`PreviewData`]; `report::preview` draws the sheet — the synthesizer draws nothing).
//! - [`biron`]: seed 003's BIRON home tour (`[biron]` scenarios): visitors, two-microphone
//!   audio, faces ([`face`]), and the pan-tilt camera in closed loop with the attention system.
//! - [`rng`]: seeded randomness.
//!
//! Not modelled: global illumination, cast shadows other than soft floor shadows under people,
//! motion blur, rolling shutter, lens vignetting.

pub mod biron;
pub mod face;
pub mod follow;
pub mod laser;
pub mod motion;
pub mod person;
pub mod render;
pub use crate::rng;
pub mod robot;
pub mod scenario;
pub mod session;
pub mod shapes;
pub mod world;

use std::path::{Path, PathBuf};

use rayon::prelude::*;

pub use scenario::{Scenario, ScenarioError};
pub use session::{PreviewData, SynthError};

/// Where and how to synthesize.
#[derive(Clone)]
pub struct SynthOptions {
    pub profile: String,
    /// Folder for the session logs (default: the scenario's folder, `full/` below it for the
    /// full profile).
    pub out: Option<PathBuf>,
    /// Progress bars (`None`: silent).
    pub progress: crate::progress::SharedReporter,
}

/// What was written, and what the preview sheet of the dataset shows.
pub struct SynthSummary {
    pub name: String,
    pub sessions: Vec<PathBuf>,
    /// One instant of the profile's first session (none when the scenario has no sessions).
    pub preview: Option<PreviewData>,
}

/// Default folder of a profile's logs.
pub fn default_out(scenario_path: &Path, profile: &str) -> PathBuf {
    let dir = scenario_path
        .parent()
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
    if profile == "quick" {
        dir
    } else {
        dir.join(profile)
    }
}

/// Synthesize every session of a scenario (sessions in parallel, rows in parallel).
pub fn synthesize(scenario_path: &Path, opts: &SynthOptions) -> anyhow::Result<SynthSummary> {
    synthesize_sessions(scenario_path, opts, false)
}

/// [`synthesize`], leaving out (with `missing_only`) the sessions whose log already exists:
/// each session is rendered from its own index and seed, so completing an interrupted render
/// gives the same logs as one uninterrupted render. [`SynthSummary::sessions`] lists the
/// sessions written.
/// Why the logs already in `dir` are not what this scenario renders now, if they are not:
/// the first log (by name) whose `peopletrack.scenario` metadata names another scenario text
/// or another generator version. Logs without that metadata, or that cannot be opened, are
/// named too (a render will replace them). `None`: every log matches (or there is none).
pub fn stale_logs(
    scenario_path: &Path,
    profile: &str,
    dir: &Path,
) -> anyhow::Result<Option<String>> {
    let (_, text) = Scenario::load(scenario_path, profile)?;
    let mut logs: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|d| {
            d.filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|x| x == "mcap"))
                .collect()
        })
        .unwrap_or_default();
    logs.sort();
    for log in logs {
        let meta = match crate::log::SessionLog::open(&log) {
            Ok(l) => l
                .summary()
                .metadata
                .iter()
                .find(|m| m.name == "peopletrack.scenario")
                .map(|m| m.entries.clone()),
            Err(e) => return Ok(Some(format!("{}: {e}", log.display()))),
        };
        let Some(meta) = meta else {
            return Ok(Some(format!(
                "{}: no peopletrack.scenario metadata",
                log.display()
            )));
        };
        if meta.get("scenario_toml") != Some(&text) {
            return Ok(Some(format!(
                "{} was rendered from another version of {}",
                log.display(),
                scenario_path.display()
            )));
        }
        if meta.get("generator").map(String::as_str) != Some(session::GENERATOR_VERSION) {
            return Ok(Some(format!(
                "{} was rendered by {}, not {}",
                log.display(),
                meta.get("generator")
                    .map_or("an unknown generator", String::as_str),
                session::GENERATOR_VERSION
            )));
        }
    }
    Ok(None)
}

pub fn synthesize_sessions(
    scenario_path: &Path,
    opts: &SynthOptions,
    missing_only: bool,
) -> anyhow::Result<SynthSummary> {
    let (s, text) = Scenario::load(scenario_path, &opts.profile)?;
    let out = opts
        .out
        .clone()
        .unwrap_or_else(|| default_out(scenario_path, &opts.profile));
    let base = scenario_path
        .parent()
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
    let bars = crate::progress::reporter(&opts.progress);
    let first = s.scenario.first_session;
    let path_of = |k: u32| out.join(format!("{}_{:02}.mcap", s.scenario.name, k));
    let wanted: Vec<u32> = (first..first + s.scenario.sessions)
        .filter(|&k| !(missing_only && path_of(k).is_file()))
        .collect();
    let results: Vec<anyhow::Result<(PathBuf, Option<session::PreviewData>)>> = wanted
        .into_par_iter()
        .map(|k| {
            let path = path_of(k);
            let bar = bars.bar(&format!("{} {k}", s.scenario.name), "sensor frames");
            // a `[biron]` scenario has its own session writer (seed 003's BIRON, issue 33)
            let preview = match &s.biron {
                Some(spec) => {
                    biron::write_session(&s, spec, &text, &opts.profile, k, &path, bar.as_ref())?
                }
                None => {
                    session::write_session(&s, &text, &opts.profile, &base, k, &path, bar.as_ref())?
                }
            };
            Ok((path, (k == first).then_some(preview)))
        })
        .collect();
    let mut sessions = Vec::new();
    let mut first_preview = None;
    for r in results {
        let (p, pv) = r?;
        sessions.push(p);
        if pv.is_some() {
            first_preview = pv;
        }
    }
    Ok(SynthSummary {
        name: s.scenario.name.clone(),
        sessions,
        preview: first_preview,
    })
}

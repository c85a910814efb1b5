//! Synthetic sessions that follow each paper's set-up, rendered from a scenario file
//! (`datasets/<name>/scenario.toml`) into ROS 2 MCAP logs that go through the same reader as
//! real ones. Everything is deterministic from the scenario seed, whatever the thread count.
//!
//! - [`scenario`]: the file format (world, people, robot, sensors, profiles).
//! - [`world`]: static scene, moving background, materials and light; [`shapes`]: primitives.
//! - [`person`]: articulated people; [`motion`]: how they move; [`robot`]: the robot.
//! - [`render`]: per-pixel ray casting for every camera model; [`laser`]: scans.
//! - [`session`]: one session written as a log; [`preview`]: the preview sheet.
//! - [`rng`]: seeded randomness.
//!
//! Not modelled: global illumination, cast shadows other than soft floor shadows under people,
//! motion blur, rolling shutter, lens vignetting.

pub mod laser;
pub mod motion;
pub mod person;
pub mod preview;
pub mod render;
pub mod rng;
pub mod robot;
pub mod scenario;
pub mod session;
pub mod shapes;
pub mod world;

use std::path::{Path, PathBuf};

use indicatif::{MultiProgress, ProgressBar, ProgressStyle};
use rayon::prelude::*;

pub use scenario::{Scenario, ScenarioError};
pub use session::SynthError;

/// Where and how to synthesize.
#[derive(Debug, Clone)]
pub struct SynthOptions {
    pub profile: String,
    /// Folder for the session logs (default: the scenario's folder, `full/` below it for the
    /// full profile).
    pub out: Option<PathBuf>,
    /// Folder for `<name>/preview.png` (none: no preview).
    pub preview_root: Option<PathBuf>,
    pub progress: bool,
}

/// What was written.
#[derive(Debug, Clone)]
pub struct SynthSummary {
    pub name: String,
    pub sessions: Vec<PathBuf>,
    pub preview: Option<PathBuf>,
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
    let (s, text) = Scenario::load(scenario_path, &opts.profile)?;
    let out = opts
        .out
        .clone()
        .unwrap_or_else(|| default_out(scenario_path, &opts.profile));
    let base = scenario_path
        .parent()
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
    let multi = MultiProgress::new();
    if !opts.progress {
        multi.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    let style =
        ProgressStyle::with_template("{prefix:>24} [{bar:30}] {pos}/{len} sensor frames {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> ");
    let results: Vec<anyhow::Result<(PathBuf, Option<session::PreviewData>)>> = (0..s
        .scenario
        .sessions)
        .into_par_iter()
        .map(|k| {
            let path = out.join(format!("{}_{:02}.mcap", s.scenario.name, k));
            let bar = multi.add(ProgressBar::new(0));
            bar.set_style(style.clone());
            bar.set_prefix(format!("{} {k}", s.scenario.name));
            let preview = session::write_session(&s, &text, &opts.profile, &base, k, &path, &bar)?;
            bar.finish_and_clear();
            Ok((path, (k == 0).then_some(preview)))
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
    let mut preview = None;
    if let (Some(root), Some(pv)) = (&opts.preview_root, first_preview) {
        let path = root.join(&s.scenario.name).join("preview.png");
        let png = preview::sheet(&s.scenario.name, &pv)?;
        crate::report::atomic::write_atomic(&path, &png, Some(root))?;
        preview = Some(path);
    }
    Ok(SynthSummary {
        name: s.scenario.name.clone(),
        sessions,
        preview,
    })
}

//! `peopletrack train omni-appearance --sessions GLOB`: learn an appearance model from your own
//! logs and save it (network, feature normalisation, provenance) for `peopletrack run` to load.
//!
//! Training is the s000_cielniak_omni pipeline run on the given sessions: the webcam measurement system is
//! calibrated on the calibration segment and provides the distances the network learns, and
//! the usual tables (calibration, ANN error over random splits, ...) are written as well, so a
//! model never comes without its own evaluation.

use std::path::PathBuf;

use anyhow::Context;

use peopletrack::pipelines;
use peopletrack::report::atomic;
use peopletrack::run::RunOptions;

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub model: Model,
}

#[derive(Debug, clap::Subcommand)]
pub enum Model {
    /// The omnidirectional appearance model of seed 000 (3 depth-cue features -> distance).
    ///
    /// Each session needs the omni camera, the webcams of the measurement system (with TF and
    /// camera_info) and /ground_truth/calibration_targets for the calibration. Load the saved
    /// model on other logs with `model = "PATH"` in the pipeline file (and `webcams = []` when
    /// those logs have no measurement system): per-frame estimates go to estimates.csv.
    OmniAppearance(OmniArgs),
}

#[derive(Debug, clap::Args)]
pub struct OmniArgs {
    /// Sessions to train on (glob; repeat for more), e.g. 'datasets/omni_lab/*.mcap'.
    #[arg(long, value_name = "GLOB", required = true)]
    pub sessions: Vec<String>,
    /// Pipeline file with the settings (webcams, hat colour, panorama, network size, epochs).
    #[arg(long, default_value = "pipelines/s000_cielniak_omni.toml")]
    pub config: PathBuf,
    /// Where to write the trained model (JSON).
    #[arg(long, short, default_value = "models/omni_appearance.json")]
    pub output: PathBuf,
    /// Output root for the evaluation tables and the per-session cache.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Recompute sessions even when a cached result matches.
    #[arg(long)]
    pub force: bool,
}

pub fn run(a: &Args, out: &mut dyn std::io::Write) -> anyhow::Result<()> {
    let Model::OmniAppearance(a) = &a.model;
    let opts = RunOptions {
        sessions: Some(a.sessions.clone()),
        dry_run: false,
        shard: None,
        aggregate_only: false,
        force: a.force,
        out: a.out.clone(),
        git_commit: super::git_commit(),
        progress: super::progress::shared(super::stderr_is_terminal()),
        write_tracks: None,
    };
    atomic::sweep_scratch(&a.out)?;
    let s = pipelines::run_file(&a.config, &opts)?;
    let model = s.artifacts.iter().find(|p| p.ends_with(".json")).with_context(|| {
        format!(
            "{} trained no model: it must have `model = \"\"` (it loads one) and a non-empty `save_model`",
            a.config.display()
        )
    })?;
    let bytes = std::fs::read(model).with_context(|| format!("reading {model}"))?;
    atomic::write_atomic(&a.output, &bytes, None)
        .with_context(|| format!("writing {}", a.output.display()))?;
    writeln!(
        out,
        "{}: trained on {} sessions in {:.1} s",
        s.pipeline, s.sessions, s.seconds
    )?;
    writeln!(out, "  model  {}", a.output.display())?;
    for (t, p) in &s.tables {
        writeln!(out, "  {}  {t}", a.out.join(p).display())?;
    }
    for (session, why) in &s.skipped {
        eprintln!("warning: skipped {session}: {why}");
    }
    Ok(())
}

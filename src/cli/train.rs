//! `peopletrack train omni-appearance --sessions GLOB`: learn an appearance model from your own
//! logs and save it (network, feature normalisation, provenance) for `peopletrack run` to load.
//! `peopletrack train leg-detector --out FILE`: the random-forest laser leg detector of
//! `pipelines::laser_people::learned` (real leg_tracker CSVs or synthetic logs), with its
//! grouped cross-validation printed and written as CSV.
//!
//! Training is the s000_cielniak_omni pipeline run on the given sessions: the webcam measurement system is
//! calibrated on the calibration segment and provides the distances the network learns, and
//! the usual tables (calibration, ANN error over random splits, ...) are written as well, so a
//! model never comes without its own evaluation.

use std::path::PathBuf;

use anyhow::Context;

use peopletrack::groundtruth::PEOPLE_TOPIC;
use peopletrack::laser::training::FeatureSet;
use peopletrack::pipelines;
use peopletrack::pipelines::laser_people::LearnedParams;
use peopletrack::pipelines::laser_people::learned::{self, Source, Unavailable};
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
    /// A random-forest leg detector for 2-D laser scans (the `learned` methods of
    /// pipelines/laser_people.toml).
    ///
    /// Each scan is cut into segments (jump distance 0.1 m, ≥ 3 points); a segment is
    /// described by 12 features (points, spread, width, linearity, circularity, fitted radius,
    /// boundary length and regularity, mean curvature, two occlusion flags, range), or with
    /// --features leg-tracker by leg_tracker's 17 cluster features.
    ///
    /// --source real reads leg_tracker's training CSVs (Leigh et al., ICRA 2015) in --dir:
    /// positive_K_scans.csv + positive_K_legs.csv (labelled leg centroids; the nearest
    /// segment within 0.1 m of a label is a leg) and negative_K_scans.csv (people-free scans;
    /// every --negative-keep-every-th segment is a non-leg). --source synthetic reads synthetic logs with
    /// /ground_truth/people (legs: segments near a ground-truth leg; non-legs: segments
    /// farther than 0.5 m from every leg, within 5 m).
    ///
    /// Prints and writes (TABLE, default: the model's path with .cv.csv) precision, recall
    /// and F1 of k-fold cross-validation grouped by file, so that scans of one recording never
    /// sit on both sides; the probability threshold is the one with the best out-of-fold F1.
    /// The final model (all samples) is saved as JSON with its threshold and CV scores. The
    /// same seed gives the same model. The pipeline trains the same model itself; to use a
    /// saved one instead (e.g. trained on your own CSVs) set `model = "FILE"` in
    /// `[params.learned]` or `[params.learned_free_space]` of pipelines/laser_people.toml.
    ///
    /// Example: peopletrack train leg-detector --out models/legs.json
    LegDetector(LegArgs),
}

#[derive(Debug, clap::Args)]
pub struct LegArgs {
    /// Where to write the model (JSON).
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// Training data: the leg_tracker CSVs (real) or synthetic logs with ground truth.
    #[arg(long, value_enum, default_value = "real")]
    pub source: LegSource,
    /// Folder of the leg_tracker training CSVs (--source real).
    #[arg(long, default_value = "../shared/real/laser/leg_training")]
    pub dir: PathBuf,
    /// Synthetic logs (glob; repeat for more; --source synthetic).
    #[arg(long, value_name = "GLOB", default_values = ["datasets/segway_park/*.mcap", "datasets/office_network/*.mcap"])]
    pub sessions: Vec<String>,
    /// Cross-validation folds (grouped by file).
    #[arg(long, default_value_t = 3)]
    pub folds: usize,
    #[arg(long, default_value_t = 100)]
    pub trees: u16,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Segment features: ours (12) or leg_tracker's (17).
    #[arg(long, value_enum, default_value = "segment")]
    pub features: LegFeatures,
    /// Real negatives: every n-th segment of the people-free scans (leg_tracker: 50).
    #[arg(long, default_value_t = 50)]
    pub negative_keep_every: usize,
    /// Where to write the cross-validation table (CSV).
    #[arg(long, value_name = "TABLE")]
    pub table: Option<PathBuf>,
}

#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum LegFeatures {
    Segment,
    LegTracker,
}

#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum LegSource {
    Real,
    Synthetic,
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
    let a = match &a.model {
        Model::OmniAppearance(a) => a,
        Model::LegDetector(l) => return leg_detector(l, out),
    };
    let opts = RunOptions {
        sessions: Some(a.sessions.clone()),
        dry_run: false,
        shard: None,
        aggregate_only: false,
        expect_shards: None,
        force: a.force,
        out: a.out.clone(),
        git_commit: super::git_commit(),
        progress: super::progress::shared(super::stderr_is_terminal()),
        write_tracks: None,
        recover: false,
        keep_going: false,
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

fn leg_detector(a: &LegArgs, out: &mut dyn std::io::Write) -> anyhow::Result<()> {
    use std::fmt::Write as _;
    let p = LearnedParams {
        training_dir: a.dir.display().to_string(),
        synthetic_sessions: a.sessions.clone(),
        folds: a.folds,
        n_trees: a.trees,
        seed: a.seed,
        negative_keep_every: a.negative_keep_every,
        feature_set: match a.features {
            LegFeatures::Segment => FeatureSet::Segment,
            LegFeatures::LegTracker => FeatureSet::LegTracker,
        },
        ..LearnedParams::default()
    };
    anyhow::ensure!(
        a.folds >= 2 && a.trees >= 1 && a.negative_keep_every >= 1,
        "--folds must be ≥ 2, --trees and --negative-keep-every ≥ 1"
    );
    let source = match a.source {
        LegSource::Real => Source::Real,
        LegSource::Synthetic => Source::Synthetic,
    };
    let model = match learned::train_source(source, &p, "/scan", PEOPLE_TOPIC) {
        Ok(m) => m,
        Err(Unavailable::Absent(why) | Unavailable::Failed(why)) => anyhow::bail!("{why}"),
    };
    let json = serde_json::to_vec(&*model)?;
    atomic::write_atomic(&a.out, &json, None)
        .with_context(|| format!("writing {}", a.out.display()))?;
    let mut csv = String::from(
        "source,fold,test_groups,test_legs,test_non_legs,precision,recall,f1,threshold\n",
    );
    writeln!(
        out,
        "{} leg detector: {} legs, {} non-legs ({} labels without a segment), threshold {:.2}",
        source.name(),
        model.positives,
        model.negatives,
        model.unmatched_labels,
        model.threshold
    )?;
    writeln!(
        out,
        "  {:<8} {:>6} {:>8} {:>9} {:>7} {:>6}  test groups",
        "fold", "legs", "non-legs", "precision", "recall", "F1"
    )?;
    for f in &model.cv {
        writeln!(
            out,
            "  {:<8} {:>6} {:>8} {:>9.3} {:>7.3} {:>6.3}  {}",
            f.fold,
            f.positives,
            f.negatives,
            f.precision,
            f.recall,
            f.f1,
            f.groups.join(" ")
        )?;
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{:.4},{:.4},{:.4},{:.2}",
            source.name(),
            f.fold,
            f.groups.join(" "),
            f.positives,
            f.negatives,
            f.precision,
            f.recall,
            f.f1,
            model.threshold
        );
    }
    let table = a
        .table
        .clone()
        .unwrap_or_else(|| a.out.with_extension("cv.csv"));
    atomic::write_atomic(&table, csv.as_bytes(), None)
        .with_context(|| format!("writing {}", table.display()))?;
    writeln!(out, "  model  {}", a.out.display())?;
    writeln!(out, "  table  {}", table.display())?;
    Ok(())
}

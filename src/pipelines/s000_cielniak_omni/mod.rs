//! `s000_cielniak_omni` — appearance-based tracking with an omnidirectional camera (seed 000, Cielniak et al.
//! 2003), every step on the logged images:
//!
//! 1. **External measurement system** (section 3): webcams find the green hat, turn its column
//!    into a bearing, triangulate every pair that sees the whole hat; calibration of each
//!    camera's (α, X, Y, Δα) on the calibration segment by minimising d̄ (Nelder–Mead).
//! 2. **Omni pre-processing** (4.2): polar unwrap, background from person-free frames,
//!    histograms, person localisation, angle from the horizontal histogram.
//! 3. **Features** (4.3): width, apparent distance, foreground pixels; Pearson r with distance.
//! 4. **ANN** (4.4): 3-H-1 network, back-propagation, 30/70 splits repeated 10 times; a sweep
//!    over hidden units and learning rates.
//! 5. **Person-specific models** (6.1): 2×2 table and an unpaired t-test at 99 %.
//! 6. **Kalman filter** (5): Q and R from the training data; appearance model vs Kalman with an
//!    unpaired t-test; a fragment of the tracked path.
//!
//! As in the paper, the "true" distance for training and error measurement is the external
//! measurement system's; the simulator's own truth, when the log has it, is used only for extra
//! rows that measure the measurement system itself. Person identity (for person-specific models)
//! comes from the ground-truth ids when present, otherwise from the halves of the session.
//!
//! Layout: [`params`]; the per-session stage in [`session`] (webcam hats, ground truth) and
//! [`omni`] (panorama features), reading the log through [`crate::frames`] ([`sources`]:
//! camera frames and rig cameras; ground truth; bad messages skipped and counted) and writing the row types of
//! [`tables`]; the aggregation reads them
//! into a [`dataset`], then runs one module per sub-experiment in the order of the paper:
//! [`calibration`], [`angle`], [`splits`] (with the shared protocol of [`ann`]),
//! [`correlations`], [`sweep`], [`person`], [`kalman`], [`truth_check`], [`estimates`].

mod angle;
mod ann;
mod calibration;
mod correlations;
mod dataset;
mod estimates;
mod kalman;
mod omni;
mod params;
mod person;
mod session;
mod shared;
mod sources;
mod splits;
mod sweep;
mod tables;
mod truth_check;

use std::collections::BTreeMap;

use anyhow::Context;

use crate::groundtruth::{PEOPLE_TOPIC, TARGETS_TOPIC};
use crate::progress::Progress;
use crate::run::config::Invalid;
use crate::run::{Aggregate, Experiment, Products, Session, SessionTables, Stage};

pub use estimates::AppearanceModel;
pub use params::Params;

pub struct OmniAppearance;

impl Experiment for OmniAppearance {
    const KIND: &'static str = estimates::MODEL_KIND;
    /// 2: the session stage reads through the frames layer (bad messages skipped and counted
    /// in a `skips` table instead of failing the session).
    const VERSION: u32 = 2;
    const SESSION_TABLES: &'static [crate::run::schemas::TableDoc] = tables::SESSION_TABLES;
    type Params = Params;

    fn validate(p: &Params) -> Vec<Invalid> {
        params::validate(p)
    }

    /// The model to load (`model`), checked before anything runs.
    fn required_files(p: &Params) -> Vec<(String, std::path::PathBuf)> {
        if p.model.is_empty() {
            Vec::new()
        } else {
            vec![("model".to_string(), p.model.clone().into())]
        }
    }

    fn plan(p: &Params, _: &BTreeMap<String, String>) -> Vec<Stage> {
        vec![
            Stage {
                name: "hat detection (webcams)".into(),
                requires: p
                    .webcams
                    .iter()
                    .map(|c| format!("/{c}/camera_info"))
                    .collect(),
                optional: vec![TARGETS_TOPIC.into()],
            },
            Stage {
                name: "omni features".into(),
                requires: vec![format!("/{}/camera_info", p.omni), "/tf_static".into()],
                optional: vec![PEOPLE_TOPIC.into()],
            },
        ]
    }

    fn process(
        s: &Session,
        p: &Params,
        _: &BTreeMap<String, String>,
        bar: &dyn Progress,
    ) -> anyhow::Result<SessionTables> {
        session::process(s, p, bar)
    }

    fn aggregate(ctx: &Aggregate, p: &Params) -> anyhow::Result<Products> {
        analyse(ctx, p)
    }
}

/// The aggregation: each sub-experiment in turn, adding its tables, figures and summary lines.
fn analyse(ctx: &Aggregate, p: &Params) -> anyhow::Result<Products> {
    let mut out = Products::default();
    out.summary.extend(dataset::skipped_summary(ctx)?);
    let loaded = estimates::load(p)?;
    if p.webcams.is_empty() {
        // no measurement system: only estimate positions with the loaded model
        let model = loaded
            .as_ref()
            .context("no webcams and no model: nothing to do")?;
        let csv = estimates::estimates_csv(ctx, &model.regressor)?;
        out.artifacts.push(("estimates.csv".into(), csv));
        out.summary.push(format!(
            "Positions estimated with {} written to out/s000_cielniak_omni/estimates.csv.",
            p.model
        ));
        return Ok(out);
    }
    let inputs = dataset::Inputs::read(ctx)?;
    let cams = calibration::run(ctx, &inputs, &mut out)?;
    let data = dataset::build(&inputs, &cams, p.background_frames)?;
    truth_check::measurement_summary(&data, &mut out);
    angle::run(&data.rows, &mut out)?;

    let learner = ann::Learner::new(&data, p, loaded.as_ref().map(|m| &m.regressor));
    learner.check_fraction(
        data.rows.len(),
        "the frames with features and a measured position",
    )?;
    let split0 = ann::Split0::new(&learner)?;
    splits::run(&learner, &data.rows, p, &mut out)?;
    correlations::run(&learner, &split0, &mut out)?;
    sweep::run(&learner, p, &mut out)?;
    person::run(&learner, &data.rows, &mut out)?;
    let tracked = kalman::run(&learner, &data, &split0, p.max_gap_s, &mut out)?;
    truth_check::run(&data, &tracked, &mut out)?;

    // the general model on all data (or the loaded one): per-frame estimates, and the artefact
    let general = learner.model(&learner.all(), 400)?;
    let trained_on = loaded.is_none().then_some(data.rows.len());
    estimates::run(ctx, p, general, trained_on, &mut out)?;
    Ok(out)
}

//! The experiments, one module each, and the registry that maps a pipeline file's `kind` to
//! its implementation.

pub mod dataset_quality;
pub mod multicam_cylinders;

use std::path::Path;

use crate::run::{Experiment, RunOptions, RunSummary, config, run_experiment, unknown_kind};

/// Every `pipeline.kind` this build knows.
pub const KINDS: &[&str] = &[
    dataset_quality::DatasetQuality::KIND,
    multicam_cylinders::MulticamCylinders::KIND,
];

/// Run one pipeline file, dispatching on its `kind`.
pub fn run_file(path: &Path, opts: &RunOptions) -> anyhow::Result<RunSummary> {
    let (text, kind) = config::read_kind(path)?;
    match kind.as_str() {
        dataset_quality::DatasetQuality::KIND => {
            run_experiment::<dataset_quality::DatasetQuality>(path, &text, opts)
        }
        multicam_cylinders::MulticamCylinders::KIND => {
            run_experiment::<multicam_cylinders::MulticamCylinders>(path, &text, opts)
        }
        _ => Err(unknown_kind(path, &kind, KINDS).into()),
    }
}

//! The experiments, one module each, and the registry that maps a pipeline file's `kind` to
//! its implementation.

pub mod background_tracking;
pub mod dataset_quality;

use std::path::Path;

use crate::run::{Experiment, RunOptions, RunSummary, config, run_experiment, unknown_kind};

/// Every `pipeline.kind` this build knows.
pub const KINDS: &[&str] = &[
    background_tracking::BackgroundTracking::KIND,
    dataset_quality::DatasetQuality::KIND,
];

/// Run one pipeline file, dispatching on its `kind`.
pub fn run_file(path: &Path, opts: &RunOptions) -> anyhow::Result<RunSummary> {
    let (text, kind) = config::read_kind(path)?;
    match kind.as_str() {
        background_tracking::BackgroundTracking::KIND => {
            run_experiment::<background_tracking::BackgroundTracking>(path, &text, opts)
        }
        dataset_quality::DatasetQuality::KIND => {
            run_experiment::<dataset_quality::DatasetQuality>(path, &text, opts)
        }
        _ => Err(unknown_kind(path, &kind, KINDS).into()),
    }
}

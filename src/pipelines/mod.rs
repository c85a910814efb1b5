//! The experiments, one module each, and the registry that maps a pipeline file's `kind` to
//! its implementation.

pub mod background_tracking;
pub mod columns;
pub mod dataset_quality;
pub mod multicam_cylinders;
pub mod omni_appearance;

use std::path::Path;

use crate::run::{Experiment, RunOptions, RunSummary, config, run_experiment, unknown_kind};

/// Every `pipeline.kind` this build knows.
pub const KINDS: &[&str] = &[
    background_tracking::BackgroundTracking::KIND,
    dataset_quality::DatasetQuality::KIND,
    multicam_cylinders::MulticamCylinders::KIND,
    omni_appearance::OmniAppearance::KIND,
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
        multicam_cylinders::MulticamCylinders::KIND => {
            run_experiment::<multicam_cylinders::MulticamCylinders>(path, &text, opts)
        }
        omni_appearance::OmniAppearance::KIND => {
            run_experiment::<omni_appearance::OmniAppearance>(path, &text, opts)
        }
        _ => Err(unknown_kind(path, &kind, KINDS).into()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every kind listed in `KINDS` has a dispatch arm: a file naming it fails (it has no
    /// inputs) for any reason but an unknown kind.
    #[test]
    fn every_listed_kind_is_dispatched() {
        let dir = tempfile::tempdir().expect("tempdir");
        for kind in KINDS {
            let path = dir.path().join(format!("{kind}.toml"));
            std::fs::write(
                &path,
                format!("[pipeline]\nname = \"x\"\nkind = \"{kind}\"\n"),
            )
            .expect("write");
            let opts = RunOptions {
                sessions: None,
                dry_run: false,
                shard: None,
                aggregate_only: false,
                force: false,
                out: dir.path().join("out"),
                git_commit: String::new(),
                progress: None,
                write_tracks: None,
            };
            if let Err(e) = run_file(&path, &opts) {
                let msg = format!("{e:#}");
                assert!(!msg.contains("unknown pipeline kind"), "{kind}: {msg}");
            }
        }
    }
}

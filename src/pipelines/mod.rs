//! The experiments, one module each, and the registry that maps a pipeline file's `kind` to
//! its implementation.

pub mod dataset_quality;
pub mod laser_people;
pub mod s000_cielniak_omni;
pub mod s001_kobilarov_following;
pub mod s002_brooks_height;
pub mod s003_biron_anchoring;
pub mod s003_zivkovic_background;
pub mod s004_mohedano_multicam;

use std::path::Path;

use crate::run::schemas::KindInfo;
use crate::run::{
    Experiment, RunOptions, RunSummary, check_experiment, config, run_experiment, unknown_kind,
};

/// The one list of experiments: each type's `KIND` is listed in [`KINDS`] and dispatched by
/// [`run_file`].
macro_rules! registry {
    ($($ty:path),* $(,)?) => {
        /// Every `pipeline.kind` this build knows.
        pub const KINDS: &[&str] = &[$(<$ty as Experiment>::KIND),*];

        /// Run one pipeline file, dispatching on its `kind`.
        pub fn run_file(path: &Path, opts: &RunOptions) -> anyhow::Result<RunSummary> {
            let (text, kind) = config::read_kind(path)?;
            $(
                if kind == <$ty as Experiment>::KIND {
                    return run_experiment::<$ty>(path, &text, opts);
                }
            )*
            Err(unknown_kind(path, &kind, KINDS).into())
        }

        /// What the registry knows of a kind: its `VERSION` and its per-session tables.
        pub fn kind_info(kind: &str) -> Option<KindInfo> {
            $(
                if kind == <$ty as Experiment>::KIND {
                    return Some(KindInfo {
                        version: <$ty as Experiment>::VERSION,
                        session_tables: <$ty as Experiment>::SESSION_TABLES,
                    });
                }
            )*
            None
        }

        /// Parse and validate a pipeline file's text as its `kind` (no sessions are looked
        /// for, nothing is run): what `run` checks first. `path` only names it in errors.
        pub fn check_text(path: &Path, text: &str) -> Result<(), config::ConfigError> {
            let kind = config::kind_of(path, text)?;
            $(
                if kind == <$ty as Experiment>::KIND {
                    return check_experiment::<$ty>(path, text).map(|_| ());
                }
            )*
            Err(unknown_kind(path, &kind, KINDS))
        }
    };
}

registry!(
    dataset_quality::DatasetQuality,
    laser_people::LaserPeople,
    s000_cielniak_omni::OmniAppearance,
    s001_kobilarov_following::KobilarovFollowing,
    s002_brooks_height::BrooksHeight,
    s003_biron_anchoring::BironAnchoring,
    s003_zivkovic_background::BackgroundTracking,
    s004_mohedano_multicam::MulticamCylinders,
);

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
                expect_shards: None,
                force: false,
                out: dir.path().join("out"),
                git_commit: String::new(),
                progress: None,
                write_tracks: None,
                recover: false,
                keep_going: false,
            };
            if let Err(e) = run_file(&path, &opts) {
                let msg = format!("{e:#}");
                assert!(!msg.contains("unknown pipeline kind"), "{kind}: {msg}");
            }
        }
    }
}

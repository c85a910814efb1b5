//! What the plan checks about a run's inputs before anything runs, so that a mistake is said
//! at once (in `--dry-run` too) with the pipeline file and the key's line, instead of deep in
//! the run or not at all:
//!
//! - files the parameters name ([`super::Experiment::required_files`], e.g. a model to load)
//!   must exist: a missing one is an error naming the file, its line and key, and the path;
//! - a `[topics]` remap to a topic that none of the run's sessions has is a notice (the
//!   stages that read it run without it: a ground-truth remap with a typo would give results
//!   without ground truth), printed as a warning and listed in REPORT.md.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use rayon::prelude::*;

use super::config::{self, ConfigError, SessionRef};
use crate::log::SessionLog;

/// The first of `files` (`(key path within [params], path)`) that cannot be read, as an
/// error naming the pipeline file, the key's line and the path.
pub fn check_required(
    path: &Path,
    text: &str,
    files: &[(String, PathBuf)],
) -> Result<(), ConfigError> {
    for (key, file) in files {
        let problem = match std::fs::metadata(file) {
            Ok(m) if m.is_dir() => Some(format!("{} is a folder, not a file", file.display())),
            Ok(_) => None,
            Err(e) => Some(format!("cannot read {}: {e}", file.display())),
        };
        if let Some(reason) = problem {
            return Err(config::invalid(
                path,
                text,
                &format!("params.{key}"),
                reason,
            ));
        }
    }
    Ok(())
}

/// A notice for each `[topics]` remap whose topic none of `sessions` has (sessions whose log
/// cannot be opened, or is absent under `--aggregate-only`, say nothing either way; with none
/// that can, nothing is said).
pub fn absent_topics(
    path: &Path,
    text: &str,
    topics: &BTreeMap<String, String>,
    sessions: &[SessionRef],
) -> Vec<String> {
    if topics.is_empty() || sessions.is_empty() {
        return Vec::new();
    }
    let wanted: Vec<&str> = topics.values().map(String::as_str).collect();
    // per session that opens: which of the remapped topics it has
    let seen: Vec<Vec<bool>> = sessions
        .par_iter()
        .filter_map(|s| {
            let log = SessionLog::open(&s.path).ok()?;
            Some(
                wanted
                    .iter()
                    .map(|t| log.summary().channel(t).is_some())
                    .collect(),
            )
        })
        .collect();
    if seen.is_empty() {
        return Vec::new();
    }
    topics
        .iter()
        .enumerate()
        .filter(|(i, _)| !seen.iter().any(|has| has[*i]))
        .map(|(_, (key, topic))| {
            let reason = format!(
                "no session has topic `{topic}` (none of the {} that open): what reads `{key}` ran without it",
                seen.len()
            );
            config::invalid(path, text, &format!("topics.{key}"), reason).to_string()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_required_file_names_the_pipeline_line_and_path() {
        let dir = tempfile::tempdir().expect("tempdir");
        let text = "[pipeline]\nname = \"x\"\n\n[params]\nmodel = \"gone.json\"\n";
        let missing = dir.path().join("gone.json");
        let e = check_required(
            Path::new("p.toml"),
            text,
            &[("model".to_string(), missing.clone())],
        )
        .expect_err("missing");
        assert_eq!(
            e.to_string(),
            format!(
                "p.toml:5: `params.model`: cannot read {}: No such file or directory (os error 2)",
                missing.display()
            )
        );
        let e = check_required(
            Path::new("p.toml"),
            text,
            &[("model".to_string(), dir.path().to_path_buf())],
        )
        .expect_err("a folder");
        assert!(e.to_string().ends_with("is a folder, not a file"), "{e}");
        std::fs::write(&missing, b"{}").expect("write");
        check_required(Path::new("p.toml"), text, &[("model".to_string(), missing)])
            .expect("present");
    }
}

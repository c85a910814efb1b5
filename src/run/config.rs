//! Pipeline files (`pipelines/*.toml`), parsed in two steps (raw TOML → typed, validated
//! config). Unknown keys and wrongly typed values are errors with the file, line and column
//! (from the TOML parser); values out of range are errors with the line of the key.
//!
//! ```toml
//! [pipeline]
//! name = "dataset_quality"        # output folder: out/<name>/
//! kind = "dataset_quality"        # which experiment implementation runs
//! title = "Dataset quality"
//!
//! [inputs]
//! sessions = ["datasets/*/*.mcap", "../shared/real/laser/*/*.mcap"]  # globs, relative to the working directory
//! exclude = ["*.tmp"]
//!
//! [topics]                        # logical name -> topic, for logs that use other names
//! scan = "/scan"
//!
//! [params]                        # the experiment's own parameters (paper defaults)
//! bin_s = 1.0
//! ```

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    #[error("cannot read pipeline file {path}: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: {message}")]
    Parse { path: PathBuf, message: String },
    #[error("{path}:{line}: `{key}`: {reason}")]
    Invalid {
        path: PathBuf,
        line: usize,
        key: String,
        reason: String,
    },
    #[error("{path}: unknown pipeline kind `{kind}` (known: {known})")]
    UnknownKind {
        path: PathBuf,
        kind: String,
        known: String,
    },
    #[error("bad session glob `{pattern}`: {reason}")]
    Glob { pattern: String, reason: String },
}

/// `[pipeline]`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PipelineSection {
    pub name: String,
    pub kind: String,
    pub title: String,
    #[serde(default)]
    pub description: String,
}

/// `[inputs]`.
#[derive(Debug, Clone, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct InputsSection {
    pub sessions: Vec<String>,
    #[serde(default)]
    pub exclude: Vec<String>,
}

/// A whole pipeline file with the experiment's parameter type `P`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PipelineFile<P> {
    pub pipeline: PipelineSection,
    pub inputs: InputsSection,
    #[serde(default)]
    pub topics: BTreeMap<String, String>,
    #[serde(default)]
    pub params: P,
}

#[derive(Deserialize)]
struct KindOnly {
    pipeline: KindSection,
}

#[derive(Deserialize)]
struct KindSection {
    kind: String,
}

/// Read a pipeline file and return its text and `pipeline.kind`.
pub fn read_kind(path: &Path) -> Result<(String, String), ConfigError> {
    let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    let k: KindOnly = toml::from_str(&text).map_err(|e| ConfigError::Parse {
        path: path.to_path_buf(),
        message: e.to_string().trim_end().to_string(),
    })?;
    Ok((text, k.pipeline.kind))
}

/// Parse the whole file with the experiment's parameter type.
pub fn parse<P: DeserializeOwned + Default>(
    path: &Path,
    text: &str,
) -> Result<PipelineFile<P>, ConfigError> {
    toml::from_str(text).map_err(|e| ConfigError::Parse {
        path: path.to_path_buf(),
        message: e.to_string().trim_end().to_string(),
    })
}

/// Line (1-based) of `key` inside `[section]` of a TOML text, for validation messages.
pub fn line_of(text: &str, section: &str, key: &str) -> usize {
    let mut in_section = false;
    let header = format!("[{section}]");
    for (i, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.starts_with('[') {
            in_section = t == header;
            continue;
        }
        if in_section
            && let Some((k, _)) = t.split_once('=')
            && k.trim() == key
        {
            return i + 1;
        }
    }
    0
}

/// A validation failure of one parameter: `(key within [params], reason)`.
pub type Invalid = (String, String);

/// Turn the first validation failure into an error with its line.
pub fn check(path: &Path, text: &str, problems: Vec<Invalid>) -> Result<(), ConfigError> {
    match problems.into_iter().next() {
        None => Ok(()),
        Some((key, reason)) => Err(ConfigError::Invalid {
            path: path.to_path_buf(),
            line: line_of(text, "params", &key),
            key: format!("params.{key}"),
            reason,
        }),
    }
}

/// A session found by the input globs.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Serialize)]
pub struct SessionRef {
    /// Dataset = name of the folder holding the file.
    pub dataset: String,
    /// Session = file name without `.mcap`.
    pub name: String,
    pub path: PathBuf,
}

/// The dataset a session file belongs to: the folder holding it, or, for a profile's folder
/// written by `peopletrack synth --profile full` (`datasets/<name>/full/`: no `scenario.toml`
/// of its own, one in its parent), the folder above.
fn dataset_name(file: &std::path::Path) -> String {
    let name = |d: &std::path::Path| {
        d.file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    let Some(folder) = file.parent() else {
        return String::new();
    };
    match folder.parent() {
        Some(up)
            if !folder.join("scenario.toml").is_file() && up.join("scenario.toml").is_file() =>
        {
            name(up)
        }
        _ => name(folder),
    }
}

/// Expand globs (sorted, without repeats), drop excluded names, name each session.
pub fn find_sessions(
    patterns: &[String],
    exclude: &[String],
) -> Result<Vec<SessionRef>, ConfigError> {
    let excludes: Vec<glob::Pattern> = exclude
        .iter()
        .map(|p| {
            glob::Pattern::new(p).map_err(|e| ConfigError::Glob {
                pattern: p.clone(),
                reason: e.to_string(),
            })
        })
        .collect::<Result<_, _>>()?;
    let mut out = Vec::new();
    for pattern in patterns {
        let paths = glob::glob(pattern).map_err(|e| ConfigError::Glob {
            pattern: pattern.clone(),
            reason: e.to_string(),
        })?;
        for p in paths.flatten() {
            if !p.is_file() {
                continue;
            }
            let file = p
                .file_name()
                .map(|f| f.to_string_lossy().into_owned())
                .unwrap_or_default();
            if excludes
                .iter()
                .any(|e| e.matches(&file) || e.matches_path(&p))
            {
                continue;
            }
            let dataset = dataset_name(&p);
            let name = file.strip_suffix(".mcap").unwrap_or(&file).to_string();
            out.push(SessionRef {
                dataset,
                name,
                path: p,
            });
        }
    }
    out.sort();
    out.dedup();
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Default, Deserialize, Serialize)]
    #[serde(deny_unknown_fields)]
    struct P {
        #[serde(default)]
        alpha: f64,
    }

    const GOOD: &str = "[pipeline]\nname = \"x\"\nkind = \"k\"\ntitle = \"X\"\n\n[inputs]\nsessions = [\"a/*.mcap\"]\n\n[params]\nalpha = 0.5\n";

    #[test]
    fn parses_and_finds_lines() {
        let f: PipelineFile<P> = parse(Path::new("p.toml"), GOOD).expect("parses");
        assert_eq!(f.params.alpha, 0.5);
        assert_eq!(line_of(GOOD, "params", "alpha"), 10);
        let e = check(
            Path::new("p.toml"),
            GOOD,
            vec![("alpha".into(), "must be in (0, 0.1]".into())],
        )
        .expect_err("invalid");
        assert_eq!(
            e.to_string(),
            "p.toml:10: `params.alpha`: must be in (0, 0.1]"
        );
    }

    #[test]
    fn unknown_keys_and_bad_types_name_the_line() {
        let text = GOOD.replace("alpha = 0.5", "alpah = 0.5");
        let e = parse::<P>(Path::new("p.toml"), &text)
            .expect_err("unknown key")
            .to_string();
        assert!(e.contains("line 10") && e.contains("alpah"), "{e}");
        let text = GOOD.replace("alpha = 0.5", "alpha = \"half\"");
        let e = parse::<P>(Path::new("p.toml"), &text)
            .expect_err("bad type")
            .to_string();
        assert!(e.contains("line 10"), "{e}");
        let text = GOOD.replace("title = \"X\"\n", "");
        let e = parse::<P>(Path::new("p.toml"), &text)
            .expect_err("missing")
            .to_string();
        assert!(e.contains("title"), "{e}");
    }

    /// Regression: full-profile logs (`datasets/<name>/full/*.mcap`) were all named dataset
    /// `full`, merging every dataset's per-dataset tables and defeating dataset filters.
    #[test]
    fn full_profile_sessions_keep_their_dataset_name() {
        let dir = tempfile::tempdir().expect("tempdir");
        for f in [
            "walker/scenario.toml",
            "walker/full/walker_00.mcap",
            "mine/full/x.mcap",
        ] {
            let p = dir.path().join(f);
            std::fs::create_dir_all(p.parent().expect("parent")).expect("mkdir");
            std::fs::write(&p, b"x").expect("write");
        }
        let pat = format!("{}/*/full/*.mcap", dir.path().display());
        let s = find_sessions(&[pat], &[]).expect("globs");
        let names: Vec<(String, String)> = s
            .iter()
            .map(|s| (s.dataset.clone(), s.name.clone()))
            .collect();
        // a user's folder named `full` without a scenario above it keeps its name
        assert_eq!(
            names,
            vec![
                ("full".into(), "x".into()),
                ("walker".into(), "walker_00".into())
            ]
        );
    }

    #[test]
    fn sessions_are_named_by_folder_and_file() {
        let dir = tempfile::tempdir().expect("tempdir");
        for f in [
            "lab/b.mcap",
            "lab/a.mcap",
            "lab/skip.tmp.mcap",
            "park/c.mcap",
        ] {
            let p = dir.path().join(f);
            std::fs::create_dir_all(p.parent().expect("parent")).expect("mkdir");
            std::fs::write(&p, b"x").expect("write");
        }
        let pat = format!("{}/*/*.mcap", dir.path().display());
        let s = find_sessions(&[pat.clone(), pat], &["*.tmp.mcap".into()]).expect("globs");
        let names: Vec<(String, String)> = s
            .iter()
            .map(|s| (s.dataset.clone(), s.name.clone()))
            .collect();
        assert_eq!(
            names,
            vec![
                ("lab".into(), "a".into()),
                ("lab".into(), "b".into()),
                ("park".into(), "c".into())
            ]
        );
    }
}

//! Pipeline files (`pipelines/*.toml`), parsed in two steps (raw TOML → typed, validated
//! config). Unknown keys and wrongly typed values are errors with the file, line and column
//! (from the TOML parser); values out of range are errors with the line of the key and its
//! full key path (`params.local_eval.min_iou`, `params.sequences[1].scans`), found in the
//! document the `toml` crate parses with spans ([`toml::de::DeTable`]). A `[topics]` key the
//! experiment does not remap is an error naming it.
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
//! ground_truth = "/ground_truth/people"
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
    // `error`, not `source`: a source would be printed twice in an error chain
    #[error("cannot read pipeline file {path}: {error}")]
    Read {
        path: PathBuf,
        error: std::io::Error,
    },
    #[error("{path}: {message}")]
    Parse { path: PathBuf, message: String },
    /// A value out of range (or a key the experiment does not know). `line` is the line of the
    /// key, or of the deepest table above it that the file writes when the key itself is not
    /// written (a default); `None` when the file writes none of its path.
    #[error("{path}{}: `{key}`: {reason}", line.map_or(String::new(), |l| format!(":{l}")))]
    Invalid {
        path: PathBuf,
        line: Option<usize>,
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
    /// A folder a session glob walks cannot be read: its sessions would be missing unsaid.
    #[error("session glob `{pattern}`: cannot read folder {}: {error}", folder.display())]
    GlobFolder {
        pattern: String,
        folder: PathBuf,
        error: std::io::Error,
    },
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
    name: Option<String>,
}

/// Read a pipeline file and return its text and `pipeline.kind`.
pub fn read_kind(path: &Path) -> Result<(String, String), ConfigError> {
    let text = std::fs::read_to_string(path).map_err(|error| ConfigError::Read {
        path: path.to_path_buf(),
        error,
    })?;
    let kind = kind_of(path, &text)?;
    Ok((text, kind))
}

/// The `pipeline.kind` of a pipeline file's text (`path` only names it in errors).
pub fn kind_of(path: &Path, text: &str) -> Result<String, ConfigError> {
    let k: KindOnly = toml::from_str(text).map_err(|e| ConfigError::Parse {
        path: path.to_path_buf(),
        message: e.to_string().trim_end().to_string(),
    })?;
    Ok(k.pipeline.kind)
}

/// The `pipeline.name` of a pipeline file (the folder below `--out` that it writes).
pub fn read_name(path: &Path) -> Result<String, ConfigError> {
    let text = std::fs::read_to_string(path).map_err(|error| ConfigError::Read {
        path: path.to_path_buf(),
        error,
    })?;
    let k: KindOnly = toml::from_str(&text).map_err(|e| ConfigError::Parse {
        path: path.to_path_buf(),
        message: e.to_string().trim_end().to_string(),
    })?;
    Ok(k.pipeline.name.unwrap_or_default())
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

/// One step of a key path: a table key or an index into an array (of tables).
#[derive(Debug, Clone, PartialEq)]
enum Step {
    Key(String),
    Index(usize),
}

/// `a.b[2].c` → `[Key(a), Key(b), Index(2), Key(c)]`. Keys are bare TOML keys (no dots or
/// brackets inside), as every parameter name is.
fn steps(path: &str) -> Vec<Step> {
    let mut out = Vec::new();
    for part in path.split('.') {
        let (key, mut rest) = part.split_once('[').map_or((part, ""), |(k, r)| (k, r));
        if !key.is_empty() {
            out.push(Step::Key(key.to_string()));
        }
        while let Some((index, after)) = rest.split_once(']') {
            if let Ok(i) = index.parse() {
                out.push(Step::Index(i));
            }
            rest = after.strip_prefix('[').unwrap_or(after);
        }
    }
    out
}

/// Line (1-based) of the key at `path` (`params.local_eval.min_iou`, `params.sequences[1]`) in
/// a TOML text, and whether the whole path was found. When the file does not write the key
/// (a default), the line of the deepest table on the path that it writes; `None` when it
/// writes none of it (or the text does not parse).
pub fn line_of(text: &str, path: &str) -> Option<(usize, bool)> {
    use toml::de::{DeTable, DeValue};
    let doc = DeTable::parse(text).ok()?;
    let line = |offset: usize| text[..offset.min(text.len())].matches('\n').count() + 1;
    let mut table: &DeTable = doc.get_ref();
    let mut value: Option<&toml::Spanned<DeValue>> = None;
    let mut found: Option<usize> = None;
    let path = steps(path);
    for (k, step) in path.iter().enumerate() {
        let next = match (step, value.map(toml::Spanned::get_ref)) {
            (Step::Key(key), None | Some(DeValue::Table(_))) => {
                if let Some(DeValue::Table(t)) = value.map(toml::Spanned::get_ref) {
                    table = t;
                }
                table
                    .iter()
                    .find(|(name, _)| name.get_ref().as_ref() == key.as_str())
                    .map(|(name, v)| (name.span().start, v))
            }
            (Step::Index(i), Some(DeValue::Array(a))) => a.get(*i).map(|v| (v.span().start, v)),
            _ => None,
        };
        let Some((offset, v)) = next else {
            return found.map(|l| (l, false));
        };
        found = Some(line(offset));
        value = Some(v);
        if k + 1 == path.len() {
            return found.map(|l| (l, true));
        }
    }
    found.map(|l| (l, true))
}

/// A validation failure of one parameter: `(key path within [params], reason)`. The path
/// names the key as the file writes it: `roc.adaptive.history`, `sequences[1].scans`.
pub type Invalid = (String, String);

/// Turn the first validation failure into an error with its line and full key path.
pub fn check(path: &Path, text: &str, problems: Vec<Invalid>) -> Result<(), ConfigError> {
    match problems.into_iter().next() {
        None => Ok(()),
        Some((key, reason)) => Err(invalid(path, text, &format!("params.{key}"), reason)),
    }
}

/// The error for the key at `key_path` (from the top of the file), with its line.
pub fn invalid(path: &Path, text: &str, key_path: &str, reason: String) -> ConfigError {
    let (line, exact) = line_of(text, key_path).map_or((None, false), |(l, e)| (Some(l), e));
    ConfigError::Invalid {
        path: path.to_path_buf(),
        line,
        key: key_path.to_string(),
        reason: if exact || line.is_none() {
            reason
        } else {
            format!("{reason} (not set in the file: the default)")
        },
    }
}

/// `[topics]` keys that the experiment does not remap are errors naming them; `known` is
/// every logical name it reads.
pub fn check_topics(
    path: &Path,
    text: &str,
    topics: &BTreeMap<String, String>,
    known: &[String],
) -> Result<(), ConfigError> {
    let Some(unknown) = topics.keys().find(|k| !known.contains(k)) else {
        return Ok(());
    };
    let reason = if known.is_empty() {
        "unknown topic name: this pipeline takes no [topics] remaps".to_string()
    } else {
        format!(
            "unknown topic name (this pipeline remaps: {})",
            known.join(", ")
        )
    };
    // a quoted key with dots or brackets cannot be found as a path: the table's line then
    let key_path = format!("topics.{unknown}");
    let mut e = invalid(path, text, &key_path, reason);
    if let ConfigError::Invalid { reason, .. } = &mut e
        && let Some(r) = reason.strip_suffix(" (not set in the file: the default)")
    {
        *reason = r.to_string();
    }
    Err(e)
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
    if crate::storage::is_url(file) {
        // no scenario file to look for in a store: a `full/` folder is a profile's
        return match folder.parent() {
            Some(up) if name(folder) == "full" => name(up),
            _ => name(folder),
        };
    }
    match folder.parent() {
        Some(up)
            if !folder.join("scenario.toml").is_file() && up.join("scenario.toml").is_file() =>
        {
            name(up)
        }
        _ => name(folder),
    }
}

/// The session of log `p`, unless an exclude pattern drops it.
fn session_of(p: PathBuf, excludes: &[glob::Pattern]) -> Option<SessionRef> {
    let file = p
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    if excludes
        .iter()
        .any(|e| e.matches(&file) || e.matches_path(&p))
    {
        return None;
    }
    let dataset = dataset_name(&p);
    let name = file.strip_suffix(".mcap").unwrap_or(&file).to_string();
    Some(SessionRef {
        dataset,
        name,
        path: p,
    })
}

/// Expand globs (sorted, without repeats; `s3://` globs list the store, feature `s3`), drop excluded names, name each session. A folder
/// on a glob's way that cannot be read is an error naming it (its sessions would be missing).
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
        if crate::storage::is_url(Path::new(pattern)) {
            let urls = crate::storage::list_matching(pattern).map_err(|e| ConfigError::Glob {
                pattern: pattern.clone(),
                reason: e.to_string(),
            })?;
            out.extend(
                urls.into_iter()
                    .map(PathBuf::from)
                    .filter_map(|p| session_of(p, &excludes)),
            );
            continue;
        }
        let paths = glob::glob(pattern).map_err(|e| ConfigError::Glob {
            pattern: pattern.clone(),
            reason: e.to_string(),
        })?;
        for p in paths {
            let p = p.map_err(|e| ConfigError::GlobFolder {
                pattern: pattern.clone(),
                folder: e.path().to_path_buf(),
                error: e.into(),
            })?;
            if !p.is_file() {
                continue;
            }
            out.extend(session_of(p, &excludes));
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
        assert_eq!(line_of(GOOD, "params.alpha"), Some((10, true)));
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

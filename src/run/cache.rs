//! The per-session Parquet cache: `out/<pipeline>/sessions/dataset=<dataset>/session=<session>/`
//! (hive-style, so that Python polars, pandas/pyarrow and DuckDB read every session of a table
//! with `dataset` and `session` columns from the path: `docs/notebooks.md`) holds one
//! `<table>.parquet` per table, `source.txt` (the log's hash and path) and `key.txt`, written
//! last. The key hashes the log's bytes, the experiment's kind and `VERSION`, the tool version,
//! the parameters and the topic remaps (and `--recover` and a structure limit set by
//! `--max-structure-mib`, when given): a result is reused only when all of them match.
//!
//! `--aggregate-only` needs no logs: a session whose log is absent is found through the path
//! recorded in its `source.txt`, and its key is recomputed from the recorded hash.

use std::io::Read;
use std::path::{Path, PathBuf};

use xxhash_rust::xxh3::Xxh3;

use super::SessionTables;
use super::config::SessionRef;
use crate::report::table::{parquet_bytes, read_parquet};
use anyhow::Context;

use crate::report::atomic::{at, io_error};
use crate::report::{Provenance, atomic};

const KEY_FILE: &str = "key.txt";
const SOURCE_FILE: &str = "source.txt";
/// The reading warnings of a session's log (recovery losses, a linear re-index), one per line.
const WARNINGS_FILE: &str = "warnings.txt";

/// Hash of a file's bytes (xxh3-128, streamed); of an object in a store (`s3://`), the
/// content key [`crate::storage::RemoteObject::content_hash`] gives (its ETag and size).
pub fn hash_file(path: &Path) -> std::io::Result<u128> {
    if crate::storage::is_url(path) {
        return crate::storage::RemoteObject::open(&path.to_string_lossy())?.content_hash();
    }
    let mut f = std::fs::File::open(path)?;
    let mut h = Xxh3::new();
    let mut buf = vec![0u8; 1 << 20];
    loop {
        let n = f.read(&mut buf)?;
        if n == 0 {
            break;
        }
        h.update(&buf[..n]);
    }
    Ok(h.digest128())
}

/// What a session's cached result depends on besides its log.
pub struct KeyParts<'a> {
    pub kind: &'a str,
    pub version: u32,
    pub params_json: &'a str,
    pub topics_json: &'a str,
    /// `--recover`: results from a damaged log's readable part are cached apart.
    pub recover: bool,
}

impl KeyParts<'_> {
    /// The cache key of a log whose bytes hash to `file_hash`.
    pub fn key(&self, file_hash: u128) -> String {
        let mut h = Xxh3::new();
        h.update(&file_hash.to_le_bytes());
        h.update(self.kind.as_bytes());
        h.update(env!("CARGO_PKG_VERSION").as_bytes());
        h.update(&self.version.to_le_bytes());
        h.update(self.params_json.as_bytes());
        h.update(self.topics_json.as_bytes());
        if self.recover {
            h.update(b"recover");
        }
        // a raised (or lowered) structure budget can let a message decode that the default
        // refuses: such results are cached apart; the default leaves keys as they were
        if let Some(limit) = crate::log::cdr::structure_limit() {
            h.update(b"structure-limit");
            h.update(&(limit as u64).to_le_bytes());
        }
        format!("{:032x}", h.digest128())
    }
}

/// Prefix of a dataset's folder in the cache (hive partition key).
pub const DATASET_KEY: &str = "dataset=";
/// Prefix of a session's folder in the cache (hive partition key).
pub const SESSION_KEY: &str = "session=";

/// The cache folder of one session.
pub fn session_dir(out: &Path, pipeline: &str, s: &SessionRef) -> PathBuf {
    out.join(pipeline)
        .join("sessions")
        .join(format!("{DATASET_KEY}{}", s.dataset))
        .join(format!("{SESSION_KEY}{}", s.name))
}

/// Cached tables and the log's reading warnings if the stored key is `key`.
pub fn load(dir: &Path, key: &str) -> Option<(SessionTables, Vec<String>)> {
    let stored = std::fs::read_to_string(dir.join(KEY_FILE)).ok()?;
    if stored.trim() != key {
        return None;
    }
    let mut tables = SessionTables::new();
    for entry in std::fs::read_dir(dir).ok()? {
        let p = entry.ok()?.path();
        if p.extension().is_some_and(|e| e == "parquet") {
            let name = p.file_stem()?.to_string_lossy().into_owned();
            tables.insert(name, read_parquet(&p).ok()?);
        }
    }
    let warnings = match std::fs::read_to_string(dir.join(WARNINGS_FILE)) {
        Ok(text) => text.lines().map(str::to_string).collect(),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Vec::new(),
        Err(_) => return None,
    };
    // another run may have replaced the folder while it was read: then compute it again
    let after = std::fs::read_to_string(dir.join(KEY_FILE)).ok()?;
    (after == stored).then_some((tables, warnings))
}

/// The log hash recorded with a cached result (none for caches without `source.txt`).
pub fn recorded_hash(dir: &Path) -> Option<u128> {
    let text = std::fs::read_to_string(dir.join(SOURCE_FILE)).ok()?;
    u128::from_str_radix(text.lines().next()?.trim(), 16).ok()
}

/// Write a session's tables: into a folder staged in this run's scratch folder first, key
/// last, then moved into place by one rename, so a cached result is complete or absent.
/// Errors name the path and the step.
///
/// Another run may store the same session at the same time (two runs into one folder, or
/// shards that overlap): an old result in the way is moved aside (a rename) and the new one
/// renamed in; when the result in place already has this key, another run stored this same
/// result (same inputs, same key, same bytes) and it is kept.
pub fn store(
    out: &Path,
    dir: &Path,
    key: &str,
    source: (&Path, u128),
    (tables, warnings): (&SessionTables, &[String]),
    prov: &Provenance,
) -> anyhow::Result<()> {
    let scratch = atomic::scratch_dir(out)?;
    let tag = xxhash_rust::xxh3::xxh3_64(dir.to_string_lossy().as_bytes());
    let staged = scratch.join(format!("session-{tag:016x}"));
    if staged.exists() {
        std::fs::remove_dir_all(&staged).map_err(at("removing", &staged))?;
    }
    std::fs::create_dir_all(&staged).map_err(at("creating folder", &staged))?;
    let write = |name: &str, bytes: &[u8]| {
        let p = staged.join(name);
        std::fs::write(&p, bytes).map_err(at("writing", &p))
    };
    for (name, df) in tables {
        let bytes = parquet_bytes(df, prov)
            .with_context(|| format!("table {name} of {}", dir.display()))?;
        write(&format!("{name}.parquet"), &bytes)?;
    }
    let (path, hash) = source;
    write(
        SOURCE_FILE,
        format!("{hash:032x}\n{}\n", path.display()).as_bytes(),
    )?;
    if !warnings.is_empty() {
        // one line each: a warning never holds a newline (they are one-line messages)
        let lines: Vec<String> = warnings.iter().map(|w| w.replace('\n', " ")).collect();
        write(WARNINGS_FILE, (lines.join("\n") + "\n").as_bytes())?;
    }
    write(KEY_FILE, key.as_bytes())?;
    if let Some(parent) = dir.parent() {
        std::fs::create_dir_all(parent).map_err(at("creating folder", parent))?;
    }
    atomic::maybe_abort_hook();
    install(
        &staged,
        dir,
        key,
        &scratch.join(format!("replaced-{tag:016x}")),
    )
}

/// Move the staged folder to `dir`, moving a result in the way aside (to `aside`, then
/// removed), or keeping it when it is this same result stored by another run.
fn install(staged: &Path, dir: &Path, key: &str, aside: &Path) -> anyhow::Result<()> {
    const TRIES: usize = 8;
    for attempt in 0..TRIES {
        let aside = aside.with_extension(attempt.to_string());
        match std::fs::rename(staged, dir) {
            Ok(()) => return Ok(()),
            Err(_) if dir.is_dir() => {
                let in_place = std::fs::read_to_string(dir.join(KEY_FILE)).ok();
                if in_place.as_deref().map(str::trim) == Some(key) {
                    let _ = std::fs::remove_dir_all(staged);
                    return Ok(());
                }
                match std::fs::rename(dir, &aside) {
                    Ok(()) => {
                        let _ = std::fs::remove_dir_all(&aside);
                    }
                    // another run moved it first
                    Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                    Err(e) => {
                        let what = format!(
                            "moving the earlier cached result {} aside to",
                            dir.display()
                        );
                        return Err(io_error(&what, &aside, &e).into());
                    }
                }
            }
            Err(e) => {
                return Err(io_error(
                    &format!("moving {} into place at", staged.display()),
                    dir,
                    &e,
                )
                .into());
            }
        }
    }
    anyhow::bail!(
        "{}: other runs kept replacing this cached result ({TRIES} tries)",
        dir.display()
    )
}

/// Sessions with a cached result under `out/<pipeline>/sessions/` whose recorded log path
/// matches one of `patterns` and none of `exclude` (the logs themselves may be absent).
pub fn cached_sessions(
    out: &Path,
    pipeline: &str,
    patterns: &[String],
    exclude: &[String],
) -> Vec<SessionRef> {
    let compile = |ps: &[String]| -> Vec<glob::Pattern> {
        ps.iter()
            .filter_map(|p| glob::Pattern::new(p).ok())
            .collect()
    };
    let (patterns, exclude) = (compile(patterns), compile(exclude));
    let opts = glob::MatchOptions {
        require_literal_separator: true,
        ..glob::MatchOptions::new()
    };
    let mut found = Vec::new();
    let Ok(datasets) = std::fs::read_dir(out.join(pipeline).join("sessions")) else {
        return found;
    };
    for d in datasets.flatten() {
        let dataset = d.file_name().to_string_lossy().into_owned();
        let Some(dataset) = dataset.strip_prefix(DATASET_KEY).map(str::to_string) else {
            continue;
        };
        let Ok(sessions) = std::fs::read_dir(d.path()) else {
            continue;
        };
        for s in sessions.flatten() {
            let session = s.file_name().to_string_lossy().into_owned();
            let Some(session) = session.strip_prefix(SESSION_KEY).map(str::to_string) else {
                continue;
            };
            let Ok(text) = std::fs::read_to_string(s.path().join(SOURCE_FILE)) else {
                continue;
            };
            let Some(path) = text.lines().nth(1).map(PathBuf::from) else {
                continue;
            };
            let file = path
                .file_name()
                .map(|f| f.to_string_lossy().into_owned())
                .unwrap_or_default();
            let selected = patterns.iter().any(|p| p.matches_path_with(&path, opts))
                && !exclude
                    .iter()
                    .any(|e| e.matches(&file) || e.matches_path(&path));
            if selected {
                found.push(SessionRef {
                    dataset: dataset.clone(),
                    name: session,
                    path,
                });
            }
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cache is hive-style (`dataset=<d>/session=<s>`), and only such folders are found
    /// again: a folder of the earlier `<d>/<s>` layout is not a cached session.
    #[test]
    fn the_cache_is_hive_style_and_found_again_by_its_keys() {
        let dir = tempfile::tempdir().expect("tempdir");
        let out = dir.path();
        let s = SessionRef {
            dataset: "lab".into(),
            name: "lab_00".into(),
            path: PathBuf::from("/data/lab/lab_00.mcap"),
        };
        let hive = session_dir(out, "p", &s);
        assert_eq!(hive, out.join("p/sessions/dataset=lab/session=lab_00"));
        let old = out.join("p/sessions/lab/lab_01");
        for (d, log) in [
            (&hive, "/data/lab/lab_00.mcap"),
            (&old, "/data/lab/lab_01.mcap"),
        ] {
            std::fs::create_dir_all(d).expect("mkdir");
            std::fs::write(d.join(SOURCE_FILE), format!("{:032x}\n{log}\n", 7u128))
                .expect("source");
        }
        let found = cached_sessions(out, "p", &["/data/lab/*.mcap".to_string()], &[]);
        assert_eq!(found.len(), 1, "{found:?}");
        assert_eq!(
            (found[0].dataset.as_str(), found[0].name.as_str()),
            ("lab", "lab_00")
        );
        assert_eq!(recorded_hash(&hive), Some(7));
    }
}

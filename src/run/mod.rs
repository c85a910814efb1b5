//! Running a pipeline: plan, then run (per session, cached), then aggregate.
//!
//! 1. **Plan**: parse the pipeline file, find its sessions, and say which stages read which
//!    topics (`--dry-run` prints this and stops).
//! 2. **Per session** (rayon over sessions): the experiment's `process` turns one log into
//!    named tables, saved as Parquet under `out/<pipeline>/sessions/<dataset>/<session>/` with a
//!    key (input file hash + parameters + experiment version). A later run with the same key
//!    loads them instead of recomputing, so an interrupted or repeated run skips finished work.
//!    `--shard K/N` runs only every N-th session, for array jobs on a cluster scheduler.
//! 3. **Aggregate**: the experiment's `aggregate` reads every session's tables and returns
//!    result tables and figures, written under `out/<pipeline>/{tables,figures}/`.
//!
//! A session that cannot be processed (unreadable log, missing topic) is skipped, counted and
//! listed with its reason in the run summary and the report — never silently dropped.

pub mod config;
pub mod report;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

use anyhow::Context;
use polars::prelude::DataFrame;
use rayon::prelude::*;
use serde::Serialize;
use serde::de::DeserializeOwned;
use xxhash_rust::xxh3::Xxh3;

use crate::log::SessionLog;
use crate::progress::{Progress, SharedReporter, reporter};
use crate::report::table::{parquet_bytes, read_parquet};
use crate::report::{Figure, Provenance, Table, atomic, table::write_table, write_figure};
use config::{ConfigError, Invalid, PipelineFile, SessionRef};

/// Tables produced for one session, by name (cached as Parquet).
pub type SessionTables = BTreeMap<String, DataFrame>;

/// One session as an experiment sees it.
pub struct Session {
    pub log: SessionLog,
    pub info: SessionRef,
}

/// A stage and the topics it reads (logical name → topic), for plans and for checks.
#[derive(Debug, Clone, Serialize)]
pub struct Stage {
    pub name: String,
    /// Topics that must be present for the session to be processed.
    pub requires: Vec<String>,
    /// Topics used when present.
    pub optional: Vec<String>,
}

/// What aggregation returns.
#[derive(Default)]
pub struct Products {
    pub tables: Vec<Table>,
    pub figures: Vec<Figure>,
    /// Lines for the report (key findings, caveats).
    pub summary: Vec<String>,
    /// Other files (e.g. a trained model): `(path, bytes)`, written atomically; relative paths
    /// are below `out/<pipeline>/`.
    pub artifacts: Vec<(PathBuf, Vec<u8>)>,
}

/// Context handed to `aggregate`.
pub struct Aggregate<'a> {
    pub sessions: &'a [(SessionRef, SessionTables)],
    pub provenance: Provenance,
    /// `--write-tracks`: folder for copies of the logs with the tracks added (pipelines that
    /// produce tracks; others ignore it).
    pub write_tracks: Option<&'a Path>,
}

/// One experiment (paper reproduction) as the runner drives it.
pub trait Experiment: Sync {
    /// The `pipeline.kind` this implements.
    const KIND: &'static str;
    /// Bump when per-session results change meaning: cached results of older versions are
    /// recomputed.
    const VERSION: u32;
    type Params: DeserializeOwned + Serialize + Default + Sync + std::fmt::Debug;

    /// Parameter checks beyond types: `(key, reason)` for each problem.
    fn validate(_params: &Self::Params) -> Vec<Invalid> {
        Vec::new()
    }

    /// The stages and the topics they read, with `[topics]` remaps applied.
    fn plan(params: &Self::Params, topics: &BTreeMap<String, String>) -> Vec<Stage>;

    /// Files outside the session logs that `aggregate` reads (e.g. a real reference sequence),
    /// listed in the plan. Aggregation reads nothing else but the cached session tables.
    fn external_inputs(_params: &Self::Params) -> Vec<PathBuf> {
        Vec::new()
    }

    /// Process one session into named tables.
    fn process(
        session: &Session,
        params: &Self::Params,
        topics: &BTreeMap<String, String>,
        progress: &dyn Progress,
    ) -> anyhow::Result<SessionTables>;

    /// Turn all sessions' tables into result tables and figures.
    fn aggregate(ctx: &Aggregate, params: &Self::Params) -> anyhow::Result<Products>;
}

/// Options from the command line.
#[derive(Clone)]
pub struct RunOptions {
    /// Replace the pipeline's input globs.
    pub sessions: Option<Vec<String>>,
    pub dry_run: bool,
    /// `(k, n)`: process sessions k-1, k-1+n, ... (1-based k); skips aggregation.
    pub shard: Option<(usize, usize)>,
    /// Aggregate cached session results only (after sharded runs).
    pub aggregate_only: bool,
    /// Recompute even when a cached result matches.
    pub force: bool,
    pub out: PathBuf,
    /// Git commit and tool version for provenance.
    pub git_commit: String,
    /// Progress bars (`None` in tests: silent).
    pub progress: SharedReporter,
    /// Write tracks back into copies of the logs under this folder (`--write-tracks`).
    pub write_tracks: Option<PathBuf>,
}

/// What a run did, for the report.
#[derive(Debug, Clone, Serialize)]
pub struct RunSummary {
    pub pipeline: String,
    pub title: String,
    pub file: String,
    pub sessions: usize,
    pub computed: usize,
    pub cached: usize,
    pub skipped: Vec<(String, String)>,
    /// `(caption, path relative to out/)` of each table's Markdown.
    pub tables: Vec<(String, String)>,
    pub figures: Vec<(String, String)>,
    pub summary: Vec<String>,
    /// Paths of other files written (models).
    pub artifacts: Vec<String>,
    pub seconds: f64,
    /// Dry-run plan text (empty for real runs).
    pub plan: String,
}

/// Hash of a file's bytes (xxh3-128, streamed).
fn hash_file(path: &Path) -> std::io::Result<u128> {
    use std::io::Read;
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

fn session_dir(out: &Path, pipeline: &str, s: &SessionRef) -> PathBuf {
    out.join(pipeline)
        .join("sessions")
        .join(&s.dataset)
        .join(&s.name)
}

const KEY_FILE: &str = "key.txt";

/// Load cached frames if the key matches.
fn load_cached(dir: &Path, key: &str) -> Option<SessionTables> {
    let stored = std::fs::read_to_string(dir.join(KEY_FILE)).ok()?;
    if stored.trim() != key {
        return None;
    }
    let mut frames = SessionTables::new();
    for entry in std::fs::read_dir(dir).ok()? {
        let p = entry.ok()?.path();
        if p.extension().is_some_and(|e| e == "parquet") {
            let name = p.file_stem()?.to_string_lossy().into_owned();
            frames.insert(name, read_parquet(&p).ok()?);
        }
    }
    Some(frames)
}

/// Write a session's frames: into a scratch folder first, key last, then swap it into place.
fn store(
    out: &Path,
    dir: &Path,
    key: &str,
    frames: &SessionTables,
    prov: &Provenance,
) -> anyhow::Result<()> {
    let tag = xxhash_rust::xxh3::xxh3_64(dir.to_string_lossy().as_bytes());
    let scratch = out
        .join(atomic::SCRATCH_DIR)
        .join(format!("session-{}-{tag:016x}", std::process::id()));
    if scratch.exists() {
        std::fs::remove_dir_all(&scratch)?;
    }
    std::fs::create_dir_all(&scratch)?;
    for (name, df) in frames {
        std::fs::write(
            scratch.join(format!("{name}.parquet")),
            parquet_bytes(df, prov)?,
        )?;
    }
    std::fs::write(scratch.join(KEY_FILE), key)?;
    if dir.exists() {
        std::fs::remove_dir_all(dir)?;
    }
    atomic::maybe_abort_hook();
    if let Some(parent) = dir.parent() {
        std::fs::create_dir_all(parent)?;
    }
    std::fs::rename(&scratch, dir)?;
    Ok(())
}

/// Check that a session has every required topic.
fn missing_topics(log: &SessionLog, stages: &[Stage]) -> Vec<String> {
    let mut missing: Vec<String> = stages
        .iter()
        .flat_map(|s| s.requires.iter())
        .filter(|t| log.summary().channel(t).is_none())
        .cloned()
        .collect();
    missing.sort();
    missing.dedup();
    missing
}

fn plan_text<E: Experiment>(
    file: &PipelineFile<E::Params>,
    sessions: &[SessionRef],
    stages: &[Stage],
) -> String {
    use std::fmt::Write;
    let mut o = String::new();
    let _ = writeln!(
        o,
        "pipeline {} (kind {}): {}",
        file.pipeline.name, file.pipeline.kind, file.pipeline.title
    );
    let _ = writeln!(o, "stages:");
    for s in stages {
        let _ = writeln!(
            o,
            "  {:24} requires [{}]{}",
            s.name,
            s.requires.join(", "),
            if s.optional.is_empty() {
                String::new()
            } else {
                format!(", uses if present [{}]", s.optional.join(", "))
            }
        );
    }
    let inputs = E::external_inputs(&file.params);
    if !inputs.is_empty() {
        let _ = writeln!(o, "other inputs (read by aggregation):");
        for p in inputs {
            let state = if p.exists() {
                "present"
            } else {
                "absent: SKIPPED"
            };
            let _ = writeln!(o, "  {}  ({state})", p.display());
        }
    }
    let _ = writeln!(
        o,
        "parameters: {}",
        serde_json::to_string(&file.params).unwrap_or_default()
    );
    let _ = writeln!(o, "sessions ({}):", sessions.len());
    for s in sessions {
        let status = match SessionLog::open(&s.path) {
            Ok(log) => {
                let missing = missing_topics(&log, stages);
                if missing.is_empty() {
                    format!("ok, {} topics", log.summary().channels.len())
                } else {
                    format!("would be skipped: missing {}", missing.join(", "))
                }
            }
            Err(e) => format!("would be skipped: {e}"),
        };
        let _ = writeln!(
            o,
            "  {}/{}  {}  ({status})",
            s.dataset,
            s.name,
            s.path.display()
        );
    }
    o
}

/// Run one pipeline file end to end with experiment `E`.
pub fn run_experiment<E: Experiment>(
    path: &Path,
    text: &str,
    opts: &RunOptions,
) -> anyhow::Result<RunSummary> {
    let started = Instant::now();
    let file: PipelineFile<E::Params> = config::parse(path, text)?;
    config::check(path, text, E::validate(&file.params))?;
    let stages = E::plan(&file.params, &file.topics);
    let patterns = opts
        .sessions
        .clone()
        .unwrap_or_else(|| file.inputs.sessions.clone());
    let mut sessions = config::find_sessions(&patterns, &file.inputs.exclude)?;
    if let Some((k, n)) = opts.shard {
        sessions = sessions
            .into_iter()
            .enumerate()
            .filter(|(i, _)| i % n == k - 1)
            .map(|(_, s)| s)
            .collect();
    }
    let name = file.pipeline.name.clone();
    let mut summary = RunSummary {
        pipeline: name.clone(),
        title: file.pipeline.title.clone(),
        file: path.display().to_string(),
        sessions: sessions.len(),
        computed: 0,
        cached: 0,
        skipped: Vec::new(),
        tables: Vec::new(),
        figures: Vec::new(),
        summary: Vec::new(),
        artifacts: Vec::new(),
        seconds: 0.0,
        plan: String::new(),
    };
    if opts.dry_run {
        summary.plan = plan_text::<E>(&file, &sessions, &stages);
        return Ok(summary);
    }
    if sessions.is_empty() {
        anyhow::bail!("{}: no sessions match {:?}", path.display(), patterns);
    }
    let params_json = serde_json::to_string(&file.params)?;
    let topics_json = serde_json::to_string(&file.topics)?;
    let provenance = Provenance {
        dataset: {
            let mut d: Vec<&str> = sessions.iter().map(|s| s.dataset.as_str()).collect();
            d.dedup();
            format!("{} ({} sessions)", d.join(", "), sessions.len())
        },
        seed: None,
        git_commit: opts.git_commit.clone(),
        tool_version: env!("CARGO_PKG_VERSION").to_string(),
        parameters: serde_json::from_str::<BTreeMap<String, serde_json::Value>>(&params_json)
            .unwrap_or_default()
            .into_iter()
            .map(|(k, v)| (k, v.to_string()))
            .collect(),
    };

    let bars = reporter(&opts.progress);
    let total = bars.bar(&name, "sessions");
    total.set_length(sessions.len() as u64);
    let counts = Mutex::new((0usize, 0usize));
    let results: Vec<Result<(SessionRef, SessionTables), (SessionRef, String)>> = sessions
        .par_iter()
        .map(|s| {
            let dir = session_dir(&opts.out, &name, s);
            let outcome = (|| -> anyhow::Result<(SessionTables, bool)> {
                let file_hash =
                    hash_file(&s.path).with_context(|| format!("reading {}", s.path.display()))?;
                let mut h = Xxh3::new();
                h.update(&file_hash.to_le_bytes());
                h.update(E::KIND.as_bytes());
                h.update(env!("CARGO_PKG_VERSION").as_bytes());
                h.update(&E::VERSION.to_le_bytes());
                h.update(params_json.as_bytes());
                h.update(topics_json.as_bytes());
                let key = format!("{:032x}", h.digest128());
                if !opts.force
                    && let Some(frames) = load_cached(&dir, &key)
                {
                    return Ok((frames, true));
                }
                if opts.aggregate_only {
                    anyhow::bail!("no cached result for this session (run the shards first)");
                }
                let log = SessionLog::open(&s.path)?;
                let missing = missing_topics(&log, &stages);
                if !missing.is_empty() {
                    anyhow::bail!("missing topic(s) {}", missing.join(", "));
                }
                let bar = bars.bar(&format!("{}/{}", s.dataset, s.name), "");
                let session = Session {
                    log,
                    info: s.clone(),
                };
                let frames = E::process(&session, &file.params, &file.topics, bar.as_ref());
                drop(bar);
                let frames = frames?;
                store(&opts.out, &dir, &key, &frames, &provenance)?;
                Ok((frames, false))
            })();
            total.inc(1);
            match outcome {
                Ok((frames, cached)) => {
                    if let Ok(mut c) = counts.lock() {
                        if cached { c.1 += 1 } else { c.0 += 1 }
                    }
                    Ok((s.clone(), frames))
                }
                Err(e) => Err((s.clone(), format!("{e:#}"))),
            }
        })
        .collect();
    drop(total);
    let (computed, cached) = counts.into_inner().unwrap_or_default();
    summary.computed = computed;
    summary.cached = cached;
    let mut done = Vec::new();
    for r in results {
        match r {
            Ok(x) => done.push(x),
            Err((s, reason)) => summary
                .skipped
                .push((format!("{}/{}", s.dataset, s.name), reason)),
        }
    }
    if opts.shard.is_some() {
        summary.seconds = started.elapsed().as_secs_f64();
        return Ok(summary);
    }
    if done.is_empty() {
        anyhow::bail!(
            "{}: every session was skipped; first: {}",
            path.display(),
            summary
                .skipped
                .first()
                .map_or(String::new(), |s| format!("{}: {}", s.0, s.1))
        );
    }
    let products = E::aggregate(
        &Aggregate {
            sessions: &done,
            provenance: provenance.clone(),
            write_tracks: opts.write_tracks.as_deref(),
        },
        &file.params,
    )?;
    let pipeline_dir = opts.out.join(&name);
    for t in products.tables {
        let t = if t.provenance.git_commit.is_empty() {
            t.with_provenance(provenance.clone())
        } else {
            t
        };
        write_table(&pipeline_dir.join("tables"), &t, &opts.out)?;
        summary
            .tables
            .push((t.title.clone(), format!("{name}/tables/{}.md", t.name)));
    }
    for f in products.figures {
        write_figure(&pipeline_dir.join("figures"), &f, &opts.out)?;
        summary
            .figures
            .push((f.title.clone(), format!("{name}/figures/{}.png", f.name)));
    }
    for (path, bytes) in &products.artifacts {
        let path = if path.is_absolute() {
            path.clone()
        } else {
            pipeline_dir.join(path)
        };
        atomic::write_atomic(&path, bytes, Some(&opts.out))
            .with_context(|| format!("writing {}", path.display()))?;
        summary.artifacts.push(path.display().to_string());
    }
    summary.summary = products.summary;
    summary.seconds = started.elapsed().as_secs_f64();
    Ok(summary)
}

/// Re-export for pipeline implementations.
pub use config::ConfigError as PipelineConfigError;

/// Unknown `kind` in a pipeline file.
pub fn unknown_kind(path: &Path, kind: &str, known: &[&str]) -> ConfigError {
    ConfigError::UnknownKind {
        path: path.to_path_buf(),
        kind: kind.to_string(),
        known: known.join(", "),
    }
}

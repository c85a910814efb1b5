//! Running a pipeline: plan, then run (per session, cached), then aggregate.
//!
//! 1. **Plan**: parse the pipeline file, find its sessions, and say which stages read which
//!    topics (`--dry-run` prints this and stops).
//! 2. **Per session** (rayon over sessions): the experiment's `process` turns one log into
//!    named tables, saved as Parquet under `out/<pipeline>/sessions/dataset=<dataset>/session=<session>/` with a
//!    key (input file hash + parameters + experiment version). A later run with the same key
//!    loads them instead of recomputing, so an interrupted or repeated run skips finished work.
//!    `--shard K/N` runs only every N-th session, for array jobs on a cluster scheduler.
//! 3. **Aggregate**: the experiment's `aggregate` reads every session's tables and returns
//!    result tables and figures, written under `out/<pipeline>/{tables,figures}/`.
//!
//! 4. **Write**: the products go under `out/<pipeline>/` atomically, listed in the summary.
//!
//! A session that cannot be processed (unreadable log, missing topic, an error or a panic in
//! `process`) is skipped, counted and listed with its reason in the run summary, in the
//! pipeline's `skipped_sessions` table ([`skipped`], written by the runner for every pipeline)
//! and in the report — never silently dropped; the other sessions' results are kept. The cache lives in `cache`
//! (`--aggregate-only` reads it without the logs). A session computed but whose results could
//! not be stored in the cache keeps its results in this run's tables, is listed (`unstored`,
//! with the cache path and the reason) and fails the run unless `--keep-going`.
//!
//! Runs that share an output folder: a run that writes a pipeline's products (a full run or
//! `--aggregate-only`) holds `out/<pipeline>/.lock` ([`lock`]) from its plan to its end, so a
//! second one fails at once naming the folder and the holder's process id; shards only store
//! sessions (complete or absent, by rename) and take no lock; every process writes its scratch
//! files in its own folder ([`crate::report::atomic`]).

mod cache;
pub mod config;
mod inputs;
pub mod lock;
pub mod report;
pub mod schemas;
pub mod shard;
pub mod skipped;
pub mod slurm;

use std::collections::BTreeMap;
use std::panic::{self, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use polars::prelude::DataFrame;
use rayon::prelude::*;
use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::log::{LogError, LogErrorKind, SessionLog};
use crate::progress::{Progress, SharedReporter, reporter};
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
    /// The per-session tables `process` writes and what a row of each is: `docs/schemas.md`
    /// is generated from it (`peopletrack schemas`, which refuses a table missing here).
    const SESSION_TABLES: &'static [schemas::TableDoc] = &[];
    type Params: DeserializeOwned + Serialize + Default + Sync + std::fmt::Debug;

    /// Parameter checks beyond types: `(key, reason)` for each problem.
    fn validate(_params: &Self::Params) -> Vec<Invalid> {
        Vec::new()
    }

    /// Every logical topic name `[topics]` may remap (any other key is an error naming it).
    /// The default: none, for experiments that take their topics from `[params]`.
    fn topic_keys(_params: &Self::Params) -> Vec<String> {
        Vec::new()
    }

    /// The stages and the topics they read, with `[topics]` remaps applied.
    fn plan(params: &Self::Params, topics: &BTreeMap<String, String>) -> Vec<Stage>;

    /// Files outside the session logs that `aggregate` reads (e.g. a real reference sequence),
    /// listed in the plan. Aggregation reads nothing else but the cached session tables.
    fn external_inputs(_params: &Self::Params) -> Vec<PathBuf> {
        Vec::new()
    }

    /// Files the parameters name that must exist before anything runs (e.g. a model to
    /// load): `(key path within [params], path)`. A missing one is an error naming the
    /// pipeline file, the key's line and the path, in `--dry-run` too.
    fn required_files(_params: &Self::Params) -> Vec<(String, PathBuf)> {
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
    /// With `aggregate_only`: the number of shards whose records must all be there
    /// (`--expect-shards N`); their skipped sessions are reported with their reasons.
    pub expect_shards: Option<usize>,
    /// Recompute even when a cached result matches.
    pub force: bool,
    pub out: PathBuf,
    /// Git commit and tool version for provenance.
    pub git_commit: String,
    /// Progress bars (`None` in tests: silent).
    pub progress: SharedReporter,
    /// Write tracks back into copies of the logs under this folder (`--write-tracks`).
    pub write_tracks: Option<PathBuf>,
    /// Read damaged logs as far as they go (`--recover`): every complete chunk before the
    /// damage (and good chunks after it); what was lost is listed per session.
    pub recover: bool,
    /// `--keep-going`: a session computed but whose results could not be stored in the cache
    /// does not fail the run (it is still listed, `unstored`).
    pub keep_going: bool,
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
    /// `(dataset/session, warnings)` of sessions that gave results but whose log needed
    /// recovery (`--recover`) or a linear re-index (a chunk index that lies).
    pub warned: Vec<(String, String)>,
    /// Path (relative to out/) of the `skipped_sessions` table's Markdown; empty when it was
    /// not written (dry runs, shards).
    pub skipped_table: String,
    /// `(caption, path relative to out/)` of each table's Markdown.
    pub tables: Vec<(String, String)>,
    pub figures: Vec<(String, String)>,
    pub summary: Vec<String>,
    /// Paths of other files written (models).
    pub artifacts: Vec<String>,
    pub seconds: f64,
    /// Dry-run plan text (empty for real runs).
    pub plan: String,
    /// Warnings about the run as a whole (a `[topics]` remap no session has, a folder that
    /// could not be locked), each naming the file or folder.
    pub notices: Vec<String>,
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
    notices: &[String],
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
    for n in notices {
        let _ = writeln!(o, "warning: {n}");
    }
    o
}

/// Step 1, the plan: the parsed pipeline file, its stages and the sessions to run.
struct Plan<P> {
    file: PipelineFile<P>,
    stages: Vec<Stage>,
    /// The session globs in force (the file's, or `--sessions`).
    patterns: Vec<String>,
    sessions: Vec<SessionRef>,
}

/// Parse and validate a pipeline file's text (`path` only names it in errors) as experiment
/// `E`, and plan its stages: everything `run` checks before it looks for sessions.
pub fn check_experiment<E: Experiment>(
    path: &Path,
    text: &str,
) -> Result<(PipelineFile<E::Params>, Vec<Stage>), ConfigError> {
    let file: PipelineFile<E::Params> = config::parse(path, text)?;
    config::check(path, text, E::validate(&file.params))?;
    config::check_topics(path, text, &file.topics, &E::topic_keys(&file.params))?;
    let stages = E::plan(&file.params, &file.topics);
    Ok((file, stages))
}

fn plan<E: Experiment>(
    path: &Path,
    text: &str,
    opts: &RunOptions,
) -> anyhow::Result<Plan<E::Params>> {
    let (file, stages) = check_experiment::<E>(path, text)?;
    inputs::check_required(path, text, &E::required_files(&file.params))?;
    let patterns = opts
        .sessions
        .clone()
        .unwrap_or_else(|| file.inputs.sessions.clone());
    let mut sessions = config::find_sessions(&patterns, &file.inputs.exclude)?;
    if opts.aggregate_only {
        // sessions whose logs are gone but whose results are cached
        let cached = cache::cached_sessions(
            &opts.out,
            &file.pipeline.name,
            &patterns,
            &file.inputs.exclude,
        );
        for c in cached {
            if !sessions
                .iter()
                .any(|s| s.dataset == c.dataset && s.name == c.name)
            {
                sessions.push(c);
            }
        }
        sessions.sort();
    }
    if let Some((k, n)) = opts.shard {
        if sessions.is_empty() {
            anyhow::bail!("{}: no sessions match {patterns:?}", path.display());
        }
        // a shard may have no session (more shards than sessions): it records that it ran
        sessions = shard::of_shard(sessions, k, n);
    }
    Ok(Plan {
        file,
        stages,
        patterns,
        sessions,
    })
}

/// Where tables come from: provenance of every table and cached file of this run.
fn provenance(sessions: &[SessionRef], git_commit: &str, params_json: &str) -> Provenance {
    let mut d: Vec<&str> = sessions.iter().map(|s| s.dataset.as_str()).collect();
    d.dedup();
    Provenance {
        dataset: format!("{} ({} sessions)", d.join(", "), sessions.len()),
        seed: None,
        git_commit: git_commit.to_string(),
        tool_version: env!("CARGO_PKG_VERSION").to_string(),
        parameters: serde_json::from_str::<BTreeMap<String, serde_json::Value>>(params_json)
            .unwrap_or_default()
            .into_iter()
            .map(|(k, v)| (k, v.to_string()))
            .collect(),
    }
}

/// Everything one session's processing needs besides the session itself.
struct SessionJob<'a, P> {
    plan: &'a Plan<P>,
    opts: &'a RunOptions,
    pipeline: &'a str,
    key: cache::KeyParts<'a>,
    provenance: &'a Provenance,
    bars: &'a dyn crate::progress::Reporter,
}

/// One session's results: its tables, whether they came from the cache, and what reading
/// its log warned about (losses under `--recover`, a linear re-index).
struct SessionResult {
    tables: SessionTables,
    cached: bool,
    warnings: Vec<String>,
    /// Why its results, computed, could not be stored in the cache (naming the path).
    not_stored: Option<String>,
}

/// Step 2, one session: its cached tables when the key matches, else `process` (then cached).
fn session_tables<E: Experiment>(
    job: &SessionJob<E::Params>,
    s: &SessionRef,
) -> anyhow::Result<SessionResult> {
    let opts = job.opts;
    let dir = cache::session_dir(&opts.out, job.pipeline, s);
    let file_hash = if opts.aggregate_only && !s.path.exists() {
        match cache::recorded_hash(&dir) {
            Some(h) => h,
            None => anyhow::bail!(skipped::NOT_CACHED),
        }
    } else {
        cache::hash_file(&s.path).with_context(|| format!("reading {}", s.path.display()))?
    };
    let key = job.key.key(file_hash);
    if !opts.force
        && let Some((tables, warnings)) = cache::load(&dir, &key)
    {
        return Ok(SessionResult {
            tables,
            cached: true,
            warnings,
            not_stored: None,
        });
    }
    if opts.aggregate_only {
        anyhow::bail!(skipped::NOT_CACHED);
    }
    let log = if opts.recover {
        SessionLog::open_recovering(&s.path)?
    } else {
        SessionLog::open(&s.path)?
    };
    let (tables, log) = match process_log::<E>(job, s, log.clone()) {
        // the index's time ranges lie: the data, scanned, decides the order
        Err(e) if chunk_index_lies(&e) && !opts.recover => {
            let log = SessionLog::open_scanning(&s.path)?;
            (process_log::<E>(job, s, log.clone())?, log)
        }
        result => (result?, log),
    };
    let warnings = log.summary().warnings.clone();
    let not_stored = cache::store(
        &opts.out,
        &dir,
        &key,
        (&s.path, file_hash),
        (&tables, &warnings),
        job.provenance,
    )
    .err()
    .map(|e| format!("{}{}: {e:#}", skipped::NOT_STORED, dir.display()));
    Ok(SessionResult {
        tables,
        cached: false,
        warnings,
        not_stored,
    })
}

/// The experiment's `process` on one opened log (a missing required topic is a skip).
fn process_log<E: Experiment>(
    job: &SessionJob<E::Params>,
    s: &SessionRef,
    log: SessionLog,
) -> anyhow::Result<SessionTables> {
    let missing = missing_topics(&log, &job.plan.stages);
    if !missing.is_empty() {
        anyhow::bail!("{}{}", skipped::MISSING_TOPICS, missing.join(", "));
    }
    let bar = job.bars.bar(&format!("{}/{}", s.dataset, s.name), "");
    let session = Session {
        log,
        info: s.clone(),
    };
    let file = &job.plan.file;
    let tables = E::process(&session, &file.params, &file.topics, bar.as_ref());
    drop(bar);
    tables
}

/// Whether `e` comes from a chunk index whose time ranges lie
/// ([`LogErrorKind::ChunkStartsEarlier`]): reading the log again by a linear scan of the data
/// keeps log-time order.
fn chunk_index_lies(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<LogError>()
            .is_some_and(|l| matches!(*l.kind, LogErrorKind::ChunkStartsEarlier { .. }))
    })
}

/// The text of a panic's payload.
fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "(no message)".to_string()
    }
}

/// One session's outcome: its results, or why it was skipped.
type Outcome = Result<(SessionRef, SessionResult), (SessionRef, String)>;

/// Step 2, every session (in parallel): a session that fails or panics becomes a skip with
/// its reason; the others' results are kept. Outcomes come back in session order.
fn process_sessions<E: Experiment>(job: &SessionJob<E::Params>) -> Vec<Outcome> {
    let sessions = &job.plan.sessions;
    let total = job.bars.bar(job.pipeline, "sessions");
    total.set_length(sessions.len() as u64);
    let outcomes = sessions
        .par_iter()
        .map(|s| {
            let outcome = panic::catch_unwind(AssertUnwindSafe(|| session_tables::<E>(job, s)))
                .unwrap_or_else(|p| {
                    Err(anyhow::anyhow!(
                        "{}{}",
                        skipped::PANICKED,
                        panic_message(&*p)
                    ))
                });
            total.inc(1);
            match outcome {
                Ok(result) => Ok((s.clone(), result)),
                Err(e) => Err((s.clone(), format!("{e:#}"))),
            }
        })
        .collect();
    drop(total);
    outcomes
}

/// Step 4: write the aggregation's tables, figures and other files; list them in `summary`.
fn write_products(
    products: Products,
    out: &Path,
    provenance: &Provenance,
    summary: &mut RunSummary,
) -> anyhow::Result<()> {
    let name = summary.pipeline.clone();
    let pipeline_dir = out.join(&name);
    for t in products.tables {
        let t = if t.provenance.git_commit.is_empty() {
            t.with_provenance(provenance.clone())
        } else {
            t
        };
        write_table(&pipeline_dir.join("tables"), &t, out)?;
        summary
            .tables
            .push((t.title.clone(), format!("{name}/tables/{}.md", t.name)));
    }
    for f in products.figures {
        write_figure(&pipeline_dir.join("figures"), &f, out)?;
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
        atomic::write_atomic(&path, bytes, Some(out))
            .with_context(|| format!("writing {}", path.display()))?;
        summary.artifacts.push(path.display().to_string());
    }
    summary.summary = products.summary;
    Ok(())
}

/// What step 2 gave, sorted for the later steps.
#[derive(Default)]
struct Collected {
    /// Sessions with results.
    done: Vec<(SessionRef, SessionTables)>,
    /// Sessions without results, and why.
    not_done: Vec<(SessionRef, String)>,
    /// Sessions with results and a warning: read with warnings, or not stored in the cache.
    warned: Vec<(SessionRef, String)>,
}

/// Sort the sessions' outcomes into results, skips and warnings, counted in `summary`.
fn collect(outcomes: Vec<Outcome>, summary: &mut RunSummary) -> Collected {
    let mut c = Collected::default();
    let label = |s: &SessionRef| format!("{}/{}", s.dataset, s.name);
    for outcome in outcomes {
        match outcome {
            Ok((s, result)) => {
                if result.cached {
                    summary.cached += 1;
                } else {
                    summary.computed += 1;
                }
                let warnings = (!result.warnings.is_empty()).then(|| result.warnings.join("; "));
                for why in warnings.into_iter().chain(result.not_stored) {
                    summary.warned.push((label(&s), why.clone()));
                    c.warned.push((s.clone(), why));
                }
                c.done.push((s, result.tables));
            }
            Err((s, reason)) => {
                summary.skipped.push((label(&s), reason.clone()));
                c.not_done.push((s, reason));
            }
        }
    }
    c
}

/// Run one pipeline file end to end with experiment `E`: plan, per-session processing
/// (cached), aggregation, and writing of its products.
pub fn run_experiment<E: Experiment>(
    path: &Path,
    text: &str,
    opts: &RunOptions,
) -> anyhow::Result<RunSummary> {
    let started = Instant::now();
    let mut plan = plan::<E>(path, text, opts)?;
    let params_json = serde_json::to_string(&plan.file.params)?;
    let topics_json = serde_json::to_string(&plan.file.topics)?;
    let config = shard::config_hash(E::KIND, E::VERSION, &params_json, &topics_json);
    let pipeline_dir = opts.out.join(&plan.file.pipeline.name);
    let recorded = match opts.expect_shards {
        Some(n) if opts.aggregate_only => {
            shard::expect(&pipeline_dir, n, &config, &mut plan.sessions)?
        }
        _ => Vec::new(),
    };
    let file = &plan.file;
    let name = file.pipeline.name.clone();
    let mut summary = RunSummary {
        pipeline: name.clone(),
        title: file.pipeline.title.clone(),
        file: path.display().to_string(),
        sessions: plan.sessions.len(),
        computed: 0,
        cached: 0,
        skipped: Vec::new(),
        warned: Vec::new(),
        skipped_table: String::new(),
        tables: Vec::new(),
        figures: Vec::new(),
        summary: Vec::new(),
        artifacts: Vec::new(),
        seconds: 0.0,
        plan: String::new(),
        notices: Vec::new(),
    };
    if plan.sessions.is_empty() && opts.shard.is_none() {
        anyhow::bail!("{}: no sessions match {:?}", path.display(), plan.patterns);
    }
    // a run that writes the pipeline's products holds its folder from here to its end
    let held = if opts.dry_run || opts.shard.is_some() {
        None
    } else {
        Some(lock::FolderLock::acquire(&opts.out.join(&name))?)
    };
    summary
        .notices
        .extend(held.as_ref().and_then(|l| l.unsupported.clone()));
    summary.notices.extend(inputs::absent_topics(
        path,
        text,
        &file.topics,
        &plan.sessions,
    ));
    if opts.dry_run {
        summary.plan = plan_text::<E>(file, &plan.sessions, &plan.stages, &summary.notices);
        return Ok(summary);
    }
    let provenance = provenance(&plan.sessions, &opts.git_commit, &params_json);
    let job = SessionJob {
        plan: &plan,
        opts,
        pipeline: &name,
        key: cache::KeyParts {
            kind: E::KIND,
            version: E::VERSION,
            params_json: &params_json,
            topics_json: &topics_json,
            recover: opts.recover,
        },
        provenance: &provenance,
        bars: reporter(&opts.progress),
    };
    let mut c = collect(process_sessions::<E>(&job), &mut summary);
    shard::use_recorded_reasons(&recorded, &mut c.not_done, &mut summary.skipped);
    if let Some(k_of_n) = opts.shard {
        summary.seconds = started.elapsed().as_secs_f64();
        skipped::fail_if_unstored(&summary, opts)?;
        let (sessions, not_done) = (&plan.sessions, &c.not_done);
        shard::write_record(
            &opts.out,
            &pipeline_dir,
            k_of_n,
            &config,
            sessions,
            not_done,
        )?;
        return Ok(summary);
    }
    if c.done.is_empty() {
        anyhow::bail!(
            "{}: every session was skipped; first: {}",
            path.display(),
            summary
                .skipped
                .first()
                .map_or(String::new(), |s| format!("{}: {}", s.0, s.1))
        );
    }
    // step 3: aggregate
    let products = E::aggregate(
        &Aggregate {
            sessions: &c.done,
            provenance: provenance.clone(),
            write_tracks: opts.write_tracks.as_deref(),
        },
        &file.params,
    )?;
    let skipped_table = skipped::table(&c.not_done, &c.warned, &provenance)?;
    write_products(products, &opts.out, &provenance, &mut summary)
        .and_then(|()| {
            let tables = opts.out.join(&name).join("tables");
            Ok(write_table(&tables, &skipped_table, &opts.out).map(|_| ())?)
        })
        .map_err(|e| skipped::also_unstored(e, &summary))?;
    summary.skipped_table = format!("{name}/tables/{}.md", skipped::TABLE);
    summary.seconds = started.elapsed().as_secs_f64();
    skipped::fail_if_unstored(&summary, opts)?;
    drop(held);
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

#[cfg(test)]
mod tests;

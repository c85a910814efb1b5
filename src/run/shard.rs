//! Shards: which sessions shard `K/N` runs, and the record each shard leaves for the aggregate.
//!
//! Assignment is stable: sessions are ordered by the hash of their log's bytes (xxh3-128, the
//! hash the cache records; dataset and name break ties between identical logs) and session `i`
//! of that order goes to shard `i mod N + 1`. A shard's sessions therefore do not depend on file
//! names, glob order, the machine or the folder the logs sit in.
//!
//! Each shard that finishes writes `<out>/<pipeline>/shards/<N>/<K>.json` (atomically): the
//! sessions it ran, which of them were skipped and why, and the configuration it ran with. The
//! aggregate (`--aggregate-only --expect-shards N`) reads the `N` records and names every shard
//! that left none, that ran another configuration, or whose record is unreadable — it never
//! aggregates over a silently missing shard.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use anyhow::Context;
use xxhash_rust::xxh3::Xxh3;

use super::config::SessionRef;
use crate::report::atomic::write_atomic;

/// Keep the sessions of shard `k` of `n` (1-based): index `i` of the order by
/// `(hash, dataset, name)` belongs to shard `i mod n + 1`. `hash` is the log's content hash.
pub fn assign<E>(
    sessions: Vec<SessionRef>,
    (k, n): (usize, usize),
    hash: impl Fn(&SessionRef) -> Result<u128, E>,
) -> Result<Vec<SessionRef>, E> {
    let mut keyed = sessions
        .into_iter()
        .map(|s| Ok((hash(&s)?, s)))
        .collect::<Result<Vec<_>, E>>()?;
    keyed.sort_by(|(ha, a), (hb, b)| (ha, &a.dataset, &a.name).cmp(&(hb, &b.dataset, &b.name)));
    let mut mine: Vec<SessionRef> = keyed
        .into_iter()
        .enumerate()
        .filter(|(i, _)| i % n == k - 1)
        .map(|(_, (_, s))| s)
        .collect();
    // the rest of the run (and its tables) sees the usual order
    mine.sort();
    Ok(mine)
}

/// One session of a shard's record.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct RecordedSession {
    pub dataset: String,
    pub name: String,
    /// The log it was read from (the aggregate may run with the logs gone).
    pub path: PathBuf,
    /// Why it has no result (`None`: its result is in the cache).
    pub skipped: Option<String>,
}

/// What shard `shard` of `of` left for the aggregate.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Record {
    pub shard: usize,
    pub of: usize,
    /// Hash of the configuration (parameters, topics, experiment version): a record from
    /// another configuration does not count.
    pub config: String,
    pub sessions: Vec<RecordedSession>,
}

/// `<out>/<pipeline>/shards/<n>/<k>.json`.
pub fn record_path(pipeline_dir: &Path, k: usize, n: usize) -> PathBuf {
    pipeline_dir
        .join("shards")
        .join(n.to_string())
        .join(format!("{k}.json"))
}

/// The records of all `n` shards, and one line per shard that does not count, naming it.
pub fn check_records(pipeline_dir: &Path, n: usize, config: &str) -> (Vec<Record>, Vec<String>) {
    let mut records = Vec::new();
    let mut problems = Vec::new();
    for k in 1..=n {
        let p = record_path(pipeline_dir, k, n);
        let text = match std::fs::read_to_string(&p) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                problems.push(format!(
                    "shard {k}/{n} did not finish (no record {})",
                    p.display()
                ));
                continue;
            }
            Err(e) => {
                problems.push(format!("shard {k}/{n}: cannot read {}: {e}", p.display()));
                continue;
            }
        };
        match serde_json::from_str::<Record>(&text) {
            Ok(r) if r.shard != k || r.of != n => problems.push(format!(
                "shard {k}/{n}: {} records shard {}/{}",
                p.display(),
                r.shard,
                r.of
            )),
            Ok(r) if r.config != config => problems.push(format!(
                "shard {k}/{n} ran another configuration (its record {} has {}, this run {config})",
                p.display(),
                r.config
            )),
            Ok(r) => records.push(r),
            Err(e) => problems.push(format!(
                "shard {k}/{n}: its record {} is damaged: {e}",
                p.display()
            )),
        }
    }
    (records, problems)
}

/// The sessions of shard `k` of `n` among `sessions`, by the hash of each log's bytes. A log
/// that cannot be read hashes as 0 here: it still belongs to exactly one shard, whose run
/// reports it skipped with the read error.
pub fn of_shard(sessions: Vec<SessionRef>, k: usize, n: usize) -> Vec<SessionRef> {
    let hashed = assign(sessions, (k, n), |s| {
        Ok::<_, std::convert::Infallible>(super::cache::hash_file(&s.path).unwrap_or(0))
    });
    match hashed {
        Ok(v) => v,
        Err(never) => match never {},
    }
}

/// What a record's configuration hash covers: the experiment, its version and its parameters
/// and topic remaps (the parts of the cache key that are not the log).
pub fn config_hash(kind: &str, version: u32, params_json: &str, topics_json: &str) -> String {
    let mut h = Xxh3::new();
    for part in [
        kind.as_bytes(),
        &version.to_le_bytes(),
        params_json.as_bytes(),
    ] {
        h.update(&(part.len() as u64).to_le_bytes());
        h.update(part);
    }
    h.update(topics_json.as_bytes());
    format!("{:032x}", h.digest128())
}

/// Write shard `k/n`'s record: its sessions and, for those without a result, why.
pub fn write_record(
    out: &Path,
    pipeline_dir: &Path,
    (k, n): (usize, usize),
    config: &str,
    sessions: &[SessionRef],
    not_done: &[(SessionRef, String)],
) -> anyhow::Result<()> {
    let record = Record {
        shard: k,
        of: n,
        config: config.to_string(),
        sessions: sessions
            .iter()
            .map(|s| RecordedSession {
                dataset: s.dataset.clone(),
                name: s.name.clone(),
                path: s.path.clone(),
                skipped: not_done
                    .iter()
                    .find(|(d, _)| d == s)
                    .map(|(_, why)| why.clone()),
            })
            .collect(),
    };
    let path = record_path(pipeline_dir, k, n);
    let json = serde_json::to_string_pretty(&record)?;
    write_atomic(&path, json.as_bytes(), Some(out))
        .with_context(|| format!("writing shard {k}/{n}'s record {}", path.display()))
}

/// `--expect-shards n`: every shard's record must count, else an error naming each shard that
/// does not; the recorded sessions join `sessions` (their logs may be gone) and the reasons
/// of those recorded as skipped are returned, keyed by `(dataset, name)`.
pub fn expect(
    pipeline_dir: &Path,
    n: usize,
    config: &str,
    sessions: &mut Vec<SessionRef>,
) -> anyhow::Result<Vec<((String, String), String)>> {
    let (records, problems) = check_records(pipeline_dir, n, config);
    if !problems.is_empty() {
        anyhow::bail!(
            "{} of {n} shards do not count, so nothing was aggregated:\n  {}\n\
             rerun those shards (sessions already cached are not recomputed), then aggregate again",
            problems.len(),
            problems.join("\n  ")
        );
    }
    let mut reasons = Vec::new();
    for r in records.into_iter().flat_map(|r| r.sessions) {
        if !sessions
            .iter()
            .any(|s| s.dataset == r.dataset && s.name == r.name)
        {
            sessions.push(SessionRef {
                dataset: r.dataset.clone(),
                name: r.name.clone(),
                path: r.path.clone(),
            });
        }
        if let Some(why) = r.skipped {
            reasons.push(((r.dataset, r.name), why));
        }
    }
    sessions.sort();
    Ok(reasons)
}

/// Give sessions skipped for want of a cached result the reason their shard recorded.
pub fn use_recorded_reasons(
    reasons: &[((String, String), String)],
    not_done: &mut [(SessionRef, String)],
    skipped: &mut [(String, String)],
) {
    for ((dataset, name), why) in reasons {
        let label = format!("{dataset}/{name}");
        for (s, r) in not_done.iter_mut() {
            if &s.dataset == dataset && &s.name == name && r == super::skipped::NOT_CACHED {
                r.clone_from(why);
            }
        }
        for (l, r) in skipped.iter_mut() {
            if *l == label && r == super::skipped::NOT_CACHED {
                r.clone_from(why);
            }
        }
    }
}

#[cfg(test)]
mod tests;

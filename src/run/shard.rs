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

use super::config::SessionRef;

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

#[cfg(test)]
mod tests;

//! The `skipped_sessions` table that the runner writes for every pipeline (beside the
//! experiment's own tables, `out/<pipeline>/tables/skipped_sessions.*`): one row per session
//! that produced no results, with its status and reason — so a table never silently stands
//! for fewer sessions than its inputs — and one per session whose results come from a log
//! read with warnings (the readable part of a damaged log under `--recover`, or a log
//! re-indexed from its data because its chunk index lies), so partial data is never silent,
//! and one per session computed but whose results could not be stored in the cache
//! (`unstored`: the cache folder and the reason). Written on every full run, with no rows when nothing was
//! skipped, so a stale list from an earlier run cannot survive. REPORT.md links it in each
//! pipeline's "Skipped sessions" section (`run::report`). A run with `unstored` sessions fails
//! after writing its products unless `--keep-going` ([`fail_if_unstored`]).

use crate::report::{Provenance, Table};
use crate::table_row;

use super::config::SessionRef;
use super::{RunOptions, RunSummary};

/// File stem of the table.
pub const TABLE: &str = "skipped_sessions";

/// The reason a session whose processing panicked starts with.
pub const PANICKED: &str = "panicked: ";
/// The reason of a session without a required topic starts with.
pub const MISSING_TOPICS: &str = "missing topic(s) ";
/// The reason of an `--aggregate-only` session that was never processed.
pub const NOT_CACHED: &str = "no cached result for this session (run the shards first)";
/// The reason of a session computed but whose results could not be stored starts with this,
/// then the cache folder and the error.
pub const NOT_STORED: &str = "computed, but its results could not be stored in the cache at ";

table_row! {
    /// One session without results.
    #[derive(Debug, Clone, PartialEq)]
    pub struct SkippedRow {
        pub dataset: String,
        pub session: String,
        /// `skipped` (not runnable: a required topic is missing, or no cached result with
        /// `--aggregate-only`), `failed` (the log or the experiment's processing gave an
        /// error), `panicked` (the processing panicked: a bug, reported, never fatal),
        /// `warned` (results kept, but the log was read with the warnings in `reason`), or
        /// `unstored` (results kept in this run's tables, but they could not be stored in
        /// the cache: `reason` names the folder and the error).
        pub status: String,
        pub reason: String,
        pub path: String,
    }
}

/// The status of a skip from its reason (see [`SkippedRow::status`]).
pub fn status(reason: &str) -> &'static str {
    if reason.starts_with(PANICKED) {
        "panicked"
    } else if reason.starts_with(MISSING_TOPICS) || reason == NOT_CACHED {
        "skipped"
    } else {
        "failed"
    }
}

/// Status of a session whose results were kept though its log was read with warnings.
pub const WARNED: &str = "warned";
/// Status of a session whose results were kept but not stored in the cache.
pub const UNSTORED: &str = "unstored";

/// The status of a session kept with a warning, from its reason: [`UNSTORED`] or [`WARNED`].
pub fn warned_status(reason: &str) -> &'static str {
    if reason.starts_with(NOT_STORED) {
        UNSTORED
    } else {
        WARNED
    }
}

/// The table of `skipped` sessions, then the `warned` ones (each in session order), with the
/// run's provenance.
pub fn table(
    skipped: &[(SessionRef, String)],
    warned: &[(SessionRef, String)],
    provenance: &Provenance,
) -> anyhow::Result<Table> {
    use crate::report::rows::Rows;
    let row = |(s, reason): &(SessionRef, String), status: &str| SkippedRow {
        dataset: s.dataset.clone(),
        session: s.name.clone(),
        status: status.to_string(),
        reason: reason.clone(),
        path: s.path.display().to_string(),
    };
    let rows: Vec<SkippedRow> = skipped
        .iter()
        .map(|s| row(s, status(&s.1)))
        .chain(warned.iter().map(|s| row(s, warned_status(&s.1))))
        .collect();
    let unstored = warned
        .iter()
        .filter(|s| warned_status(&s.1) == UNSTORED)
        .count();
    let read_with_warnings = warned.len() - unstored;
    let mut note = if skipped.is_empty() {
        "Every session was processed (or loaded from the cache).".to_string()
    } else {
        format!(
            "{} session(s) gave no results; every other table of this pipeline leaves them out.",
            skipped.len()
        )
    };
    if read_with_warnings > 0 {
        note.push_str(&format!(
            " {read_with_warnings} session(s) were read with warnings (status `warned`): their results are in the \
             other tables, from the part of the log that could be read."
        ));
    }
    if unstored > 0 {
        note.push_str(&format!(
            " {unstored} session(s) were computed but could not be stored in the cache (status \
             `unstored`): their results are in the other tables, but a later run computes them again."
        ));
    }
    Ok(Table::new(
        TABLE,
        "Sessions without results (skipped, failed or panicked) or read with warnings, with the reason",
        SkippedRow::frame(&rows)?,
    )
    .with_note(note)
    .with_provenance(provenance.clone()))
}

/// Products that could not be written (a full disk) are the run's error; sessions not stored
/// in the cache either are counted in it (their own errors would repeat the system's).
pub(super) fn also_unstored(e: anyhow::Error, summary: &RunSummary) -> anyhow::Error {
    let unstored: Vec<&String> = summary
        .warned
        .iter()
        .filter(|(_, why)| why.starts_with(NOT_STORED))
        .map(|(s, _)| s)
        .collect();
    match unstored.first() {
        None => e,
        Some(first) => e.context(format!(
            "{}: {} session(s) computed but not stored in the cache (first: {first}), and the tables could not be written either",
            summary.file,
            unstored.len()
        )),
    }
}

/// A run with sessions computed but not stored in the cache fails (after writing what it
/// could), unless `--keep-going`.
pub(super) fn fail_if_unstored(summary: &RunSummary, opts: &RunOptions) -> anyhow::Result<()> {
    let unstored: Vec<&(String, String)> = summary
        .warned
        .iter()
        .filter(|(_, why)| why.starts_with(NOT_STORED))
        .collect();
    let Some((first, why)) = unstored.first() else {
        return Ok(());
    };
    if opts.keep_going {
        return Ok(());
    }
    let kept = if opts.shard.is_some() {
        "this shard's results for them are lost".to_string()
    } else {
        format!(
            "their results are in this run's tables and they are listed in {}, but the next run must compute them again",
            opts.out.join(&summary.skipped_table).display()
        )
    };
    anyhow::bail!(
        "{}: {} session(s) computed but not stored in the cache ({kept}; --keep-going accepts this); first: {first}: {why}",
        summary.file,
        unstored.len()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn status_follows_the_reason() {
        assert_eq!(status("panicked: index out of bounds"), "panicked");
        assert_eq!(status("missing topic(s) /scan"), "skipped");
        assert_eq!(status(NOT_CACHED), "skipped");
        assert_eq!(status("reading x.mcap: file is truncated"), "failed");
        assert_eq!(warned_status("recovered: bytes 8..90 are lost"), WARNED);
        assert_eq!(
            warned_status(&format!(
                "{NOT_STORED}out/p/sessions/dataset=d/session=s: disk full"
            )),
            UNSTORED
        );
    }
}

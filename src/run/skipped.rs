//! The `skipped_sessions` table that the runner writes for every pipeline (beside the
//! experiment's own tables, `out/<pipeline>/tables/skipped_sessions.*`): one row per session
//! that produced no results, with its status and reason — so a table never silently stands
//! for fewer sessions than its inputs — and one per session whose results come from a log
//! read with warnings (the readable part of a damaged log under `--recover`, or a log
//! re-indexed from its data because its chunk index lies), so partial data is never silent. Written on every full run, with no rows when nothing was
//! skipped, so a stale list from an earlier run cannot survive. REPORT.md links it in each
//! pipeline's "Skipped sessions" section (`run::report`).

use crate::report::{Provenance, Table};
use crate::table_row;

use super::config::SessionRef;

/// File stem of the table.
pub const TABLE: &str = "skipped_sessions";

/// The reason a session whose processing panicked starts with.
pub const PANICKED: &str = "panicked: ";
/// The reason of a session without a required topic starts with.
pub const MISSING_TOPICS: &str = "missing topic(s) ";
/// The reason of an `--aggregate-only` session that was never processed.
pub const NOT_CACHED: &str = "no cached result for this session (run the shards first)";

table_row! {
    /// One session without results.
    #[derive(Debug, Clone, PartialEq)]
    pub struct SkippedRow {
        pub dataset: String,
        pub session: String,
        /// `skipped` (not runnable: a required topic is missing, or no cached result with
        /// `--aggregate-only`), `failed` (the log or the experiment's processing gave an
        /// error), `panicked` (the processing panicked: a bug, reported, never fatal), or
        /// `warned` (results kept, but the log was read with the warnings in `reason`).
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
        .chain(warned.iter().map(|s| row(s, WARNED)))
        .collect();
    let mut note = if skipped.is_empty() {
        "Every session was processed (or loaded from the cache).".to_string()
    } else {
        format!(
            "{} session(s) gave no results; every other table of this pipeline leaves them out.",
            skipped.len()
        )
    };
    if !warned.is_empty() {
        note.push_str(&format!(
            " {} session(s) were read with warnings (status `warned`): their results are in the \
             other tables, from the part of the log that could be read.",
            warned.len()
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn status_follows_the_reason() {
        assert_eq!(status("panicked: index out of bounds"), "panicked");
        assert_eq!(status("missing topic(s) /scan"), "skipped");
        assert_eq!(status(NOT_CACHED), "skipped");
        assert_eq!(status("reading x.mcap: file is truncated"), "failed");
    }
}

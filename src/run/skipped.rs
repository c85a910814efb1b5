//! The `skipped_sessions` table that the runner writes for every pipeline (beside the
//! experiment's own tables, `out/<pipeline>/tables/skipped_sessions.*`): one row per session
//! that produced no results, with its status and reason — so a table never silently stands
//! for fewer sessions than its inputs. Written on every full run, with no rows when nothing was
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
        /// error) or `panicked` (the processing panicked: a bug, reported, never fatal).
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

/// The table of `skipped` sessions (in session order), with the run's provenance.
pub fn table(skipped: &[(SessionRef, String)], provenance: &Provenance) -> anyhow::Result<Table> {
    use crate::report::rows::Rows;
    let rows: Vec<SkippedRow> = skipped
        .iter()
        .map(|(s, reason)| SkippedRow {
            dataset: s.dataset.clone(),
            session: s.name.clone(),
            status: status(reason).to_string(),
            reason: reason.clone(),
            path: s.path.display().to_string(),
        })
        .collect();
    let note = if rows.is_empty() {
        "Every session was processed (or loaded from the cache).".to_string()
    } else {
        format!(
            "{} session(s) gave no results; every other table of this pipeline leaves them out.",
            rows.len()
        )
    };
    Ok(Table::new(
        TABLE,
        "Sessions without results (skipped, failed or panicked), with the reason",
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

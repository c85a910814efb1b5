//! The per-session tables: what the session stage writes (cached as Parquet) and the
//! aggregation reads back, one row struct per table.

use anyhow::Context;

use crate::report::rows::Rows;
use crate::run::SessionTables;
use crate::table_row;

pub const SESSION: &str = "session";
pub const SCANS: &str = "scans";
pub const TRUTH: &str = "truth";
pub const TRACKS: &str = "tracks";

table_row! {
    /// What one session read: `session` (one row).
    #[derive(Debug, Clone, PartialEq)]
    pub struct SessionRow {
        pub scan_topic: String,
        pub gt_topic: String,
        /// `leg_tracker` (laser-frame positions by log time), `synthetic` (map-frame JSON by
        /// stamp) or `none` (no ground-truth topic in the log).
        pub gt_kind: String,
        /// The frame tracks live in (`odom`, `map`, or the sensor frame without TF).
        pub fixed_frame: String,
        pub scans: i64,
        /// Scans TF could not place (tracked in the sensor frame).
        pub unposed: i64,
        /// The free-space methods' fixed frame: `tf` (the log's), `scan_match`
        /// ([`crate::laser::scan_match`]: no TF or only the sensor's own frame, or the
        /// sequence withholds it), or `none_scan_match_unfit` (no odometry and the matcher
        /// failed on more than [`crate::laser::scan_match::MAX_FAILED_SHARE`] of the scans:
        /// they track in the laser frame).
        pub odometry: String,
        /// Scans the scan matcher could not match (they took its prediction; for
        /// `none_scan_match_unfit`, the first pass's failures).
        pub scan_match_failures: i64,
        /// Where the log's TF was withheld: the scan-matched odometry's mean relative pose
        /// error over 1 s windows against TF (m, degrees); NaN otherwise.
        pub odometry_rpe_m: f64,
        pub odometry_rpe_deg: f64,
        /// Ground-truth positions kept.
        pub gt_rows: i64,
        /// Ground-truth positions dropped: before the first scan, a second position of the
        /// same id on one scan, or (synthetic) on a scan without a pose.
        pub gt_dropped: i64,
        /// Messages that did not decode (scans and ground truth).
        pub skipped_messages: i64,
        pub first_error: Option<String>,
    }
}

table_row! {
    /// One scan: `scans`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct ScanRow {
        /// 0-based, in log order.
        pub scan_idx: i64,
        pub stamp_ns: i64,
        pub log_time_ns: i64,
        pub posed: bool,
        /// Leg-model legs and people (leg pairs) found.
        pub legs: i64,
        pub people: i64,
    }
}

table_row! {
    /// A ground-truth person on a scan, laser frame (m): `truth`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct TruthRow {
        pub scan_idx: i64,
        pub id: i64,
        pub x: f64,
        pub y: f64,
    }
}

table_row! {
    /// A hypothesis on a scan: `tracks`. `x`, `y` in the laser frame, `world_x`, `world_y`
    /// in the fixed frame (m).
    #[derive(Debug, Clone, PartialEq)]
    pub struct TrackRow {
        pub detector: String,
        pub scan_idx: i64,
        pub id: i64,
        pub x: f64,
        pub y: f64,
        pub world_x: f64,
        pub world_y: f64,
    }
}

/// One cached table read back as rows.
pub fn read<R: Rows>(tables: &SessionTables, name: &str, session: &str) -> anyhow::Result<Vec<R>> {
    let df = tables
        .get(name)
        .with_context(|| format!("{session}: cached result lacks the {name} table"))?;
    R::read(df).with_context(|| format!("{session}: reading the cached {name} table"))
}

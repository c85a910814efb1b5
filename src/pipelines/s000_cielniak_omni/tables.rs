//! The per-session tables: what the session stage writes (cached as Parquet) and the
//! aggregation reads back, one row struct per table.

use polars::prelude::DataFrame;

use crate::report::rows::Rows;
use crate::run::schemas::{TableDoc, table};
use crate::run::{Aggregate, SessionTables};
use crate::table_row;

/// Every per-session table and what a row of it is (`docs/schemas.md`).
pub const SESSION_TABLES: &[TableDoc] = &[
    table(
        "cameras",
        "A webcam's nominal parameters (TF pose, camera_info).",
    ),
    table("camera_truth", "A webcam's true pose (simulator metadata)."),
    table("hats", "A hat blob in a webcam frame."),
    table("targets", "A calibration mark where the hat stands."),
    table("truth", "A person's true position (simulator)."),
    table(
        "omni",
        "The depth-cue features of one omni frame (NaN where no person).",
    ),
    table("omni_pose", "The omni camera's pose in the map (one row)."),
    table(
        "skips",
        "Messages the frames layer skipped on one topic (they did not decode).",
    ),
];

table_row! {
    /// A webcam's nominal parameters (TF pose, camera_info): `cameras`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct CameraRow {
        pub camera: String,
        pub x: f64,
        pub y: f64,
        /// Heading of the optical axis in the map (rad).
        pub heading: f64,
        /// Horizontal field of view (rad).
        pub range: f64,
        /// Image width (px).
        pub width: f64,
    }
}

table_row! {
    /// A hat blob in a webcam frame: `hats`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct HatRow {
        pub stamp: i64,
        /// Index of the webcam in `params.webcams`.
        pub camera: i64,
        pub u: f64,
        pub v: f64,
        pub area: i64,
        /// The blob does not touch the image border.
        pub whole: bool,
    }
}

table_row! {
    /// A calibration mark where the hat stands: `targets`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct TargetRow {
        pub stamp: i64,
        pub x: f64,
        pub y: f64,
    }
}

table_row! {
    /// A person's true position (simulator): `truth`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct TruthRow {
        pub stamp: i64,
        pub id: i64,
        pub x: f64,
        pub y: f64,
    }
}

table_row! {
    /// A webcam's true pose (simulator metadata): `camera_truth`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct CameraTruthRow {
        pub camera: String,
        pub true_x: f64,
        pub true_y: f64,
        pub true_yaw_deg: f64,
    }
}

table_row! {
    /// The depth-cue features of one omni frame (NaN where no person): `omni`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct OmniRow {
        pub stamp: i64,
        pub valid: bool,
        pub width: f64,
        pub apparent_distance: f64,
        pub pixels: f64,
        /// Bearing of the person in the camera frame (rad).
        pub angle: f64,
    }
}

table_row! {
    /// The omni camera's pose in the map: `omni_pose` (one row).
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct PoseRow {
        pub x: f64,
        pub y: f64,
        pub yaw: f64,
    }
}

table_row! {
    /// Messages the frames layer skipped on one topic (they did not decode): `skips`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct SkipRow {
        pub topic: String,
        pub count: i64,
        pub first_error: String,
    }
}

/// Rows of one table (none when the table is absent or has no columns).
pub fn read<R: Rows>(tables: &SessionTables, name: &str) -> anyhow::Result<Vec<R>> {
    match tables.get(name) {
        Some(df) if df.width() > 0 => Ok(R::read(df)?),
        _ => Ok(Vec::new()),
    }
}

/// Rows of one table over all sessions, each with its session's index, in session order.
pub fn all<R: Rows>(ctx: &Aggregate, name: &str) -> anyhow::Result<Vec<(usize, R)>> {
    let mut out = Vec::new();
    for (i, (_, tables)) in ctx.sessions.iter().enumerate() {
        out.extend(read::<R>(tables, name)?.into_iter().map(|r| (i, r)));
    }
    Ok(out)
}

/// Rows of one table of the first session.
pub fn first<R: Rows>(ctx: &Aggregate, name: &str) -> anyhow::Result<Vec<R>> {
    match ctx.sessions.first() {
        Some((_, tables)) => read(tables, name),
        None => Ok(Vec::new()),
    }
}

/// A frame of rows (the session stage's output).
pub fn frame<R: Rows>(rows: &[R]) -> anyhow::Result<DataFrame> {
    Ok(R::frame(rows)?)
}

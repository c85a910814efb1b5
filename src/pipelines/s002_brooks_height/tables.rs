//! The per-session tables (what [`super::session`] writes, cached as Parquet, and the
//! aggregation reads back) and the result rows, one struct per table.

use anyhow::Context;

use crate::report::rows::Rows;
use crate::run::SessionTables;
use crate::run::schemas::{TableDoc, table};
use crate::table_row;

pub const LASER: &str = "laser_obs";
pub const CAMERA: &str = "camera_obs";
pub const TRUTH: &str = "truth";
pub const PLANES: &str = "planes";
pub const FIG4: &str = "fig4";

/// Every per-session table and what a row of it is (`docs/schemas.md`), single and multi mode.
pub const SESSION_TABLES: &[TableDoc] = &[
    table(
        LASER,
        "A leg pair on a scan (§3): range–bearing of the midpoint in the laser frame, and the \
         laser's pose on the floor plan (map frame).",
    ),
    table(
        CAMERA,
        "A camera person detection (§4): bearing and elevation of the head top in the map frame \
         from the camera centre, the pixel, the blob rectangle and its top-fifth skin share.",
    ),
    table(
        "camera_obs_{name}",
        "Multi mode: camera `{name}`'s person detections, the columns of `camera_obs`.",
    ),
    table(TRUTH, "The person's ground truth at one stamp (map frame)."),
    table(
        PEOPLE_TRUTH,
        "Multi mode: one person at one ground-truth stamp (map frame).",
    ),
    table(
        PLANES,
        "One background-subtraction configuration over the session's frames after warm-up: time \
         per frame (this machine, one thread) and detection quality against the exact person mask.",
    ),
    table(
        FIG4,
        "Fig. 4's four panels of one frame as a PNG (base64), at most one row.",
    ),
];

table_row! {
    /// A leg pair on a scan (§3): range–bearing of the midpoint in the laser frame, and the
    /// laser's pose on the floor plan (map frame): `laser_obs`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct LaserObsRow {
        pub scan_idx: i64,
        pub stamp_ns: i64,
        pub range_m: f64,
        pub bearing_rad: f64,
        pub laser_x: f64,
        pub laser_y: f64,
        pub laser_yaw: f64,
    }
}

table_row! {
    /// A camera person detection (§4): bearing and elevation of the head top in the map frame
    /// from the camera centre, the pixel, the blob rectangle and its top-fifth skin share:
    /// `camera_obs`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct CameraObsRow {
        pub frame_idx: i64,
        pub stamp_ns: i64,
        pub bearing_rad: f64,
        pub elevation_rad: f64,
        pub cam_x: f64,
        pub cam_y: f64,
        pub cam_z: f64,
        pub u: f64,
        pub v: f64,
        pub x0: i64,
        pub y0: i64,
        pub x1: i64,
        pub y1: i64,
        pub skin_fraction: f64,
    }
}

table_row! {
    /// The person's ground truth (map frame): `truth`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct TruthRow {
        pub stamp_ns: i64,
        pub x: f64,
        pub y: f64,
        pub vx: f64,
        pub vy: f64,
        pub height_m: f64,
    }
}

table_row! {
    /// One background-subtraction configuration over the session's frames after warm-up:
    /// time per frame (this machine, one thread) and detection quality against the exact
    /// person mask: `planes`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct PlanesRow {
        pub config: String,
        pub planes: i64,
        pub frames: i64,
        pub ms_per_frame: f64,
        pub precision: f64,
        pub recall: f64,
        pub f1: f64,
        /// Frames where the person is visible in the ground truth.
        pub person_frames: i64,
        /// Of those, frames with a person detection (moving blob with skin on top).
        pub detected_frames: i64,
        /// Detections on frames without a visible person, or far (> 20 px) from its head.
        pub false_detections: i64,
        /// Mean distance of the detected head top to the true head-top pixel.
        pub head_err_px: Option<f64>,
    }
}

table_row! {
    /// Fig. 4's four panels of one frame as a PNG (base64): `fig4` (at most one row).
    #[derive(Debug, Clone, PartialEq)]
    pub struct Fig4Row {
        pub frame_idx: i64,
        pub stamp_ns: i64,
        pub png_base64: String,
    }
}

/// One cached table read back as rows.
pub fn read<R: Rows>(tables: &SessionTables, name: &str, session: &str) -> anyhow::Result<Vec<R>> {
    let df = tables
        .get(name)
        .with_context(|| format!("{session}: cached result lacks the {name} table"))?;
    R::read(df).with_context(|| format!("{session}: reading the cached {name} table"))
}

/// Multi mode: the ground truth of every person (map frame): `people_truth`.
pub const PEOPLE_TRUTH: &str = "people_truth";

/// Multi mode: the table of camera `name`'s head-top observations (rows of [`CameraObsRow`]).
pub fn camera_table(name: &str) -> String {
    format!("{CAMERA}_{name}")
}

table_row! {
    /// Multi mode: one person at one ground-truth stamp: `people_truth`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct PersonRow {
        pub stamp_ns: i64,
        pub id: i64,
        pub x: f64,
        pub y: f64,
        pub height_m: f64,
    }
}

//! The per-session tables (cached as Parquet, read back by the aggregation), one row struct
//! each.

use anyhow::Context;

use crate::report::rows::Rows;
use crate::run::SessionTables;
use crate::run::schemas::{TableDoc, table};
use crate::table_row;

pub const DOA: &str = "doa_blocks";
pub const FACES: &str = "faces";
pub const FACE_FRAMES: &str = "face_frames";
pub const STEPS: &str = "steps";
pub const SPEAKER: &str = "speaker";
pub const MOT: &str = "mot";
pub const TIMELINE: &str = "timeline";
pub const REPLAY: &str = "replay";
pub const CORRELOGRAM: &str = "correlogram";
pub const SKIPS: &str = "skips";

/// Every per-session table and what a row of it is (`docs/schemas.md`).
pub const SESSION_TABLES: &[TableDoc] = &[
    table(
        DOA,
        "One 0.5 s block of one acoustic condition with a single speaker.",
    ),
    table(
        FACES,
        "A true face in a frame (in the image, mostly visible).",
    ),
    table(
        FACE_FRAMES,
        "Detections of a frame and those matching no true face.",
    ),
    table(
        STEPS,
        "One system variant at one step: its attention and the truth's.",
    ),
    table(
        SPEAKER,
        "One active sound block of a variant: where it landed and who spoke.",
    ),
    table(
        MOT,
        "CLEAR MOT of a variant's person anchors over the session.",
    ),
    table(TIMELINE, "One anchor of the full system at one step."),
    table(REPLAY, "The replay against the logged `/attention/state`."),
    table(
        CORRELOGRAM,
        "The direction-of-arrival correlogram figure as a PNG (one row, `png` bytes).",
    ),
    table(SKIPS, "Messages skipped while reading, per topic."),
];

table_row! {
    /// One 0.5 s block of one acoustic condition with a single speaker: `doa_blocks`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct DoaRow {
        pub rt60_ms: i64,
        pub snr_db: i64,
        pub t_s: f64,
        pub speaker: i64,
        /// The speaker's cone angle at the microphones (far field, mouth height included).
        pub true_cone_deg: f64,
        pub est_cone_deg: f64,
        pub err_deg: f64,
        pub peak: f64,
        /// Behind the microphone axis (the mirror side).
        pub behind: bool,
    }
}

table_row! {
    /// A true face in a frame (in the image, mostly visible): `faces`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct FaceRow {
        pub k: i64,
        pub person: i64,
        pub width_px: f64,
        pub yaw_deg: f64,
        pub visible: f64,
        pub detected: bool,
    }
}

table_row! {
    /// Detections of a frame and those matching no true face: `face_frames`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct FaceFrameRow {
        pub k: i64,
        pub detections: i64,
        pub false_faces: i64,
    }
}

table_row! {
    /// One system variant at one step: its attention and the truth's: `steps`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct StepRow {
        pub variant: String,
        pub k: i64,
        pub t_s: f64,
        pub mode: String,
        /// The focus anchor (−1: none) and the true person it is matched to (−1: none).
        pub focus_anchor: i64,
        pub focus_person: i64,
        pub true_mode: String,
        pub true_focus: i64,
        pub right: bool,
    }
}

table_row! {
    /// One active sound block of a variant: where it landed and who spoke: `speaker`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct SpeakerRow {
        pub variant: String,
        pub k: i64,
        pub t_s: f64,
        /// True speakers at the step (0, 1 or more).
        pub speakers: i64,
        /// The single true speaker (−1 unless exactly one) and whether the robot senses them.
        pub speaker: i64,
        pub in_region: bool,
        pub anchor: i64,
        pub anchor_person: i64,
        pub right: bool,
    }
}

table_row! {
    /// CLEAR MOT of a variant's person anchors over the session: `mot`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct MotRow {
        pub variant: String,
        pub objects: i64,
        pub misses: i64,
        pub false_positives: i64,
        pub switches: i64,
        pub matches: i64,
        pub distance_m: f64,
        pub mota: f64,
        pub top_down_steps: i64,
    }
}

table_row! {
    /// One anchor of the full system at one step: `timeline`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct TimelineRow {
        pub k: i64,
        pub t_s: f64,
        pub anchor: i64,
        pub person: i64,
        /// Component states: 0 lost, 1 associated, 2 grounded.
        pub legs: i64,
        pub face: i64,
        pub torso: i64,
        pub voice: i64,
        pub category: i64,
        /// The matched person speaks (truth).
        pub speaking: bool,
    }
}

table_row! {
    /// The replay against the logged `/attention/state`: `replay`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct ReplayRow {
        pub steps: i64,
        pub logged: i64,
        pub mode_agree: i64,
        pub focus_agree: i64,
    }
}

table_row! {
    /// Messages skipped while reading: `skips`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct SkipRow {
        pub topic: String,
        pub count: i64,
        pub first_error: String,
    }
}

/// One cached table read back as rows.
pub fn read<R: Rows>(tables: &SessionTables, name: &str, session: &str) -> anyhow::Result<Vec<R>> {
    let df = tables
        .get(name)
        .with_context(|| format!("{session}: cached result lacks the {name} table"))?;
    R::read(df).with_context(|| format!("{session}: reading the cached {name} table"))
}

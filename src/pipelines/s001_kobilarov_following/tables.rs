//! The per-session tables (what the session stage writes, cached as Parquet, and the
//! aggregation reads back), one row struct per table.

use anyhow::Context;

use crate::report::rows::Rows;
use crate::run::schemas::{TableDoc, table};
use crate::run::{Aggregate, SessionTables};
use crate::table_row;

pub const TRACKS: &str = "tracks";
pub const TRUTH: &str = "truth";
pub const LOOP: &str = "closed_loop";
pub const METHOD1: &str = "method1";
pub const REAL: &str = "real";
pub const COLOUR: &str = "colour";

/// Every per-session table and what a row of it is (`docs/schemas.md`).
pub const SESSION_TABLES: &[TableDoc] = &[
    table(
        TRACKS,
        "One replayed method on one scan: its estimate in the evaluation frame (`map` on \
         synthetic logs, the laser frame on real ones) and what it did.",
    ),
    table(
        TRUTH,
        "The ground truth at each scan (synthetic logs, `map` frame): the robot's true pose and \
         speed, the target, and whether the laser could see the target.",
    ),
    table(
        LOOP,
        "The closed loop's own tracker output on one scan, as the robot logged it \
         (`/follower/state`), moved into `map`.",
    ),
    table(
        METHOD1,
        "Method 1 on one omni frame: the detection's bearing, the target's true bearing in the \
         camera frame and the robot's speed.",
    ),
    table(
        REAL,
        "A real laser log: one method on one annotated scan (laser frame); empty for synthetic logs.",
    ),
    table(
        COLOUR,
        "One blob of one scan as the paper's configuration saw it: its normalised correlation \
         with the template, what the ground truth says it is, a person's blob's offset from \
         them and every blob's offset from the target (m).",
    ),
];

table_row! {
    /// One replayed method on one scan: its estimate in the evaluation frame (`map` on
    /// synthetic logs, the laser frame on real ones) and what it did: `tracks`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct TrackRow {
        pub method: String,
        pub scan_idx: i64,
        pub t_s: f64,
        pub x: Option<f64>,
        pub y: Option<f64>,
        pub vx: Option<f64>,
        pub vy: Option<f64>,
        pub cov_norm: Option<f64>,
        pub reset: bool,
        pub initialised: bool,
        pub blobs: i64,
        pub gated: i64,
        pub beta0: Option<f64>,
        pub lr: Option<f64>,
        /// The chosen blob's normalised correlation with the template.
        pub corr: Option<f64>,
        /// Distance to the target's true position (m), when both exist.
        pub target_err_m: Option<f64>,
        /// The person nearest the estimate (ground-truth id) and the distance to them.
        pub nearest_id: Option<i64>,
        pub nearest_m: Option<f64>,
    }
}

table_row! {
    /// The ground truth at each scan (synthetic logs, `map` frame): the robot's true pose and
    /// speed, the target, and whether the laser could see the target: `truth`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct TruthRow {
        pub scan_idx: i64,
        pub t_s: f64,
        pub robot_x: f64,
        pub robot_y: f64,
        pub robot_yaw: f64,
        pub robot_v: f64,
        /// Base pitch, positive nose down (rad).
        pub pitch: f64,
        pub target_x: Option<f64>,
        pub target_y: Option<f64>,
        pub target_vx: Option<f64>,
        pub target_vy: Option<f64>,
        /// Range and bearing of the target from the robot (m, rad).
        pub range_m: Option<f64>,
        pub bearing_rad: Option<f64>,
        /// The laser's beam towards the target meets the ground before it ("gnd").
        pub ground: bool,
        /// Another person stands in the laser's line of sight to the target ("x").
        pub occluded: bool,
        /// The target lies outside the laser's field of view or range.
        pub out_of_view: bool,
        /// The scan returns short of the target on every beam towards it and neither the
        /// ground nor another person explains it: a static obstacle (tree, bush) in the way
        /// ([`super::scene::short_of`]).
        pub obstacle: bool,
    }
}

table_row! {
    /// The closed loop's own tracker output, as the robot logged it (`/follower/state`),
    /// moved into `map`: `closed_loop`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct LoopRow {
        pub t_s: f64,
        pub x: Option<f64>,
        pub y: Option<f64>,
        pub vx: Option<f64>,
        pub vy: Option<f64>,
        pub cov_norm: Option<f64>,
        pub reset: bool,
        pub controller: String,
        pub cmd_v: f64,
        pub cmd_w: f64,
        pub desired_m: f64,
        /// The platform's obstacle check changed the command (`synth::follow::avoid`).
        pub avoided: bool,
        /// The footprint touched an obstacle since the previous scan (a bumper's report).
        pub contact: bool,
    }
}

#[cfg(test)]
impl LoopRow {
    /// A test row: a direct-following scan at `t_s`, at `(x, 0)` when `x` is given.
    pub(crate) fn at(t_s: f64, x: Option<f64>) -> LoopRow {
        LoopRow {
            t_s,
            x,
            y: x.map(|_| 0.0),
            vx: None,
            vy: None,
            cov_norm: None,
            reset: false,
            controller: "direct".into(),
            cmd_v: 0.0,
            cmd_w: 0.0,
            desired_m: 3.2,
            avoided: false,
            contact: false,
        }
    }
}

table_row! {
    /// Method 1 on one omni frame: the detection's bearing, the target's true bearing in the
    /// camera frame and the robot's speed: `method1`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct Method1Row {
        pub frame_idx: i64,
        pub t_s: f64,
        pub robot_v: f64,
        pub est_azimuth: Option<f64>,
        pub true_azimuth: Option<f64>,
        pub lost: bool,
        pub features: i64,
        pub fallback_views: i64,
    }
}

table_row! {
    /// One blob of one scan as the paper's configuration saw it: its normalised correlation
    /// with the template and what the ground truth says it is (`target`, `person` — another
    /// person — or `static`: nobody within `lock_m`), and for a person's blob its centre minus
    /// that person's true position (map frame, m); `tdx`, `tdy`: its centre minus the
    /// target's true position (when the target is in the scene): `colour`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct ColourRow {
        pub scan_idx: i64,
        pub kind: String,
        pub corr: f64,
        pub dx: Option<f64>,
        pub dy: Option<f64>,
        pub tdx: Option<f64>,
        pub tdy: Option<f64>,
    }
}

table_row! {
    /// A real laser log: one method on one annotated scan (laser frame): `real`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct RealRow {
        pub method: String,
        pub scan_idx: i64,
        pub gt_x: f64,
        pub gt_y: f64,
        pub x: Option<f64>,
        pub y: Option<f64>,
        pub err_m: Option<f64>,
        pub reset: bool,
    }
}

/// One cached table read back as rows.
pub fn read<R: Rows>(tables: &SessionTables, name: &str, session: &str) -> anyhow::Result<Vec<R>> {
    let df = tables
        .get(name)
        .with_context(|| format!("{session}: cached result lacks the {name} table"))?;
    R::read(df).with_context(|| format!("{session}: reading the cached {name} table"))
}

/// One session's cached rows.
pub struct SessionData {
    pub name: String,
    pub tracks: Vec<TrackRow>,
    pub truth: Vec<TruthRow>,
    pub closed_loop: Vec<LoopRow>,
    pub method1: Vec<Method1Row>,
    pub real: Vec<RealRow>,
    pub colour: Vec<ColourRow>,
}

impl SessionData {
    /// A real log (its rows are in `real` only).
    pub fn is_real(&self) -> bool {
        !self.real.is_empty()
    }

    /// One method's rows, in scan order.
    pub fn method<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a TrackRow> + 'a {
        self.tracks.iter().filter(move |r| r.method == name)
    }
}

/// Every session, in the runner's (sorted) order.
pub fn load(ctx: &Aggregate) -> anyhow::Result<Vec<SessionData>> {
    ctx.sessions
        .iter()
        .map(|(info, t)| {
            let name = info.name.clone();
            Ok(SessionData {
                tracks: read(t, TRACKS, &name)?,
                truth: read(t, TRUTH, &name)?,
                closed_loop: read(t, LOOP, &name)?,
                method1: read(t, METHOD1, &name)?,
                real: read(t, REAL, &name)?,
                colour: read(t, COLOUR, &name)?,
                name,
            })
        })
        .collect()
}

//! The aggregation: every session's filters ([`super::fusion`]), then position errors and lag
//! per method with paired t-tests, our CV variant, and §4's plane grid averaged over the
//! sessions (the height tables and camera only's constant-vs-walk tables read these runs in
//! [`super::height`] and [`super::walk`]).

use std::collections::BTreeMap;

use super::fusion::{self, Method, Run, Scored, Sensors};
use super::params::Params;
use super::tables::{self, CameraObsRow, LaserObsRow, PlanesRow, TruthRow};
use crate::eval::stats;
use crate::report::rows::Rows;
use crate::report::table::Table;
use crate::run::{Aggregate, Products};
use crate::table_row;
use crate::track::height_ekf::Motion;

/// The paper's numbers (§6) for the notes.
pub const PAPER_HEIGHT_M: f64 = 1.87;
pub const PAPER_TRUTH_M: f64 = 1.84;

/// One session's inputs and filter runs.
pub struct SessionData {
    pub name: String,
    pub laser: Vec<LaserObsRow>,
    pub camera: Vec<CameraObsRow>,
    pub truth: Vec<TruthRow>,
    pub planes: Vec<PlanesRow>,
    pub fig4: Vec<tables::Fig4Row>,
    /// Method name → run and its scores.
    pub runs: BTreeMap<&'static str, (Run, Vec<Scored>)>,
    /// Session whose learned height the camera-only run starts from, and its true height.
    pub height_from: String,
    pub height_from_truth_m: f64,
}

pub const FUSED: &str = "laser+camera";
pub const LASER_ONLY: &str = "laser only";
pub const CAMERA_ONLY: &str = "camera only";
pub const FUSED_CV: &str = "laser+camera CV (ours)";
/// The random-walk variant of the height (`q_height_walk`): laser + camera learns it, camera
/// only starts from what that variant learned.
pub const FUSED_WALK: &str = "laser+camera, height walk";
pub const CAMERA_ONLY_WALK: &str = "camera only, height walk";

/// Methods in table order.
pub const METHODS: [&str; 6] = [
    FUSED,
    LASER_ONLY,
    CAMERA_ONLY,
    FUSED_CV,
    FUSED_WALK,
    CAMERA_ONLY_WALK,
];

impl SessionData {
    /// A session with its observations and no filter run yet.
    pub fn new(name: &str, laser: Vec<LaserObsRow>, camera: Vec<CameraObsRow>) -> SessionData {
        SessionData {
            name: name.into(),
            laser,
            camera,
            truth: Vec::new(),
            planes: Vec::new(),
            fig4: Vec::new(),
            runs: BTreeMap::new(),
            height_from: String::new(),
            height_from_truth_m: f64::NAN,
        }
    }

    /// The person's true height (first ground-truth stamp; NaN without truth).
    pub fn truth_m(&self) -> f64 {
        self.truth.first().map_or(f64::NAN, |t| t.height_m)
    }

    /// Mean position error of method `name` over its scored stamps.
    pub fn mean_error(&self, name: &str) -> Option<f64> {
        let e: Vec<f64> = self.runs.get(name)?.1.iter().map(|s| s.error_m).collect();
        mean(&e)
    }
}

table_row! {
    /// Position error and lag per session and method (`all`: pooled): `position_error`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct ErrorRow {
        pub session: String,
        pub method: String,
        pub n: i64,
        pub mean_m: Option<f64>,
        pub rmse_m: Option<f64>,
        pub p95_m: Option<f64>,
        /// Mean of (truth − estimate) along the direction of motion while moving (m).
        pub lag_m: Option<f64>,
        /// lag_m over the mean speed then (s).
        pub lag_s: Option<f64>,
        pub camera_from: String,
    }
}

table_row! {
    /// Our CV variant beside the paper's filter, per session: `cv_variant`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct CvRow {
        pub session: String,
        pub method: String,
        pub mean_error_m: Option<f64>,
        /// Largest speed of the estimate (m/s; 0 for constant position).
        pub max_speed_mps: f64,
        /// Longest time locked out of the gate: from an accepted observation to a later
        /// rejected event with no accepted one between (s).
        pub longest_lockout_s: f64,
        pub laser_rejected: i64,
        pub camera_rejected: i64,
        pub reinits: i64,
    }
}

table_row! {
    /// Paired t-test of two methods' errors at the same truth stamps: `paired_ttest`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct PairRow {
        pub method_a: String,
        pub method_b: String,
        pub n: i64,
        pub mean_a_m: f64,
        pub mean_b_m: f64,
        pub mean_diff_m: f64,
        pub t: Option<f64>,
        pub p_two_sided: Option<f64>,
    }
}

/// The filter configuration of method `name`; camera only starts from `learned` (height, σ)
/// and its walk variant from `learned_walk`.
pub fn method(name: &'static str, learned: (f64, f64), learned_walk: (f64, f64)) -> Method {
    let (sensors, motion, walk) = match name {
        LASER_ONLY => (Sensors::LaserOnly, Motion::ConstantPosition, false),
        CAMERA_ONLY => (camera_only(learned), Motion::ConstantPosition, false),
        FUSED_CV => (Sensors::Fused, Motion::ConstantVelocity, false),
        FUSED_WALK => (Sensors::Fused, Motion::ConstantPosition, true),
        CAMERA_ONLY_WALK => (camera_only(learned_walk), Motion::ConstantPosition, true),
        _ => (Sensors::Fused, Motion::ConstantPosition, false),
    };
    Method {
        name,
        sensors,
        motion,
        walk,
    }
}

fn camera_only((h_m, sigma_h_m): (f64, f64)) -> Sensors {
    Sensors::CameraOnly { h_m, sigma_h_m }
}

/// Read every session and run its filters ([`run_filters`]).
pub fn load(ctx: &Aggregate, p: &Params) -> anyhow::Result<Vec<SessionData>> {
    let mut out = Vec::new();
    for (info, t) in ctx.sessions {
        if p.is_training(&info.path) {
            continue;
        }
        let n = &info.name;
        out.push(SessionData {
            truth: tables::read(t, tables::TRUTH, n)?,
            planes: tables::read(t, tables::PLANES, n)?,
            fig4: tables::read(t, tables::FIG4, n)?,
            ..SessionData::new(
                n,
                tables::read(t, tables::LASER, n)?,
                tables::read(t, tables::CAMERA, n)?,
            )
        });
    }
    run_filters(&mut out, p);
    Ok(out)
}

/// Every method on every session. The camera-only runs of session k start from the height
/// (and σ) that laser + camera learned — with the constant height, and with the random walk
/// for the walk variant — in session `height_from.source(k, n)`: the previous session, or its
/// pair partner (a single session starts from itself, said in the tables).
pub fn run_filters(data: &mut [SessionData], p: &Params) {
    let learned = |s: &SessionData, name: &'static str| {
        let r = fusion::run(&s.laser, &s.camera, p, method(name, (0.0, 0.0), (0.0, 0.0)));
        r.last()
            .map_or((p.h0_m, p.sigma_h0_m), |e| (e.h, e.sigma_h))
    };
    let fused: Vec<((f64, f64), (f64, f64))> = data
        .iter()
        .map(|s| (learned(s, FUSED), learned(s, FUSED_WALK)))
        .collect();
    let n = data.len();
    for k in 0..n {
        let from = p.height_from.source(k, n);
        data[k].height_from = data[from].name.clone();
        data[k].height_from_truth_m = data[from].truth_m();
        for name in METHODS {
            let m = method(name, fused[from].0, fused[from].1);
            let s = &data[k];
            let run = fusion::run(&s.laser, &s.camera, p, m);
            let scored = fusion::score(&run, &s.truth, p, m.motion);
            data[k].runs.insert(name, (run, scored));
        }
    }
}

pub fn mean(v: &[f64]) -> Option<f64> {
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

fn error_row(session: &str, method: &str, scored: &[&Scored], camera_from: &str) -> ErrorRow {
    let e: Vec<f64> = scored.iter().map(|s| s.error_m).collect();
    let mut sorted = e.clone();
    sorted.sort_by(f64::total_cmp);
    let along: Vec<(f64, f64)> = scored
        .iter()
        .filter_map(|s| s.along_m.map(|a| (a, s.speed)))
        .collect();
    let lag = mean(&along.iter().map(|a| a.0).collect::<Vec<_>>());
    let speed = mean(&along.iter().map(|a| a.1).collect::<Vec<_>>());
    ErrorRow {
        session: session.into(),
        method: method.into(),
        n: e.len() as i64,
        mean_m: mean(&e),
        rmse_m: mean(&e.iter().map(|x| x * x).collect::<Vec<_>>()).map(f64::sqrt),
        p95_m: (!sorted.is_empty()).then(|| {
            sorted[((sorted.len() as f64 * 0.95).ceil() as usize).clamp(1, sorted.len()) - 1]
        }),
        lag_m: lag,
        lag_s: lag.zip(speed).map(|(l, v)| l / v),
        camera_from: camera_from.into(),
    }
}

/// Errors of `a` and `b` at the truth stamps both scored, pooled over sessions.
fn paired(data: &[SessionData], a: &str, b: &str) -> (Vec<f64>, Vec<f64>) {
    let (mut xa, mut xb) = (Vec::new(), Vec::new());
    for s in data {
        let (Some((_, sa)), Some((_, sb))) = (s.runs.get(a), s.runs.get(b)) else {
            continue;
        };
        let by: BTreeMap<i64, f64> = sb.iter().map(|r| (r.stamp_ns, r.error_m)).collect();
        for r in sa {
            if let Some(e) = by.get(&r.stamp_ns) {
                xa.push(r.error_m);
                xb.push(*e);
            }
        }
    }
    (xa, xb)
}

/// The error, paired-test, CV and plane-grid tables (the height tables are
/// [`super::height`]'s, the constant-vs-walk ones [`super::walk`]'s).
pub fn tables(data: &[SessionData], p: &Params, out: &mut Products) -> anyhow::Result<()> {
    error_tables(data, p, out)
}

fn error_tables(data: &[SessionData], p: &Params, out: &mut Products) -> anyhow::Result<()> {
    let mut rows = Vec::new();
    for name in METHODS {
        let mut pooled: Vec<&Scored> = Vec::new();
        for s in data {
            let scored: Vec<&Scored> = s.runs[name].1.iter().collect();
            let from = if name == CAMERA_ONLY || name == CAMERA_ONLY_WALK {
                s.height_from.as_str()
            } else {
                ""
            };
            rows.push(error_row(&s.name, name, &scored, from));
            pooled.extend(scored);
        }
        rows.push(error_row("all", name, &pooled, ""));
    }
    let mut t = Table::new(
        "position_error",
        "Position error against the ground truth (m) and the lag along the direction of motion, per session and method",
        ErrorRow::frame(&rows)?,
    );
    for c in ["mean_m", "rmse_m", "p95_m", "lag_m", "lag_s"] {
        t = t.with_precision(c, 3);
    }
    out.tables.push(t.with_note(format!(
        "Scored at every ground-truth stamp from the filter's start with its latest estimate (constant velocity: extrapolated). lag_m: mean of (truth − estimate) along the true velocity while faster than {} m/s; positive = behind (the paper: 'position estimates lag slightly behind moving targets'). camera only starts from the height and sigma laser + camera learned in session camera_from. laser+camera CV is our addition (white-noise acceleration {} m²/s³). Height: a constant the filter learns (q_height = {} m²/s, the paper's model); the 'height walk' rows a random walk of {} m²/s.",
        p.lag_min_speed, p.q_pos_cv, p.q_height, p.q_height_walk
    )));
    let mut pairs = Vec::new();
    for (a, b) in [
        (FUSED, LASER_ONLY),
        (FUSED, CAMERA_ONLY),
        (LASER_ONLY, CAMERA_ONLY),
        (FUSED_CV, FUSED),
        (CAMERA_ONLY, CAMERA_ONLY_WALK),
        (FUSED, FUSED_WALK),
    ] {
        let (xa, xb) = paired(data, a, b);
        let test = stats::paired_t(&xa, &xb, p.level).ok();
        pairs.push(PairRow {
            method_a: a.into(),
            method_b: b.into(),
            n: xa.len() as i64,
            mean_a_m: mean(&xa).unwrap_or(f64::NAN),
            mean_b_m: mean(&xb).unwrap_or(f64::NAN),
            mean_diff_m: test.as_ref().map_or(f64::NAN, |t| t.mean_diff),
            t: test.as_ref().map(|t| t.t),
            p_two_sided: test.as_ref().map(|t| t.p_two_sided),
        });
    }
    let mut t = Table::new(
        "paired_ttest",
        "Position errors of two methods at the same ground-truth stamps (all sessions): paired t-test",
        PairRow::frame(&pairs)?,
    );
    for c in ["mean_a_m", "mean_b_m", "mean_diff_m", "t", "p_two_sided"] {
        t = t.with_precision(c, 4);
    }
    out.tables.push(t.with_note(format!(
        "Two-sided, level {}; mean_diff = a − b (negative: a closer to the truth). Successive errors are autocorrelated, so the p-values are optimistic.",
        p.level
    )));
    cv_table(data, p, out)?;
    planes_table(data, out)
}

fn cv_table(data: &[SessionData], p: &Params, out: &mut Products) -> anyhow::Result<()> {
    let mut rows = Vec::new();
    for name in [FUSED, FUSED_CV] {
        for s in data {
            let (run, scored) = &s.runs[name];
            let e: Vec<f64> = scored.iter().map(|x| x.error_m).collect();
            rows.push(CvRow {
                session: s.name.clone(),
                method: name.into(),
                mean_error_m: mean(&e),
                max_speed_mps: run
                    .estimates
                    .iter()
                    .map(|x| x.vx.hypot(x.vy))
                    .fold(0.0, f64::max),
                longest_lockout_s: run.longest_lockout_s,
                laser_rejected: run.laser_rejected as i64,
                camera_rejected: run.camera_rejected as i64,
                reinits: run.reinits as i64,
            });
        }
    }
    let mut t = Table::new(
        "cv_variant",
        "Our constant-velocity variant beside the paper's constant-position filter (laser + camera): speed, gate lock-out, re-initialisations",
        CvRow::frame(&rows)?,
    );
    for c in ["mean_error_m", "max_speed_mps", "longest_lockout_s"] {
        t = t.with_precision(c, 3);
    }
    out.tables.push(t.with_note(format!(
        "The CV variant re-initialises its position at the next leg pair (at rest, height and its sigma kept) once no observation was accepted for {} s (cv_reinit_after_s; 0 = never); the paper's filter never does. longest_lockout_s: the longest span from an accepted observation to a rejected event with none accepted between.",
        p.cv_reinit_after_s
    )));
    Ok(())
}

fn planes_table(data: &[SessionData], out: &mut Products) -> anyhow::Result<()> {
    let mut rows: Vec<PlanesRow> = Vec::new();
    for cfg in super::params::PLANE_GRID {
        let name = super::params::plane_name(cfg.0, cfg.1);
        let all: Vec<&PlanesRow> = data
            .iter()
            .flat_map(|s| s.planes.iter().filter(|r| r.config == name))
            .collect();
        let Some(first) = all.first() else { continue };
        let frames: i64 = all.iter().map(|r| r.frames).sum();
        let wmean = |f: &dyn Fn(&PlanesRow) -> f64| {
            all.iter().map(|r| f(r) * r.frames as f64).sum::<f64>() / frames.max(1) as f64
        };
        let errs: Vec<f64> = all.iter().filter_map(|r| r.head_err_px).collect();
        rows.push(PlanesRow {
            config: name.clone(),
            planes: first.planes,
            frames,
            ms_per_frame: wmean(&|r| r.ms_per_frame),
            precision: wmean(&|r| r.precision),
            recall: wmean(&|r| r.recall),
            f1: wmean(&|r| r.f1),
            person_frames: all.iter().map(|r| r.person_frames).sum(),
            detected_frames: all.iter().map(|r| r.detected_frames).sum(),
            false_detections: all.iter().map(|r| r.false_detections).sum(),
            head_err_px: mean(&errs),
        });
    }
    let mut t = Table::new(
        "planes",
        "Seed 002 §4 scaling: background-subtraction time per frame and detection quality, 1 / 3 colour × 0 / 1 / 2 edge planes",
        PlanesRow::frame(&rows)?,
    );
    for c in ["ms_per_frame", "precision", "recall", "f1", "head_err_px"] {
        t = t.with_precision(c, 3);
    }
    out.tables.push(t.with_note(
        "ms_per_frame: the Jabri split + update + test alone, on the thread of its session (sessions run in parallel), this machine and build (timings vary run to run; compare the ratios); precision/recall/F1 of the moving-pixel mask against the exact person mask; detected_frames: frames with a person detection (moving blob with skin in its top fifth) within 20 px of the true head top; means over sessions weighted by frames.",
    ));
    Ok(())
}

//! The camera's mount (our addition; seed 002 gives no camera height and no camera-only
//! number, only "less accuracy"): the paper's filters of [`super::aggregate`] run once per
//! camera of `cameras` over the same sessions — the same person on the same walks seen by
//! cameras at several heights on one mast (`office_network_mount`) — so that only the mount
//! differs. Per camera: how often the head top is detected, the height laser + camera learns,
//! and camera only's position and height error with the constant height and with the random
//! walk (paired t-test across sessions), beside the closed-form range sensitivity
//! |dρ/dε| = (ρ² + Δz²)/|Δz| ([`crate::track::height_ekf::range_per_elevation`]): a head top
//! near the camera's height carries little range information.

use super::aggregate::{
    self, CAMERA_ONLY, CAMERA_ONLY_WALK, FUSED, FUSED_WALK, LASER_ONLY, SessionData, mean,
};
use super::params::Params;
use super::tables::{self, CameraObsRow, LaserObsRow, TruthRow};
use super::walk;
use crate::eval::stats;
use crate::report::figure::{Figure, FigureKind, LinePlot, Mark, Panels, Series};
use crate::report::rows::Rows;
use crate::report::table::Table;
use crate::run::{Aggregate, Products};
use crate::table_row;
use crate::track::height_ekf::range_per_elevation;

/// Floor range (m) at which the `mount` table gives the closed-form range sensitivity: about
/// the middle of the walking area seen from the east wall.
pub const REFERENCE_RANGE_M: f64 = 5.0;

/// One camera's sessions with every filter run.
pub struct MountCamera {
    pub camera: String,
    /// Camera centre height (m, from its observations' TF pose; `None` without detections).
    pub z_m: Option<f64>,
    pub sessions: Vec<SessionData>,
}

table_row! {
    /// One camera on one session: `mount_sessions`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct MountSessionRow {
        pub camera: String,
        pub camera_z_m: Option<f64>,
        pub session: String,
        pub truth_m: f64,
        /// Frames with a person detection (after the background warm-up).
        pub camera_frames: i64,
        pub learned_m: Option<f64>,
        pub learned_walk_m: Option<f64>,
        pub fused_error_m: Option<f64>,
        pub camera_only_error_m: Option<f64>,
        pub camera_only_walk_error_m: Option<f64>,
        pub camera_only_final_m: Option<f64>,
        pub camera_only_walk_final_m: Option<f64>,
    }
}

table_row! {
    /// One camera over the sessions: `mount`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct MountRow {
        pub camera: String,
        pub camera_z_m: Option<f64>,
        /// Mean true head top − camera height (m).
        pub head_dz_m: Option<f64>,
        /// Closed-form range change per mrad of elevation at `REFERENCE_RANGE_M` (m).
        pub range_per_mrad_m: Option<f64>,
        pub sessions: i64,
        pub camera_frames_per_session: f64,
        /// Height laser + camera learns, minus the truth: mean and sd over sessions.
        pub learned_error_m: Option<f64>,
        pub learned_error_sd_m: Option<f64>,
        pub laser_only_error_m: Option<f64>,
        pub fused_error_m: Option<f64>,
        pub camera_only_error_m: Option<f64>,
        pub camera_only_walk_error_m: Option<f64>,
        /// Paired t-test across sessions of camera only's mean error, constant vs walk.
        pub walk_t: Option<f64>,
        pub walk_p: Option<f64>,
        /// Camera only's final height minus the truth (mean over sessions).
        pub camera_only_height_error_m: Option<f64>,
        pub camera_only_walk_height_error_m: Option<f64>,
    }
}

/// Read every evaluated session and run the paper's filters once per camera.
pub fn compute(ctx: &Aggregate, p: &Params) -> anyhow::Result<Vec<MountCamera>> {
    type Read = (
        String,
        Vec<LaserObsRow>,
        Vec<TruthRow>,
        Vec<Vec<CameraObsRow>>,
    );
    let mut read: Vec<Read> = Vec::new();
    for (info, t) in ctx.sessions {
        if p.is_training(&info.path) {
            continue;
        }
        let n = &info.name;
        let mut cams = Vec::new();
        for cam in &p.cameras {
            cams.push(tables::read(t, &tables::camera_table(cam), n)?);
        }
        read.push((
            n.clone(),
            tables::read(t, tables::LASER, n)?,
            tables::read(t, tables::TRUTH, n)?,
            cams,
        ));
    }
    let mut out = Vec::new();
    for (i, cam) in p.cameras.iter().enumerate() {
        let mut sessions: Vec<SessionData> = read
            .iter()
            .map(|(n, laser, truth, cams)| SessionData {
                truth: truth.clone(),
                ..SessionData::new(n, laser.clone(), cams[i].clone())
            })
            .collect();
        aggregate::run_filters(&mut sessions, p);
        let z_m = sessions
            .iter()
            .find_map(|s| s.camera.first().map(|c| c.cam_z));
        out.push(MountCamera {
            camera: cam.clone(),
            z_m,
            sessions,
        });
    }
    Ok(out)
}

fn final_h(s: &SessionData, name: &str) -> Option<f64> {
    s.runs.get(name)?.0.last().map(|e| e.h)
}

fn session_row(c: &MountCamera, s: &SessionData) -> MountSessionRow {
    let mut frames: Vec<i64> = s.camera.iter().map(|o| o.frame_idx).collect();
    frames.dedup();
    MountSessionRow {
        camera: c.camera.clone(),
        camera_z_m: c.z_m,
        session: s.name.clone(),
        truth_m: s.truth_m(),
        camera_frames: frames.len() as i64,
        learned_m: final_h(s, FUSED),
        learned_walk_m: final_h(s, FUSED_WALK),
        fused_error_m: s.mean_error(FUSED),
        camera_only_error_m: s.mean_error(CAMERA_ONLY),
        camera_only_walk_error_m: s.mean_error(CAMERA_ONLY_WALK),
        camera_only_final_m: final_h(s, CAMERA_ONLY),
        camera_only_walk_final_m: final_h(s, CAMERA_ONLY_WALK),
    }
}

/// Mean of `f` over the rows where it is defined.
fn mean_of(rows: &[MountSessionRow], f: impl Fn(&MountSessionRow) -> Option<f64>) -> Option<f64> {
    mean(&rows.iter().filter_map(f).collect::<Vec<_>>())
}

fn camera_row(c: &MountCamera, rows: &[MountSessionRow], level: f64) -> MountRow {
    let dz = c.z_m.and_then(|z| mean_of(rows, |r| Some(r.truth_m - z)));
    let learned_err: Vec<f64> = rows
        .iter()
        .filter_map(|r| r.learned_m.map(|h| h - r.truth_m))
        .collect();
    let test = walk::test(&c.sessions, CAMERA_ONLY, CAMERA_ONLY_WALK, level);
    MountRow {
        camera: c.camera.clone(),
        camera_z_m: c.z_m,
        head_dz_m: dz,
        range_per_mrad_m: dz.map(|dz| 1e-3 * range_per_elevation(REFERENCE_RANGE_M, dz)),
        sessions: rows.len() as i64,
        camera_frames_per_session: mean_of(rows, |r| Some(r.camera_frames as f64)).unwrap_or(0.0),
        learned_error_m: mean(&learned_err),
        learned_error_sd_m: stats::describe(&learned_err).ok().map(|s| s.std),
        laser_only_error_m: mean(
            &c.sessions
                .iter()
                .filter_map(|s| s.mean_error(LASER_ONLY))
                .collect::<Vec<_>>(),
        ),
        fused_error_m: mean_of(rows, |r| r.fused_error_m),
        camera_only_error_m: mean_of(rows, |r| r.camera_only_error_m),
        camera_only_walk_error_m: mean_of(rows, |r| r.camera_only_walk_error_m),
        walk_t: test.t,
        walk_p: test.p_two_sided,
        camera_only_height_error_m: mean_of(rows, |r| r.camera_only_final_m.map(|h| h - r.truth_m)),
        camera_only_walk_height_error_m: mean_of(rows, |r| {
            r.camera_only_walk_final_m.map(|h| h - r.truth_m)
        }),
    }
}

/// The `mount` and `mount_sessions` tables and the `mount_camera_only` figure.
pub fn products(cams: &[MountCamera], p: &Params, out: &mut Products) -> anyhow::Result<()> {
    let mut per_session = Vec::new();
    let mut per_camera = Vec::new();
    for c in cams {
        let rows: Vec<MountSessionRow> = c.sessions.iter().map(|s| session_row(c, s)).collect();
        per_camera.push(camera_row(c, &rows, p.level));
        per_session.extend(rows);
    }
    let mut t = Table::new(
        "mount",
        "Seed 002's filters against the camera's mount: the same walks seen from cameras at several heights (camera only: the paper's second trial)",
        MountRow::frame(&per_camera)?,
    );
    t = t.with_precisions(
        &[
            "camera_z_m",
            "head_dz_m",
            "range_per_mrad_m",
            "camera_frames_per_session",
            "learned_error_m",
            "learned_error_sd_m",
            "laser_only_error_m",
            "fused_error_m",
            "camera_only_error_m",
            "camera_only_walk_error_m",
            "walk_t",
            "walk_p",
            "camera_only_height_error_m",
            "camera_only_walk_height_error_m",
        ],
        3,
    );
    out.tables.push(t.with_note(format!(
        "Means over sessions. range_per_mrad_m: (rho² + dz²)/|dz| × 1 mrad at rho = {REFERENCE_RANGE_M} m, the range one mrad of elevation error moves (a pixel is about 3.8 mrad here). learned_error: the height laser + camera learns (constant height) minus the truth; camera only starts from it (height_from = {}); walk: q_height_walk = {} m²/s in both trials; walk_t / walk_p: paired t-test across sessions of camera only's mean error, constant − walk. Every camera looks at the same point; its detector values are the paper run's (chosen on office_network's 2.2 m camera).",
        p.height_from.name(),
        p.q_height_walk
    )));
    let mut t = Table::new(
        "mount_sessions",
        "The mount table per camera and session",
        MountSessionRow::frame(&per_session)?,
    );
    t = t.with_precisions(
        &[
            "camera_z_m",
            "truth_m",
            "learned_m",
            "learned_walk_m",
            "fused_error_m",
            "camera_only_error_m",
            "camera_only_walk_error_m",
            "camera_only_final_m",
            "camera_only_walk_final_m",
        ],
        3,
    );
    out.tables.push(t);
    out.figures.push(figure(&per_camera));
    Ok(())
}

/// Position error (camera only both ways, laser + camera) and height error against the
/// camera's height.
fn figure(rows: &[MountRow]) -> Figure {
    let line = |name: &str, f: &dyn Fn(&MountRow) -> Option<f64>, color: usize| {
        let pts: Vec<(f64, f64)> = rows.iter().filter_map(|r| r.camera_z_m.zip(f(r))).collect();
        Series::line(name, pts, color).with_mark(Mark::LinePoints)
    };
    let panel = |name: &str, title: &str, y: &str, series: Vec<Series>| {
        let y_range = legend_headroom(&series);
        Figure::new(
            name.to_string(),
            title.to_string(),
            FigureKind::Lines(LinePlot {
                x_label: "camera height (m)".into(),
                y_label: y.into(),
                series,
                y_range,
                ..LinePlot::default()
            }),
        )
    };
    Figure::new(
        "mount_camera_only",
        "Seed 002 against the camera's mount (same walks; means over sessions)",
        FigureKind::Panels(Panels {
            columns: 1,
            panels: vec![
                panel(
                    "position",
                    "mean position error",
                    "position error (m)",
                    vec![
                        line(
                            "camera only (constant height)",
                            &|r| r.camera_only_error_m,
                            1,
                        ),
                        line(
                            "camera only (height random walk)",
                            &|r| r.camera_only_walk_error_m,
                            2,
                        ),
                        line("laser + camera", &|r| r.fused_error_m, 3),
                    ],
                ),
                panel(
                    "height",
                    "height minus the truth",
                    "height error (m)",
                    vec![
                        line("learned by laser + camera", &|r| r.learned_error_m, 3),
                        line(
                            "camera only at the end (constant)",
                            &|r| r.camera_only_height_error_m,
                            1,
                        ),
                        line(
                            "camera only at the end (random walk)",
                            &|r| r.camera_only_walk_height_error_m,
                            2,
                        ),
                    ],
                ),
            ],
        }),
    )
}

/// Share of a panel's data span left empty above the data, so the legend (drawn in the upper
/// right) hides no point.
const LEGEND_HEADROOM: f64 = 0.45;

/// The y range of a panel: the data's span, with `LEGEND_HEADROOM` above it and a little below.
fn legend_headroom(series: &[Series]) -> Option<(f64, f64)> {
    let ys = series.iter().flat_map(|s| s.points.iter().map(|p| p.1));
    let (lo, hi) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), y| {
        (lo.min(y), hi.max(y))
    });
    let span = (hi - lo).max(1e-3);
    (lo.is_finite() && hi.is_finite()).then_some((lo - 0.05 * span, hi + LEGEND_HEADROOM * span))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_legend_headroom_keeps_every_point_inside_and_leaves_the_top_empty() {
        let s = |ys: &[f64]| Series::line("s", ys.iter().map(|&y| (1.0, y)).collect(), 1);
        // Span 1 m from -0.5 to 0.5: 5 % below, 45 % above.
        let (lo, hi) = legend_headroom(&[s(&[-0.5, 0.1]), s(&[0.5])]).expect("points");
        assert!(
            (lo - -0.55).abs() < 1e-12 && (hi - 0.95).abs() < 1e-12,
            "{lo} {hi}"
        );
        assert_eq!(legend_headroom(&[s(&[])]), None);
    }
}

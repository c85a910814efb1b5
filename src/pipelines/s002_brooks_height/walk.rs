//! Seed 002's second trial with the height as the paper models it (a constant, learned by
//! laser + camera in the first trial) against a height random walk (`q_height_walk`, the model
//! this project used before): per session the camera-only run's start and final height and
//! mean position error in both models, and paired t-tests across sessions (one mean error per
//! session and model) for camera only and for laser + camera. Camera only cannot observe the
//! height (§5: the camera gives "a relationship between height and range"), so a random walk
//! lets the height drift and the range with it. Reads only the filter runs of
//! [`super::aggregate`].

use super::aggregate::{CAMERA_ONLY, CAMERA_ONLY_WALK, FUSED, FUSED_WALK, SessionData, mean};
use super::params::Params;
use crate::eval::stats;
use crate::report::rows::Rows;
use crate::report::table::Table;
use crate::run::Products;
use crate::table_row;

table_row! {
    /// Camera only per session, constant height and random walk: `camera_only_walk`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct WalkRow {
        pub session: String,
        pub truth_m: f64,
        /// The session whose learned height camera only starts from, and that person's height.
        pub height_from: String,
        pub height_from_truth_m: f64,
        pub start_m: Option<f64>,
        pub final_m: Option<f64>,
        pub mean_error_m: Option<f64>,
        pub start_walk_m: Option<f64>,
        pub final_walk_m: Option<f64>,
        pub mean_error_walk_m: Option<f64>,
    }
}

table_row! {
    /// Constant height against the random walk, one mean error per session:
    /// `camera_only_walk_ttest`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct WalkTestRow {
        pub method: String,
        pub sessions: i64,
        pub mean_constant_m: Option<f64>,
        pub mean_walk_m: Option<f64>,
        /// constant − walk (negative: the constant height is closer to the truth).
        pub mean_diff_m: Option<f64>,
        pub t: Option<f64>,
        pub p_two_sided: Option<f64>,
        pub ci_low_m: Option<f64>,
        pub ci_high_m: Option<f64>,
    }
}

fn row(s: &SessionData) -> WalkRow {
    let ends = |name: &str| {
        let run = &s.runs[name].0;
        (run.estimates.first().map(|e| e.h), run.last().map(|e| e.h))
    };
    let (start, fin) = ends(CAMERA_ONLY);
    let (start_walk, final_walk) = ends(CAMERA_ONLY_WALK);
    WalkRow {
        session: s.name.clone(),
        truth_m: s.truth_m(),
        height_from: s.height_from.clone(),
        height_from_truth_m: s.height_from_truth_m,
        start_m: start,
        final_m: fin,
        mean_error_m: s.mean_error(CAMERA_ONLY),
        start_walk_m: start_walk,
        final_walk_m: final_walk,
        mean_error_walk_m: s.mean_error(CAMERA_ONLY_WALK),
    }
}

/// Paired t-test of the per-session mean errors of `constant` and `walk`.
pub fn test(data: &[SessionData], constant: &str, walk: &str, level: f64) -> WalkTestRow {
    let (a, b): (Vec<f64>, Vec<f64>) = data
        .iter()
        .filter_map(|s| s.mean_error(constant).zip(s.mean_error(walk)))
        .unzip();
    let t = stats::paired_t(&a, &b, level).ok();
    WalkTestRow {
        method: constant.into(),
        sessions: a.len() as i64,
        mean_constant_m: mean(&a),
        mean_walk_m: mean(&b),
        mean_diff_m: mean(&a).zip(mean(&b)).map(|(x, y)| x - y),
        t: t.as_ref().map(|t| t.t),
        p_two_sided: t.as_ref().map(|t| t.p_two_sided),
        ci_low_m: t.as_ref().map(|t| t.ci_low),
        ci_high_m: t.as_ref().map(|t| t.ci_high),
    }
}

/// The `camera_only_walk` and `camera_only_walk_ttest` tables.
pub fn tables(data: &[SessionData], p: &Params, out: &mut Products) -> anyhow::Result<()> {
    let rows: Vec<WalkRow> = data.iter().map(row).collect();
    let other = rows
        .iter()
        .filter(|r| (r.truth_m - r.height_from_truth_m).abs() > 1e-3)
        .count();
    let mut t = Table::new(
        "camera_only_walk",
        "Camera only (seed 002's second trial) per session: the height a constant vs a random walk",
        WalkRow::frame(&rows)?,
    );
    t = t.with_precisions(
        &[
            "truth_m",
            "height_from_truth_m",
            "start_m",
            "final_m",
            "mean_error_m",
            "start_walk_m",
            "final_walk_m",
            "mean_error_walk_m",
        ],
        3,
    );
    let warn = if other > 0 {
        format!(
            " WARNING: {other} session(s) start from another person's height (height_from_truth_m differs): check height_from."
        )
    } else {
        String::new()
    };
    out.tables.push(t.with_note(format!(
        "Camera only starts from the height and sigma laser + camera learned in session height_from (height_from = {}); constant: q_height = {} m²/s (the paper), walk: q_height_walk = {} m²/s in both trials. mean_error_m: position error over the ground-truth stamps.{warn}",
        p.height_from.name(),
        p.q_height,
        p.q_height_walk
    )));
    let tests = vec![
        test(data, CAMERA_ONLY, CAMERA_ONLY_WALK, p.level),
        test(data, FUSED, FUSED_WALK, p.level),
    ];
    let mut t = Table::new(
        "camera_only_walk_ttest",
        "Constant height vs height random walk: paired t-test across sessions of the per-session mean position error",
        WalkTestRow::frame(&tests)?,
    );
    t = t.with_precisions(
        &[
            "mean_constant_m",
            "mean_walk_m",
            "mean_diff_m",
            "t",
            "p_two_sided",
            "ci_low_m",
            "ci_high_m",
        ],
        4,
    );
    out.tables.push(t.with_note(format!(
        "Two-sided, level {}; one pair per session (sessions are independent walks, unlike the stamps of paired_ttest). method: the constant-height method; its walk variant is the same sensors with q_height_walk.",
        p.level
    )));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipelines::s002_brooks_height::fusion::{Run, Scored};

    fn session(errors: &[(&'static str, &[f64])]) -> SessionData {
        let mut s = SessionData::new("s", Vec::new(), Vec::new());
        for (name, e) in errors {
            let scored = e
                .iter()
                .map(|&error_m| Scored {
                    stamp_ns: 0,
                    error_m,
                    along_m: None,
                    speed: 0.0,
                })
                .collect();
            s.runs.insert(name, (Run::default(), scored));
        }
        s
    }

    #[test]
    fn the_walk_test_pairs_one_mean_error_per_session() {
        // per-session means 0.2 / 0.5 and 0.4 / 0.9: differences −0.3 and −0.5, mean −0.4,
        // sd 0.1414, se 0.1, t = −4 on 1 degree of freedom
        let data = [
            session(&[(CAMERA_ONLY, &[0.1, 0.3]), (CAMERA_ONLY_WALK, &[0.5])]),
            session(&[(CAMERA_ONLY, &[0.4]), (CAMERA_ONLY_WALK, &[0.8, 1.0])]),
        ];
        let t = test(&data, CAMERA_ONLY, CAMERA_ONLY_WALK, 0.95);
        assert_eq!(t.sessions, 2);
        assert!((t.mean_constant_m.expect("some") - 0.3).abs() < 1e-12);
        assert!((t.mean_diff_m.expect("some") + 0.4).abs() < 1e-12);
        assert!((t.t.expect("t") + 4.0).abs() < 1e-9);
        // p = 2 P(T_1 > 4) = 1 − (2/π) atan 4
        let p = 1.0 - 2.0 / std::f64::consts::PI * 4f64.atan();
        assert!((t.p_two_sided.expect("p") - p).abs() < 1e-9);
    }
}

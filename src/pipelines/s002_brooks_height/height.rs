//! The learned height (seed 002 §6: "the target's height was estimated to be 1.87 metres,
//! compared with the value of 1.84 metres which was measured with a tape measure", one trial):
//! per session the height laser + camera holds at the end — the paper's constant height, the
//! random-walk variant and our CV variant beside it; per person (sessions grouped by their true
//! height: the full profile has people of several heights, each walking two trials); and
//! one-sample t-tests of learned − true height against 0, over sessions and over people.
//! Reads only the filter runs of [`super::aggregate`].

use std::collections::BTreeMap;

use super::aggregate::{
    FUSED, FUSED_CV, FUSED_WALK, PAPER_HEIGHT_M, PAPER_TRUTH_M, SessionData, mean,
};
use super::params::Params;
use crate::eval::stats;
use crate::report::rows::Rows;
use crate::report::table::Table;
use crate::run::Products;
use crate::table_row;

table_row! {
    /// Final height per session: `height`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct HeightRow {
        pub session: String,
        pub truth_m: f64,
        pub final_m: Option<f64>,
        pub sigma_m: Option<f64>,
        pub error_m: Option<f64>,
        /// The random-walk variant's final height and its error.
        pub final_walk_m: Option<f64>,
        pub error_walk_m: Option<f64>,
        pub final_cv_m: Option<f64>,
        pub camera_accepted: i64,
        pub camera_rejected: i64,
        pub laser_accepted: i64,
        pub laser_rejected: i64,
        pub first_camera_s: Option<f64>,
    }
}

table_row! {
    /// The sessions of one person (one true height): `height_per_person`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct PersonHeightRow {
        pub truth_m: f64,
        pub sessions: i64,
        pub mean_final_m: Option<f64>,
        pub mean_error_m: Option<f64>,
        pub min_final_m: Option<f64>,
        pub max_final_m: Option<f64>,
        pub mean_final_walk_m: Option<f64>,
        pub mean_error_walk_m: Option<f64>,
    }
}

table_row! {
    /// One-sample t-test of learned − true height against 0: `height_ttest`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct HeightTestRow {
        /// `session` (one error per session) or `person` (the mean error of each person).
        pub unit: String,
        /// `constant` (the paper's model) or `random walk`.
        pub height_model: String,
        pub n: i64,
        pub truth_min_m: f64,
        pub truth_max_m: f64,
        pub mean_error_m: Option<f64>,
        pub std_error_m: Option<f64>,
        pub t: Option<f64>,
        pub p_two_sided: Option<f64>,
        pub ci_low_m: Option<f64>,
        pub ci_high_m: Option<f64>,
        pub paper_m: f64,
        pub paper_truth_m: f64,
    }
}

/// One session's row.
fn row(s: &SessionData) -> HeightRow {
    let truth = s.truth_m();
    let (run, _) = &s.runs[FUSED];
    let last = run.last();
    let walk = s.runs[FUSED_WALK].0.last().map(|e| e.h);
    HeightRow {
        session: s.name.clone(),
        truth_m: truth,
        final_m: last.map(|e| e.h),
        sigma_m: last.map(|e| e.sigma_h),
        error_m: last.map(|e| e.h - truth),
        final_walk_m: walk,
        error_walk_m: walk.map(|h| h - truth),
        final_cv_m: s.runs[FUSED_CV].0.last().map(|e| e.h),
        camera_accepted: run.camera_accepted as i64,
        camera_rejected: run.camera_rejected as i64,
        laser_accepted: run.laser_accepted as i64,
        laser_rejected: run.laser_rejected as i64,
        first_camera_s: run
            .first_camera_ns
            .zip(run.estimates.first())
            .map(|(c, e)| (c - e.stamp_ns) as f64 * 1e-9),
    }
}

/// Sessions grouped by true height (to the millimetre), in height order.
fn people(rows: &[HeightRow]) -> Vec<PersonHeightRow> {
    let mut by: BTreeMap<i64, Vec<&HeightRow>> = BTreeMap::new();
    for r in rows.iter().filter(|r| r.truth_m.is_finite()) {
        by.entry((r.truth_m * 1e3).round() as i64)
            .or_default()
            .push(r);
    }
    by.into_values()
        .map(|g| {
            let finals: Vec<f64> = g.iter().filter_map(|r| r.final_m).collect();
            let errs: Vec<f64> = g.iter().filter_map(|r| r.error_m).collect();
            let walks: Vec<f64> = g.iter().filter_map(|r| r.final_walk_m).collect();
            let walk_errs: Vec<f64> = g.iter().filter_map(|r| r.error_walk_m).collect();
            PersonHeightRow {
                truth_m: g[0].truth_m,
                sessions: g.len() as i64,
                mean_final_m: mean(&finals),
                mean_error_m: mean(&errs),
                min_final_m: finals.iter().copied().reduce(f64::min),
                max_final_m: finals.iter().copied().reduce(f64::max),
                mean_final_walk_m: mean(&walks),
                mean_error_walk_m: mean(&walk_errs),
            }
        })
        .collect()
}

/// One-sample t-test of `errors` against 0 (a paired test against zeros).
fn test(unit: &str, model: &str, errors: &[f64], truths: &[f64], level: f64) -> HeightTestRow {
    let summary = stats::describe(errors).ok();
    let t = stats::paired_t(errors, &vec![0.0; errors.len()], level).ok();
    HeightTestRow {
        unit: unit.into(),
        height_model: model.into(),
        n: errors.len() as i64,
        truth_min_m: truths.iter().copied().fold(f64::INFINITY, f64::min),
        truth_max_m: truths.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        mean_error_m: mean(errors),
        std_error_m: summary.as_ref().map(|s| s.std),
        t: t.as_ref().map(|t| t.t),
        p_two_sided: t.as_ref().map(|t| t.p_two_sided),
        ci_low_m: t.as_ref().map(|t| t.ci_low),
        ci_high_m: t.as_ref().map(|t| t.ci_high),
        paper_m: PAPER_HEIGHT_M,
        paper_truth_m: PAPER_TRUTH_M,
    }
}

/// The t-tests: over sessions and over people, constant height and random walk.
fn tests(rows: &[HeightRow], persons: &[PersonHeightRow], level: f64) -> Vec<HeightTestRow> {
    let pick = |f: &dyn Fn(&HeightRow) -> Option<f64>| -> (Vec<f64>, Vec<f64>) {
        rows.iter()
            .filter_map(|r| f(r).map(|e| (e, r.truth_m)))
            .unzip()
    };
    let pick_p = |f: &dyn Fn(&PersonHeightRow) -> Option<f64>| -> (Vec<f64>, Vec<f64>) {
        persons
            .iter()
            .filter_map(|r| f(r).map(|e| (e, r.truth_m)))
            .unzip()
    };
    let mut out = Vec::new();
    for (model, walk) in [("constant", false), ("random walk", true)] {
        let (e, t) = pick(&|r| if walk { r.error_walk_m } else { r.error_m });
        out.push(test("session", model, &e, &t, level));
        let (e, t) = pick_p(&|r| {
            if walk {
                r.mean_error_walk_m
            } else {
                r.mean_error_m
            }
        });
        out.push(test("person", model, &e, &t, level));
    }
    // each person on their own: learned against true height over that person's sessions (the
    // full profile has two per person, so these tests have one degree of freedom)
    for person in persons.iter().filter(|p| p.sessions >= 2) {
        let mine = |r: &&HeightRow| (r.truth_m - person.truth_m).abs() < 5e-4;
        for (model, walk) in [("constant", false), ("random walk", true)] {
            let e: Vec<f64> = rows
                .iter()
                .filter(mine)
                .filter_map(|r| if walk { r.error_walk_m } else { r.error_m })
                .collect();
            let t = vec![person.truth_m; e.len()];
            let unit = format!("person {:.2} m", person.truth_m);
            out.push(test(&unit, model, &e, &t, level));
        }
    }
    out
}

/// The `height`, `height_per_person` and `height_ttest` tables.
pub fn tables(data: &[SessionData], p: &Params, out: &mut Products) -> anyhow::Result<()> {
    let rows: Vec<HeightRow> = data.iter().map(row).collect();
    let mut t = Table::new(
        "height",
        "Height learned by laser + camera at the end of each session vs the truth (seed 002 §6: 1.87 m vs 1.84 m)",
        HeightRow::frame(&rows)?,
    );
    t = t.with_precisions(
        &[
            "truth_m",
            "final_m",
            "sigma_m",
            "error_m",
            "final_walk_m",
            "error_walk_m",
            "final_cv_m",
            "first_camera_s",
        ],
        3,
    );
    out.tables.push(t.with_note(format!(
        "EKF over (x, y, h), constant position, h0 = {} m with sigma {} m, 3-sigma gate (Mahalanobis <= {}); the height a constant the filter learns (q_height = {} m²/s, the paper's model); final_walk_m: the random-walk variant (q_height_walk = {} m²/s). camera/laser accepted and rejected count observation events (a rejected camera event is one whose every detection implied a state outside the gate). first_camera_s: first camera detection after the filter started.",
        p.h0_m, p.sigma_h0_m, p.gate_sigma, p.q_height, p.q_height_walk
    )));
    let persons = people(&rows);
    let mut t = Table::new(
        "height_per_person",
        "Learned height per person (sessions grouped by true height) against the truth",
        PersonHeightRow::frame(&persons)?,
    );
    t = t.with_precisions(
        &[
            "truth_m",
            "mean_final_m",
            "mean_error_m",
            "min_final_m",
            "max_final_m",
            "mean_final_walk_m",
            "mean_error_walk_m",
        ],
        3,
    );
    out.tables.push(t.with_note(
        "A person is a true height (synthetic people of one height); the paper measured one person once (1.87 m learned vs 1.84 m taped).",
    ));
    let mut t = Table::new(
        "height_ttest",
        "Learned − true height: mean, std and a one-sample t-test against 0, over sessions and over people",
        HeightTestRow::frame(&tests(&rows, &persons, p.level))?,
    );
    t = t.with_precisions(
        &[
            "truth_min_m",
            "truth_max_m",
            "mean_error_m",
            "std_error_m",
            "t",
            "p_two_sided",
            "ci_low_m",
            "ci_high_m",
        ],
        4,
    );
    out.tables.push(t.with_note(format!(
        "Two-sided, level {}; ci of the mean error. unit = person: each person's mean error over their sessions; unit = person <h> m: that person's sessions alone (n = their sessions). The paper reports one trial ({PAPER_HEIGHT_M} m vs {PAPER_TRUTH_M} m: +0.03 m), so it has no test.",
        p.level
    )));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn r(truth: f64, fin: f64, walk: f64) -> HeightRow {
        HeightRow {
            session: String::new(),
            truth_m: truth,
            final_m: Some(fin),
            sigma_m: Some(0.01),
            error_m: Some(fin - truth),
            final_walk_m: Some(walk),
            error_walk_m: Some(walk - truth),
            final_cv_m: None,
            camera_accepted: 0,
            camera_rejected: 0,
            laser_accepted: 0,
            laser_rejected: 0,
            first_camera_s: None,
        }
    }

    #[test]
    fn people_group_by_true_height_and_the_t_test_is_one_sample_against_zero() {
        // two people, two trials each: errors +0.01, +0.03 (1.55 m) and +0.02, +0.04 (1.84 m)
        let rows = [
            r(1.84, 1.86, 1.90),
            r(1.55, 1.56, 1.60),
            r(1.84, 1.88, 1.92),
            r(1.55, 1.58, 1.62),
        ];
        let p = people(&rows);
        assert_eq!(p.len(), 2);
        assert_eq!((p[0].truth_m, p[0].sessions), (1.55, 2));
        assert!((p[0].mean_error_m.expect("some") - 0.02).abs() < 1e-12);
        assert!((p[1].mean_final_m.expect("some") - 1.87).abs() < 1e-12);
        assert_eq!(
            (p[1].min_final_m, p[1].max_final_m),
            (Some(1.86), Some(1.88))
        );
        let t = tests(&rows, &p, 0.95);
        assert_eq!(t.len(), 8);
        // sessions: errors 0.02, 0.01, 0.04, 0.03 — mean 0.025, sd 0.012910, t = 3.873
        let s = &t[0];
        assert_eq!(
            (s.unit.as_str(), s.height_model.as_str(), s.n),
            ("session", "constant", 4)
        );
        assert!((s.mean_error_m.expect("some") - 0.025).abs() < 1e-12);
        let sd = (0.0005f64 / 3.0).sqrt();
        assert!((s.t.expect("t") - 0.025 / (sd / 2.0)).abs() < 1e-9);
        assert_eq!((s.truth_min_m, s.truth_max_m), (1.55, 1.84));
        // people: mean errors 0.02 and 0.03; the walk variant is 0.04 higher everywhere
        assert_eq!(t[1].n, 2);
        assert!((t[1].mean_error_m.expect("some") - 0.025).abs() < 1e-12);
        assert!((t[2].mean_error_m.expect("some") - 0.065).abs() < 1e-12);
        // each person alone: 1.55 m has errors 0.01 and 0.03 — mean 0.02, sd √2·0.01, so
        // t = 0.02 / (√2·0.01 / √2) = 2 with one degree of freedom
        let one = &t[4];
        assert_eq!(
            (one.unit.as_str(), one.height_model.as_str(), one.n),
            ("person 1.55 m", "constant", 2)
        );
        assert!((one.t.expect("t") - 2.0).abs() < 1e-9);
        assert_eq!((one.truth_min_m, one.truth_max_m), (1.55, 1.55));
        assert_eq!(t[7].unit, "person 1.84 m");
        assert_eq!(t[7].height_model, "random walk");
    }
}

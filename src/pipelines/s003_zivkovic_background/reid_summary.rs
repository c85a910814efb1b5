//! Re-identification across sessions (seed 003 §V, issue 31): the per-session runs of
//! `reid_report` pooled per clip, source and method (`reid_pooled`), paired t-tests of the
//! paper's model against every other method across sessions (`reid_ttests`), what the
//! training split fitted beside the printed prior (`reid_prior`), and the paper's results
//! as goals in the report's summary.

use std::collections::BTreeMap;

use super::reid_methods::{METHODS, PAPER, Training};
use super::reid_params::ReidParams;
use super::reid_report::{ReidRow, RetrievalRow, Runs, SOURCES, feature_name};
use crate::eval::stats;
use crate::report::Table;
use crate::report::rows::Rows;
use crate::run::Products;
use crate::table_row;

table_row! {
    /// A row of the `reid_pooled` table.
    #[derive(Debug, Clone, PartialEq)]
    struct PooledRow {
        clip: String,
        source: String,
        method: String,
        sessions: i64,
        observations: i64,
        misidentified: i64,
        misidentified_pct: f64,
        sessions_without_error: i64,
        mean_people_error: f64,
        mean_abs_people_error: f64,
        mean_wrongly_new: f64,
        mean_merged: f64,
        mean_people_wrong: f64,
        mean_adjusted_rand: f64,
        mean_rank1: f64,
        mean_map: f64,
    }
}

table_row! {
    /// A row of the `reid_ttests` table.
    #[derive(Debug, Clone, PartialEq)]
    struct TestRow {
        clip: String,
        source: String,
        baseline: String,
        sessions: i64,
        paper_misidentified_pct: f64,
        baseline_misidentified_pct: f64,
        t: Option<f64>,
        p_two_sided: Option<f64>,
    }
}

table_row! {
    /// A row of the `reid_prior` table.
    #[derive(Debug, Clone, PartialEq)]
    struct PriorRow {
        feature: String,
        training_sessions: String,
        observations: i64,
        people: i64,
        within_sd: f64,
        between_sd: f64,
        kappa0_printed: f64,
        kappa0_moved: f64,
        c0_printed: f64,
        c0_moved: f64,
        a0_printed: String,
        a0_moved: String,
        nn_threshold: Option<f64>,
    }
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// The runs of one (clip, source, method), in session order.
fn of<'a>(rows: &'a [ReidRow], clip: &str, source: &str, method: &str) -> Vec<&'a ReidRow> {
    rows.iter()
        .filter(|r| r.clip == clip && r.source == source && r.method == method)
        .collect()
}

/// Mean rank-1 and mAP over the sessions of (clip, source, feature).
fn retrieval_means(r: &[RetrievalRow], clip: &str, source: &str, feature: &str) -> (f64, f64) {
    let v: Vec<&RetrievalRow> = r
        .iter()
        .filter(|x| x.clip == clip && x.source == source && x.feature == feature)
        .collect();
    let rank1: Vec<f64> = v.iter().map(|x| x.rank1).collect();
    let map: Vec<f64> = v.iter().map(|x| x.map).collect();
    (mean(&rank1), mean(&map))
}

fn pooled(runs: &Runs, p: &ReidParams) -> Vec<PooledRow> {
    let mut out = Vec::new();
    for clip in &p.clips {
        for source in SOURCES {
            for m in &METHODS {
                let v = of(&runs.rows, &clip.name, source, m.name);
                if v.is_empty() {
                    continue;
                }
                let col =
                    |f: &dyn Fn(&ReidRow) -> f64| mean(&v.iter().map(|r| f(r)).collect::<Vec<_>>());
                let scored: i64 = v.iter().map(|r| r.observations - r.no_person).sum();
                let mis: i64 = v.iter().map(|r| r.misidentified).sum();
                let (rank1, map) = retrieval_means(
                    &runs.retrieval,
                    &clip.name,
                    source,
                    &feature_name(m.feature),
                );
                out.push(PooledRow {
                    clip: clip.name.clone(),
                    source: source.into(),
                    method: m.name.into(),
                    sessions: v.len() as i64,
                    observations: scored,
                    misidentified: mis,
                    misidentified_pct: 100.0 * mis as f64 / scored.max(1) as f64,
                    sessions_without_error: v.iter().filter(|r| r.misidentified == 0).count()
                        as i64,
                    mean_people_error: col(&|r| r.people_error as f64),
                    mean_abs_people_error: col(&|r| r.people_error.abs() as f64),
                    mean_wrongly_new: col(&|r| r.wrongly_new as f64),
                    mean_merged: col(&|r| r.merged as f64),
                    mean_people_wrong: col(&|r| r.people_wrong as f64),
                    mean_adjusted_rand: col(&|r| r.adjusted_rand),
                    mean_rank1: rank1,
                    mean_map: map,
                });
            }
        }
    }
    out
}

/// Paired t-tests of the mis-identified percentage across sessions: the paper's model against
/// each other method, per clip and source (sessions where both ran).
fn ttests(rows: &[ReidRow], p: &ReidParams) -> Vec<TestRow> {
    let mut out = Vec::new();
    for clip in &p.clips {
        for source in SOURCES {
            let paper: BTreeMap<&str, f64> = of(rows, &clip.name, source, PAPER.name)
                .into_iter()
                .map(|r| (r.session.as_str(), r.misidentified_pct))
                .collect();
            for m in &METHODS[1..] {
                let (a, b): (Vec<f64>, Vec<f64>) = of(rows, &clip.name, source, m.name)
                    .into_iter()
                    .filter_map(|r| {
                        paper
                            .get(r.session.as_str())
                            .map(|x| (*x, r.misidentified_pct))
                    })
                    .unzip();
                if a.is_empty() {
                    continue;
                }
                let test = stats::paired_t(&a, &b, p.level).ok();
                out.push(TestRow {
                    clip: clip.name.clone(),
                    source: source.into(),
                    baseline: m.name.into(),
                    sessions: a.len() as i64,
                    paper_misidentified_pct: mean(&a),
                    baseline_misidentified_pct: mean(&b),
                    t: test.as_ref().map(|t| t.t).filter(|t| t.is_finite()),
                    p_two_sided: test
                        .as_ref()
                        .map(|t| t.p_two_sided)
                        .filter(|p| p.is_finite()),
                });
            }
        }
    }
    out
}

fn vector(v: &[f64]) -> String {
    let parts: Vec<String> = v.iter().map(|x| format!("{x:.3}")).collect();
    format!("[{}]", parts.join(", "))
}

/// What the training split fitted, per feature variant, beside the printed values.
fn prior_rows(t: &Training) -> Vec<PriorRow> {
    t.priors
        .iter()
        .map(|(f, m)| PriorRow {
            feature: feature_name(*f),
            training_sessions: t.sessions.join(" "),
            observations: m.observations as i64,
            people: m.people as i64,
            within_sd: m.within_sd,
            between_sd: m.between_sd,
            kappa0_printed: 100.0,
            kappa0_moved: m.prior.kappa0,
            c0_printed: 1e-3,
            c0_moved: m.prior.c0,
            a0_printed: vector(&[0.0; 9]),
            a0_moved: vector(&m.prior.a0),
            nn_threshold: t.thresholds.get(f).copied(),
        })
        .collect()
}

/// The paper's results as goals (issue 31), for `method` on `source`: the similar-light clip
/// without error in how many sessions, the mean number of people wrong across light, and the
/// t-test against the nearest neighbour fitted on the training split.
fn goals(
    rows: &[ReidRow],
    tests: &[TestRow],
    p: &ReidParams,
    method: &str,
    source: &str,
) -> Vec<String> {
    let mut out = Vec::new();
    if let Some(similar) = p.clips.first() {
        let v = of(rows, &similar.name, source, method);
        if !v.is_empty() {
            out.push(format!(
                "{method}, {source} tracks, {}: no mis-identified observation in {} of {} sessions (paper: its one clip without error; goal: at least 8 of 10).",
                similar.name,
                v.iter().filter(|r| r.misidentified == 0).count(),
                v.len()
            ));
        }
    }
    if let Some(across) = p.clips.get(1) {
        let v = of(rows, &across.name, source, method);
        if !v.is_empty() {
            let wrong: Vec<f64> = v.iter().map(|r| r.people_wrong as f64).collect();
            out.push(format!(
                "{method}, {source} tracks, {}: {:.2} people per session wrongly new or merged (new {:.2}, merged {:.2}; paper: 1 of 5 wrongly new; goal: at most 1).",
                across.name,
                mean(&wrong),
                mean(&v.iter().map(|r| r.wrongly_new as f64).collect::<Vec<_>>()),
                mean(&v.iter().map(|r| r.merged as f64).collect::<Vec<_>>()),
            ));
        }
    }
    if method == PAPER.name {
        for t in tests
            .iter()
            .filter(|t| t.source == source && t.baseline.starts_with("nearest neighbour"))
        {
            out.push(format!(
                "paper vs {}, {source} tracks, {}: {:.1} % vs {:.1} % mis-identified over {} sessions, p = {} (goal: the paper's model better, p < 0.05).",
                t.baseline,
                t.clip,
                t.paper_misidentified_pct,
                t.baseline_misidentified_pct,
                t.sessions,
                t.p_two_sided.map_or("—".to_string(), |p| format!("{p:.4}"))
            ));
        }
    }
    out
}

pub(super) fn products(
    runs: &Runs,
    training: &Training,
    p: &ReidParams,
    products: &mut Products,
) -> anyhow::Result<()> {
    let tests = ttests(&runs.rows, p);
    for source in SOURCES {
        for method in [PAPER.name, METHODS[1].name] {
            products
                .summary
                .extend(goals(&runs.rows, &tests, p, method, source));
        }
    }
    if training.sessions.is_empty() {
        products.summary.push(format!(
            "Re-identification: no training session (datasets {:?}) in this run: the rows with the prior moved to the features' units and the fitted nearest-neighbour threshold are left out.",
            p.train_datasets
        ));
    }
    products.tables.push(
        Table::new("reid_pooled", "Re-identification pooled over the scored sessions, per clip, source and method", PooledRow::frame(&pooled(runs, p))?)
            .with_precision("misidentified_pct", 1)
            .with_precision("mean_people_error", 2)
            .with_precision("mean_abs_people_error", 2)
            .with_precision("mean_wrongly_new", 2)
            .with_precision("mean_merged", 2)
            .with_precision("mean_people_wrong", 2)
            .with_precision("mean_adjusted_rand", 3)
            .with_precision("mean_rank1", 3)
            .with_precision("mean_map", 3)
            .with_note("misidentified_pct = all mis-identified observations over all scored ones; the means are over sessions (one run per session); rank-1 and mAP of the method's feature (reid_retrieval). Paper: clip 1 without error, clip 2 one of five people wrongly new."),
    );
    products.tables.push(
        Table::new("reid_ttests", "Re-identification: paired t-tests across sessions of the mis-identified percentage, the paper's model against each other method", TestRow::frame(&tests)?)
            .with_precision("paper_misidentified_pct", 1)
            .with_precision("baseline_misidentified_pct", 1)
            .with_precision("t", 3)
            .with_precision("p_two_sided", 4)
            .with_note("One pair per scored session where both ran; t and p are empty with fewer than two sessions or no variation."),
    );
    products.tables.push(
        Table::new("reid_prior", "Re-identification: the prior as printed and moved to the features' units on the training split (our addition), and the fitted nearest-neighbour threshold", PriorRow::frame(&prior_rows(training))?)
            .with_precision("within_sd", 4)
            .with_precision("between_sd", 4)
            .with_precision("kappa0_moved", 2)
            .with_precision("c0_moved", 5)
            .with_note("Fitted on the ground-truth local tracks of the training sessions only (never a scored one; `track::reid::Prior::moved`): a₀ = the mean look; κ₀ = s_b²/s_w² (m ~ N(a₀, κ₀V): the spread of people's means over one person's looks; at least 1), s_w² the pooled within-person variance per dimension, s_b² the variance of the people's means less their looks' noise; C₀ = c·I with c such that a kernel seen once predicts the next look with the spread of the difference of two looks, 2·s_w²; η₀ = 9 as printed. The nearest-neighbour threshold is the one of 0.01..2.00 with the fewest mis-identified observations on the training sessions."),
    );
    Ok(())
}

//! The learned leg detectors' products: the `leg_classifier` table (cross-validated
//! precision / recall / F1 per training source and fold, training sizes, the chosen
//! threshold) and the `leg_features_<feature>` figures (real vs synthetic leg clusters, each
//! feature's distribution at equal range).
//!
//! **Equal range**: the leg samples of both sources within [`RANGE_BINS_M`] are binned by
//! range (0.5 m bins); each synthetic sample is weighted by (real share of its bin) /
//! (synthetic share of its bin), so the synthetic histogram has the real range distribution.
//! Bins one source lacks are left out of both.

use std::sync::Arc;

use super::learned::{self, LegModel, Source, Unavailable};
use super::methods::Method;
use super::params::Params;
use crate::laser::training::{Sample, sample_feature_names};
use crate::report::Table;
use crate::report::figure::{Figure, FigureKind, LinePlot, Series};
use crate::report::rows::Rows;
use crate::run::Products;
use crate::table_row;

/// Range interval (m) of the feature comparison, in 0.5 m bins.
pub const RANGE_BINS_M: (f64, f64) = (0.5, 5.0);

/// A figure feature's axis label with its unit.
fn axis_label(feature: &str) -> String {
    let unit = match feature {
        "points" => "returns",
        "width" | "std_dev" | "radius" => "m",
        "circularity" => "m²",
        "mean_curvature" => "1/m",
        _ => "",
    };
    if unit.is_empty() {
        feature.to_string()
    } else {
        format!("{feature} ({unit})")
    }
}

/// The features compared in figures.
pub const FIGURE_FEATURES: [&str; 6] = [
    "points",
    "width",
    "std_dev",
    "radius",
    "circularity",
    "mean_curvature",
];

table_row! {
    /// One training source × fold: `leg_classifier`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct ClassifierRow {
        pub source: String,
        /// `fold k`, `pooled`, or `SKIPPED: why`.
        pub fold: String,
        pub test_groups: String,
        pub test_legs: i64,
        pub test_non_legs: i64,
        pub precision: Option<f64>,
        pub recall: Option<f64>,
        pub f1: Option<f64>,
        pub threshold: Option<f64>,
        pub training_legs: i64,
        pub training_non_legs: i64,
        pub unmatched_labels: i64,
    }
}

fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

/// Why `method` has no results: its training data is absent.
pub fn skip_reason(method: Method, p: &Params) -> Option<String> {
    learned::absent(method.source()?, p.learned_for(method))
}

fn rows(source: &str, m: &Result<Arc<LegModel>, Unavailable>) -> Vec<ClassifierRow> {
    let blank = |fold: String| ClassifierRow {
        source: source.into(),
        fold,
        test_groups: String::new(),
        test_legs: 0,
        test_non_legs: 0,
        precision: None,
        recall: None,
        f1: None,
        threshold: None,
        training_legs: 0,
        training_non_legs: 0,
        unmatched_labels: 0,
    };
    match m {
        Err(Unavailable::Absent(why)) => vec![blank(format!("SKIPPED: {why}"))],
        Err(Unavailable::Failed(why)) => vec![blank(format!("FAILED: {why}"))],
        Ok(m) => {
            m.cv.iter()
                .map(|f| ClassifierRow {
                    test_groups: f.groups.join(" "),
                    test_legs: f.positives as i64,
                    test_non_legs: f.negatives as i64,
                    precision: finite(f.precision),
                    recall: finite(f.recall),
                    f1: finite(f.f1),
                    threshold: Some(m.threshold),
                    training_legs: m.positives as i64,
                    training_non_legs: m.negatives as i64,
                    unmatched_labels: m.unmatched_labels as i64,
                    ..blank(f.fold.clone())
                })
                .collect()
        }
    }
}

fn bin(range_m: f64) -> Option<usize> {
    let (lo, hi) = RANGE_BINS_M;
    (range_m >= lo && range_m < hi).then(|| ((range_m - lo) / 0.5) as usize)
}

/// `(value, weight)` pairs.
type Weighted = Vec<(f64, f64)>;

/// `(value, weight)` of feature `k` of the real and the synthetic samples of class `leg`
/// (legs, or clutter), at equal range.
fn matched(real: &[Sample], syn: &[Sample], k: usize, leg: bool) -> (Weighted, Weighted) {
    let nbins = bin(RANGE_BINS_M.1 - 1e-9).unwrap_or(0) + 1;
    let count = |s: &[Sample]| {
        let mut c = vec![0usize; nbins];
        for x in s.iter().filter(|x| x.leg == leg) {
            if let Some(b) = bin(x.range_m) {
                c[b] += 1;
            }
        }
        c
    };
    let (cr, cs) = (count(real), count(syn));
    let both: Vec<bool> = cr.iter().zip(&cs).map(|(a, b)| *a > 0 && *b > 0).collect();
    let nr: usize = cr
        .iter()
        .zip(&both)
        .filter(|(_, b)| **b)
        .map(|(c, _)| c)
        .sum();
    let ns: usize = cs
        .iter()
        .zip(&both)
        .filter(|(_, b)| **b)
        .map(|(c, _)| c)
        .sum();
    let pick = |s: &[Sample], w: &dyn Fn(usize) -> f64| -> Vec<(f64, f64)> {
        s.iter()
            .filter(|x| x.leg == leg)
            .filter_map(|x| {
                let b = bin(x.range_m)?;
                both[b].then(|| (x.features[k], w(b)))
            })
            .collect()
    };
    let real_w = pick(real, &|_| 1.0);
    let syn_w = pick(syn, &|b| {
        (cr[b] as f64 / nr.max(1) as f64) / (cs[b] as f64 / ns.max(1) as f64)
    });
    (real_w, syn_w)
}

/// A density histogram as a step line over `edges`.
fn histogram(v: &[(f64, f64)], edges: &[f64]) -> Vec<(f64, f64)> {
    let total: f64 = v.iter().map(|x| x.1).sum();
    let width = edges[1] - edges[0];
    let mut out = Vec::new();
    for w in edges.windows(2) {
        let mass: f64 = v
            .iter()
            .filter(|x| x.0 >= w[0] && x.0 < w[1])
            .map(|x| x.1)
            .sum();
        let d = if total > 0.0 {
            mass / total / width
        } else {
            0.0
        };
        out.push((w[0], d));
        out.push((w[1], d));
    }
    out
}

fn quantile(mut v: Vec<f64>, q: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(((v.len() as f64 - 1.0) * q).round() as usize)
        .copied()
        .unwrap_or(0.0)
}

/// One figure per feature of `wanted`: real vs synthetic samples of class `leg` at equal
/// range, named `<prefix>_<feature>`.
fn figures(
    real: &[Sample],
    syn: &[Sample],
    names: &[&str],
    wanted: &[&str],
    leg: bool,
    prefix: &str,
) -> Vec<Figure> {
    let what = if leg {
        "Leg clusters"
    } else {
        "Clutter (non-leg segments)"
    };
    wanted
        .iter()
        .filter_map(|f| names.iter().position(|n| n == f).map(|k| (f, k)))
        .filter_map(|(f, k)| {
            let (r, s) = matched(real, syn, k, leg);
            if r.is_empty() || s.is_empty() {
                return None;
            }
            let all: Vec<f64> = r.iter().chain(&s).map(|x| x.0).collect();
            let (lo, hi) = (quantile(all.clone(), 0.0), quantile(all, 0.98));
            let hi = if hi > lo { hi } else { lo + 1.0 };
            let edges: Vec<f64> = (0..=30)
                .map(|i| lo + (hi - lo) * f64::from(i) / 30.0)
                .collect();
            Some(Figure::new(
                format!("{prefix}_{f}"),
                format!(
                    "{what}, {f}: real vs synthetic at equal range ({}–{} m)",
                    RANGE_BINS_M.0, RANGE_BINS_M.1
                ),
                FigureKind::Lines(LinePlot {
                    x_label: axis_label(f),
                    y_label: "density".into(),
                    series: vec![
                        Series::line(
                            format!("real (leg_tracker CSVs, n = {})", r.len()),
                            histogram(&r, &edges),
                            0,
                        ),
                        Series::line(
                            format!("synthetic (range-weighted, n = {})", s.len()),
                            histogram(&s, &edges),
                            1,
                        ),
                    ],
                    x_range: Some((lo, hi)),
                    ..LinePlot::default()
                }),
            ))
        })
        .collect()
}

/// leg_tracker features compared in the `lt_*` figures (legs and clutter).
pub const LT_FIGURE_FEATURES: [&str; 5] =
    ["points", "width", "std_dev", "linearity", "circularity"];

/// The table and figures, when a learned method is listed: the `[params.learned]` models
/// (source `real` / `synthetic`, figures `leg_features_*`) and, when a free-space learned
/// method is listed, the `[params.learned_free_space]` ones (source `real_lt` /
/// `synthetic_lt`, figures `lt_legs_*` and `lt_clutter_*`).
pub fn products(p: &Params, out: &mut Products) -> anyhow::Result<()> {
    let learned_methods: Vec<&Method> = p.methods.iter().filter(|m| m.source().is_some()).collect();
    if learned_methods.is_empty() {
        return Ok(());
    }
    let (st, gt) = (&p.synthetic.scan_topic, &p.synthetic.gt_topic);
    let train = |lp: &learned::LearnedParams| -> Vec<(Source, _)> {
        [Source::Real, Source::Synthetic]
            .into_iter()
            .map(|s| (s, learned::model(s, lp, st, gt)))
            .collect()
    };
    let mut rows_out = Vec::new();
    let old = learned_methods.iter().any(|m| !m.free_space());
    let new = learned_methods.iter().any(|m| m.free_space());
    if old {
        let models = train(&p.learned);
        rows_out.extend(models.iter().flat_map(|(s, m)| rows(s.name(), m)));
        if let (Ok(r), Ok(s)) = (&models[0].1, &models[1].1) {
            let names = sample_feature_names();
            out.figures.extend(figures(
                &r.samples,
                &s.samples,
                &names,
                &FIGURE_FEATURES,
                true,
                "leg_features",
            ));
        }
    }
    if new {
        let models = train(&p.learned_free_space);
        rows_out.extend(
            models
                .iter()
                .flat_map(|(s, m)| rows(&format!("{}_lt", s.name()), m)),
        );
        if let (Ok(r), Ok(s)) = (&models[0].1, &models[1].1) {
            let names = p.learned_free_space.feature_set.names();
            for (leg, prefix) in [(true, "lt_legs"), (false, "lt_clutter")] {
                out.figures.extend(figures(
                    &r.samples,
                    &s.samples,
                    &names,
                    &LT_FIGURE_FEATURES,
                    leg,
                    prefix,
                ));
            }
        }
    }
    let mut t = Table::new(
        "leg_classifier",
        "Learned leg detectors: cross-validated precision / recall / F1 (folds grouped by file)",
        ClassifierRow::frame(&rows_out)?,
    );
    for c in ["precision", "recall", "f1", "threshold"] {
        t = t.with_precision(c, 3);
    }
    let (a, b) = (&p.learned, &p.learned_free_space);
    out.tables.push(t.with_note(format!(
        "Random forest (smartcore; {} trees, depth ≤ 20, 2 features per split, seed {}). Sources real / synthetic: 12 segment features (src/laser/features + range) ([params.learned]); real_lt / synthetic_lt: leg_tracker's 17 cluster features ([params.learned_free_space]). Real: leg_tracker's training CSVs, positives = segments nearest a label within 0.1 m, negatives = every {}-th ({} for *_lt) segment of the people-free scans; synthetic: every {}-th scan of the synthetic logs ({} for *_lt: {}), legs within leg radius + 0.1 m, non-legs farther than 0.5 m from every leg within {} m (every {}-th kept). Threshold: best pooled out-of-fold F1, where each kept negative counts as the segments it stands for (precision estimated for whole scans, not the thinned sample). Test groups never appear in their fold's training.",
        a.n_trees, a.seed, a.negative_keep_every, b.negative_keep_every, a.synthetic_scan_every, b.synthetic_scan_every, b.synthetic_sessions.join(", "), a.max_range_m, a.synthetic_negative_keep_every
    )));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn leg(range_m: f64, v: f64) -> Sample {
        Sample {
            group: String::new(),
            scan_idx: 0,
            features: vec![v],
            range_m,
            leg: true,
        }
    }

    /// Synthetic legs weighted to the real range distribution: real has 1 sample in bin
    /// 1.0–1.5 m and 3 in 2.0–2.5 m; synthetic 2 and 2; a bin only one side has is dropped.
    #[test]
    fn synthetic_weights_follow_the_real_range_distribution() {
        let real = vec![
            leg(1.2, 1.0),
            leg(2.1, 2.0),
            leg(2.2, 2.0),
            leg(2.3, 2.0),
            leg(3.3, 9.0),
        ];
        let syn = vec![leg(1.1, 5.0), leg(1.4, 5.0), leg(2.0, 6.0), leg(2.4, 6.0)];
        let (r, s) = matched(&real, &syn, 0, true);
        assert_eq!(r.len(), 4);
        let w: Vec<(f64, f64)> = s;
        // bin 1.0-1.5: (1/4)/(2/4) = 0.5; bin 2.0-2.5: (3/4)/(2/4) = 1.5
        assert_eq!(w, vec![(5.0, 0.5), (5.0, 0.5), (6.0, 1.5), (6.0, 1.5)]);
        let h = histogram(&r, &[0.0, 1.5, 3.0]);
        // real values 1, 2, 2, 2: a quarter of the mass in [0, 1.5), three quarters in [1.5, 3)
        assert_eq!(
            h,
            vec![
                (0.0, 0.25 / 1.5),
                (1.5, 0.25 / 1.5),
                (1.5, 0.75 / 1.5),
                (3.0, 0.75 / 1.5)
            ]
        );
    }
}

//! ROC of background subtraction (paper fig. 1), the aggregation: the `roc` and
//! `roc_summary` tables, a summary line per scene and one ROC figure per scene, over every
//! ROC model of `roc::variants` (the adaptive GMM, the fixed-M baseline, the
//! `[[params.roc.extra]]` variants).

use std::collections::BTreeMap;

use polars::prelude::*;

use super::components::ComponentsSample;
use super::params::{Params, RocParams};
use super::roc::{
    COMPONENTS_TABLE, COUNTS_TABLE, DEFAULT_C_THR, PEOPLE_TABLE, PeopleCounts, RocCounts,
    STANDING_SPEED_MPS, Variant, VariantComponents, add_counts, variants,
};
use super::shared::by_dataset;
use crate::names::sanitize;
use crate::report::figure::{FigureKind, LinePlot, Mark, Series};
use crate::report::rows::Rows;
use crate::report::{Figure, Table};
use crate::run::{Aggregate, Products, SessionTables};
use crate::table_row;
use crate::vision::score::MaskCounts;

table_row! {
    /// A row of the `roc` table.
    #[derive(Debug, Clone, PartialEq)]
    struct RocRow {
        dataset: String,
        model: String,
        c_thr: f64,
        tp_pct: f64,
        fp_pct: f64,
        f_measure: f64,
        frames: i64,
    }
}

table_row! {
    /// A row of the `roc_summary` table (the extra variants' columns are added after).
    #[derive(Debug, Clone, PartialEq)]
    struct SummaryRow {
        dataset: String,
        measure: String,
        adaptive: Option<f64>,
        fixed_m4: Option<f64>,
    }
}

/// One point of a ROC curve.
#[derive(Debug, Clone, Copy)]
struct RocPoint {
    var_threshold: f64,
    tp_pct: f64,
    fp_pct: f64,
    f_measure: f64,
}

impl RocPoint {
    fn of(var_threshold: f64, c: &MaskCounts) -> Self {
        Self {
            var_threshold,
            tp_pct: 100.0 * ratio(c.true_positive, c.true_positive + c.false_negative),
            fp_pct: 100.0 * ratio(c.false_positive, c.false_positive + c.true_negative),
            f_measure: c.f_measure(),
        }
    }
}

/// TP % at a given FP % by linear interpolation along the curve (sorted by FP); `None`
/// outside the range the curve covers.
fn tp_at_fp(curve: &[RocPoint], fp: f64) -> Option<f64> {
    let mut pts: Vec<(f64, f64)> = curve.iter().map(|c| (c.fp_pct, c.tp_pct)).collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    for w in pts.windows(2) {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        if fp >= x0 && fp <= x1 {
            if x1 == x0 {
                return Some(y0.max(y1));
            }
            return Some(y0 + (y1 - y0) * (fp - x0) / (x1 - x0));
        }
    }
    None
}

fn ratio(a: u64, b: u64) -> f64 {
    if b == 0 {
        f64::NAN
    } else {
        a as f64 / b as f64
    }
}

fn fmt_opt(v: Option<f64>, d: usize) -> String {
    v.map_or("—".to_string(), |x| format!("{x:.d$} %"))
}

/// The counts of a dataset's sessions summed per (model, c_thr): one curve per model of
/// `labels` (in that order) with the frames scored per point, sorted by c_thr.
type Curves = Vec<Vec<(RocPoint, i64)>>;

fn dataset_curves(sessions: &[&SessionTables], labels: &[&str]) -> anyhow::Result<Option<Curves>> {
    let mut sums: BTreeMap<(String, u64), (MaskCounts, i64, f64)> = BTreeMap::new();
    for f in sessions {
        let Some(roc) = f.get(COUNTS_TABLE) else {
            continue;
        };
        for r in RocCounts::read(roc)? {
            let e = sums
                .entry((r.model.clone(), r.var_threshold.to_bits()))
                .or_insert((MaskCounts::default(), 0, r.var_threshold));
            add_counts(
                &mut e.0,
                &MaskCounts {
                    true_positive: r.true_positive as u64,
                    false_positive: r.false_positive as u64,
                    false_negative: r.false_negative as u64,
                    true_negative: r.true_negative as u64,
                },
            );
            e.1 += r.frames;
        }
    }
    if sums.is_empty() {
        return Ok(None);
    }
    let curves = labels
        .iter()
        .map(|name| {
            let mut pts: Vec<(RocPoint, i64)> = sums
                .iter()
                .filter(|((m, _), _)| m == name)
                .map(|(_, (c, n, thr))| (RocPoint::of(*thr, c), *n))
                .collect();
            pts.sort_by(|a, b| a.0.var_threshold.total_cmp(&b.0.var_threshold));
            pts
        })
        .collect();
    Ok(Some(curves))
}

/// The `roc` and `roc_summary` tables, a summary line per scene and the ROC figures.
pub(super) fn products(ctx: &Aggregate, p: &Params, products: &mut Products) -> anyhow::Result<()> {
    let vs = variants(&p.roc);
    let labels: Vec<&str> = vs.iter().map(|v| v.label).collect();
    let mut rows = Vec::new();
    let mut curves: Vec<(String, Vec<Vec<RocPoint>>)> = Vec::new();
    let mut people: Vec<(String, [PeopleCounts; 2])> = Vec::new();
    for (dataset, sessions) in by_dataset(ctx) {
        let Some(c) = dataset_curves(&sessions, &labels)? else {
            continue;
        };
        for (k, curve) in c.iter().enumerate() {
            for (pt, n) in curve {
                rows.push(RocRow {
                    dataset: dataset.clone(),
                    model: labels[k].to_string(),
                    c_thr: pt.var_threshold,
                    tp_pct: pt.tp_pct,
                    fp_pct: pt.fp_pct,
                    f_measure: pt.f_measure,
                    frames: *n,
                });
            }
        }
        people.push((dataset.clone(), people_counts(&sessions)?));
        let points = c
            .into_iter()
            .map(|v| v.into_iter().map(|(pt, _)| pt).collect())
            .collect();
        curves.push((dataset, points));
    }
    if curves.is_empty() {
        products
            .summary
            .push("ROC: no session has exact masks; nothing to score.".into());
        return Ok(());
    }
    products.tables.push(roc_table(&rows, &p.roc)?);
    let summary = summary_table(ctx, p, &vs, &curves, &people, products)?;
    products.tables.push(summary);
    for (dataset, curve) in &curves {
        products.figures.push(roc_figure(dataset, &labels, curve));
    }
    Ok(())
}

fn roc_table(rows: &[RocRow], p: &RocParams) -> anyhow::Result<Table> {
    let mut table = Table::new(
        "roc",
        "ROC of background subtraction: adaptive GMM vs fixed M = 4, per scene and c_thr (paper fig. 1)",
        RocRow::frame(rows)?,
    )
    .with_precision("c_thr", 0)
    .with_precision("tp_pct", 2)
    .with_precision("fp_pct", 3)
    .with_precision("f_measure", 3)
    .with_note(format!(
        "TP % = person pixels called foreground / person pixels; FP % = other pixels called foreground / other pixels, against the exact person masks, summed over all frames after the first {} of each session. Shadow pixels (127) count as background. c_thr is OpenCV's varThreshold (squared Mahalanobis distance; default 16). Everything else at OpenCV MOG2's defaults; the baseline has M = 4 and c_T = 0.",
        p.skip_frames
    ))
    .with_note("Paper (Zivkovic 2004, fig. 1 and text): a ROC curve is shown for the 'lab' sequence only, with 'slight improvement in segmentation results' for the adaptive model and the same for the other two scenes; no numbers are given in the text.")
    .with_note("Moving scene parts that are not people (cars in 'street', the monitor and plant in 'lab') are background in the masks: detecting them is a false positive.");
    if !p.extra.is_empty() {
        table = table.with_note(variants_note());
    }
    Ok(table)
}

/// What the rows beyond the two models are, and why the ROC axis is a Mahalanobis threshold.
fn variants_note() -> String {
    "More rows ([[params.roc.extra]]): 'adaptive GMM as printed' is Zivkovic's model with the paper's c_T = 0.01 and its pruning rule (a component is dropped when its weight after eq. 14 becomes negative, then the weights are renormalised) instead of OpenCV's c_T = 0.05 and drop below αc_T; T = 500, M = 5 (OpenCV's; the paper states no maximum), shadows as OpenCV. 'Stauffer-Grimson 1999 as published' is the original (CVPR 1999): K = 4, match within 2.5σ, ω ← (1 − α)ω + αM with constant α = 1/500, ρ = α η(x | µ, σ) for the matched component, ranking by ω/σ, background = the first B with Σω > T = 0.9, no match → the least probable component replaced (σ₀² = 900, weight 0.05: OpenCV's legacy MOG), no shadow detection; the values it leaves open are listed in vision::sg1999. Every model is swept over the same c_thr: the paper's eq. 2 thresholds the density, but for one isotropic Gaussian that is a threshold on the squared Mahalanobis distance, which is what OpenCV's varThreshold is; for Stauffer-Grimson a pixel is background at c_thr when its squared distance to one of the first B components is below c_thr (6.25 = its own 2.5σ match), its update always matching at 2.5σ.".into()
}

/// The `roc_summary` table: the summary rows, one column per extra variant.
fn summary_table(
    ctx: &Aggregate,
    p: &Params,
    vs: &[Variant<'_>],
    curves: &[(String, Vec<Vec<RocPoint>>)],
    people: &[(String, [PeopleCounts; 2])],
    products: &mut Products,
) -> anyhow::Result<Table> {
    let (summary, extra) = summary_rows(ctx, p, vs, curves, products)?;
    let mut df = SummaryRow::frame(&summary)?;
    for (v, values) in vs.iter().skip(2).zip(extra) {
        df.with_column(Column::new(v.name.into(), values))?;
    }
    let mut table = Table::new(
        "roc_summary",
        "Background subtraction summary per scene: true positives at fixed false positives, the default threshold, components per pixel",
        df,
    )
    .with_precision("adaptive", 3)
    .with_precision("fixed_m4", 3);
    for v in vs.iter().skip(2) {
        table = table.with_precision(v.name, 3);
    }
    let mut table = table
        .with_note("TP at a fixed FP is read off each ROC curve by linear interpolation between swept thresholds; — where the curve does not reach that FP.")
        .with_note("Paper: 'slight improvement in segmentation results' and fewer components where the scene is static (fig. 2); no numbers in the text.")
        .with_note(standing_note(people));
    if vs.len() > 2 {
        let cols: Vec<String> = vs
            .iter()
            .skip(2)
            .map(|v| format!("{} = {}", v.name, v.label))
            .collect();
        table = table.with_note(format!(
            "Columns adaptive = {}, fixed_m4 = {} (OpenCV MOG2's update with M = 4, c_T = 0), {}. Components per pixel: the two first from every frame of the timing run, the others from the frames with masks of the ROC run.",
            vs[0].label,
            vs[1].label,
            cols.join(", ")
        ));
    }
    Ok(table)
}

/// Per extra variant, its `roc_summary` column.
type ExtraColumns = Vec<Vec<Option<f64>>>;

/// The summary rows per scene (and its summary lines): the two models' rows and, per extra
/// variant, its column.
fn summary_rows(
    ctx: &Aggregate,
    p: &Params,
    vs: &[Variant<'_>],
    curves: &[(String, Vec<Vec<RocPoint>>)],
    products: &mut Products,
) -> anyhow::Result<(Vec<SummaryRow>, ExtraColumns)> {
    let mut rows = Vec::new();
    let mut extra: Vec<Vec<Option<f64>>> = vec![Vec::new(); vs.len().saturating_sub(2)];
    for (dataset, curve) in curves {
        let mut push = |measure: String, values: Vec<Option<f64>>| {
            rows.push(SummaryRow {
                dataset: dataset.clone(),
                measure,
                adaptive: values[0],
                fixed_m4: values[1],
            });
            for (col, v) in extra.iter_mut().zip(&values[2..]) {
                col.push(*v);
            }
        };
        for &fp in &p.roc.fp_at_pct {
            let v = curve.iter().map(|c| tp_at_fp(c, fp)).collect();
            push(format!("TP % at FP = {fp} %"), v);
        }
        let at16 = |c: &[RocPoint]| c.iter().find(|x| x.var_threshold == DEFAULT_C_THR).copied();
        let at: Vec<Option<RocPoint>> = curve.iter().map(|c| at16(c)).collect();
        for (what, get) in [
            (
                "TP % at c_thr = 16",
                (|x: RocPoint| x.tp_pct) as fn(RocPoint) -> f64,
            ),
            ("FP % at c_thr = 16", |x: RocPoint| x.fp_pct),
            ("F-measure at c_thr = 16", |x: RocPoint| x.f_measure),
        ] {
            push(what.to_string(), at.iter().map(|x| x.map(get)).collect());
        }
        push(
            "components per pixel (mean over frames and pixels)".into(),
            components_per_pixel(ctx, dataset, vs)?,
        );
        let (a, b) = (at[0], at[1]);
        products.summary.push(format!(
            "{dataset}: TP at FP = 1 %: adaptive {} vs fixed-M {}; at c_thr = 16 adaptive TP {:.1} % / FP {:.2} %, fixed-M TP {:.1} % / FP {:.2} %.",
            fmt_opt(tp_at_fp(&curve[0], 1.0), 1),
            fmt_opt(tp_at_fp(&curve[1], 1.0), 1),
            a.map_or(f64::NAN, |x| x.tp_pct),
            a.map_or(f64::NAN, |x| x.fp_pct),
            b.map_or(f64::NAN, |x| x.tp_pct),
            b.map_or(f64::NAN, |x| x.fp_pct),
        ));
        if vs.len() > 2 {
            let more: Vec<String> = vs
                .iter()
                .zip(curve)
                .skip(2)
                .map(|(v, c)| format!("{} {}", v.name, fmt_opt(tp_at_fp(c, 1.0), 1)))
                .collect();
            products.summary.push(format!(
                "{dataset}: TP at FP = 1 % of the printed variants: {}.",
                more.join(", ")
            ));
        }
    }
    Ok((rows, extra))
}

/// Mean components per pixel of every variant over a dataset's sessions: the two timed
/// models from the `components` samples, the extra variants from `roc_components`.
fn components_per_pixel(
    ctx: &Aggregate,
    dataset: &str,
    vs: &[Variant<'_>],
) -> anyhow::Result<Vec<Option<f64>>> {
    let mut comp = [Vec::new(), Vec::new()];
    let mut extra = vec![(0.0, 0i64); vs.len().saturating_sub(2)];
    for (info, tables) in ctx.sessions {
        if info.dataset != dataset {
            continue;
        }
        for s in ComponentsSample::of_session(tables)? {
            comp[0].push(s.adaptive_mean_components);
            comp[1].push(s.baseline_mean_components);
        }
        if let Some(t) = tables.get(COMPONENTS_TABLE) {
            for r in VariantComponents::read(t)? {
                if let Some(k) = vs.iter().skip(2).position(|v| v.label == r.model) {
                    extra[k].0 += r.mean_components_sum;
                    extra[k].1 += r.frames;
                }
            }
        }
    }
    let mean = |v: &[f64]| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
    let mut out = vec![mean(&comp[0]), mean(&comp[1])];
    out.extend(
        extra
            .iter()
            .map(|&(sum, n)| (n > 0).then(|| sum / n as f64)),
    );
    Ok(out)
}

/// A dataset's standing/walking counts summed over its sessions: `[walking, standing]`.
fn people_counts(sessions: &[&SessionTables]) -> anyhow::Result<[PeopleCounts; 2]> {
    let mut sum = [false, true].map(|standing| PeopleCounts {
        standing,
        ..Default::default()
    });
    for f in sessions {
        let Some(t) = f.get(PEOPLE_TABLE) else {
            continue;
        };
        for r in PeopleCounts::read(t)? {
            let s = &mut sum[usize::from(r.standing)];
            s.views += r.views;
            s.person_px += r.person_px;
            s.foreground_px += r.foreground_px;
            s.shadow_px += r.shadow_px;
        }
    }
    Ok(sum)
}

/// The note on the TP ceiling of scenes where people stand, with the shares measured in the
/// scenes that have standing people.
fn standing_note(people: &[(String, [PeopleCounts; 2])]) -> String {
    let pct = |a: i64, b: i64, d: usize| {
        if b > 0 {
            format!("{:.d$} %", 100.0 * a as f64 / b as f64)
        } else {
            "—".to_string()
        }
    };
    let measured: Vec<String> = people
        .iter()
        .filter(|(_, [_, standing])| standing.person_px > 0)
        .map(|(dataset, [walking, standing])| {
            let shadow = walking.shadow_px + standing.shadow_px;
            let all = walking.person_px + standing.person_px;
            format!(
                "{dataset}: {} of standing people's pixels are foreground against {} of walking people's, shadow labels {}",
                pct(standing.foreground_px, standing.person_px, 0),
                pct(walking.foreground_px, walking.person_px, 0),
                pct(shadow, all, 1)
            )
        })
        .collect();
    let tail = if measured.is_empty() {
        "no scene scored here has a standing person".to_string()
    } else {
        format!(
            "measured with the adaptive model at c_thr = 16 over the scored frames, person pixels = exact mask inside the person's box, standing = ground-truth speed below {STANDING_SPEED_MPS} m/s: {}",
            measured.join("; ")
        )
    };
    format!(
        "The exact masks mark every person, also one standing still, while both models absorb a still object into the background after log(1 − c_f)/log(1 − α) frames, as designed: a scene where people stand keeps a TP ceiling that no c_thr lifts ({tail})."
    )
}

fn roc_figure(dataset: &str, labels: &[&str], curve: &[Vec<RocPoint>]) -> Figure {
    let series = curve
        .iter()
        .zip(labels)
        .enumerate()
        .map(|(k, (c, label))| {
            let mut pts: Vec<(f64, f64)> = c.iter().map(|c| (c.fp_pct, c.tp_pct)).collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
            Series::line(*label, pts, k + 1).with_mark(Mark::LinePoints)
        })
        .collect();
    let fp_max = curve.iter().flatten().map(|c| c.fp_pct).fold(0.0, f64::max);
    Figure::new(
        format!("roc_{}", sanitize(dataset)),
        format!("ROC, {dataset}: adaptive vs fixed-M GMM (c_thr swept)"),
        FigureKind::Lines(LinePlot {
            x_label: "false positives (% of background pixels)".into(),
            y_label: "true positives (% of person pixels)".into(),
            series,
            x_range: Some((0.0, (fp_max * 1.05).max(0.1))),
            y_range: Some((0.0, 100.0)),
            ..Default::default()
        }),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipelines::s003_zivkovic_background::params::model_name;

    fn point(fp_pct: f64, tp_pct: f64) -> RocPoint {
        RocPoint {
            var_threshold: 0.0,
            tp_pct,
            fp_pct,
            f_measure: 0.0,
        }
    }

    #[test]
    fn tp_at_fp_interpolates_between_the_swept_points() {
        // unsorted on purpose: the curve is sorted by FP first
        let curve = [point(4.0, 90.0), point(0.0, 50.0), point(2.0, 80.0)];
        assert_eq!(tp_at_fp(&curve, 1.0), Some(65.0));
        assert_eq!(tp_at_fp(&curve, 3.0), Some(85.0));
        assert_eq!(tp_at_fp(&curve, 2.0), Some(80.0));
        assert_eq!(tp_at_fp(&curve, 5.0), None);
        // a vertical step: the higher TP
        let step = [point(1.0, 40.0), point(1.0, 70.0)];
        assert_eq!(tp_at_fp(&step, 1.0), Some(70.0));
    }

    #[test]
    fn roc_points_and_session_counts_sum_per_model_and_threshold() {
        let counts = |model: &str, thr: f64, tp: i64, fp: i64, fne: i64, tn: i64| RocCounts {
            model: model.to_string(),
            var_threshold: thr,
            true_positive: tp,
            false_positive: fp,
            false_negative: fne,
            true_negative: tn,
            frames: 10,
        };
        let session = |rows: &[RocCounts]| {
            let mut t = SessionTables::new();
            t.insert(COUNTS_TABLE.into(), RocCounts::frame(rows).expect("frame"));
            t
        };
        let (a_name, b_name) = (model_name(true), model_name(false));
        let a = session(&[
            counts(a_name, 16.0, 30, 10, 10, 950),
            counts(b_name, 16.0, 5, 0, 35, 960),
            counts("extra", 16.0, 1, 0, 39, 960),
        ]);
        let b = session(&[
            counts(a_name, 16.0, 50, 10, 10, 930),
            counts(b_name, 16.0, 15, 0, 25, 960),
            counts("extra", 16.0, 3, 0, 37, 960),
        ]);
        let labels = [a_name, b_name, "extra", "absent"];
        let c = dataset_curves(&[&a, &b], &labels)
            .expect("reads")
            .expect("has counts");
        let (adaptive, n) = c[0][0];
        assert_eq!(n, 20);
        // 80 of 100 person pixels, 20 of 1900 other pixels
        assert!((adaptive.tp_pct - 80.0).abs() < 1e-12);
        assert!((adaptive.fp_pct - 100.0 * 20.0 / 1900.0).abs() < 1e-12);
        assert!((adaptive.f_measure - 160.0 / 200.0).abs() < 1e-12);
        // the baseline: 20 of 80 person pixels; the extra model 4 of 80; no rows: no curve
        assert!((c[1][0].0.tp_pct - 25.0).abs() < 1e-12);
        assert!((c[2][0].0.tp_pct - 5.0).abs() < 1e-12);
        assert!(c[3].is_empty());
        assert!(
            dataset_curves(&[&SessionTables::new()], &labels)
                .expect("reads")
                .is_none()
        );
    }

    #[test]
    fn the_standing_note_states_the_measured_shares() {
        let counts = |standing, person_px, foreground_px, shadow_px| PeopleCounts {
            standing,
            views: 1,
            person_px,
            foreground_px,
            shadow_px,
        };
        let note = standing_note(&[
            (
                "lab".into(),
                [counts(false, 100, 73, 1), counts(true, 100, 25, 0)],
            ),
            (
                "hall".into(),
                [counts(false, 10, 9, 0), counts(true, 0, 0, 0)],
            ),
        ]);
        assert!(
            note.contains("lab: 25 % of standing people's pixels are foreground against 73 % of walking people's, shadow labels 0.5 %"),
            "{note}"
        );
        assert!(!note.contains("hall"), "{note}");
        assert!(standing_note(&[]).contains("no scene scored here has a standing person"));
    }
}

//! ROC of background subtraction (paper fig. 1): the adaptive GMM and the fixed-M baseline at
//! every swept c_thr, scored against the exact person masks; per session the mask counts, and
//! the pixels of standing vs walking people that the adaptive model at c_thr = 16 calls
//! foreground (the TP ceiling of scenes where people stand). Aggregation: the `roc` and
//! `roc_summary` tables and one ROC figure per scene.

use std::collections::BTreeMap;

use rayon::prelude::*;

use super::components::ComponentsSample;
use super::params::{Params, RocParams, model_name};
use super::shared::{Frame, by_dataset};
use crate::names::sanitize;
use crate::report::figure::{FigureKind, LinePlot, Mark, Series};
use crate::report::rows::Rows;
use crate::report::{Figure, Table};
use crate::run::{Aggregate, Products, SessionTables};
use crate::table_row;
use crate::vision::gmm::FOREGROUND;
use crate::vision::score::{MaskCounts, ShadowAs};
use crate::vision::{AdaptiveGmm, GmmParams};

/// The threshold at which the summary and the standing/walking counts read the models
/// (OpenCV's default varThreshold).
const DEFAULT_C_THR: f64 = 16.0;
/// A ground-truth person slower than this (m/s) is standing.
const STANDING_SPEED_MPS: f64 = 0.05;
/// Cached per-session tables.
const COUNTS_TABLE: &str = "roc";
const PEOPLE_TABLE: &str = "roc_people";

table_row! {
    /// Cached per session: one model at one c_thr, mask counts summed over the scored frames.
    #[derive(Debug, Clone, PartialEq)]
    pub(super) struct RocCounts {
        pub model: String,
        pub var_threshold: f64,
        pub true_positive: i64,
        pub false_positive: i64,
        pub false_negative: i64,
        pub true_negative: i64,
        pub frames: i64,
    }
}

table_row! {
    /// Cached per session: person pixels (exact mask inside a person's box) of standing or
    /// walking people, and how the adaptive model at c_thr = 16 labelled them.
    #[derive(Debug, Clone, Default, PartialEq)]
    pub(super) struct PeopleCounts {
        pub standing: bool,
        pub views: i64,
        pub person_px: i64,
        pub foreground_px: i64,
        pub shadow_px: i64,
    }
}

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
    /// A row of the `roc_summary` table.
    #[derive(Debug, Clone, PartialEq)]
    struct SummaryRow {
        dataset: String,
        measure: String,
        adaptive: Option<f64>,
        fixed_m4: Option<f64>,
    }
}

struct RocModel {
    adaptive: bool,
    var_threshold: f32,
    gmm: AdaptiveGmm,
    mask: Vec<u8>,
    counts: MaskCounts,
    frames: i64,
}

/// The ROC models of one session and their counts.
pub(super) struct RocRun {
    models: Vec<RocModel>,
    skip_frames: usize,
    /// Frames with an exact mask seen (scored or not).
    masked_frames: usize,
    camera: String,
    /// `[walking, standing]`.
    people: [PeopleCounts; 2],
}

impl RocRun {
    /// Both models at every c_thr when `active`; nothing otherwise.
    pub fn new(p: &Params, active: bool) -> anyhow::Result<Self> {
        let mut models = Vec::new();
        if active {
            for adaptive in [true, false] {
                let base = if adaptive {
                    p.roc.adaptive
                } else {
                    p.roc.baseline
                };
                for &v in &p.roc.var_thresholds {
                    models.push(RocModel {
                        adaptive,
                        var_threshold: v,
                        gmm: AdaptiveGmm::new(GmmParams {
                            var_threshold: v,
                            ..base
                        })?,
                        mask: Vec::new(),
                        counts: MaskCounts::default(),
                        frames: 0,
                    });
                }
            }
        }
        let people = [false, true].map(|standing| PeopleCounts {
            standing,
            ..Default::default()
        });
        Ok(Self {
            models,
            skip_frames: p.roc.skip_frames,
            masked_frames: 0,
            camera: p.camera.clone(),
            people,
        })
    }

    /// Update every model with a frame that has an exact mask; count after `skip_frames`.
    pub fn step(&mut self, f: &Frame) -> anyhow::Result<()> {
        let Some(truth) = f.mask else { return Ok(()) };
        if self.models.is_empty() {
            return Ok(());
        }
        let scored = f.index as usize >= self.skip_frames;
        self.masked_frames += 1;
        let npx = truth.len();
        self.models
            .par_iter_mut()
            .try_for_each(|m| -> anyhow::Result<()> {
                m.mask.resize(npx, 0);
                m.gmm.apply(f.view, None, &mut m.mask)?;
                if scored && let Some(c) = MaskCounts::count(&m.mask, truth, ShadowAs::Background) {
                    add_counts(&mut m.counts, &c);
                    m.frames += 1;
                }
                Ok(())
            })?;
        let default = self
            .models
            .iter()
            .find(|m| m.adaptive && f64::from(m.var_threshold) == DEFAULT_C_THR);
        if let (true, Some(m), Some(people)) = (scored, default, f.truth) {
            let shadow = m.gmm.params().shadow_value;
            let width = f.rgb.width() as usize;
            for q in &people.people {
                let standing = q.vx.hypot(q.vy) < STANDING_SPEED_MPS;
                for v in q.cameras.iter().filter(|v| v.camera == self.camera) {
                    if let Some(b) = v.bbox {
                        let c = &mut self.people[usize::from(standing)];
                        c.views += 1;
                        count_person(&m.mask, truth, width, b, shadow, c);
                    }
                }
            }
        }
        Ok(())
    }

    /// The cached `roc` and `roc_people` tables (none when the models did not run).
    pub fn finish(self, out: &mut SessionTables) -> anyhow::Result<()> {
        if self.models.is_empty() {
            return Ok(());
        }
        if self.masked_frames > 0 && self.models.iter().all(|m| m.frames == 0) {
            // every masked frame fell inside the skipped start: the ROC would be 0/0 = NaN
            anyhow::bail!(
                "`params.roc.skip_frames` = {} leaves no frame to score: the session has {} \
                 frames with exact masks, all among its first {} frames",
                self.skip_frames,
                self.masked_frames,
                self.skip_frames
            );
        }
        let rows: Vec<RocCounts> = self
            .models
            .iter()
            .map(|m| RocCounts {
                model: model_name(m.adaptive).to_string(),
                var_threshold: f64::from(m.var_threshold),
                true_positive: m.counts.true_positive as i64,
                false_positive: m.counts.false_positive as i64,
                false_negative: m.counts.false_negative as i64,
                true_negative: m.counts.true_negative as i64,
                frames: m.frames,
            })
            .collect();
        out.insert(COUNTS_TABLE.into(), RocCounts::frame(&rows)?);
        out.insert(PEOPLE_TABLE.into(), PeopleCounts::frame(&self.people)?);
        Ok(())
    }
}

/// Person pixels of the exact mask inside `bbox` (`[x0, y0, x1, y1]` inclusive), and how many
/// of them `predicted` calls foreground or shadow.
fn count_person(
    predicted: &[u8],
    truth: &[u8],
    width: usize,
    bbox: [f64; 4],
    shadow: u8,
    c: &mut PeopleCounts,
) {
    let height = truth.len() / width.max(1);
    if width == 0 || height == 0 {
        return;
    }
    let x0 = bbox[0].max(0.0) as usize;
    let y0 = bbox[1].max(0.0) as usize;
    let x1 = (bbox[2].max(0.0) as usize).min(width - 1);
    let y1 = (bbox[3].max(0.0) as usize).min(height - 1);
    for y in y0..=y1 {
        for x in x0..=x1 {
            let i = y * width + x;
            if truth[i] != FOREGROUND {
                continue;
            }
            c.person_px += 1;
            c.foreground_px += i64::from(predicted[i] == FOREGROUND);
            c.shadow_px += i64::from(predicted[i] == shadow && shadow != FOREGROUND);
        }
    }
}

fn add_counts(a: &mut MaskCounts, b: &MaskCounts) {
    a.true_positive += b.true_positive;
    a.false_positive += b.false_positive;
    a.false_negative += b.false_negative;
    a.true_negative += b.true_negative;
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

/// The counts of a dataset's sessions summed per (model, c_thr): `[adaptive, baseline]`
/// curves with the frames scored per point, sorted by c_thr.
type Curves = [Vec<(RocPoint, i64)>; 2];

fn dataset_curves(sessions: &[&SessionTables]) -> anyhow::Result<Option<Curves>> {
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
    let curves = [true, false].map(|adaptive| {
        let name = model_name(adaptive);
        let mut pts: Vec<(RocPoint, i64)> = sums
            .iter()
            .filter(|((m, _), _)| m == name)
            .map(|(_, (c, n, thr))| (RocPoint::of(*thr, c), *n))
            .collect();
        pts.sort_by(|a, b| a.0.var_threshold.total_cmp(&b.0.var_threshold));
        pts
    });
    Ok(Some(curves))
}

/// The `roc` and `roc_summary` tables, a summary line per scene and the ROC figures.
pub(super) fn products(ctx: &Aggregate, p: &Params, products: &mut Products) -> anyhow::Result<()> {
    let mut rows = Vec::new();
    let mut curves: Vec<(String, [Vec<RocPoint>; 2])> = Vec::new();
    let mut people: Vec<(String, [PeopleCounts; 2])> = Vec::new();
    for (dataset, sessions) in by_dataset(ctx) {
        let Some(c) = dataset_curves(&sessions)? else {
            continue;
        };
        for (k, curve) in c.iter().enumerate() {
            for (pt, n) in curve {
                rows.push(RocRow {
                    dataset: dataset.clone(),
                    model: model_name(k == 0).to_string(),
                    c_thr: pt.var_threshold,
                    tp_pct: pt.tp_pct,
                    fp_pct: pt.fp_pct,
                    f_measure: pt.f_measure,
                    frames: *n,
                });
            }
        }
        people.push((dataset.clone(), people_counts(&sessions)?));
        curves.push((
            dataset,
            c.map(|v| v.into_iter().map(|(pt, _)| pt).collect()),
        ));
    }
    if curves.is_empty() {
        products
            .summary
            .push("ROC: no session has exact masks; nothing to score.".into());
        return Ok(());
    }
    products.tables.push(roc_table(&rows, &p.roc)?);
    let summary = summary_rows(ctx, p, &curves, products)?;
    products.tables.push(
        Table::new(
            "roc_summary",
            "Background subtraction summary per scene: true positives at fixed false positives, the default threshold, components per pixel",
            SummaryRow::frame(&summary)?,
        )
        .with_precision("adaptive", 3)
        .with_precision("fixed_m4", 3)
        .with_note("TP at a fixed FP is read off each ROC curve by linear interpolation between swept thresholds; — where the curve does not reach that FP.")
        .with_note("Paper: 'slight improvement in segmentation results' and fewer components where the scene is static (fig. 2); no numbers in the text.")
        .with_note(standing_note(&people)),
    );
    for (dataset, curve) in &curves {
        products.figures.push(roc_figure(dataset, curve));
    }
    Ok(())
}

fn roc_table(rows: &[RocRow], p: &RocParams) -> anyhow::Result<Table> {
    Ok(Table::new(
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
    .with_note("Moving scene parts that are not people (cars in 'street', the monitor and plant in 'lab') are background in the masks: detecting them is a false positive."))
}

/// The summary rows per scene (and its summary line).
fn summary_rows(
    ctx: &Aggregate,
    p: &Params,
    curves: &[(String, [Vec<RocPoint>; 2])],
    products: &mut Products,
) -> anyhow::Result<Vec<SummaryRow>> {
    let mut rows = Vec::new();
    for (dataset, curve) in curves {
        let mut push = |measure: String, a: Option<f64>, b: Option<f64>| {
            rows.push(SummaryRow {
                dataset: dataset.clone(),
                measure,
                adaptive: a,
                fixed_m4: b,
            })
        };
        for &fp in &p.roc.fp_at_pct {
            push(
                format!("TP % at FP = {fp} %"),
                tp_at_fp(&curve[0], fp),
                tp_at_fp(&curve[1], fp),
            );
        }
        let at16 = |c: &[RocPoint]| c.iter().find(|x| x.var_threshold == DEFAULT_C_THR).copied();
        let (a, b) = (at16(&curve[0]), at16(&curve[1]));
        for (what, get) in [
            (
                "TP % at c_thr = 16",
                (|x: RocPoint| x.tp_pct) as fn(RocPoint) -> f64,
            ),
            ("FP % at c_thr = 16", |x: RocPoint| x.fp_pct),
            ("F-measure at c_thr = 16", |x: RocPoint| x.f_measure),
        ] {
            push(what.to_string(), a.map(get), b.map(get));
        }
        // mean components per pixel over the run
        let mut comp = [Vec::new(), Vec::new()];
        for (info, tables) in ctx.sessions {
            if info.dataset == *dataset {
                for s in ComponentsSample::of_session(tables)? {
                    comp[0].push(s.adaptive_mean_components);
                    comp[1].push(s.baseline_mean_components);
                }
            }
        }
        let mean = |v: &[f64]| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
        push(
            "components per pixel (mean over frames and pixels)".into(),
            mean(&comp[0]),
            mean(&comp[1]),
        );
        products.summary.push(format!(
            "{dataset}: TP at FP = 1 %: adaptive {} vs fixed-M {}; at c_thr = 16 adaptive TP {:.1} % / FP {:.2} %, fixed-M TP {:.1} % / FP {:.2} %.",
            fmt_opt(tp_at_fp(&curve[0], 1.0), 1),
            fmt_opt(tp_at_fp(&curve[1], 1.0), 1),
            a.map_or(f64::NAN, |x| x.tp_pct),
            a.map_or(f64::NAN, |x| x.fp_pct),
            b.map_or(f64::NAN, |x| x.tp_pct),
            b.map_or(f64::NAN, |x| x.fp_pct),
        ));
    }
    Ok(rows)
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

fn roc_figure(dataset: &str, curve: &[Vec<RocPoint>; 2]) -> Figure {
    let series = [0usize, 1]
        .iter()
        .map(|&k| {
            let mut pts: Vec<(f64, f64)> = curve[k].iter().map(|c| (c.fp_pct, c.tp_pct)).collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
            Series::line(model_name(k == 0), pts, k + 1).with_mark(Mark::LinePoints)
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
        let counts = |model: bool, thr: f64, tp: i64, fp: i64, fne: i64, tn: i64| RocCounts {
            model: model_name(model).to_string(),
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
        let a = session(&[
            counts(true, 16.0, 30, 10, 10, 950),
            counts(false, 16.0, 5, 0, 35, 960),
        ]);
        let b = session(&[
            counts(true, 16.0, 50, 10, 10, 930),
            counts(false, 16.0, 15, 0, 25, 960),
        ]);
        let c = dataset_curves(&[&a, &b])
            .expect("reads")
            .expect("has counts");
        let (adaptive, n) = c[0][0];
        assert_eq!(n, 20);
        // 80 of 100 person pixels, 20 of 1900 other pixels
        assert!((adaptive.tp_pct - 80.0).abs() < 1e-12);
        assert!((adaptive.fp_pct - 100.0 * 20.0 / 1900.0).abs() < 1e-12);
        assert!((adaptive.f_measure - 160.0 / 200.0).abs() < 1e-12);
        // the baseline: 20 of 80 person pixels
        assert!((c[1][0].0.tp_pct - 25.0).abs() < 1e-12);
        assert!(
            dataset_curves(&[&SessionTables::new()])
                .expect("reads")
                .is_none()
        );
    }

    #[test]
    fn skip_frames_past_every_masked_frame_is_an_error_naming_it() {
        let p = Params::default();
        // masked frames were seen, none was scored: 0/0 would be a NaN table
        let mut run = RocRun::new(&p, true).expect("models");
        run.masked_frames = 3;
        let err = run
            .finish(&mut SessionTables::new())
            .expect_err("nothing scored")
            .to_string();
        assert!(
            err.starts_with("`params.roc.skip_frames` = 45 leaves no frame to score")
                && err.contains(" 3 frames with exact masks"),
            "{err}"
        );
        // a session without masks has no ROC at all, and is not an error
        let mut out = SessionTables::new();
        RocRun::new(&p, true)
            .expect("models")
            .finish(&mut out)
            .expect("no masks");
        assert!(out.contains_key(COUNTS_TABLE));
    }

    #[test]
    fn person_pixels_are_the_mask_inside_the_box() {
        // 4x3 image; the person is the 2x2 block at x 1..=2, y 0..=1, plus one pixel outside
        // the box that must not count
        let truth = [0, 255, 255, 0, 0, 255, 255, 0, 255, 0, 0, 0];
        let predicted = [0, 255, 127, 255, 0, 0, 255, 0, 255, 0, 0, 0];
        let mut c = PeopleCounts::default();
        count_person(&predicted, &truth, 4, [1.0, 0.0, 2.0, 1.0], 127, &mut c);
        assert_eq!((c.person_px, c.foreground_px, c.shadow_px), (4, 2, 1));
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

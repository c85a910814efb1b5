//! The aggregation, from the cached per-session tables only: CLEAR MOT, IDF1 and HOTA per
//! sequence × detector in the laser frame under each sequence's protocol (scored scans,
//! wedge, range), paired t-tests of the per-scan position errors of every two methods, the
//! sessions' reading statistics, and the tracks as CSV (the figures and the marker export use
//! its rows). A listed real sequence without results gets SKIPPED rows.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::PathBuf;

use super::classifier;
use super::fp_causes::{self, FpCauseRow};
use super::methods::Method;
use super::paper;
use super::params::{Params, Sequence};
use super::tables::{self, ScanRow, SessionRow, TrackRow, TruthRow};
use crate::eval::mot::{EventKind, Geometry, GroundPoint, MatchRule, Observation, evaluate};
use crate::eval::stats::paired_t;
use crate::names::sanitize;
use crate::report::Table;
use crate::report::rows::Rows;
use crate::run::{Aggregate, Products};
use crate::table_row;

table_row! {
    /// One sequence × detector: `results`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct ResultRow {
        pub dataset: String,
        pub sequence: String,
        pub detector: String,
        /// `ok`, or `SKIPPED: why`.
        pub status: String,
        pub scored_scans: Option<i64>,
        pub gt_count: Option<i64>,
        pub mota: Option<f64>,
        pub motp_m: Option<f64>,
        pub idf1: Option<f64>,
        pub hota: Option<f64>,
        pub false_positives: Option<i64>,
        pub misses: Option<i64>,
        pub id_switches: Option<i64>,
    }
}

table_row! {
    /// Paired t-test of the position errors (`method_a` − `method_b`) on the (scan, person)
    /// pairs both methods matched: `paired_ttest`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct TTestRow {
        pub dataset: String,
        pub sequence: String,
        pub method_a: String,
        pub method_b: String,
        pub status: String,
        pub pairs: i64,
        pub mean_a_m: Option<f64>,
        pub mean_b_m: Option<f64>,
        pub mean_diff_m: Option<f64>,
        pub t: Option<f64>,
        pub df: Option<f64>,
        pub p_two_sided: Option<f64>,
        pub ci_low_m: Option<f64>,
        pub ci_high_m: Option<f64>,
    }
}

table_row! {
    /// What each session read: `sessions`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct SessionsRow {
        pub dataset: String,
        pub sequence: String,
        pub scan_topic: String,
        pub gt_kind: String,
        pub fixed_frame: String,
        pub scans: i64,
        pub unposed: i64,
        pub odometry: String,
        pub scan_match_failures: i64,
        pub odometry_rpe_m: f64,
        pub odometry_rpe_deg: f64,
        pub gt_rows: i64,
        pub gt_dropped: i64,
        pub skipped_messages: i64,
        pub first_error: Option<String>,
    }
}

/// One session's cached rows.
pub(super) struct SessionData {
    pub dataset: String,
    pub name: String,
    pub session: SessionRow,
    pub scans: Vec<ScanRow>,
    pub truth: Vec<TruthRow>,
    pub tracks: Vec<TrackRow>,
}

fn point(frame: i64, id: i64, x: f64, y: f64) -> Observation {
    Observation {
        frame,
        id,
        geometry: Geometry::Point(GroundPoint { x_m: x, y_m: y }),
        confidence: 1.0,
    }
}

/// Scores of one detector, its match distances by (scan, ground-truth id) and the causes of
/// its false positives.
struct Scored {
    row: ResultRow,
    errors: BTreeMap<(i64, i64), f64>,
    causes: FpCauseRow,
}

fn score(d: &SessionData, seq: &Sequence, detector: &str, match_m: f64) -> anyhow::Result<Scored> {
    let keep = |idx: i64, x: f64, y: f64| seq.scores_scan(idx) && seq.scores_point(x, y);
    let gt: Vec<Observation> = d
        .truth
        .iter()
        .filter(|r| keep(r.scan_idx, r.x, r.y))
        .map(|r| point(r.scan_idx, r.id, r.x, r.y))
        .collect();
    let hyp: Vec<Observation> = d
        .tracks
        .iter()
        .filter(|r| r.detector == detector && keep(r.scan_idx, r.x, r.y))
        .map(|r| point(r.scan_idx, r.id, r.x, r.y))
        .collect();
    let ev = evaluate(&gt, &hyp, MatchRule::Euclidean { max_m: match_m })
        .map_err(|e| anyhow::anyhow!("{}/{} {detector}: {e}", d.dataset, d.name))?;
    let errors = ev
        .events
        .iter()
        .filter(|e| matches!(e.kind, EventKind::Match | EventKind::Switch))
        .filter_map(|e| Some(((e.frame, e.gt_id?), e.distance?)))
        .collect();
    let fps: Vec<(i64, i64)> = ev
        .events
        .iter()
        .filter(|e| e.kind == EventKind::FalsePositive)
        .filter_map(|e| Some((e.frame, e.hyp_id?)))
        .collect();
    let scored_truth: Vec<&TruthRow> = d
        .truth
        .iter()
        .filter(|r| keep(r.scan_idx, r.x, r.y))
        .collect();
    let blank = FpCauseRow {
        dataset: d.dataset.clone(),
        sequence: d.name.clone(),
        detector: detector.into(),
        false_positives: 0,
        unannotated_scan: 0,
        near_person: 0,
        static_track: 0,
        other: 0,
    };
    let causes = fp_causes::classify(blank, &fps, &scored_truth, &d.tracks, match_m);
    let m = &ev.metrics;
    let scored = d
        .scans
        .iter()
        .filter(|s| seq.scores_scan(s.scan_idx))
        .count();
    let row = ResultRow {
        dataset: d.dataset.clone(),
        sequence: d.name.clone(),
        detector: detector.into(),
        status: "ok".into(),
        scored_scans: Some(scored as i64),
        gt_count: Some(gt.len() as i64),
        mota: Some(m.clear.mota),
        motp_m: Some(m.clear.motp),
        idf1: Some(m.identity.idf1),
        hota: Some(m.hota.hota),
        false_positives: Some(m.clear.num_false_positives as i64),
        misses: Some(m.clear.num_misses as i64),
        id_switches: Some(m.clear.num_switches as i64),
    };
    Ok(Scored {
        row,
        errors,
        causes,
    })
}

fn ttest(d: &SessionData, first: &Scored, second: &Scored, level: f64) -> TTestRow {
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for (k, ea) in &first.errors {
        if let Some(eb) = second.errors.get(k) {
            a.push(*ea);
            b.push(*eb);
        }
    }
    let mean = |v: &[f64]| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
    let mut row = TTestRow {
        dataset: d.dataset.clone(),
        sequence: d.name.clone(),
        method_a: first.row.detector.clone(),
        method_b: second.row.detector.clone(),
        status: "ok".into(),
        pairs: a.len() as i64,
        mean_a_m: mean(&a),
        mean_b_m: mean(&b),
        mean_diff_m: None,
        t: None,
        df: None,
        p_two_sided: None,
        ci_low_m: None,
        ci_high_m: None,
    };
    match paired_t(&a, &b, level) {
        Ok(t) => {
            row.mean_diff_m = Some(t.mean_diff);
            row.t = Some(t.t);
            row.df = Some(t.df);
            row.p_two_sided = Some(t.p_two_sided);
            row.ci_low_m = Some(t.ci_low);
            row.ci_high_m = Some(t.ci_high);
        }
        Err(e) => row.status = format!("not computed: {e}"),
    }
    row
}

fn skipped_rows(name: &str, methods: &[Method]) -> Vec<ResultRow> {
    methods
        .iter()
        .map(|m| ResultRow {
            dataset: name.into(),
            sequence: name.into(),
            detector: m.name().into(),
            status: "SKIPPED: log absent or not processed".into(),
            scored_scans: None,
            gt_count: None,
            mota: None,
            motp_m: None,
            idf1: None,
            hota: None,
            false_positives: None,
            misses: None,
            id_switches: None,
        })
        .collect()
}

/// `scan_idx,id,x,y,world_x,world_y` of one detector (laser frame, then fixed frame; m).
pub fn tracks_csv(tracks: &[TrackRow], detector: &str) -> Vec<u8> {
    let mut s = String::from("scan_idx,id,x,y,world_x,world_y\n");
    for r in tracks.iter().filter(|r| r.detector == detector) {
        let _ = writeln!(
            s,
            "{},{},{:.4},{:.4},{:.4},{:.4}",
            r.scan_idx, r.id, r.x, r.y, r.world_x, r.world_y
        );
    }
    s.into_bytes()
}

/// Every session's rows, in the order of `ctx.sessions`.
fn load(ctx: &Aggregate) -> anyhow::Result<Vec<SessionData>> {
    ctx.sessions
        .iter()
        .map(|(info, t)| {
            let label = format!("{}/{}", info.dataset, info.name);
            let session = tables::read::<SessionRow>(t, tables::SESSION, &label)?
                .into_iter()
                .next()
                .ok_or_else(|| anyhow::anyhow!("{label}: empty session table"))?;
            Ok(SessionData {
                dataset: info.dataset.clone(),
                name: info.name.clone(),
                session,
                scans: tables::read(t, tables::SCANS, &label)?,
                truth: tables::read(t, tables::TRUTH, &label)?,
                tracks: tables::read(t, tables::TRACKS, &label)?,
            })
        })
        .collect()
}

fn fmt_opt(v: Option<f64>, decimals: usize) -> String {
    v.filter(|x| x.is_finite())
        .map_or_else(|| "n/a".into(), |x| format!("{x:.decimals$}"))
}

/// The tables, with the rows the figures and the marker export use.
pub(super) fn run(
    ctx: &Aggregate,
    p: &Params,
) -> anyhow::Result<(Products, Vec<SessionData>, Vec<ResultRow>)> {
    let data = load(ctx)?;
    let mut out = Products::default();
    let (active, skipped_methods) = split_methods(p);
    let (mut results, mut tests, mut sessions) = (Vec::new(), Vec::new(), Vec::new());
    let mut causes = Vec::new();
    for d in &data {
        let seq = p.sequence(&d.name);
        let scored: Vec<Scored> = active
            .iter()
            .map(|m| score(d, seq, m.name(), p.match_m))
            .collect::<anyhow::Result<_>>()?;
        results.extend(skipped_methods.iter().map(|(m, why)| ResultRow {
            status: format!("SKIPPED: {why}"),
            ..skipped_rows(&d.name, &[*m]).remove(0)
        }));
        for (i, a) in scored.iter().enumerate() {
            for b in &scored[i + 1..] {
                tests.push(ttest(d, a, b, p.level));
            }
        }
        if p.is_listed(&d.name) {
            for s in &scored {
                let r = &s.row;
                out.summary.push(format!(
                    "{} {}: MOTA {}, MOTP {} m, IDF1 {}, HOTA {} ({} scored scans, {} ground-truth positions).",
                    r.sequence,
                    r.detector,
                    fmt_opt(r.mota, 3),
                    fmt_opt(r.motp_m, 3),
                    fmt_opt(r.idf1, 3),
                    fmt_opt(r.hota, 3),
                    r.scored_scans.unwrap_or(0),
                    r.gt_count.unwrap_or(0),
                ));
            }
        }
        causes.extend(scored.iter().map(|s| s.causes.clone()));
        results.extend(scored.into_iter().map(|s| s.row));
        for m in &active {
            out.artifacts.push((
                PathBuf::from(format!("tracks/{}_{}.csv", sanitize(&d.name), m.name())),
                tracks_csv(&d.tracks, m.name()),
            ));
        }
        let s = &d.session;
        sessions.push(SessionsRow {
            dataset: d.dataset.clone(),
            sequence: d.name.clone(),
            scan_topic: s.scan_topic.clone(),
            gt_kind: s.gt_kind.clone(),
            fixed_frame: s.fixed_frame.clone(),
            scans: s.scans,
            unposed: s.unposed,
            odometry: s.odometry.clone(),
            scan_match_failures: s.scan_match_failures,
            odometry_rpe_m: s.odometry_rpe_m,
            odometry_rpe_deg: s.odometry_rpe_deg,
            gt_rows: s.gt_rows,
            gt_dropped: s.gt_dropped,
            skipped_messages: s.skipped_messages,
            first_error: s.first_error.clone(),
        });
    }
    for seq in &p.sequences {
        if !data.iter().any(|d| d.name == seq.name) {
            results.extend(skipped_rows(&seq.name, &p.methods));
            out.summary.push(format!(
                "{}: SKIPPED (log absent or not processed).",
                seq.name
            ));
        }
    }
    push_tables(&mut out, p, &results, &tests, &sessions)?;
    out.tables.push(
        Table::new(
            "fp_causes",
            "False positives by cause, per sequence and method (the first cause that applies)",
            FpCauseRow::frame(&causes)?,
        )
        .with_note(format!(
            "unannotated_scan: no scored ground truth on the scan; near_person: a scored person within {} m ({} × the match distance); static_track: the hypothesis' track stays within a fixed-frame box of diagonal < {} m over its life; other: the rest. Counts are CLEAR MOT false positives under each sequence's protocol.",
            fp_causes::NEAR_FACTOR * p.match_m,
            fp_causes::NEAR_FACTOR,
            fp_causes::STATIC_EXTENT_M
        )),
    );
    let counts: Vec<paper::Counts> = results
        .iter()
        .map(|r| paper::Counts {
            sequence: r.sequence.clone(),
            detector: r.detector.clone(),
            objects: r.gt_count,
            misses: r.misses,
            id_switches: r.id_switches,
            false_positives: r.false_positives,
            mota: r.mota,
            motp_m: r.motp_m,
        })
        .collect();
    paper::products(p, &counts, &mut out)?;
    classifier::products(p, &mut out)?;
    Ok((out, data, results))
}

/// The methods to score, and those skipped with the reason (a learned method whose training
/// data is absent).
fn split_methods(p: &Params) -> (Vec<Method>, Vec<(Method, String)>) {
    let mut active = Vec::new();
    let mut skipped = Vec::new();
    for &m in &p.methods {
        match classifier::skip_reason(m, p) {
            Some(why) => skipped.push((m, why)),
            None => active.push(m),
        }
    }
    (active, skipped)
}

fn describe(s: &Sequence) -> String {
    let mut parts = vec![format!("scans {}", s.scan_topic)];
    if let Some([a, b]) = s.scans {
        parts.push(format!("scored scans {a}..{b}"));
    }
    if let Some([lo, hi]) = s.wedge_deg {
        parts.push(format!("bearing {lo}..{hi} deg"));
    }
    if let Some(r) = s.max_range_m {
        parts.push(format!("range ≤ {r} m"));
    }
    parts.join(", ")
}

/// The scoring protocol of every sequence, for the table's note.
fn protocol_note(p: &Params) -> String {
    let mut s = String::from("Protocols (ground truth and hypotheses filtered alike): ");
    for q in &p.sequences {
        let _ = write!(s, "{}: {}; ", q.name, describe(q));
    }
    let _ = write!(
        s,
        "other (synthetic) sessions: {}, ground truth moved from map into the laser frame through TF at the scan stamp.",
        describe(&p.synthetic)
    );
    s
}

fn push_tables(
    out: &mut Products,
    p: &Params,
    results: &[ResultRow],
    tests: &[TTestRow],
    sessions: &[SessionsRow],
) -> anyhow::Result<()> {
    let mut t = Table::new(
        "results",
        "Laser people tracking: CLEAR MOT, IDF1 and HOTA per sequence and detector (laser frame)",
        ResultRow::frame(results)?,
    );
    for c in ["mota", "motp_m", "idf1", "hota"] {
        t = t.with_precision(c, 3);
    }
    out.tables.push(
        t.with_note(format!(
            "Matching: Euclidean in the laser frame, threshold {} m (CLEAR MOT as py-motmetrics, IDF1, HOTA with zero similarity at {} m). {} Detectors and tracker at the defaults of src/laser (chosen on synthetic data, not tuned on these logs).",
            p.match_m,
            2.0 * p.match_m,
            p.methods
                .iter()
                .map(|m| format!("{}: {}.", m.name(), m.describe()))
                .collect::<Vec<_>>()
                .join(" ")
        ))
        .with_note(protocol_note(p)),
    );
    let mut t = Table::new(
        "paired_ttest",
        "Position error of every two methods on the (scan, person) pairs both matched: paired t-test",
        TTestRow::frame(tests)?,
    );
    for c in [
        "mean_a_m",
        "mean_b_m",
        "mean_diff_m",
        "t",
        "ci_low_m",
        "ci_high_m",
    ] {
        t = t.with_precision(c, 4);
    }
    out.tables.push(
        t.with_precision("df", 0)
            .with_precision("p_two_sided", 4)
            .with_note(format!(
                "Two-sided, confidence level {}; differences are method_a − method_b (negative: method_a closer to the ground truth).",
                p.level
            )),
    );
    out.tables.push(Table::new(
        "sessions",
        "Laser sessions read: topics, fixed frame, unposed scans, ground truth kept and dropped",
        SessionsRow::frame(sessions)?,
    ));
    Ok(())
}

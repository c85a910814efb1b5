//! Multi mode's result tables and figure (our addition): CLEAR MOT / IDF1 per session and
//! configuration, each person's final height against their own true height, paired t-tests
//! of one vs two cameras (height error per person, position error per person and stamp), and
//! a top view of the first session.

use std::collections::BTreeMap;

use super::multi::{self, Config, MultiSession, Scored};
use super::params::Params;
use crate::eval::mot::{ClearMot, IdMetrics};
use crate::eval::stats;
use crate::report::figure::{Figure, FigureKind, Mark, Sensor, Series, TopView};
use crate::report::rows::Rows;
use crate::report::table::Table;
use crate::run::{Aggregate, Products};
use crate::table_row;

table_row! {
    /// CLEAR MOT and IDF1 per session (`all`: combined) and configuration: `multi_mot`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct MotRow {
        pub session: String,
        pub config: String,
        pub people: i64,
        pub gt: i64,
        pub mota: f64,
        pub motp_m: f64,
        pub idf1: f64,
        pub misses: i64,
        pub false_positives: i64,
        pub id_switches: i64,
        pub mostly_tracked: i64,
        pub mostly_lost: i64,
        /// Distinct reported tracks.
        pub tracks: i64,
        /// Tracks started (reported or not).
        pub born: i64,
        pub camera_assigned: i64,
        pub camera_unassigned: i64,
    }
}

table_row! {
    /// Each person's height at the end vs their true height: `multi_height`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct PersonHeightRow {
        pub session: String,
        pub person: i64,
        pub config: String,
        pub truth_m: f64,
        pub final_m: Option<f64>,
        pub sigma_m: Option<f64>,
        pub error_m: Option<f64>,
        pub matched: i64,
    }
}

table_row! {
    /// Paired t-test of two configurations: `multi_paired_ttest`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct MultiPairRow {
        pub measure: String,
        pub config_a: String,
        pub config_b: String,
        pub n: i64,
        pub mean_a_m: Option<f64>,
        pub mean_b_m: Option<f64>,
        pub mean_diff_m: Option<f64>,
        pub t: Option<f64>,
        pub p_two_sided: Option<f64>,
    }
}

/// Every session × configuration, tracked and scored.
pub struct Results {
    pub configs: Vec<Config>,
    pub sessions: Vec<MultiSession>,
    /// `[session][config]`.
    pub runs: Vec<Vec<(multi::TrackRun, Scored)>>,
}

/// Load, track and score (see [`super::multi`]).
pub fn compute(ctx: &Aggregate, p: &Params) -> anyhow::Result<Results> {
    let sessions = multi::load(ctx, p)?;
    let configs = multi::configs(p);
    let mut runs = Vec::new();
    for s in &sessions {
        let mut row = Vec::new();
        for c in &configs {
            let run = multi::track(s, p, c);
            let scored = multi::score(s, &run, p)?;
            row.push((run, scored));
        }
        runs.push(row);
    }
    Ok(Results {
        configs,
        sessions,
        runs,
    })
}

fn mot_row(session: &str, config: &str, m: &ClearMot, id: &IdMetrics) -> MotRow {
    MotRow {
        session: session.into(),
        config: config.into(),
        people: m.num_unique_objects as i64,
        gt: m.num_objects as i64,
        mota: m.mota,
        motp_m: m.motp,
        idf1: id.idf1,
        misses: m.num_misses as i64,
        false_positives: m.num_false_positives as i64,
        id_switches: m.num_switches as i64,
        mostly_tracked: m.mostly_tracked as i64,
        mostly_lost: m.mostly_lost as i64,
        tracks: 0,
        born: 0,
        camera_assigned: 0,
        camera_unassigned: 0,
    }
}

fn mean(v: &[f64]) -> Option<f64> {
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

/// The tables and the figure.
pub fn products(r: &Results, p: &Params, out: &mut Products) -> anyhow::Result<()> {
    let mut rows = Vec::new();
    for (k, c) in r.configs.iter().enumerate() {
        let mut clear = Vec::new();
        let mut ids = Vec::new();
        let mut totals = [0i64; 4];
        for (s, runs) in r.sessions.iter().zip(&r.runs) {
            let (run, sc) = &runs[k];
            let m = &sc.eval.metrics;
            let counts = [
                sc.tracks as i64,
                run.born as i64,
                run.camera_assigned as i64,
                run.camera_unassigned as i64,
            ];
            rows.push(MotRow {
                tracks: counts[0],
                born: counts[1],
                camera_assigned: counts[2],
                camera_unassigned: counts[3],
                ..mot_row(&s.name, &c.name, &m.clear, &m.identity)
            });
            for (t, v) in totals.iter_mut().zip(counts) {
                *t += v;
            }
            clear.push(&m.clear);
            ids.push(&m.identity);
        }
        if !clear.is_empty() {
            rows.push(MotRow {
                tracks: totals[0],
                born: totals[1],
                camera_assigned: totals[2],
                camera_unassigned: totals[3],
                ..mot_row(
                    "all",
                    &c.name,
                    &ClearMot::merge(&clear),
                    &IdMetrics::merge(&ids),
                )
            });
        }
    }
    let mut t = Table::new(
        "multi_mot",
        "Several people (our addition): CLEAR MOT and IDF1 on the floor per session and sensor configuration",
        MotRow::frame(&rows)?,
    );
    for c in ["mota", "motp_m", "idf1"] {
        t = t.with_precision(c, 3);
    }
    out.tables.push(t.with_note(format!(
        "One EKF over (x, y, h) per person (track::height_tracks): GNN inside the {}-sigma gate, births from leg pairs no track took (not within {} m of a track), reported after {} leg pairs, deleted {} s after their last update. Scored at every ground-truth stamp with the latest reported tracks; a match within {} m (Euclidean). camera_assigned / camera_unassigned: head-top detections that updated a track / that no track took.",
        p.gate_sigma, p.birth_clearance_m, p.confirm_hits, p.delete_after_s, p.mot_max_m
    )));
    height_table(r, out)?;
    paired_table(r, p, out)?;
    if let Some(fig) = top_view(r, p) {
        out.figures.push(fig);
    }
    Ok(())
}

fn height_table(r: &Results, out: &mut Products) -> anyhow::Result<()> {
    let mut rows = Vec::new();
    for (k, c) in r.configs.iter().enumerate() {
        for (s, runs) in r.sessions.iter().zip(&r.runs) {
            for h in &runs[k].1.heights {
                rows.push(PersonHeightRow {
                    session: s.name.clone(),
                    person: h.id,
                    config: c.name.clone(),
                    truth_m: h.truth_m,
                    final_m: h.final_m,
                    sigma_m: h.sigma_m,
                    error_m: h.final_m.map(|f| f - h.truth_m),
                    matched: h.matched as i64,
                });
            }
        }
    }
    let mut t = Table::new(
        "multi_height",
        "Several people (our addition): each person's height at the end vs their true height, per sensor configuration",
        PersonHeightRow::frame(&rows)?,
    );
    for c in ["truth_m", "final_m", "sigma_m", "error_m"] {
        t = t.with_precision(c, 3);
    }
    out.tables.push(t.with_note(
        "final_m: the height of the track matched to the person at the last ground-truth stamp at which the person was matched (matched: stamps matched). The laser alone never observes height: its tracks keep the prior h0.",
    ));
    Ok(())
}

/// Paired samples of configurations `a` and `b`: |height error| per (session, person), or
/// matched position error per (session, stamp, person).
fn pairs(r: &Results, a: usize, b: usize, height: bool) -> (Vec<f64>, Vec<f64>) {
    let (mut xa, mut xb) = (Vec::new(), Vec::new());
    for runs in &r.runs {
        let (sa, sb) = (&runs[a].1, &runs[b].1);
        if height {
            for (ha, hb) in sa.heights.iter().zip(&sb.heights) {
                if let (Some(fa), Some(fb)) = (ha.final_m, hb.final_m) {
                    xa.push((fa - ha.truth_m).abs());
                    xb.push((fb - hb.truth_m).abs());
                }
            }
        } else {
            let by: BTreeMap<&(i64, i64), &f64> = sb.errors.iter().collect();
            for (key, e) in &sa.errors {
                if let Some(eb) = by.get(key) {
                    xa.push(*e);
                    xb.push(**eb);
                }
            }
        }
    }
    (xa, xb)
}

fn paired_table(r: &Results, p: &Params, out: &mut Products) -> anyhow::Result<()> {
    let n = r.configs.len();
    let mut plan: Vec<(&str, usize, usize, bool)> = Vec::new();
    if n >= 3 {
        plan.push(("height |error| per person", 1, 2, true));
        plan.push(("position error per person and stamp", 1, 2, false));
    }
    if n >= 2 {
        plan.push(("position error per person and stamp", 0, 1, false));
    }
    let mut rows = Vec::new();
    for (measure, a, b, height) in plan {
        let (xa, xb) = pairs(r, a, b, height);
        let test = stats::paired_t(&xa, &xb, p.level).ok();
        rows.push(MultiPairRow {
            measure: measure.into(),
            config_a: r.configs[a].name.clone(),
            config_b: r.configs[b].name.clone(),
            n: xa.len() as i64,
            mean_a_m: mean(&xa),
            mean_b_m: mean(&xb),
            mean_diff_m: test.as_ref().map(|t| t.mean_diff),
            t: test.as_ref().map(|t| t.t),
            p_two_sided: test.as_ref().map(|t| t.p_two_sided),
        });
    }
    let mut t = Table::new(
        "multi_paired_ttest",
        "Several people (our addition): one vs two cameras (and laser only vs one camera), paired t-tests",
        MultiPairRow::frame(&rows)?,
    );
    for c in ["mean_a_m", "mean_b_m", "mean_diff_m", "t", "p_two_sided"] {
        t = t.with_precision(c, 4);
    }
    out.tables.push(t.with_note(format!(
        "Two-sided, level {}; mean_diff = a − b (negative: a closer to the truth). Heights: one pair per person and session where both configurations matched the person. Positions: the matched distance at the stamps where both matched the person (autocorrelated: optimistic p-values).",
        p.level
    )));
    Ok(())
}

/// Top view of the first session: the truth paths and the last configuration's tracks.
fn top_view(r: &Results, p: &Params) -> Option<Figure> {
    let s = r.sessions.first()?;
    let k = r.configs.len().checked_sub(1)?;
    let (run, _) = &r.runs.first()?[k];
    let [x0, y0, x1, y1] = p.room_m;
    let mut traj = Vec::new();
    let mut people: BTreeMap<i64, Vec<(f64, f64)>> = BTreeMap::new();
    for t in &s.truth {
        people.entry(t.id).or_default().push((t.x, t.y));
    }
    for (i, (id, pts)) in people.into_iter().enumerate() {
        traj.push(Series::line(format!("person {id} (truth)"), pts, i).with_mark(Mark::Dashed));
    }
    let mut tracks: BTreeMap<u64, Vec<(f64, f64)>> = BTreeMap::new();
    for snap in &run.snapshots {
        for t in &snap.tracks {
            tracks.entry(t.id).or_default().push((t.x, t.y));
        }
    }
    for (i, (id, pts)) in tracks.into_iter().enumerate() {
        traj.push(Series::line(format!("track {id}"), pts, i));
    }
    let mut sensors = Vec::new();
    if let Some(l) = s.laser.first() {
        sensors.push(Sensor {
            x: l.laser_x,
            y: l.laser_y,
            heading: Some(l.laser_yaw),
            label: "laser".into(),
        });
    }
    for (name, rows) in p.cameras.iter().zip(&s.cameras) {
        if let Some(c) = rows.first() {
            sensors.push(Sensor {
                x: c.cam_x,
                y: c.cam_y,
                heading: None,
                label: name.clone(),
            });
        }
    }
    Some(Figure {
        size: (640, 560),
        ..Figure::new(
            format!("multi_top_view_{}", s.name),
            format!(
                "Several people (our addition): {} top view, truth (dashed) and {} tracks",
                s.name, r.configs[k].name
            ),
            FigureKind::TopView(TopView {
                outline: vec![(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)],
                sensors,
                trajectories: traj,
                ..TopView::default()
            }),
        )
    })
}

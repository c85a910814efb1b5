//! A real laser log (Leigh et al.'s annotated person-following sequence): no camera, no
//! odometry, so every follower runs laser only in the laser frame (colour off: a method that
//! differs from another only by colour or corr is run once; the literal `rst` and the other
//! people's tracks are kept), beside the laser issue's multi-person
//! tracker. Each starts at the first annotation; every annotation belongs to the last scan
//! logged before it (the authors' rule) and is scored against the estimate of that scan.

use anyhow::Context;

use super::params::{self, Method, Params, RealSequence, Variant};
use super::replay::Runner;
use super::tables::{self, RealRow};
use crate::frames::laser::{self as laser_frames, LaserOptions};
use crate::frames::truth;
use crate::laser::follow::ScanObs;
use crate::laser::points::{self, ScanGeometry};
use crate::progress::Progress;
use crate::report::rows::Rows;
use crate::run::{Session, SessionTables};

/// The methods run on a real log: colour off (so no colour watchdog either), duplicates
/// dropped, in table order.
pub fn methods(p: &Params) -> Vec<(String, Method)> {
    let mut out: Vec<(String, Method)> = Vec::new();
    for name in &p.methods {
        let Some(m) = params::method(name) else {
            continue;
        };
        let m = match m {
            Method::Follower(v) => Method::Follower(Variant {
                model: v.model,
                association: v.association,
                colour: false,
                literal_rst: v.literal_rst,
                others: v.others,
                ..Variant::PAPER
            }),
            other => other,
        };
        if !out.iter().any(|(_, o)| *o == m) {
            out.push((name.clone(), m));
        }
    }
    out
}

pub(super) fn process(
    s: &Session,
    p: &Params,
    seq: &RealSequence,
    bar: &dyn Progress,
) -> anyhow::Result<SessionTables> {
    let log = &s.log;
    let file = log.path().display().to_string();
    if log.summary().channel(&seq.scan_topic).is_none() {
        anyhow::bail!("{file}: missing laser topic {}", seq.scan_topic);
    }
    let (gt, _) = truth::person_positions(log, &seq.gt_topic)
        .with_context(|| format!("{file}: annotations {}", seq.gt_topic))?;
    // annotated scan index per annotation: the last scan logged before it
    let mut scan_times = Vec::new();
    let mut scans = Vec::new();
    for f in laser_frames::scans(log, &seq.scan_topic, &LaserOptions::default())? {
        let f = f?;
        scan_times.push(f.log_time);
        scans.push(f);
    }
    let mut by_scan: Vec<Option<(f64, f64)>> = vec![None; scans.len()];
    for a in &gt {
        let k = scan_times.partition_point(|t| *t < a.log_time);
        if k > 0 {
            by_scan[k - 1] = Some((a.x, a.y));
        }
    }
    let Some(first) = by_scan.iter().position(Option::is_some) else {
        anyhow::bail!("{file}: no annotation on {}", seq.gt_topic);
    };
    let init = by_scan[first].map(|(x, y)| [x, y]).unwrap_or_default();
    let mut runners: Vec<(String, Runner)> = methods(p)
        .into_iter()
        .map(|(n, m)| (n, Runner::new(m, p, init)))
        .collect();
    bar.set_message("real log: laser-only followers");
    let t0 = scans[first].stamp;
    let mut rows = Vec::new();
    for (idx, f) in scans.iter().enumerate().skip(first) {
        let g = ScanGeometry::of(&f.scan);
        let pts = points::project(&f.scan.ranges, &g, None);
        let t = (f.stamp.0 as f64 - t0.0 as f64) * 1e-9;
        for (name, r) in runners.iter_mut() {
            let out = r
                .step(
                    &ScanObs {
                        t,
                        points: &pts,
                        omni: None,
                        laser_pose: None,
                    },
                    f.scan.ranges.len(),
                    None,
                )
                .with_context(|| format!("{file}: {name} at scan {idx}"))?;
            if let Some((gx, gy)) = by_scan[idx] {
                let est = out.estimate.map(|e| e.position);
                rows.push(RealRow {
                    method: name.clone(),
                    scan_idx: idx as i64,
                    gt_x: gx,
                    gt_y: gy,
                    x: est.map(|e| e[0]),
                    y: est.map(|e| e[1]),
                    err_m: est.map(|e| (e[0] - gx).hypot(e[1] - gy)),
                    reset: out.reset,
                });
            }
        }
    }
    let mut out = SessionTables::new();
    out.insert(tables::TRACKS.into(), tables::TrackRow::frame(&[])?);
    out.insert(tables::TRUTH.into(), tables::TruthRow::frame(&[])?);
    out.insert(tables::LOOP.into(), tables::LoopRow::frame(&[])?);
    out.insert(tables::METHOD1.into(), tables::Method1Row::frame(&[])?);
    out.insert(tables::REAL.into(), RealRow::frame(&rows)?);
    out.insert(tables::COLOUR.into(), tables::ColourRow::frame(&[])?);
    Ok(out)
}

crate::table_row! {
    /// One method on one real sequence: `real`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct RealResultRow {
        pub sequence: String,
        pub method: String,
        pub status: String,
        pub annotated_scans: i64,
        /// Share of annotated scans with an estimate within real_match_m of the person.
        pub on_target: Option<f64>,
        /// Mean error over the scans on target (m).
        pub mean_err_on_target_m: Option<f64>,
        pub with_estimate: Option<f64>,
        pub rst_on_annotated: i64,
    }
}

/// The real sequences' results; a listed sequence without a session says SKIPPED.
pub fn table(
    data: &[tables::SessionData],
    p: &Params,
) -> anyhow::Result<crate::report::table::Table> {
    let mut rows = Vec::new();
    for seq in &p.real {
        let Some(d) = data.iter().find(|d| d.name == seq.name && d.is_real()) else {
            rows.push(RealResultRow {
                sequence: seq.name.clone(),
                method: String::new(),
                status: "SKIPPED: log absent".into(),
                annotated_scans: 0,
                on_target: None,
                mean_err_on_target_m: None,
                with_estimate: None,
                rst_on_annotated: 0,
            });
            continue;
        };
        for (name, _) in methods(p) {
            let r: Vec<&RealRow> = d.real.iter().filter(|r| r.method == name).collect();
            let n = r.len().max(1) as f64;
            let on: Vec<f64> = r
                .iter()
                .filter_map(|x| x.err_m)
                .filter(|e| *e <= p.real_match_m)
                .collect();
            rows.push(RealResultRow {
                sequence: seq.name.clone(),
                method: name.clone(),
                status: "ok".into(),
                annotated_scans: r.len() as i64,
                on_target: Some(on.len() as f64 / n),
                mean_err_on_target_m: (!on.is_empty())
                    .then(|| on.iter().sum::<f64>() / on.len() as f64),
                with_estimate: Some(r.iter().filter(|x| x.x.is_some()).count() as f64 / n),
                rst_on_annotated: r.iter().filter(|x| x.reset).count() as i64,
            });
        }
    }
    let mut t = crate::report::table::Table::new(
        "real",
        "Real laser log (Leigh et al., person following outdoors): laser-only followers beside the laser issue's tracker",
        RealResultRow::frame(&rows)?,
    );
    for c in ["on_target", "mean_err_on_target_m", "with_estimate"] {
        t = t.with_precision(c, 3);
    }
    Ok(t.with_note(format!(
        "No camera and no odometry in this log: every follower runs laser only in the laser frame (colour off), started at the first annotation; an annotation belongs to the last scan logged before it (the authors' rule); on target = within {} m (their clear_mot.py threshold).",
        p.real_match_m
    )))
}

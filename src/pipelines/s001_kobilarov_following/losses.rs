//! `losses`: how each replayed follower first loses the person in each synthetic run — the
//! error analysis behind the runs that are not followed. A loss starts at the first scan from
//! which the method's estimate stays farther than `followed_within_m` from the person (or is
//! absent) for `LOSS_WINDOW_S`; the second after that scan says what the estimate went to,
//! the second before it what the laser saw of the person:
//!
//! - `other person, colour alike` / `other person, other colour`: the estimate was nearest
//!   another person most often in the second after, and within `followed_within_m` of them in
//!   the second either side — captured by them; alike when the median normalised correlation
//!   of the blobs taken on the scans nearest them reaches `reacquire_corr`;
//! - `no estimate`: otherwise, the track dropped (`rst`) and not re-acquired by the end;
//! - `clutter`: anything else (a tree or bush, or coasting off the person).
//!
//! The replay of the paper's configuration follows the closed loop to millimetres until the
//! loop loses the person (`replay_check`), so its row is the loop's own loss; another
//! method's loss after the loop's may come from the robot having driven away (out of view).

use super::params::Params;
use super::tables::{SessionData, TrackRow, TruthRow};
use crate::eval::stats::median;
use crate::report::rows::Rows;
use crate::report::table::Table;
use crate::table_row;

/// How long (s) the estimate must stay off the person for a loss, and the window examined
/// before and after its start.
pub const LOSS_WINDOW_S: f64 = 1.0;

/// A loss no other cause explains is put on a static obstacle when one hid the person on at
/// least this share of the second before (the rst causes' 30 %).
pub const OBSTACLE_SHARE: f64 = 0.3;

table_row! {
    /// One method's first loss of the person in one run: `losses`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct LossRow {
        pub run: String,
        pub method: String,
        pub t_s: f64,
        pub cause: String,
        /// The person the estimate was nearest most often in the second after the loss's
        /// start (ground-truth id).
        pub nearest_id: Option<i64>,
        /// Median normalised correlation of the blobs the method took in that window (on the
        /// scans nearest the other person, for a capture).
        pub corr_median: Option<f64>,
        /// Shares of the window before the loss with the person occluded, behind a ground
        /// hit, out of the laser's view, behind a static obstacle.
        pub occluded: f64,
        pub ground: f64,
        pub out_of_view: f64,
        pub obstacle: f64,
        /// `rst` (any cause) in the window after the loss's start.
        pub rst: bool,
    }
}

/// The first loss of one method's rows (scan order), with the run's truth (scan order).
pub fn first_loss(
    run: &str,
    method: &str,
    rows: &[&TrackRow],
    truth: &[TruthRow],
    p: &Params,
) -> Option<LossRow> {
    let off = |r: &TrackRow| r.target_err_m.is_none_or(|e| e > p.followed_within_m);
    let period = rows
        .windows(2)
        .map(|w| w[1].t_s - w[0].t_s)
        .find(|d| *d > 0.0)?;
    let n = ((LOSS_WINDOW_S / period).round() as usize).max(1);
    let i =
        (0..rows.len().saturating_sub(n - 1)).find(|&i| rows[i..i + n].iter().all(|r| off(r)))?;
    let after = &rows[i..i + n];
    let around = &rows[i.saturating_sub(n)..i + n];
    let target = i64::from(p.target_id);
    // the person the estimate was nearest most often after the loss's start (ties: lower id)
    let mut counts: std::collections::BTreeMap<i64, usize> = std::collections::BTreeMap::new();
    for r in after.iter().filter(|r| r.x.is_some()) {
        if let Some(id) = r.nearest_id {
            *counts.entry(id).or_default() += 1;
        }
    }
    let nearest = counts
        .iter()
        .max_by(|a, b| a.1.cmp(b.1).then(b.0.cmp(a.0)))
        .map(|(id, _)| *id);
    let other = nearest.filter(|&id| {
        id != target
            && around
                .iter()
                .filter(|r| r.nearest_id == Some(id))
                .filter_map(|r| r.nearest_m)
                .any(|d| d <= p.followed_within_m)
    });
    let corr_median = median(
        around
            .iter()
            .filter(|r| other.is_none() || r.nearest_id == other)
            .filter_map(|r| r.corr)
            .collect(),
    );
    let (t0, t1) = (rows[i].t_s - LOSS_WINDOW_S, rows[i].t_s);
    let before: Vec<&TruthRow> = truth
        .iter()
        .filter(|t| t.t_s >= t0 - 1e-9 && t.t_s < t1 - 1e-9)
        .collect();
    let share = |f: fn(&TruthRow) -> bool| {
        if before.is_empty() {
            0.0
        } else {
            before.iter().filter(|t| f(t)).count() as f64 / before.len() as f64
        }
    };
    let cause = if after.last()?.x.is_none() && other.is_none() {
        "no estimate"
    } else if other.is_some() && corr_median.is_some_and(|c| c >= p.follower.reacquire_corr) {
        "other person, colour alike"
    } else if other.is_some() {
        "other person, other colour"
    } else if share(|t| t.obstacle) >= OBSTACLE_SHARE {
        "obstacle in the way"
    } else {
        "clutter"
    };
    Some(LossRow {
        run: run.into(),
        method: method.into(),
        t_s: rows[i].t_s,
        cause: cause.into(),
        nearest_id: nearest,
        corr_median,
        occluded: share(|t| t.occluded),
        ground: share(|t| t.ground),
        out_of_view: share(|t| t.out_of_view),
        obstacle: share(|t| t.obstacle),
        rst: after.iter().any(|r| r.reset),
    })
}

/// Every (run, method) first loss, runs in order, methods in the configured order.
pub fn rows(data: &[&SessionData], p: &Params) -> Vec<LossRow> {
    let mut out = Vec::new();
    for d in data {
        for m in &p.methods {
            let rows: Vec<&TrackRow> = d.method(m).collect();
            out.extend(first_loss(&d.name, m, &rows, &d.truth, p));
        }
    }
    out
}

/// `losses`.
pub fn table(data: &[&SessionData], p: &Params) -> anyhow::Result<Table> {
    let mut t = Table::new(
        "losses",
        "How each replayed method first loses the person, per run (error analysis)",
        LossRow::frame(&rows(data, p))?,
    );
    for c in [
        "t_s",
        "corr_median",
        "occluded",
        "ground",
        "out_of_view",
        "obstacle",
    ] {
        t = t.with_precision(c, 2);
    }
    Ok(t.with_note(format!(
        "A loss starts at the first scan from which the estimate stays farther than {} m from the person (or is absent) for {} s. cause: other person when the estimate was nearest another person most often in the second after and within {} m of them in the second either side (colour alike when the median normalised correlation of the blobs taken on those scans reaches {}, the re-acquisition floor, else other colour); no estimate (dropped, not re-acquired at the end); obstacle in the way when a static obstacle hid the person on at least {} of the second before (truth.obstacle: the scan short of the person on every beam towards them, neither ground nor a person explaining it); clutter otherwise. occluded / ground / out_of_view / obstacle: shares of the second before. The paper's configuration's replay follows the closed loop until the loop loses the person; later losses of other methods may follow from where the loop drove the robot.",
        p.followed_within_m,
        LOSS_WINDOW_S,
        p.followed_within_m,
        p.follower.reacquire_corr,
        OBSTACLE_SHARE
    )))
}

table_row! {
    /// The closed loop through the occlusions of one run (seed 001's `x`): `occlusions`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct OcclusionRow {
        pub run: String,
        /// Occlusions of the person by another person of at least `min_occlusion_s` that began
        /// with the loop's estimate within `followed_within_m` of the person.
        pub events: i64,
        /// ... after which the loop's own estimate was within `followed_within_m` of the
        /// person `after_occlusion_s` after the occlusion ended.
        pub coped: i64,
        pub share: Option<f64>,
    }
}

/// Whether the loop's estimate is within `within` of the person at the scan nearest `t`.
fn loop_on_person(d: &SessionData, t: f64, within: f64) -> bool {
    let near = |ts: f64| (ts - t).abs() < 0.051;
    let l = d.closed_loop.iter().find(|l| near(l.t_s));
    let g = d.truth.iter().find(|g| near(g.t_s));
    match (l, g) {
        (Some(l), Some(g)) => match (l.x, l.y, g.target_x, g.target_y) {
            (Some(x), Some(y), Some(tx), Some(ty)) => (x - tx).hypot(y - ty) <= within,
            _ => false,
        },
        _ => false,
    }
}

/// One row per run and a last row `all`.
pub fn occlusion_rows(data: &[&SessionData], p: &Params) -> Vec<OcclusionRow> {
    let row = |run: &str, events: i64, coped: i64| OcclusionRow {
        run: run.into(),
        events,
        coped,
        share: (events > 0).then(|| coped as f64 / events as f64),
    };
    let mut out: Vec<OcclusionRow> = data
        .iter()
        .map(|d| {
            let ends: Vec<(f64, f64)> = super::compare::occlusion_ends(d, p)
                .into_iter()
                .filter(|(start, _)| loop_on_person(d, *start, p.followed_within_m))
                .collect();
            let coped = ends
                .iter()
                .filter(|(_, end)| {
                    loop_on_person(d, end + p.after_occlusion_s, p.followed_within_m)
                })
                .count();
            row(&d.name, ends.len() as i64, coped as i64)
        })
        .collect();
    let (e, c) = out
        .iter()
        .fold((0, 0), |(e, c), r| (e + r.events, c + r.coped));
    out.push(row("all", e, c));
    out
}

/// `occlusions`.
pub fn occlusion_table(data: &[&SessionData], p: &Params) -> anyhow::Result<Table> {
    let t = Table::new(
        "occlusions",
        "The closed loop through occlusions by other people (the paper's x: \"in almost all cases the system was able to cope\")",
        OcclusionRow::frame(&occlusion_rows(data, p))?,
    )
    .with_precision("share", 3);
    Ok(t.with_note(format!(
        "An occlusion: another person in the laser's line of sight to the person (within {} m of it, nearer than the person; ground truth) for at least {} s, counted when it began with the robot's own estimate on the person (within the same distance as below). Coped: the robot's own logged estimate within {} m of the person {} s after the occlusion ended.",
        p.occlusion_margin_m, p.min_occlusion_s, p.followed_within_m, p.after_occlusion_s
    )))
}

#[cfg(test)]
mod tests;

//! The replayed methods side by side, and the t-tests (paired, per run and per event):
//!
//! - **models** (CV vs CT vs IMM, all with colour): the mean error to the person in the
//!   `after_occlusion_s` after each occlusion of at least `min_occlusion_s` (the target hidden
//!   by another person from the laser, from the ground truth);
//! - **colour** (with vs without the likelihood ratio, CT): wrong-target locks — an estimate
//!   within `lock_m` of another person and farther than that from the target — as the share of
//!   scans per run, and per occlusion event whether it ended locked on someone else;
//! - **template** (held as initialised vs updated while tracking, CT with colour): wrong-target
//!   locks and mean error per run;
//! - **association** (PDAF vs nearest neighbour, CT without colour): the mean error per run and
//!   after each occlusion;
//! - **corr** (normalised, the default, vs as printed, CT with colour): share of scans on the
//!   person and wrong-target locks per run;
//! - **rst threshold** (the multiplier derived from the paper's reset timing, the default, vs
//!   its literal "usually 5", CT with colour): share of scans on the person per run.
//!
//! Every family's p-values are corrected together for multiple comparisons (Holm's step-down,
//! `eval::stats::holm`, over all the rows of the table): `p_holm`.
//!
//! A method without an estimate in an event's window leaves that event out of its pairs.
//! `replay_check` compares the replay of the paper's configuration with what the robot itself
//! logged in the closed loop (they differ only by the pose the scans were placed with).

use super::params::{self, Params};
use super::tables::{SessionData, TrackRow};
use crate::eval::stats;
use crate::report::rows::Rows;
use crate::report::table::Table;
use crate::table_row;

table_row! {
    /// One method on one run: `methods`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct MethodRow {
        pub run: String,
        pub method: String,
        pub scans: i64,
        /// Share of scans with an estimate.
        pub tracked: f64,
        /// Share of scans with the estimate within lock_m of the person.
        pub on_target: f64,
        pub mean_err_m: Option<f64>,
        pub p95_err_m: Option<f64>,
        /// Share of scans locked on another person, and how often a lock began.
        pub wrong_lock: f64,
        pub wrong_lock_events: i64,
        pub rst: i64,
        /// After each `rst`, whether the first estimate lay on the person (`right`) or not.
        pub reacq_right: i64,
        pub reacq_wrong: i64,
    }
}

table_row! {
    /// One paired t-test: `ttests`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct TestRow {
        pub question: String,
        pub unit: String,
        pub measure: String,
        pub method_a: String,
        pub method_b: String,
        pub n: i64,
        pub mean_a: Option<f64>,
        pub mean_b: Option<f64>,
        pub t: Option<f64>,
        pub p_two_sided: Option<f64>,
        /// Holm-adjusted over every test of the table.
        pub p_holm: Option<f64>,
    }
}

table_row! {
    /// The replayed paper configuration against the robot's own logged estimates: `replay_check`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct ReplayRow {
        pub run: String,
        pub scans_both: i64,
        pub mean_distance_m: Option<f64>,
        pub median_distance_m: Option<f64>,
        /// Time (s) of the first scan from which the two stay more than [`AGREE_M`] apart for
        /// [`PART_SCANS`] scans; `None` when they never do. Poses a few millimetres apart (the
        /// replay's from `/tf`, the loop's from its odometer) can tip a blob or a reset
        /// decided by a hair, after which the two follow different blobs.
        pub parted_at_s: Option<f64>,
        pub replay_rst: i64,
        pub loop_rst: i64,
    }
}

fn wrong(r: &TrackRow, p: &Params) -> bool {
    r.x.is_some()
        && r.target_err_m.is_none_or(|e| e > p.lock_m)
        && r.nearest_id.is_some_and(|id| id != i64::from(p.target_id))
        && r.nearest_m.is_some_and(|d| d <= p.lock_m)
}

/// Re-acquisitions after `rst`: (right, wrong) — the first estimate after each reset within
/// `lock_m` of the person or not.
pub fn reacquisitions(rows: &[&TrackRow], p: &Params) -> (i64, i64) {
    let (mut right, mut wrong) = (0, 0);
    let mut pending = false;
    for r in rows {
        if r.reset {
            pending = true;
        } else if pending && r.x.is_some() {
            pending = false;
            if r.target_err_m.is_some_and(|e| e <= p.lock_m) {
                right += 1;
            } else {
                wrong += 1;
            }
        }
    }
    (right, wrong)
}

fn method_row(d: &SessionData, m: &str, p: &Params) -> MethodRow {
    let rows: Vec<&TrackRow> = d.method(m).collect();
    let (reacq_right, reacq_wrong) = reacquisitions(&rows, p);
    let n = rows.len().max(1) as f64;
    let mut errs: Vec<f64> = rows.iter().filter_map(|r| r.target_err_m).collect();
    errs.sort_by(f64::total_cmp);
    let mut events = 0;
    let mut was = false;
    for r in &rows {
        let w = wrong(r, p);
        events += i64::from(w && !was);
        was = w;
    }
    MethodRow {
        run: d.name.clone(),
        method: m.into(),
        scans: rows.len() as i64,
        tracked: rows.iter().filter(|r| r.x.is_some()).count() as f64 / n,
        on_target: rows
            .iter()
            .filter(|r| r.target_err_m.is_some_and(|e| e <= p.lock_m))
            .count() as f64
            / n,
        mean_err_m: (!errs.is_empty()).then(|| errs.iter().sum::<f64>() / errs.len() as f64),
        p95_err_m: errs
            .get(((errs.len() as f64 * 0.95) as usize).min(errs.len().saturating_sub(1)))
            .copied(),
        wrong_lock: rows.iter().filter(|r| wrong(r, p)).count() as f64 / n,
        wrong_lock_events: events,
        rst: rows.iter().filter(|r| r.reset).count() as i64,
        reacq_right,
        reacq_wrong,
    }
}

/// Ends of the occlusions (s) of one run.
pub fn occlusion_ends(d: &SessionData, p: &Params) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let mut start: Option<f64> = None;
    for r in &d.truth {
        match (r.occluded, start) {
            (true, None) => start = Some(r.t_s),
            (false, Some(s)) => {
                if r.t_s - s >= p.min_occlusion_s {
                    out.push((s, r.t_s));
                }
                start = None;
            }
            _ => {}
        }
    }
    out
}

/// Per event of a run: `f` over the method's rows in the window after the occlusion.
fn per_event(
    d: &SessionData,
    m: &str,
    p: &Params,
    f: &dyn Fn(&[&TrackRow]) -> Option<f64>,
) -> Vec<Option<f64>> {
    occlusion_ends(d, p)
        .iter()
        .map(|&(_, end)| {
            let w: Vec<&TrackRow> = d
                .method(m)
                .filter(|r| r.t_s > end && r.t_s <= end + p.after_occlusion_s)
                .collect();
            f(&w)
        })
        .collect()
}

fn mean_err(w: &[&TrackRow]) -> Option<f64> {
    let e: Vec<f64> = w.iter().filter_map(|r| r.target_err_m).collect();
    (!e.is_empty()).then(|| e.iter().sum::<f64>() / e.len() as f64)
}

/// A paired t-test of two value lists, pairs with a missing side left out.
fn paired(
    q: &str,
    unit: &str,
    measure: &str,
    a: (&str, &[Option<f64>]),
    b: (&str, &[Option<f64>]),
    level: f64,
) -> TestRow {
    let (xa, xb): (Vec<f64>, Vec<f64>) =
        a.1.iter()
            .zip(b.1)
            .filter_map(|(x, y)| Some((x.filter(|v| v.is_finite())?, y.filter(|v| v.is_finite())?)))
            .unzip();
    let test = stats::paired_t(&xa, &xb, level).ok();
    let mean = |v: &[f64]| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
    TestRow {
        question: q.into(),
        unit: unit.into(),
        measure: measure.into(),
        method_a: a.0.into(),
        method_b: b.0.into(),
        n: xa.len() as i64,
        mean_a: mean(&xa),
        mean_b: mean(&xb),
        t: test.as_ref().map(|t| t.t),
        p_two_sided: test.as_ref().map(|t| t.p_two_sided),
        p_holm: None,
    }
}

/// Holm's adjustment over every row that has a p-value.
fn with_holm(mut rows: Vec<TestRow>) -> Vec<TestRow> {
    let idx: Vec<usize> = (0..rows.len())
        .filter(|&i| rows[i].p_two_sided.is_some_and(f64::is_finite))
        .collect();
    let ps: Vec<f64> = idx.iter().filter_map(|&i| rows[i].p_two_sided).collect();
    if let Ok(adj) = stats::holm(&ps) {
        for (&i, a) in idx.iter().zip(adj) {
            rows[i].p_holm = Some(a);
        }
    }
    rows
}

/// The three groups of t-tests (see the module doc); methods absent from the run are skipped.
pub fn ttests(data: &[&SessionData], p: &Params) -> Vec<TestRow> {
    let has = |m: &str| p.methods.iter().any(|x| x == m);
    let per_run = |m: &str, f: &dyn Fn(&MethodRow) -> Option<f64>| -> Vec<Option<f64>> {
        data.iter().map(|d| f(&method_row(d, m, p))).collect()
    };
    let events = |m: &str, f: &dyn Fn(&[&TrackRow]) -> Option<f64>| -> Vec<Option<f64>> {
        data.iter().flat_map(|d| per_event(d, m, p, f)).collect()
    };
    let locked = |w: &[&TrackRow]| {
        (!w.is_empty()).then(|| f64::from(u8::from(w.last().is_some_and(|r| wrong(r, p)))))
    };
    let lvl = p.level;
    let mut out = Vec::new();
    let models = [params::CV, params::PAPER, params::IMM];
    for (i, a) in models.iter().enumerate() {
        for b in &models[i + 1..] {
            if has(a) && has(b) {
                let q = "CV vs CT vs IMM: error after an occlusion";
                out.push(paired(
                    q,
                    "event",
                    "mean error (m)",
                    (a, &events(a, &mean_err)),
                    (b, &events(b, &mean_err)),
                    lvl,
                ));
                let f = |r: &MethodRow| {
                    let v: Vec<f64> = data
                        .iter()
                        .filter(|d| d.name == r.run)
                        .flat_map(|d| per_event(d, &r.method, p, &mean_err))
                        .flatten()
                        .collect();
                    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
                };
                out.push(paired(
                    q,
                    "run",
                    "mean error after occlusions (m)",
                    (a, &per_run(a, &f)),
                    (b, &per_run(b, &f)),
                    lvl,
                ));
            }
        }
    }
    let (c, nc) = (params::PAPER, params::NO_COLOUR);
    if has(c) && has(nc) {
        let q = "colour likelihood: wrong-target locks";
        let f = |r: &MethodRow| Some(r.wrong_lock);
        out.push(paired(
            q,
            "run",
            "share of scans locked on another person",
            (c, &per_run(c, &f)),
            (nc, &per_run(nc, &f)),
            lvl,
        ));
        out.push(paired(
            q,
            "event",
            "locked on another person at the window's end (0/1)",
            (c, &events(c, &locked)),
            (nc, &events(nc, &locked)),
            lvl,
        ));
    }
    if has(c) && has(nc) {
        let f = |r: &MethodRow| Some(r.on_target);
        out.push(paired(
            "colour likelihood: on the person",
            "run",
            "share of scans within lock_m of the person",
            (c, &per_run(c, &f)),
            (nc, &per_run(nc, &f)),
            lvl,
        ));
    }
    out.extend(literal_readings(data, p));
    let w = params::WATCH;
    if has(c) && has(w) {
        let f = |r: &MethodRow| Some(r.on_target);
        out.push(paired(
            "colour watchdog (ours): off (the paper) vs on",
            "run",
            "share of scans within lock_m of the person",
            (c, &per_run(c, &f)),
            (w, &per_run(w, &f)),
            lvl,
        ));
    }
    let o = params::OTHERS;
    if has(c) && has(o) {
        let f = |r: &MethodRow| Some(r.on_target);
        out.push(paired(
            "other people tracked (ours): off (the paper) vs on",
            "run",
            "share of scans within lock_m of the person",
            (c, &per_run(c, &f)),
            (o, &per_run(o, &f)),
            lvl,
        ));
    }
    let up = params::UPDATED;
    if has(c) && has(up) {
        let q = "colour template: held vs updated";
        let f = |r: &MethodRow| Some(r.wrong_lock);
        out.push(paired(
            q,
            "run",
            "share of scans locked on another person",
            (c, &per_run(c, &f)),
            (up, &per_run(up, &f)),
            lvl,
        ));
        let f = |r: &MethodRow| r.mean_err_m;
        out.push(paired(
            q,
            "run",
            "mean error (m)",
            (c, &per_run(c, &f)),
            (up, &per_run(up, &f)),
            lvl,
        ));
    }
    let nn = params::NN;
    if has(nc) && has(nn) {
        let q = "PDAF vs nearest neighbour";
        let f = |r: &MethodRow| r.mean_err_m;
        out.push(paired(
            q,
            "run",
            "mean error (m)",
            (nc, &per_run(nc, &f)),
            (nn, &per_run(nn, &f)),
            lvl,
        ));
        out.push(paired(
            q,
            "event",
            "mean error after an occlusion (m)",
            (nc, &events(nc, &mean_err)),
            (nn, &events(nn, &mean_err)),
            lvl,
        ));
    }
    out
}

/// The paper's printed readings against the defaults taken from its text (CT with colour):
/// corr as printed, and `rst` at the literal 5 σ_r.
fn literal_readings(data: &[&SessionData], p: &Params) -> Vec<TestRow> {
    let has = |m: &str| p.methods.iter().any(|x| x == m);
    let per_run = |m: &str, f: &dyn Fn(&MethodRow) -> Option<f64>| -> Vec<Option<f64>> {
        data.iter().map(|d| f(&method_row(d, m, p))).collect()
    };
    let (c, lvl) = (params::PAPER, p.level);
    let mut out = Vec::new();
    let pr = params::PRINTED;
    if has(c) && has(pr) {
        let q = "corr: normalised vs as printed";
        let f = |r: &MethodRow| Some(r.on_target);
        out.push(paired(
            q,
            "run",
            "share of scans within lock_m of the person",
            (c, &per_run(c, &f)),
            (pr, &per_run(pr, &f)),
            lvl,
        ));
        let f = |r: &MethodRow| Some(r.wrong_lock);
        out.push(paired(
            q,
            "run",
            "share of scans locked on another person",
            (c, &per_run(c, &f)),
            (pr, &per_run(pr, &f)),
            lvl,
        ));
    }
    let r5 = params::RST5;
    if has(c) && has(r5) {
        let f = |r: &MethodRow| Some(r.on_target);
        out.push(paired(
            "rst threshold: from the reset timing vs 5 sigma_r (literal)",
            "run",
            "share of scans within lock_m of the person",
            (c, &per_run(c, &f)),
            (r5, &per_run(r5, &f)),
            lvl,
        ));
    }
    out
}

/// `replay_check`: the replay and the loop agree while their estimates are this close (m),
/// well under the laser's blob spread ...
pub const AGREE_M: f64 = 0.05;
/// ... and have parted once they stay farther apart for this many scans (1 s at 10 Hz).
pub const PART_SCANS: usize = 10;

/// The time of the first of [`PART_SCANS`] scans in a row farther apart than [`AGREE_M`].
fn parted_at(dist: &[f64], times: &[f64]) -> Option<f64> {
    dist.windows(PART_SCANS)
        .position(|w| w.iter().all(|&e| e > AGREE_M))
        .map(|i| times[i])
}

fn replay_rows(data: &[&SessionData], p: &Params) -> Vec<ReplayRow> {
    let mean = |d: &[f64]| (!d.is_empty()).then(|| d.iter().sum::<f64>() / d.len() as f64);
    data.iter()
        .map(|d| {
            let rows: Vec<&TrackRow> = d.method(&p.loop_method).collect();
            let mut dist = Vec::new();
            let mut times = Vec::new();
            for l in d.closed_loop.iter().filter(|l| l.x.is_some()) {
                let near = rows
                    .iter()
                    .min_by(|a, b| (a.t_s - l.t_s).abs().total_cmp(&(b.t_s - l.t_s).abs()));
                if let Some(r) = near.filter(|r| (r.t_s - l.t_s).abs() < 0.02)
                    && let (Some(x), Some(y), Some(lx), Some(ly)) = (r.x, r.y, l.x, l.y)
                {
                    dist.push((x - lx).hypot(y - ly));
                    times.push(l.t_s);
                }
            }
            ReplayRow {
                run: d.name.clone(),
                scans_both: dist.len() as i64,
                mean_distance_m: mean(&dist),
                median_distance_m: {
                    let mut d = dist.clone();
                    d.sort_by(f64::total_cmp);
                    d.get(d.len() / 2).copied()
                },
                parted_at_s: parted_at(&dist, &times),
                replay_rst: rows.iter().filter(|r| r.reset).count() as i64,
                loop_rst: d.closed_loop.iter().filter(|l| l.reset).count() as i64,
            }
        })
        .collect()
}

/// `methods`, `ttests`, `replay_check`.
pub fn tables(data: &[&SessionData], p: &Params) -> anyhow::Result<Vec<Table>> {
    let rows: Vec<MethodRow> = data
        .iter()
        .flat_map(|d| p.methods.iter().map(|m| method_row(d, m, p)))
        .collect();
    let mut tm = Table::new(
        "methods",
        "Replayed trackers on the closed-loop logs: tracking, error to the person, wrong-target locks, rst",
        MethodRow::frame(&rows)?,
    );
    for c in [
        "tracked",
        "on_target",
        "mean_err_m",
        "p95_err_m",
        "wrong_lock",
    ] {
        tm = tm.with_precision(c, 3);
    }
    let tm = tm.with_note(format!(
        "Open-loop replays of the same logs (the robot was driven by its own tracker, the configuration {}); ct_colour_others = ours: the other people tracked, their blobs discounted. ct = coordinated turn (EKF), cv = constant velocity, imm = IMM of both (ours); colour = the HS-histogram likelihood ratio; nn = nearest neighbour; laser_tracker = the laser issue's multi-person tracker, nearest track followed. Error in map; lock radius {} m.",
        p.loop_method, p.lock_m
    ));
    let mut tt = Table::new(
        "ttests",
        "Paired t-tests: CV vs CT vs IMM after occlusions, colour vs no colour, held vs updated template, normalised vs printed corr, rst threshold derived vs literal, PDAF vs nearest neighbour (Holm-adjusted)",
        TestRow::frame(&with_holm(ttests(data, p)))?,
    );
    for c in ["mean_a", "mean_b", "t", "p_two_sided", "p_holm"] {
        tt = tt.with_precision(c, 4);
    }
    let tt = tt.with_note(format!(
        "Occlusion: another person within {} m (beyond their radius) of the laser's line of sight to the target for at least {} s (ground truth); window {} s after it ends. Pairs with a side lacking an estimate are left out (n). p_holm: Holm's step-down adjustment over every test in this table.",
        p.occlusion_margin_m, p.min_occlusion_s, p.after_occlusion_s
    ));
    let mut tr = Table::new(
        "replay_check",
        "The replayed paper configuration vs the closed loop's own logged estimates",
        ReplayRow::frame(&replay_rows(data, p))?,
    );
    tr = tr
        .with_precision("mean_distance_m", 3)
        .with_precision("median_distance_m", 3);
    Ok(vec![tm, tt, tr])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A one-scan spike does not part the two; ten scans in a row apart do, from the first.
    #[test]
    fn the_replay_parts_from_the_loop_only_when_it_stays_apart() {
        let times: Vec<f64> = (0..40).map(|k| k as f64 * 0.1).collect();
        let mut d = vec![0.004; 40];
        d[3] = 0.2;
        assert_eq!(parted_at(&d, &times), None);
        for e in &mut d[20..30] {
            *e = 0.06;
        }
        assert_eq!(parted_at(&d, &times), Some(2.0));
        d[29] = 0.05;
        assert_eq!(parted_at(&d, &times), None);
    }
}

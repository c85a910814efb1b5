use super::*;

/// A run at 10 Hz: on the person (error 0.2 m) until `from`, then off (error 3 m) nearest
/// person `id` 0.3 m away with the chosen blobs' correlation `corr`, or without an estimate.
fn run(from: usize, id: i64, corr: Option<f64>, estimate: bool) -> Vec<TrackRow> {
    (0..40)
        .map(|k| {
            let off = k >= from;
            let has = !off || estimate;
            TrackRow {
                method: "ct_colour".into(),
                scan_idx: k as i64,
                t_s: 0.1 * k as f64,
                x: has.then_some(0.0),
                y: has.then_some(0.0),
                vx: None,
                vy: None,
                cov_norm: None,
                reset: off && !estimate && k == from,
                initialised: false,
                blobs: 3,
                gated: 1,
                beta0: Some(0.1),
                lr: None,
                corr: if off { corr } else { Some(0.9) },
                target_err_m: has.then_some(if off { 3.0 } else { 0.2 }),
                nearest_id: has.then_some(if off { id } else { 1 }),
                nearest_m: has.then_some(if off { 0.3 } else { 0.2 }),
            }
        })
        .collect()
}

fn truth(occluded_from: usize) -> Vec<TruthRow> {
    (0..40)
        .map(|k| TruthRow {
            occluded: k >= occluded_from,
            ..truth_row(k)
        })
        .collect()
}

/// The person at (4, 0), the robot at the origin, scan `k` at 10 Hz.
fn truth_row(k: usize) -> TruthRow {
    TruthRow {
        scan_idx: k as i64,
        t_s: 0.1 * k as f64,
        robot_x: 0.0,
        robot_y: 0.0,
        robot_yaw: 0.0,
        robot_v: 0.0,
        pitch: 0.0,
        target_x: Some(4.0),
        target_y: Some(0.0),
        target_vx: None,
        target_vy: None,
        range_m: Some(4.0),
        bearing_rad: Some(0.0),
        ground: false,
        occluded: false,
        out_of_view: false,
        obstacle: false,
    }
}

/// 40 scans with a static obstacle hiding the person on the scans in `hidden`.
fn obstacle_on(hidden: std::ops::Range<usize>) -> Vec<TruthRow> {
    (0..40)
        .map(|k| TruthRow {
            obstacle: hidden.contains(&k),
            ..truth_row(k)
        })
        .collect()
}

fn loss(rows: &[TrackRow], truth: &[TruthRow]) -> Option<LossRow> {
    let r: Vec<&TrackRow> = rows.iter().collect();
    first_loss("run", "ct_colour", &r, truth, &Params::default())
}

/// Captured at scan 20 by person 4 of another colour, the person occluded on the last 5 of the
/// 10 scans before: the loss starts at 2.0 s, half the second before occluded.
#[test]
fn a_capture_by_another_colour() {
    let l = loss(&run(20, 4, Some(0.1), true), &truth(15)).expect("a loss");
    assert!((l.t_s - 2.0).abs() < 1e-9, "{l:?}");
    assert_eq!(l.cause, "other person, other colour");
    assert_eq!(l.nearest_id, Some(4));
    assert!((l.occluded - 0.5).abs() < 1e-9 && l.ground == 0.0, "{l:?}");
    assert_eq!(l.corr_median, Some(0.1));
    assert!(!l.rst);
}

#[test]
fn alike_colour_no_estimate_and_clutter() {
    let alike = loss(&run(20, 4, Some(0.8), true), &truth(40)).expect("alike");
    assert_eq!(alike.cause, "other person, colour alike");
    let gone = loss(&run(25, 4, None, false), &truth(40)).expect("gone");
    assert_eq!((gone.cause.as_str(), gone.rst), ("no estimate", true));
    assert!((gone.t_s - 2.5).abs() < 1e-9);
    // nearest is the target itself (coasting off it): clutter
    let drift = loss(&run(20, 1, Some(0.0), true), &truth(40)).expect("drift");
    assert_eq!(drift.cause, "clutter");
    // the same drift with a tree in the way on 3 of the 10 scans before: the obstacle
    let tree = obstacle_on(17..20);
    let hidden = loss(&run(20, 1, Some(0.0), true), &tree).expect("hidden");
    assert_eq!(hidden.cause, "obstacle in the way");
    assert!((hidden.obstacle - 0.3).abs() < 1e-9, "{hidden:?}");
    // on 2 of 10 only: below the share, clutter
    let brief = obstacle_on(18..20);
    let l = loss(&run(20, 1, Some(0.0), true), &brief).expect("brief");
    assert_eq!(l.cause, "clutter");
}

/// Off the person for 0.9 s (9 scans) and back: no loss; never off: no loss.
#[test]
fn a_short_excursion_is_no_loss() {
    let mut rows = run(20, 4, Some(0.1), true);
    for r in rows.iter_mut().skip(29) {
        r.target_err_m = Some(0.2);
    }
    assert_eq!(loss(&rows, &truth(40)), None);
    assert_eq!(loss(&run(40, 4, None, true), &truth(40)), None);
}

fn loop_row(t_s: f64, x: Option<f64>) -> super::super::tables::LoopRow {
    super::super::tables::LoopRow::at(t_s, x)
}

/// Two runs of 8 s at 10 Hz, the person at (4, 0). Run a: occluded 1.0–1.5 s (coped: the
/// loop on the person at 3.5 s) and 4.0–4.2 s (too short to count). Run b: occluded
/// 1.0–2.0 s, the loop 3 m off from 2 s on: not coped; and 5.0–5.5 s, begun with the loop
/// already off the person: not counted. Totals 2 events, 1 coped.
#[test]
fn occlusions_coped_per_run_and_in_all() {
    let session = |name: &str, occ: &dyn Fn(f64) -> bool, est: &dyn Fn(f64) -> f64| {
        let mut truth = truth(1000);
        for g in &mut truth {
            g.occluded = occ(g.t_s);
        }
        truth.extend((40..80).map(|k| {
            let mut g = truth_row(k);
            g.occluded = occ(g.t_s);
            g
        }));
        SessionData {
            name: name.into(),
            tracks: vec![],
            closed_loop: truth
                .iter()
                .map(|g| loop_row(g.t_s, Some(est(g.t_s))))
                .collect(),
            truth,
            method1: vec![],
            real: vec![],
            colour: vec![],
        }
    };
    let a = session(
        "a",
        &|t| (1.0..1.5).contains(&(t + 1e-9)) || (4.0..4.2).contains(&(t + 1e-9)),
        &|_| 4.1,
    );
    let b = session(
        "b",
        &|t| (1.0..2.0).contains(&(t + 1e-9)) || (5.0..5.5).contains(&(t + 1e-9)),
        &|t| {
            if t < 2.0 { 4.0 } else { 7.0 }
        },
    );
    let rows = occlusion_rows(&[&a, &b], &Params::default());
    let got: Vec<(&str, i64, i64)> = rows
        .iter()
        .map(|r| (r.run.as_str(), r.events, r.coped))
        .collect();
    assert_eq!(got, vec![("a", 1, 1), ("b", 1, 0), ("all", 2, 1)]);
    assert_eq!(rows[2].share, Some(0.5));
}

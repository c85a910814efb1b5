//! How the free-space tracker's odometry and confirmation values were chosen (issue 35, round
//! 2): on the **synthetic** laser logs only (`datasets/segway_park`, `datasets/laser_clutter`,
//! `datasets/office_network`), never on the scored real logs.
//!
//! 1. **Scan matching** with the log's poses withheld: for each `MatchParams` variant, the mean
//!    relative pose error over 1 s windows against the true `map` pose (m, degrees) and the
//!    failed matches, per dataset.
//! 2. **Tracking**: `FreeSpaceTracker` (seed 002 leg model's verdicts as confidences) with
//!    leg_tracker's rule alone or with our quick rule, on the true pose or on scan-matched
//!    odometry (poses withheld, as on `person_following_outdoor_1`), scored as the
//!    `laser_people` pipeline scores synthetic sessions (CLEAR MOT at 0.75 m, 180° in front,
//!    5 m). Prints MOTA, MOTP, FP, FN and ID switches summed per dataset.
//!
//! Usage: `cargo run --release --example laser_free_space_sweep [-- [--match-only]
//! [--outdoor-sensor] [--default-trackers] DATASET …]` (default: the three synthetic datasets;
//! their quick-profile logs must exist; `--match-only` stops after part 1; `--outdoor-sensor`
//! cuts the synthetic scans to the outdoor real log's scanner, 5.6 m and −34.5°..+51.3°, from
//! its README; `--default-trackers` tracks with leg_tracker's rule and the default quick rule
//! only). Part 2 tracks on the true pose, on the default matcher's odometry, and in the laser
//! frame (every pose the identity).

#[path = "common/synthetic_laser.rs"]
mod synthetic_laser;

use nalgebra::{Isometry3, Point2};
use peopletrack::eval::mot::{MatchRule, evaluate};
use peopletrack::laser::joint::{JointParams, QuickConfirm};
use peopletrack::laser::legs::{self, LegParams};
use peopletrack::laser::occupancy::GridParams;
use peopletrack::laser::people::FreeSpaceTracker;
use peopletrack::laser::points::{self, ScanGeometry};
use peopletrack::laser::scan_match::{MatchParams, Pose2, ScanOdometry, static_mask};
use peopletrack::laser::segment::{self, SegmentOptions};
use synthetic_laser::{Res, leg_model, point, scored, to_laser};

struct Scan {
    time_s: f64,
    ranges: Vec<f32>,
    geometry: ScanGeometry,
    truth: Vec<(i64, Point2<f64>)>,
    pose: Isometry3<f64>,
}

/// `--outdoor-sensor`: the synthetic scans cut to what `person_following_outdoor_1`'s scanner
/// sees, from its README's sensor facts only (range_max 5.6 m, beams −34.5°..+51.3°): returns
/// beyond either become +inf (no return), as that scanner reports them.
#[derive(Clone, Copy)]
struct Cut {
    range_max: f64,
    bearing_deg: (f64, f64),
}

const OUTDOOR_SENSOR: Cut = Cut {
    range_max: 5.6,
    bearing_deg: (-34.5, 51.3),
};

fn cut(ranges: &mut [f32], g: &ScanGeometry, c: Cut) {
    for (k, r) in ranges.iter_mut().enumerate() {
        let bearing = (g.angle_min + k as f64 * g.angle_increment).to_degrees();
        if f64::from(*r) > c.range_max || bearing < c.bearing_deg.0 || bearing > c.bearing_deg.1 {
            *r = f32::INFINITY;
        }
    }
}

fn load(path: &str, sensor: Option<Cut>) -> Res<Vec<Scan>> {
    Ok(synthetic_laser::load(path)?
        .into_iter()
        .map(|s| {
            let mut ranges = s.ranges;
            if let Some(c) = sensor {
                cut(&mut ranges, &s.geometry, c);
            }
            Scan {
                time_s: s.time_s,
                truth: s
                    .truth
                    .iter()
                    .map(|&(id, p)| (id, to_laser(&s.pose, p)))
                    .collect(),
                ranges,
                geometry: s.geometry,
                pose: s.pose,
            }
        })
        .collect())
}

/// The scan-matched poses of a session, with the mean 1 s relative pose error and failures.
fn odometry(scans: &[Scan], p: MatchParams) -> (Vec<Isometry3<f64>>, f64, f64, u64) {
    let mut odo = ScanOdometry::new(p);
    let est: Vec<Isometry3<f64>> = scans
        .iter()
        .map(|s| {
            let pts = points::project(&s.ranges, &s.geometry, None);
            let segs = segment::segment(&pts, &SegmentOptions::default());
            let d = legs::detect(&pts, &segs, s.ranges.len(), None, &LegParams::default());
            odo.step(&pts, &static_mask(&pts, &segs, &d, &p))
        })
        .collect();
    let (mut et, mut er, mut n) = (0.0, 0.0, 0);
    let mut j = 0;
    for i in 0..scans.len() {
        while j < i && scans[j + 1].time_s <= scans[i].time_s - 1.0 {
            j += 1;
        }
        if scans[i].time_s - scans[j].time_s < 1.0 {
            continue;
        }
        let a = Pose2::of(&scans[j].pose)
            .inverse()
            .compose(&Pose2::of(&scans[i].pose));
        let b = Pose2::of(&est[j]).inverse().compose(&Pose2::of(&est[i]));
        let e = a.inverse().compose(&b);
        et += e.x.hypot(e.y);
        er += e.theta.abs().to_degrees();
        n += 1;
    }
    let n = f64::from(n.max(1));
    (est, et / n, er / n, odo.failures())
}

/// Where the tracker's poses come from: the log's true pose, scan-matched odometry (the
/// default `MatchParams`), or none (every pose the identity: tracking in the laser frame, as
/// leg_tracker's own launch file runs the outdoor log).
#[derive(Clone, Copy)]
enum Source {
    Truth,
    Matched,
    Laser,
}

/// (FP, FN, IDSW, GT count, Σ match distance, matches) of one session on poses `poses`.
fn track(scans: &[Scan], poses: &[Isometry3<f64>], params: JointParams) -> Res<[f64; 6]> {
    let mut fs = FreeSpaceTracker::new(params, GridParams::default());
    let (mut gt, mut hyp) = (Vec::new(), Vec::new());
    for (i, (s, pose)) in scans.iter().zip(poses).enumerate() {
        let (pts, d) = leg_model(&s.ranges, &s.geometry, Some(pose));
        fs.step(s.time_s, &d, &[], &pts, &s.ranges, &s.geometry, Some(pose));
        let frame = i as i64;
        for (id, p) in &s.truth {
            if scored(p) {
                gt.push(point(frame, *id, *p));
            }
        }
        for t in fs.tracker.confirmed() {
            let p = to_laser(pose, t.position());
            if scored(&p) {
                hyp.push(point(frame, i64::try_from(t.id)?, p));
            }
        }
    }
    let ev = evaluate(&gt, &hyp, MatchRule::Euclidean { max_m: 0.75 })?;
    let c = &ev.metrics.clear;
    Ok([
        c.num_false_positives as f64,
        c.num_misses as f64,
        c.num_switches as f64,
        gt.len() as f64,
        c.total_distance,
        c.num_matches as f64,
    ])
}

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let match_only = args.iter().any(|a| a == "--match-only");
    let default_trackers = args.iter().any(|a| a == "--default-trackers");
    let sensor = args
        .iter()
        .any(|a| a == "--outdoor-sensor")
        .then_some(OUTDOOR_SENSOR);
    let mut sets: Vec<String> = args.into_iter().filter(|a| !a.starts_with("--")).collect();
    if sets.is_empty() {
        sets = ["segway_park", "laser_clutter", "office_network"]
            .map(String::from)
            .to_vec();
    }
    let base = MatchParams::default();
    // Round 2's values (issue 35); the variants below change them one or two at a time.
    let round2 = MatchParams {
        max_range_m: 8.0,
        min_points: 20,
        small_segment_m: 0.5,
        ..base
    };
    let matchers: Vec<(&str, MatchParams)> = vec![
        ("default", base),
        ("round 2", round2),
        (
            "legs only masked",
            MatchParams {
                small_segment_m: 0.0,
                ..round2
            },
        ),
        (
            "small < 1.0 m",
            MatchParams {
                small_segment_m: 1.0,
                ..round2
            },
        ),
        (
            "corr 0.5 m",
            MatchParams {
                max_correspondence_m: 0.5,
                ..round2
            },
        ),
        (
            "trim 0.95",
            MatchParams {
                trim: 0.95,
                ..round2
            },
        ),
        (
            "range 20 m",
            MatchParams {
                max_range_m: 20.0,
                ..round2
            },
        ),
        (
            "legs only, 20 m",
            MatchParams {
                small_segment_m: 0.0,
                max_range_m: 20.0,
                ..round2
            },
        ),
        (
            "legs only, 20 m, 10 pts",
            MatchParams {
                small_segment_m: 0.0,
                max_range_m: 20.0,
                min_points: 10,
                ..round2
            },
        ),
        (
            "legs only, 10 pts",
            MatchParams {
                small_segment_m: 0.0,
                min_points: 10,
                ..round2
            },
        ),
        (
            "legs only, 20 m, 6 pts",
            MatchParams {
                small_segment_m: 0.0,
                max_range_m: 20.0,
                min_points: 6,
                ..round2
            },
        ),
        (
            "legs only, 30 m",
            MatchParams {
                small_segment_m: 0.0,
                max_range_m: 30.0,
                ..round2
            },
        ),
        (
            "keyframe 0.1 m",
            MatchParams {
                keyframe_m: 0.1,
                keyframe_rad: 0.05,
                ..round2
            },
        ),
    ];
    let quick = |d: f64, c: f64| JointParams {
        quick: Some(QuickConfirm {
            min_displacement_m: d,
            min_confidence_sum: c,
        }),
        ..JointParams::leg_tracker()
    };
    let mut trackers: Vec<(String, JointParams)> = vec![
        ("leg_tracker".into(), JointParams::leg_tracker()),
        ("quick 0.25 m, 3".into(), JointParams::default()),
        ("quick 0.15 m, 3".into(), quick(0.15, 3.0)),
        ("quick 0.4 m, 3".into(), quick(0.4, 3.0)),
        ("quick 0.25 m, 6".into(), quick(0.25, 6.0)),
    ];
    if default_trackers {
        trackers.truncate(2);
    }
    for set in &sets {
        let mut logs: Vec<Vec<Scan>> = Vec::new();
        for k in 0..6 {
            let path = format!("datasets/{set}/{set}_0{k}.mcap");
            if std::path::Path::new(&path).exists() {
                logs.push(load(&path, sensor)?);
            }
        }
        println!("== {set}: {} sessions", logs.len());
        let mut matched: Vec<Vec<Isometry3<f64>>> = Vec::new();
        for (name, p) in &matchers {
            let (mut t, mut r, mut f) = (0.0, 0.0, 0);
            for (i, s) in logs.iter().enumerate() {
                let (est, et, er, fails) = odometry(s, *p);
                t += et / logs.len() as f64;
                r += er / logs.len() as f64;
                f += fails;
                if *name == "default" {
                    matched.insert(i.min(matched.len()), est);
                }
            }
            println!("  scan match {name:<18} RPE(1 s) {t:.4} m {r:.3} deg, failures {f}");
        }
        if match_only {
            continue;
        }
        for (name, p) in &trackers {
            for (label, source) in [
                ("true pose", Source::Truth),
                ("scan-matched", Source::Matched),
                ("laser frame", Source::Laser),
            ] {
                let mut sum = [0.0; 6];
                for (s, est) in logs.iter().zip(&matched) {
                    let truth: Vec<Isometry3<f64>> = s.iter().map(|x| x.pose).collect();
                    let laser = vec![Isometry3::identity(); s.len()];
                    let poses = match source {
                        Source::Truth => &truth,
                        Source::Matched => est,
                        Source::Laser => &laser,
                    };
                    let r = track(s, poses, *p)?;
                    for k in 0..6 {
                        sum[k] += r[k];
                    }
                }
                let [fp, fn_, sw, n, dist, m] = sum;
                let mota = 1.0 - (fp + fn_ + sw) / n;
                let motp = dist / m.max(1.0);
                println!(
                    "  track {name:<16} {label:<13} MOTA {mota:>7.4} MOTP {motp:.3} FP {fp:>5} FN {fn_:>5} IDSW {sw:>3}"
                );
            }
        }
    }
    Ok(())
}

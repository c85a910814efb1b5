//! Why the free-space tracker reports people late (issue 35): on a **synthetic** laser log
//! (never a scored real one), every scan on which a ground-truth person is in the scored area
//! (in front of the laser, within 5 m) but no reported person lies within 0.75 m of them is
//! put down to the first blocking reason that applies, looking at the tracker's object tracks
//! within 0.4 m of the person:
//!
//! - `no_leg`: the leg model found no leg of theirs on the scan;
//! - `no_track`: legs found, but no object track near them;
//! - `low_confidence`: tracks, but none with running confidence ≥ 0.1 (they cannot pair);
//! - `not_free`: confident tracks, none in free space (running free value ≥ 0.06);
//! - `one_leg`: one confident track near them and no other (the legs are one cluster, or one
//!   is hidden); `one_leg_other_rejected`: one confident track and another track near them
//!   below the confidence pairing needs (the leg model rejected the second leg);
//! - `short_travel`: two confident tracks, one free, but none travelled 0.5 m yet;
//! - `other`: all of that holds and the pair is still not a person (pairing distance, both
//!   legs matched on the scan, the quick rule's conditions).
//!
//! Prints, per log, the share of scored positions with 0, 1, 2 or 3+ segments of the scan
//! within 0.4 m of the person (what the scene shows, whatever the tracker does: a realism
//! check of synthetic legs against the real log), and the counts per rule (with the median
//! range of each reason's positions) (leg_tracker's alone, the default quick rule, and the quick
//! rule with the lone-cluster option), the delay from a person's first scored scan to their
//! first reported one, and CLEAR MOT at 0.75 m over the scored positions (the pipeline's
//! protocol: synthetic in front of the laser within 5 m; `general_tracking_moving_1` read with
//! its `ground_truth.csv`, scans 133..404, bearings −80..12°, for diagnosis only).
//!
//! Usage: `cargo run --release --example laser_confirm_probe -- LOG.mcap …`
//! (`PROBE_VERBOSE=1`: every blocked position with the tracks near it; `PROBE_FP=1`: the
//! tracks with the most false positives).

use std::collections::BTreeMap;

#[path = "common/synthetic_laser.rs"]
mod synthetic_laser;

use nalgebra::{Isometry3, Point2, Point3};
use peopletrack::eval::mot::{Geometry, MatchRule, evaluate};
use peopletrack::frames::laser::{LaserOptions, scans};
use peopletrack::laser::joint::{JointParams, LONE, LoneConfirm};
use peopletrack::laser::occupancy::GridParams;
use peopletrack::laser::people::FreeSpaceTracker;
use peopletrack::laser::points::ScanGeometry;
use peopletrack::laser::segment::{self, SegmentOptions};
use peopletrack::laser::training::centroid;
use peopletrack::log::SessionLog;
use synthetic_laser::{Res, leg_model, point, scored, to_laser};

/// `println!` that stops quietly when stdout is closed (e.g. piped into `head`).
macro_rules! say {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($t)*);
    }};
}

struct Scan {
    time_s: f64,
    ranges: Vec<f32>,
    geometry: ScanGeometry,
    /// Ground truth in the map frame, with whether it is scored.
    truth: Vec<(i64, Point2<f64>, bool)>,
    pose: Isometry3<f64>,
    /// Scored area in the laser frame: `None` = the synthetic one (in front, ≤ 5 m); else
    /// this scan is in the window and hypotheses are kept within the bearing wedge (degrees).
    area: Area,
}

#[derive(Clone, Copy)]
enum Area {
    Synthetic,
    Real { in_window: bool, wedge: [f64; 2] },
}

impl Area {
    fn keeps(self, l: Point2<f64>) -> bool {
        match self {
            Area::Synthetic => scored(&l),
            Area::Real { in_window, wedge } => {
                let a = l.y.atan2(l.x).to_degrees();
                in_window && a >= wedge[0] && a <= wedge[1]
            }
        }
    }
}

fn load(path: &str) -> Res<Vec<Scan>> {
    Ok(synthetic_laser::load(path)?
        .into_iter()
        .map(|s| Scan {
            truth: s
                .truth
                .iter()
                .map(|&(id, w)| (id, w, scored(&to_laser(&s.pose, w))))
                .collect(),
            time_s: s.time_s,
            ranges: s.ranges,
            geometry: s.geometry,
            pose: s.pose,
            area: Area::Synthetic,
        })
        .collect())
}

const REASONS: [&str; 8] = [
    "no_leg",
    "no_track",
    "low_confidence",
    "not_free",
    "one_leg",
    "one_leg_other_rejected",
    "short_travel",
    "other",
];

fn describe(
    t: f64,
    id: i64,
    w: Point2<f64>,
    objects: &[&peopletrack::laser::joint::Track],
    why: &str,
) {
    let f: Vec<String> = objects
        .iter()
        .map(|o| {
            format!(
                "[#{} d {:.2} conf {:.2} free {:.3} trav {:.2} seen {}]",
                o.id,
                (o.position() - w).norm(),
                o.confidence,
                o.free,
                o.travelled_m,
                o.seen
            )
        })
        .collect();
    say!("    {why} t {t:.1} person {id}: {}", f.join(" "));
}

/// Blocking-reason counts, per-person delays (s), scored positions and CLEAR MOT at 0.75 m
/// ([FP, FN, IDSW, GT]) of one rule on one log.
type Probe = (
    BTreeMap<&'static str, u64>,
    Vec<f64>,
    u64,
    [u64; 4],
    BTreeMap<&'static str, Vec<f64>>,
    [u64; 4],
);

/// Blocking-reason counts and per-person delays (s) of one rule on one log.
fn probe(scans: &[Scan], params: JointParams) -> Probe {
    let mut fs = FreeSpaceTracker::new(params, GridParams::default());
    let mut reasons: BTreeMap<&'static str, u64> = REASONS.iter().map(|r| (*r, 0)).collect();
    let mut first_seen: BTreeMap<i64, f64> = BTreeMap::new();
    let mut first_reported: BTreeMap<i64, f64> = BTreeMap::new();
    let mut scored = 0;
    let mut last: BTreeMap<i64, (f64, Point2<f64>)> = BTreeMap::new();
    let mut ranges: BTreeMap<&'static str, Vec<f64>> = BTreeMap::new();
    // scored positions with 0, 1, 2, 3+ segments (any confidence) within 0.4 m: the scene's
    // realism, whatever the tracker does
    let mut clusters = [0u64; 4];
    let (mut gt, mut hyp) = (Vec::new(), Vec::new());
    for (frame, s) in scans.iter().enumerate() {
        let frame = frame as i64;
        let (pts, d) = leg_model(&s.ranges, &s.geometry, Some(&s.pose));
        fs.step(
            s.time_s,
            &d,
            &[],
            &pts,
            &s.ranges,
            &s.geometry,
            Some(&s.pose),
        );
        let p = fs.tracker.params;
        for t in fs.tracker.confirmed() {
            let l = to_laser(&s.pose, t.position());
            if s.area.keeps(l) {
                hyp.push(point(frame, t.id as i64, l));
            }
        }
        let centroids: Vec<Point2<f64>> = segment::segment(&pts, &SegmentOptions::default())
            .iter()
            .map(|sg| centroid(&pts, sg))
            .collect();
        for &(id, w, ok) in &s.truth {
            if ok {
                let l = to_laser(&s.pose, w);
                gt.push(point(frame, id, l));
                let n = centroids.iter().filter(|c| (*c - l).norm() <= 0.4).count();
                clusters[n.min(3)] += 1;
            }
            let prev = last.insert(id, (s.time_s, w));
            let last: BTreeMap<i64, (f64, Point2<f64>)> =
                prev.into_iter().map(|v| (id, v)).collect();
            if !ok {
                continue;
            }
            scored += 1;
            first_seen.entry(id).or_insert(s.time_s);
            if fs
                .tracker
                .confirmed()
                .any(|t| (t.position() - w).norm() <= 0.75)
            {
                first_reported.entry(id).or_insert(s.time_s);
                continue;
            }
            let near = |q: Point2<f64>| (q - w).norm() <= 0.4;
            let objects: Vec<_> = fs
                .tracker
                .tracks()
                .iter()
                .filter(|t| !t.person && near(t.position()))
                .collect();
            let reason = if !d.legs.iter().any(|l| near(l.fixed)) {
                "no_leg"
            } else if objects.is_empty() {
                "no_track"
            } else if !objects.iter().any(|t| t.confidence >= p.min_confidence) {
                "low_confidence"
            } else if !objects
                .iter()
                .any(|t| t.confidence >= p.min_confidence && t.free < p.free_threshold)
            {
                if std::env::var("PROBE_VERBOSE").is_ok() {
                    let speed = last
                        .get(&id)
                        .map_or(f64::NAN, |(t0, w0): &(f64, Point2<f64>)| {
                            (w - w0).norm() / (s.time_s - t0)
                        });
                    let f: Vec<String> = objects.iter().map(|t| format!("{:.3}", t.free)).collect();
                    let here = fs.grid.occupancy_around(w);
                    say!(
                        "    t {:.1} person {id} speed {speed:.2} m/s, grid at person {here:.3}, track free {}",
                        s.time_s,
                        f.join(" ")
                    );
                }
                "not_free"
            } else if objects
                .iter()
                .filter(|t| t.confidence >= p.min_confidence)
                .count()
                < 2
            {
                if std::env::var("PROBE_VERBOSE").is_ok() {
                    describe(s.time_s, id, w, &objects, "one_leg");
                }
                if objects.len() >= 2 {
                    "one_leg_other_rejected"
                } else {
                    "one_leg"
                }
            } else if !objects.iter().any(|t| t.travelled_m > p.min_travel_m) {
                if std::env::var("PROBE_VERBOSE").is_ok() {
                    describe(s.time_s, id, w, &objects, "short_travel");
                }
                "short_travel"
            } else {
                if std::env::var("PROBE_VERBOSE").is_ok() {
                    describe(s.time_s, id, w, &objects, "other");
                }
                "other"
            };
            *reasons.entry(reason).or_default() += 1;
            ranges
                .entry(reason)
                .or_default()
                .push(to_laser(&s.pose, w).coords.norm());
        }
    }
    let delays = first_seen
        .iter()
        .map(|(id, t0)| first_reported.get(id).map_or(f64::INFINITY, |t| t - t0))
        .collect();
    let ev = evaluate(&gt, &hyp, MatchRule::Euclidean { max_m: 0.75 }).expect("valid observations");
    if std::env::var("PROBE_FP").is_ok() {
        let mut by: BTreeMap<i64, (i64, i64, u64)> = BTreeMap::new();
        for e in ev
            .events
            .iter()
            .filter(|e| e.kind == peopletrack::eval::mot::EventKind::FalsePositive)
        {
            let v = by
                .entry(e.hyp_id.unwrap_or(-1))
                .or_insert((e.frame, e.frame, 0));
            v.1 = e.frame;
            v.2 += 1;
        }
        let mut v: Vec<_> = by.into_iter().collect();
        v.sort_by_key(|x| std::cmp::Reverse(x.1.2));
        for (id, (a, b, n)) in v.iter().take(6) {
            // nearest ground truth to the track over its false-positive scans
            let mut near = Vec::new();
            for h in hyp
                .iter()
                .filter(|h| h.id == *id && h.frame >= *a && h.frame <= *b)
            {
                let Geometry::Point(hp) = &h.geometry else {
                    continue;
                };
                let d = gt
                    .iter()
                    .filter(|g| g.frame == h.frame)
                    .filter_map(|g| match &g.geometry {
                        Geometry::Point(gp) => Some((gp.x_m - hp.x_m).hypot(gp.y_m - hp.y_m)),
                        _ => None,
                    })
                    .fold(f64::INFINITY, f64::min);
                near.push(d);
            }
            near.sort_by(f64::total_cmp);
            let med = near.get(near.len() / 2).copied().unwrap_or(f64::NAN);
            say!(
                "    FP track {id}: {n} false positives, scans {a}..{b}, median distance to nearest person {med:.2} m"
            );
        }
    }
    let c = ev.metrics.clear;
    let mot = [
        c.num_false_positives,
        c.num_misses,
        c.num_switches,
        gt.len() as u64,
    ];
    (reasons, delays, scored, mot, ranges, clusters)
}

/// A real log of Leigh et al. with its `ground_truth.csv` beside it (laser-frame positions on
/// scan indices), scored on `scans` and within the bearing `wedge` (degrees), as the pipeline
/// file scores `general_tracking_moving_1`. Diagnosis only: nothing is chosen from it.
fn load_real(path: &str, scans_window: [usize; 2], wedge: [f64; 2]) -> Res<Vec<Scan>> {
    let log = SessionLog::open(path)?;
    let csv =
        std::fs::read_to_string(std::path::Path::new(path).with_file_name("ground_truth.csv"))?;
    let mut gt: BTreeMap<usize, Vec<(i64, Point2<f64>)>> = BTreeMap::new();
    for l in csv.lines().filter(|l| !l.starts_with('#')) {
        let f: Vec<&str> = l.split(',').collect();
        gt.entry(f[0].parse()?)
            .or_default()
            .push((f[2].parse()?, Point2::new(f[3].parse()?, f[4].parse()?)));
    }
    let mut out = Vec::new();
    let mut t0 = None;
    for (k, f) in scans(&log, "/scan", &LaserOptions::default())?.enumerate() {
        let f = f?;
        let pose = f.pose.unwrap_or_else(Isometry3::identity);
        let t0 = *t0.get_or_insert(f.stamp);
        let in_window = k >= scans_window[0] && k <= scans_window[1];
        let truth = gt
            .get(&k)
            .map(|v| {
                v.iter()
                    .map(|(id, l)| {
                        let a = l.y.atan2(l.x).to_degrees();
                        let w = pose.transform_point(&Point3::new(l.x, l.y, 0.0));
                        (
                            *id,
                            Point2::new(w.x, w.y),
                            in_window && a >= wedge[0] && a <= wedge[1],
                        )
                    })
                    .collect()
            })
            .unwrap_or_default();
        out.push(Scan {
            time_s: f.stamp.signed_sub(t0) as f64 * 1e-9,
            geometry: ScanGeometry::of(&f.scan),
            ranges: f.scan.ranges.clone(),
            truth,
            pose,
            area: Area::Real { in_window, wedge },
        });
    }
    Ok(out)
}

fn main() -> Res<()> {
    let paths: Vec<String> = std::env::args().skip(1).collect();
    if paths.is_empty() {
        return Err("usage: laser_confirm_probe LOG.mcap …".into());
    }
    let rules = [
        ("leg_tracker", JointParams::leg_tracker()),
        ("default (quick)", JointParams::default()),
        (
            "quick + lone",
            JointParams {
                lone: Some(LONE),
                ..JointParams::default()
            },
        ),
        (
            "quick + lone, 0.5 m displaced",
            JointParams {
                lone: Some(LoneConfirm {
                    min_displacement_m: 0.5,
                    ..LONE
                }),
                ..JointParams::default()
            },
        ),
    ];
    for path in &paths {
        let scans = if path.contains("general_tracking_moving_1") {
            load_real(path, [133, 404], [-80.0, 12.0])?
        } else {
            load(path)?
        };
        for (name, params) in rules {
            let (reasons, mut delays, scored, [fp, fn_, sw, n], mut ranges, clusters) =
                probe(&scans, params);
            delays.sort_by(f64::total_cmp);
            let missed: u64 = reasons.values().sum();
            let never = delays.iter().filter(|d| d.is_infinite()).count();
            let finite: Vec<String> = delays
                .iter()
                .filter(|d| d.is_finite())
                .map(|d| format!("{d:.1}"))
                .collect();
            say!(
                "{path} [{name}]: {scored} scored positions, {missed} without a reported person; {} people, {never} never reported; delays (s) {}",
                delays.len(),
                finite.join(" ")
            );
            let parts: Vec<String> = reasons
                .iter()
                .map(|(k, v)| {
                    let r = ranges.get_mut(k).map_or(f64::NAN, |r| {
                        r.sort_by(f64::total_cmp);
                        r[r.len() / 2]
                    });
                    if *v > 0 {
                        format!("{k} {v} (median range {r:.1} m)")
                    } else {
                        format!("{k} 0")
                    }
                })
                .collect();
            say!("  blocking: {}", parts.join(", "));
            let mota = 1.0 - (fp + fn_ + sw) as f64 / n.max(1) as f64;
            say!("  MOT: MOTA {mota:.3} FP {fp} FN {fn_} IDSW {sw} GT {n}");
            let share = |k: usize| clusters[k] as f64 / scored.max(1) as f64;
            say!(
                "  segments within 0.4 m of a scored person: 0 {:.2}, 1 {:.2}, 2 {:.2}, 3+ {:.2}",
                share(0),
                share(1),
                share(2),
                share(3)
            );
        }
    }
    Ok(())
}

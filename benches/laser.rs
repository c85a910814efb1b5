//! Laser people detection + tracking throughput on the real logs (`make bench-laser`), one
//! thread: scans per second, as a multiple of the sensor's real-time rate (the scan rate from
//! the log's header stamps), beside a baseline measured in the same run.
//!
//! Per sequence (`general_tracking_moving_1`, `person_following_outdoor_1` from
//! `../shared/real/laser/`; a message says SKIPPED when absent), one iteration = the whole
//! sequence:
//!
//! - `decode`: the baseline — read the log and decode every scan with its TF pose
//!   (`frames::laser::scans`), nothing else;
//! - `detect_track_gnn` / `detect_track_jpda`: on the decoded scans, the `laser_people`
//!   pipeline's per-scan work for `legs` / `legs_jpda` — points, jump-distance segments, the
//!   seed 002 leg model, `PeopleTracker` (GNN or JPDA);
//! - `decode_detect_track_gnn`: both, end to end.
//!
//! After criterion's own report, a table puts each mean (scans/s) beside the sensor's own rate
//! (`sensor/s`), their ratio against the goal of 100× real time, and the decode
//! baseline (read back from criterion's `estimates.json`).

use std::path::PathBuf;
use std::time::Duration;

use criterion::{Criterion, Throughput};
use peopletrack::frames::laser::{LaserFrame, LaserOptions, scans};
use peopletrack::laser::legs::{self, LegParams};
use peopletrack::laser::points::{self, ScanGeometry};
use peopletrack::laser::segment::{self, SegmentOptions};
use peopletrack::laser::tracker::{Association, JpdaParams, PeopleTracker, TrackerParams};
use peopletrack::log::SessionLog;

const SEQUENCES: [(&str, &str); 2] = [
    ("general_tracking_moving_1", "/scan"),
    ("person_following_outdoor_1", "/scan_base2"),
];

const IDS: [&str; 4] = [
    "decode",
    "detect_track_gnn",
    "detect_track_jpda",
    "decode_detect_track_gnn",
];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn log_path(name: &str) -> Option<PathBuf> {
    let rel = format!("shared/real/laser/{name}/{name}.mcap");
    [
        root().join("..").join(&rel),
        root().join("../..").join(&rel),
    ]
    .into_iter()
    .find(|p| p.exists())
}

fn decode(log: &SessionLog, topic: &str) -> Vec<LaserFrame> {
    scans(log, topic, &LaserOptions::default())
        .expect("scans")
        .map(|f| f.expect("scan"))
        .collect()
}

/// The `legs` / `legs_jpda` per-scan work on one scan; returns the confirmed tracks.
fn detect_track(tracker: &mut PeopleTracker, f: &LaserFrame, t0: u64) -> usize {
    let s = &f.scan;
    let g = ScanGeometry::of(s);
    let pose = f.pose.as_ref();
    let pts = points::project(&s.ranges, &g, pose);
    let segs = segment::segment(&pts, &SegmentOptions::default());
    let d = legs::detect(&pts, &segs, s.ranges.len(), pose, &LegParams::default());
    let people: Vec<_> = d.people.iter().map(|p| p.fixed).collect();
    let single: Vec<_> = d.single_legs.iter().map(|&i| d.legs[i].fixed).collect();
    let time_s = f.stamp.0.wrapping_sub(t0) as f64 * 1e-9;
    tracker.step(time_s, &people, &single);
    tracker.confirmed().count()
}

fn gnn() -> TrackerParams {
    TrackerParams::default()
}

fn jpda() -> TrackerParams {
    TrackerParams {
        association: Association::Jpda(JpdaParams::default()),
        ..TrackerParams::default()
    }
}

fn run_all(frames: &[LaserFrame], params: TrackerParams) -> usize {
    let t0 = frames.first().map_or(0, |f| f.stamp.0);
    let mut tracker = PeopleTracker::new(params);
    frames
        .iter()
        .map(|f| detect_track(&mut tracker, f, t0))
        .sum()
}

/// The goal for every stage: this many times the sensor's real-time scan rate.
const REAL_TIME_GOAL: f64 = 100.0;

/// Scans per second of the sensor, from the first and last header stamps.
fn sensor_rate(frames: &[LaserFrame]) -> f64 {
    match (frames.first(), frames.last()) {
        (Some(a), Some(b)) if b.stamp.0 > a.stamp.0 => {
            (frames.len() - 1) as f64 / ((b.stamp.0 - a.stamp.0) as f64 * 1e-9)
        }
        _ => f64::NAN,
    }
}

/// Criterion's mean time of one iteration (ns), from its `estimates.json`.
fn mean_ns(group: &str, id: &str) -> Option<f64> {
    let dir = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join("target"));
    let path = dir
        .join("criterion")
        .join(group)
        .join(id)
        .join("new/estimates.json");
    let text = std::fs::read_to_string(path).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    v["mean"]["point_estimate"].as_f64()
}

fn main() {
    let mut c = Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(5))
        .configure_from_args();
    let mut report = Vec::new();
    for (name, topic) in SEQUENCES {
        let Some(path) = log_path(name) else {
            println!("SKIPPED: ../shared/real/laser/{name}/{name}.mcap not found");
            continue;
        };
        let log = SessionLog::open(&path).expect("open");
        let frames = decode(&log, topic);
        let n = frames.len();
        let rate = sensor_rate(&frames);
        let group_name = format!("laser_{name}");
        let mut g = c.benchmark_group(&group_name);
        g.throughput(Throughput::Elements(n as u64));
        g.bench_function(IDS[0], |b| b.iter(|| decode(&log, topic).len()));
        g.bench_function(IDS[1], |b| b.iter(|| run_all(&frames, gnn())));
        g.bench_function(IDS[2], |b| b.iter(|| run_all(&frames, jpda())));
        g.bench_function(IDS[3], |b| b.iter(|| run_all(&decode(&log, topic), gnn())));
        g.finish();
        report.push((group_name, n, rate));
    }
    c.final_summary();
    println!("\nlaser detection + tracking, one thread (mean of criterion's samples)");
    println!(
        "{:<38} {:<24} {:>6} {:>10} {:>10} {:>12} {:>10} {:>6}",
        "sequence", "stage", "scans", "scans/s", "sensor/s", "× real time", "t ÷ decode", "≥ 100×"
    );
    for (group, n, rate) in report {
        let decode = mean_ns(&group, IDS[0]);
        for id in IDS {
            let Some(ns) = mean_ns(&group, id) else {
                println!("{group:<38} {id:<24} no estimate (filtered out?)");
                continue;
            };
            let per_s = n as f64 / (ns * 1e-9);
            let vs_decode = decode.map_or(f64::NAN, |d| ns / d);
            let real_time = per_s / rate;
            let met = if real_time >= REAL_TIME_GOAL {
                "yes"
            } else {
                "no"
            };
            println!(
                "{group:<38} {id:<24} {n:>6} {per_s:>10.0} {rate:>10.2} {real_time:>12.0} {vs_decode:>10.2} {met:>6}"
            );
        }
    }
}

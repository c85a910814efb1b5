//! Tracking-metrics throughput on a long synthetic sequence: 2400 frames, ~30 people at a
//! time (45 tracks), boxes that cross and overlap, and a tracker with jitter, misses, false
//! positives and identity switches, generated from a fixed seed (xorshift).
//!
//! The sequence is written as MOTChallenge CSV to `target/bench-data/mot/{gt,hyp}.txt`, and
//! our metrics to `ours.json`, so that `tools/bench_motmetrics.py` can score the same files
//! with py-motmetrics, compare the numbers and print the time ratio (`make bench-mot`).
//!
//! - `mot/clear_identity_from_csv`: parse both files, match every frame, CLEAR MOT and IDF1
//!   — the work py-motmetrics does (`loadtxt`, `compare_to_groundtruth`, `compute`).
//! - `mot/clear_identity_from_csv_two_threads`: the same with the two files parsed at once
//!   on two threads (as `peopletrack score` reads them); the rest is one thread.
//! - `mot/all_metrics_from_csv`: the same plus HOTA.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use peopletrack::eval::mot::{
    BoxPx, Geometry, GeometryKind, MatchRule, Observation, Sequence, parse_motchallenge,
    write_motchallenge,
};

const FRAMES: i64 = 2400;
const TRACKS: usize = 45;
const RULE: MatchRule = MatchRule::Iou { min_iou: 0.5 };

struct XorShift(u64);

impl XorShift {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in [-1, 1).
    fn sym(&mut self) -> f64 {
        2.0 * self.unit() - 1.0
    }
}

fn bx(frame: i64, id: i64, left: f64, top: f64, w: f64, h: f64, conf: f64) -> Observation {
    Observation {
        frame,
        id,
        geometry: Geometry::Box(BoxPx {
            left_px: left,
            top_px: top,
            width_px: w,
            height_px: h,
        }),
        confidence: conf,
    }
}

/// (ground truth, tracker output) for a 1920 × 1080 scene.
fn synthetic() -> (Vec<Observation>, Vec<Observation>) {
    let mut rng = XorShift(0x853c_49e6_748f_ea9b);
    let mut gt = Vec::new();
    let mut hyp = Vec::new();
    // Each track lives for about two thirds of the sequence: ~30 people per frame.
    struct Person {
        start: i64,
        end: i64,
        x: f64,
        y: f64,
        vx: f64,
        vy: f64,
        h: f64,
    }
    let mut people: Vec<Person> = (0..TRACKS)
        .map(|_| {
            let len = (FRAMES as f64 * (0.4 + 0.5 * rng.unit())) as i64;
            let start = (rng.next() % (FRAMES - len + 1) as u64) as i64;
            Person {
                start,
                end: start + len,
                x: 1800.0 * rng.unit(),
                y: 300.0 + 600.0 * rng.unit(),
                vx: 3.0 * rng.sym(),
                vy: 0.5 * rng.sym(),
                h: 120.0 + 160.0 * rng.unit(),
            }
        })
        .collect();
    let mut hyp_id: HashMap<usize, i64> = HashMap::new();
    let mut next_hyp_id = 1;
    for f in 1..=FRAMES {
        for (k, p) in people.iter_mut().enumerate() {
            if f < p.start || f >= p.end {
                continue;
            }
            // Walk, turning gently, bouncing off the image borders.
            p.vx = (p.vx + 0.2 * rng.sym()).clamp(-4.0, 4.0);
            p.vy = (p.vy + 0.05 * rng.sym()).clamp(-1.0, 1.0);
            p.x += p.vx;
            p.y += p.vy;
            if !(0.0..=1800.0).contains(&p.x) {
                p.vx = -p.vx;
                p.x = p.x.clamp(0.0, 1800.0);
            }
            if !(200.0..=900.0).contains(&p.y) {
                p.vy = -p.vy;
                p.y = p.y.clamp(200.0, 900.0);
            }
            let w = 0.4 * p.h;
            let gt_id = k as i64 + 1;
            gt.push(bx(f, gt_id, p.x, p.y, w, p.h, 1.0));
            // Tracker: 8 % misses, a new id 0.3 % of the time, jittered boxes.
            if rng.unit() < 0.003 || !hyp_id.contains_key(&k) {
                hyp_id.insert(k, next_hyp_id);
                next_hyp_id += 1;
            }
            if rng.unit() < 0.08 {
                continue;
            }
            let s = 1.0 + 0.08 * rng.sym();
            hyp.push(bx(
                f,
                hyp_id[&k],
                p.x + 0.06 * w * rng.sym(),
                p.y + 0.06 * p.h * rng.sym(),
                w * s,
                p.h * s,
                0.5 + 0.5 * rng.unit(),
            ));
        }
        // About one false positive per frame, each with its own short-lived id.
        while rng.unit() < 0.5 {
            let h = 100.0 + 200.0 * rng.unit();
            hyp.push(bx(
                f,
                1_000_000 + f * 10 + (rng.next() % 10) as i64,
                1800.0 * rng.unit(),
                200.0 + 700.0 * rng.unit(),
                0.4 * h,
                h,
                0.3 * rng.unit(),
            ));
        }
    }
    // A false-positive id drawn twice in one frame would be a duplicate row: keep the first.
    let mut seen = std::collections::HashSet::new();
    hyp.retain(|o| seen.insert((o.frame, o.id)));
    (gt, hyp)
}

fn bench_data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/bench-data/mot")
}

fn score_csv(gt: &str, hyp: &str, with_hota: bool) -> f64 {
    let g = parse_motchallenge(gt, Path::new("gt.txt"), GeometryKind::Box).expect("gt parses");
    let h = parse_motchallenge(hyp, Path::new("hyp.txt"), GeometryKind::Box).expect("hyp parses");
    score(&g, &h, with_hota)
}

/// `score_csv` with the two files parsed at once on two threads, as `peopletrack score` does.
fn score_csv_two_threads(gt: &str, hyp: &str) -> f64 {
    let (g, h) = rayon::join(
        || parse_motchallenge(gt, Path::new("gt.txt"), GeometryKind::Box).expect("gt parses"),
        || parse_motchallenge(hyp, Path::new("hyp.txt"), GeometryKind::Box).expect("hyp parses"),
    );
    score(&g, &h, false)
}

fn score(g: &[Observation], h: &[Observation], with_hota: bool) -> f64 {
    let seq = Sequence::new(g, h, RULE).expect("valid");
    let (clear, _events) = seq.clear_mot();
    let id = seq.identity();
    let hota = if with_hota { seq.hota().hota } else { 0.0 };
    clear.mota + id.idf1 + hota
}

fn mot(c: &mut Criterion) {
    let (gt, hyp) = synthetic();
    let (gt_text, hyp_text) = (write_motchallenge(&gt), write_motchallenge(&hyp));
    let dir = bench_data_dir();
    std::fs::create_dir_all(&dir).expect("bench-data dir");
    std::fs::write(dir.join("gt.txt"), &gt_text).expect("write gt");
    std::fs::write(dir.join("hyp.txt"), &hyp_text).expect("write hyp");
    let metrics = Sequence::new(&gt, &hyp, RULE)
        .expect("valid")
        .evaluate()
        .metrics;
    let summary = serde_json::json!({
        "frames": FRAMES,
        "gt_rows": gt.len(),
        "hyp_rows": hyp.len(),
        "metrics": metrics,
    });
    std::fs::write(
        dir.join("ours.json"),
        serde_json::to_string_pretty(&summary).expect("json"),
    )
    .expect("write ours.json");

    let mut g = c.benchmark_group("mot");
    g.sample_size(20);
    g.measurement_time(Duration::from_secs(10));
    g.bench_function("clear_identity_from_csv", |b| {
        b.iter(|| score_csv(&gt_text, &hyp_text, false))
    });
    g.bench_function("clear_identity_from_csv_two_threads", |b| {
        b.iter(|| score_csv_two_threads(&gt_text, &hyp_text))
    });
    g.bench_function("all_metrics_from_csv", |b| {
        b.iter(|| score_csv(&gt_text, &hyp_text, true))
    });
    // Stages, to see where the time goes.
    let seq = Sequence::new(&gt, &hyp, RULE).expect("valid");
    g.bench_function("stage_parse", |b| {
        b.iter(|| parse_motchallenge(&gt_text, Path::new("gt.txt"), GeometryKind::Box))
    });
    g.bench_function("stage_sequence", |b| {
        b.iter(|| Sequence::new(&gt, &hyp, RULE))
    });
    g.bench_function("stage_clear", |b| b.iter(|| seq.clear_mot()));
    g.bench_function("stage_identity", |b| b.iter(|| seq.identity()));
    g.bench_function("stage_hota", |b| b.iter(|| seq.hota()));
    g.finish();
}

criterion_group!(benches, mot);
criterion_main!(benches);

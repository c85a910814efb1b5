//! Table-I-like numbers of a closed-loop following session (seed 001 §VI), from the ground
//! truth: per session the mean ± std of the range and |bearing| from the robot's true pose to
//! the followed person, the robot's true speed (finite differences of `map <- base_link`),
//! seed 001's following error `E_follow = r − d_follow − v²/(2·a_min)`, the robot's maximum
//! speed, and from `/follower/state` the number of `rst` and the share of scans without an
//! estimate. A probe of the synthesizer's closed loop, not a pipeline.
//!
//! Usage: `cargo run --example follow_table -- [--target ID] [--d-follow M] [--a-min MPS2] LOG.mcap …`
//! (defaults: target 1, 1.8 m, 1.4 m/s², as `datasets/segway_park`).

use peopletrack::groundtruth::{FollowerState, PeopleFrame};
use peopletrack::log::SessionLog;
use peopletrack::log::tf::TfBuffer;
use peopletrack::time::Nanos;

type Res<T> = Result<T, Box<dyn std::error::Error>>;

fn mean_std(x: &[f64]) -> (f64, f64) {
    let n = x.len().max(1) as f64;
    let m = x.iter().sum::<f64>() / n;
    let v = x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (n - 1.0).max(1.0);
    (m, v.sqrt())
}

fn main() -> Res<()> {
    let mut args = std::env::args().skip(1);
    let (mut target, mut d_follow, mut a_min) = (1u32, 1.8, 1.4);
    let mut logs = Vec::new();
    while let Some(a) = args.next() {
        match a.as_str() {
            "--target" => target = args.next().ok_or("--target ID")?.parse()?,
            "--d-follow" => d_follow = args.next().ok_or("--d-follow M")?.parse()?,
            "--a-min" => a_min = args.next().ok_or("--a-min MPS2")?.parse()?,
            _ => logs.push(a),
        }
    }
    println!(
        "| session | controller | range m | abs bearing deg | speed m/s | E_follow m | max speed m/s | rst | lost % |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for path in &logs {
        let log = SessionLog::open(std::path::Path::new(path))?;
        let tf = TfBuffer::from_log(&log, 0.1)?;
        let mut rows: Vec<(f64, f64, f64, [f64; 2])> = Vec::new(); // t, range, bearing, robot xy
        for m in log.messages_on(&["/ground_truth/people"])? {
            let gt: PeopleFrame = serde_json::from_slice(&m?.data)?;
            let Some(p) = gt.people.iter().find(|p| p.id == target) else {
                continue;
            };
            let Ok(base) = tf.lookup("map", "base_link", Nanos(gt.stamp_ns)) else {
                continue;
            };
            let q = base.inverse() * nalgebra::Point3::new(p.x, p.y, 0.0);
            let t = gt.stamp_ns as f64 * 1e-9;
            let xy = [base.translation.x, base.translation.y];
            rows.push((t, q.x.hypot(q.y), q.y.atan2(q.x).abs().to_degrees(), xy));
        }
        rows.dedup_by(|a, b| a.0 == b.0);
        let (mut range, mut bearing, mut speed, mut err) = (vec![], vec![], vec![], vec![]);
        for w in rows.windows(2) {
            let dt = w[1].0 - w[0].0;
            if dt <= 0.0 {
                continue;
            }
            let v = (w[1].3[0] - w[0].3[0]).hypot(w[1].3[1] - w[0].3[1]) / dt;
            range.push(w[1].1);
            bearing.push(w[1].2);
            speed.push(v);
            err.push(w[1].1 - d_follow - v * v / (2.0 * a_min));
        }
        let states: Vec<FollowerState> = log
            .messages_on(&["/follower/state"])?
            .map(|m| Ok(serde_json::from_slice(&m?.data)?))
            .collect::<Res<_>>()?;
        let rst = states.iter().filter(|s| s.reset).count();
        let lost = states.iter().filter(|s| s.position.is_none()).count();
        let controller = states.first().map_or("-", |s| s.controller.as_str());
        let f = |x: &[f64]| {
            let (m, s) = mean_std(x);
            format!("{m:.2} ± {s:.2}")
        };
        println!(
            "| {} | {controller} | {} | {} | {} | {} | {:.2} | {rst} | {:.1} |",
            std::path::Path::new(path)
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("?"),
            f(&range),
            f(&bearing),
            f(&speed),
            f(&err),
            speed.iter().copied().fold(0.0, f64::max),
            100.0 * lost as f64 / states.len().max(1) as f64,
        );
    }
    Ok(())
}

//! How the laser tracker's JPDA defaults (and the `max_leg_only_scans` option) were chosen: on the
//! **synthetic** laser logs only (`datasets/segway_park`, `datasets/office_network`), the seed
//! 002 leg model + `PeopleTracker` under each candidate setting, scored as the `laser_people`
//! pipeline scores synthetic sessions (ground truth from `map` into the laser frame at the scan
//! stamp, nearest stamp within 0.05 s, 180° in front and 5 m, CLEAR MOT at 0.75 m). Prints MOTA,
//! IDF1, FP, FN and ID switches summed over the sessions.
//!
//! Usage: `cargo run --example laser_jpda_sweep [-- LOG.mcap …]` (default: the synthetic logs).
//! Never run it on the real logs to choose a value: those are scored once, at the defaults.

#[path = "common/synthetic_laser.rs"]
mod synthetic_laser;

use nalgebra::Point2;
use peopletrack::eval::mot::{MatchRule, evaluate};
use peopletrack::laser::tracker::{Association, JpdaParams, PeopleTracker, TrackerParams};
use synthetic_laser::{Res, leg_model, point, scored, to_laser};

/// Per scan: time, laser-frame ground truth, fixed-frame people and single legs, the pose.
struct Scan {
    time_s: f64,
    truth: Vec<(i64, Point2<f64>)>,
    people: Vec<Point2<f64>>,
    single: Vec<Point2<f64>>,
    pose: nalgebra::Isometry3<f64>,
}

/// The scans of a synthetic log with the seed 002 leg model's detections.
fn load(path: &str) -> Res<Vec<Scan>> {
    Ok(synthetic_laser::load(path)?
        .into_iter()
        .map(|s| {
            let (_, d) = leg_model(&s.ranges, &s.geometry, Some(&s.pose));
            Scan {
                time_s: s.time_s,
                truth: s
                    .truth
                    .iter()
                    .map(|&(id, p)| (id, to_laser(&s.pose, p)))
                    .collect(),
                people: d.people.iter().map(|p| p.fixed).collect(),
                single: d.single_legs.iter().map(|&i| d.legs[i].fixed).collect(),
                pose: s.pose,
            }
        })
        .collect())
}

/// (FP, FN, IDSW, GT count, IDTP, IDFP + IDFN) of one session under `params`.
fn run(scans: &[Scan], params: TrackerParams) -> Res<[f64; 6]> {
    let mut tracker = PeopleTracker::new(params);
    let (mut gt, mut hyp) = (Vec::new(), Vec::new());
    for (i, s) in scans.iter().enumerate() {
        tracker.step(s.time_s, &s.people, &s.single);
        let frame = i as i64;
        for (id, p) in &s.truth {
            if scored(p) {
                gt.push(point(frame, *id, *p));
            }
        }
        for t in tracker.confirmed() {
            let p = to_laser(&s.pose, t.position());
            if scored(&p) {
                hyp.push(point(frame, i64::try_from(t.id)?, p));
            }
        }
    }
    let ev = evaluate(&gt, &hyp, MatchRule::Euclidean { max_m: 0.75 })?;
    let c = &ev.metrics.clear;
    let id = &ev.metrics.identity;
    Ok([
        c.num_false_positives as f64,
        c.num_misses as f64,
        c.num_switches as f64,
        gt.len() as f64,
        id.idtp as f64,
        (id.idfp + id.idfn) as f64,
    ])
}

fn main() -> Res<()> {
    let mut logs: Vec<String> = std::env::args().skip(1).collect();
    if logs.is_empty() {
        for d in ["segway_park", "office_network"] {
            for k in 0..2 {
                logs.push(format!("datasets/{d}/{d}_0{k}.mcap"));
            }
        }
    }
    let sessions: Vec<Vec<Scan>> = logs.iter().map(|l| load(l)).collect::<Res<_>>()?;
    let mut configs: Vec<(String, TrackerParams)> = vec![("gnn".into(), TrackerParams::default())];
    for k in [3, 5, 10, 20] {
        let p = TrackerParams {
            max_leg_only_scans: Some(k),
            ..TrackerParams::default()
        };
        configs.push((format!("gnn max_leg_only_scans={k}"), p));
    }
    for pd in [0.6, 0.75, 0.9, 0.99] {
        for lambda in [0.005, 0.05, 0.5, 2.0] {
            let p = TrackerParams {
                association: Association::Jpda(JpdaParams {
                    detection_probability: pd,
                    clutter_density: lambda,
                    ..JpdaParams::default()
                }),
                ..TrackerParams::default()
            };
            configs.push((format!("jpda P_D={pd} λ={lambda}"), p));
        }
    }
    println!(
        "{:<28} {:>7} {:>7} {:>6} {:>6} {:>5}",
        "config", "MOTA", "IDF1", "FP", "FN", "IDSW"
    );
    for (name, p) in configs {
        let mut sum = [0.0; 6];
        for s in &sessions {
            let r = run(s, p)?;
            for k in 0..6 {
                sum[k] += r[k];
            }
        }
        let [fp, fn_, sw, n, idtp, idf] = sum;
        let mota = 1.0 - (fp + fn_ + sw) / n;
        let idf1 = 2.0 * idtp / (2.0 * idtp + idf);
        println!("{name:<28} {mota:>7.4} {idf1:>7.4} {fp:>6} {fn_:>6} {sw:>5}");
    }
    Ok(())
}

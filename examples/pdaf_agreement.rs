//! Writes the measurement sequences seed 001's target filter (`track::pdaf`) sees on real and
//! synthetic laser logs, with every step of our filter, so `tools/stonesoup_pdaf_agreement.py`
//! can run Stone Soup's PDA hypothesiser and updater (and an IMM built from its pieces) on the
//! same measurements and compare step by step (`make stonesoup-agreement`).
//!
//! Usage: `pdaf_agreement OUT_DIR [--real LOG.mcap] [--synthetic LOG.mcap] [--max-scans N]`
//!
//! Measurements: each scan's blobs (`laser::follow::blobs`, the follower's defaults) in the
//! laser frame. Likelihood ratios: 1 on the real log (no camera); on the synthetic log seeded
//! draws in [0, 2) with a fifth of them 0 (the check is of the filter's arithmetic; the colour
//! feature has its own tests). The track starts on the blob nearest the first annotation (real)
//! or straight ahead (synthetic) and, after `rst`, restarts on the blob nearest its last
//! position. For each of CV, CT and IMM and two parameter sets (the defaults; and P_D 0.7,
//! λ 0.2 /m², a 95 % gate, the maneuver gate off) one JSON file holds the parameters and per
//! step the prior (modes, probabilities, maneuver anchor), the measurements, the prediction,
//! the gated measurements, β and β₀, and the posterior.

use std::fs;
use std::path::{Path, PathBuf};

use peopletrack::frames::laser::{self as laser_frames, LaserOptions};
use peopletrack::frames::truth;
use peopletrack::laser::follow::{self, FollowParams};
use peopletrack::laser::points::{self, ScanGeometry};
use peopletrack::log::SessionLog;
use peopletrack::rng;
use peopletrack::track::pdaf::{FilterParams, ModelKind, TargetFilter};
use rand::RngExt;
use serde_json::{Value, json};

type Res<T> = Result<T, Box<dyn std::error::Error>>;

/// One scan: time (s from the first) and blob centres (laser frame).
struct Scan {
    t: f64,
    z: Vec<[f64; 2]>,
}

fn scans_of(path: &Path, topic: &str, max: usize) -> Res<Vec<Scan>> {
    let log = SessionLog::open(path)?;
    let fp = FollowParams::default();
    let mut out = Vec::new();
    let mut t0 = None;
    for f in laser_frames::scans(&log, topic, &LaserOptions::default())?.take(max) {
        let f = f?;
        let g = ScanGeometry::of(&f.scan);
        let pts = points::project(&f.scan.ranges, &g, None);
        let t0 = *t0.get_or_insert(f.stamp.0);
        // whole microseconds: Stone Soup's timestamps are datetimes
        let us = (f.stamp.0.saturating_sub(t0) as f64 / 1e3).round();
        out.push(Scan {
            t: us * 1e-6,
            z: follow::blobs(&pts, &fp).iter().map(|b| b.centre).collect(),
        });
    }
    Ok(out)
}

fn filter_json(f: &TargetFilter) -> Value {
    let (modes, mu) = f.mode_states();
    let (anchor, anchor_t) = f.maneuver_anchor();
    let (x, p) = f.state();
    json!({
        "modes": modes.iter().map(|(x, p)| json!({"x": x, "P": p})).collect::<Vec<_>>(),
        "mu": mu, "anchor": anchor, "anchor_t": anchor_t, "t": f.time(), "x": x, "P": p,
    })
}

fn nearest(z: &[[f64; 2]], to: [f64; 2]) -> Option<[f64; 2]> {
    z.iter().copied().min_by(|a, b| {
        let d = |q: &[f64; 2]| (q[0] - to[0]).hypot(q[1] - to[1]);
        d(a).total_cmp(&d(b))
    })
}

/// Our filter over the scans (see the module doc): the JSON of every step.
fn run(scans: &[Scan], lr: &[Vec<f64>], p: &FilterParams, init: [f64; 2]) -> Res<Vec<Value>> {
    let mut steps = Vec::new();
    let mut filter: Option<TargetFilter> = None;
    let mut last = init;
    for (k, s) in scans.iter().enumerate() {
        let Some(f) = filter.as_mut() else {
            if let Some(z) = nearest(&s.z, last) {
                filter = Some(TargetFilter::new(p, s.t, z));
            }
            continue;
        };
        let prior = filter_json(f);
        f.predict(s.t)?;
        let (px, pp) = f.state();
        let a = f.update(&s.z, &lr[k])?;
        last = f.position();
        steps.push(json!({
            "scan": k, "t": s.t, "prior": prior, "z": s.z, "lr": lr[k],
            "pred": {"x": px, "P": pp}, "gated": a.gated, "beta": a.beta, "beta0": a.beta0,
            "post": filter_json(f), "reset": f.needs_reset(),
        }));
        if f.needs_reset() {
            filter = None;
        }
    }
    Ok(steps)
}

fn params_json(p: &FilterParams) -> Value {
    serde_json::to_value(p).unwrap_or(Value::Null)
}

fn write(out: &Path, source: &str, scans: &[Scan], lr: &[Vec<f64>], init: [f64; 2]) -> Res<()> {
    let defaults = FilterParams::default();
    let other = FilterParams {
        p_d: 0.7,
        clutter_density: 0.2,
        gate: 5.991,
        v_max: f64::INFINITY,
        a_max: f64::INFINITY,
        ..defaults.clone()
    };
    for (set, base) in [("defaults", &defaults), ("other", &other)] {
        for (name, model) in [
            ("cv", ModelKind::Cv),
            ("ct", ModelKind::Ct),
            ("imm", ModelKind::Imm),
        ] {
            let p = FilterParams {
                model,
                ..base.clone()
            };
            let steps = run(scans, lr, &p, init)?;
            let file = out.join(format!("{source}_{name}_{set}.json"));
            let doc = json!({"source": source, "model": name, "set": set, "params": params_json(&p), "steps": steps});
            fs::write(&file, serde_json::to_vec(&doc)?)?;
            println!(
                "{}: {} steps",
                file.display(),
                doc["steps"].as_array().map_or(0, Vec::len)
            );
        }
    }
    Ok(())
}

fn main() -> Res<()> {
    let mut args = std::env::args().skip(1);
    let out =
        PathBuf::from(args.next().ok_or(
            "usage: pdaf_agreement OUT_DIR [--real LOG] [--synthetic LOG] [--max-scans N]",
        )?);
    let (mut real, mut synthetic, mut max) = (None, None, usize::MAX);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--real" => real = args.next().map(PathBuf::from),
            "--synthetic" => synthetic = args.next().map(PathBuf::from),
            "--max-scans" => max = args.next().ok_or("--max-scans N")?.parse()?,
            other => return Err(format!("unknown argument {other}").into()),
        }
    }
    fs::create_dir_all(&out)?;
    if let Some(path) = real.filter(|p| p.exists()) {
        let scans = scans_of(&path, "/scan_base2", max)?;
        let log = SessionLog::open(&path)?;
        let (gt, _) = truth::person_positions(&log, "/ground_truth_people_tracks")?;
        let init = gt.first().map_or([1.0, 0.0], |a| [a.x, a.y]);
        let lr: Vec<Vec<f64>> = scans.iter().map(|s| vec![1.0; s.z.len()]).collect();
        write(&out, "real", &scans, &lr, init)?;
    } else {
        println!("SKIPPED: the real outdoor log is absent");
    }
    if let Some(path) = synthetic.filter(|p| p.exists()) {
        let scans = scans_of(&path, "/scan", max)?;
        let mut r = rng::stream(30, "pdaf_agreement", 0);
        let lr: Vec<Vec<f64>> = scans
            .iter()
            .map(|s| {
                s.z.iter()
                    .map(|_| {
                        let v: f64 = r.random();
                        if v < 0.2 {
                            0.0
                        } else {
                            2.0 * r.random::<f64>()
                        }
                    })
                    .collect()
            })
            .collect();
        write(&out, "synthetic", &scans, &lr, [3.0, 0.0])?;
    } else {
        println!("SKIPPED: no synthetic log given");
    }
    Ok(())
}

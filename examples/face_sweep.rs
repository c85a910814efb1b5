//! Sweep (development aid, not part of the pipeline): frontal-face recall and false faces of
//! face-detector settings on the camera frames of `biron_home` logs, scored exactly as the
//! pipeline's `faces_by_width` (a detection matches a true face when its centre is within half
//! the face width and its width within a factor 2; frontal = yaw ≤ 15°, faces ≥ 24 px wide).
//!
//! Usage: `cargo run --release --example face_sweep -- LOG.mcap... [NAME:key=value,...]...`
//! with keys `thresh`, `min_face`, `pyramid`, `step`, `upscale`; the system's default settings are always
//! the first row.

use peopletrack::frames::{camera, truth};
use peopletrack::groundtruth::biron::BIRON_TOPIC;
use peopletrack::log::SessionLog;
use peopletrack::pipelines::s003_biron_anchoring::params::Params;
use peopletrack::pipelines::s003_biron_anchoring::score;
use peopletrack::vision::faces::{FaceDetector, FaceParams, grey_from_rgb};
use peopletrack::vision::view::ImageView;

fn variant(spec: &str) -> Result<(String, FaceParams), String> {
    let (name, kv) = spec
        .split_once(':')
        .ok_or(format!("{spec}: NAME:key=value,..."))?;
    let mut f = FaceParams::default();
    for pair in kv.split(',').filter(|s| !s.is_empty()) {
        let (k, v) = pair.split_once('=').ok_or(format!("{pair}: key=value"))?;
        let x: f64 = v.parse().map_err(|e| format!("{pair}: {e}"))?;
        match k {
            "thresh" => f.score_thresh = x,
            "min_face" => f.min_face_px = x as u32,
            "pyramid" => f.pyramid_scale = x as f32,
            "step" => f.step_px = x as u32,
            "upscale" => f.upscale = x as u32,
            _ => return Err(format!("unknown key {k}")),
        }
    }
    Ok((name.to_string(), f))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut variants = vec![("default".to_string(), FaceParams::default())];
    let mut logs = Vec::new();
    for a in &args {
        if a.ends_with(".mcap") {
            logs.push(a.clone());
        } else {
            variants.push(variant(a)?);
        }
    }
    let p = Params::default();
    let mut dets = variants
        .iter()
        .map(|(_, f)| FaceDetector::new(*f))
        .collect::<Result<Vec<_>, _>>()?;
    // per variant: frontal faces >= 24 px, found; 32-48 px, found; false faces; frames;
    // faces turned >= 45 deg, found
    let mut tally = vec![[0u64; 8]; variants.len()];
    for path in &logs {
        let log = SessionLog::open(path)?;
        let (gt, _) = truth::biron(&log, BIRON_TOPIC)?;
        for f in camera::frames(&log, "/camera/image_raw/compressed", None)? {
            let f = f?;
            let Some(tr) = gt.nearest(f.stamp, 20_000_000) else {
                continue;
            };
            let grey = grey_from_rgb(ImageView::rgb(&f.rgb)?)?;
            let (w, h) = (f.rgb.width() as usize, f.rgb.height() as usize);
            for (v, det) in dets.iter_mut().enumerate() {
                let found = det.detect(ImageView::new(&grey, w, h, 1)?)?;
                let (rows, falses) = score::faces(0, tr, &found, &p);
                let t = &mut tally[v];
                for r in rows
                    .iter()
                    .filter(|r| r.yaw_deg.abs() <= p.frontal_max_deg && r.width_px >= 24.0)
                {
                    t[0] += 1;
                    t[1] += u64::from(r.detected);
                    if r.width_px < 48.0 && r.width_px >= 32.0 {
                        t[2] += 1;
                        t[3] += u64::from(r.detected);
                    }
                }
                for r in rows
                    .iter()
                    .filter(|r| r.yaw_deg.abs() >= 45.0 && r.width_px >= 24.0)
                {
                    t[6] += 1;
                    t[7] += u64::from(r.detected);
                }
                t[4] += falses as u64;
                t[5] += 1;
            }
        }
    }
    println!(
        "variant | frontal >= 24 px | recall | 32-48 px recall | false faces per 100 frames | turned >= 45 deg recall"
    );
    for ((name, _), t) in variants.iter().zip(&tally) {
        println!(
            "{name} | {} | {:.3} | {:.3} | {:.2} | {:.3}",
            t[0],
            t[1] as f64 / t[0].max(1) as f64,
            t[3] as f64 / t[2].max(1) as f64,
            100.0 * t[4] as f64 / t[5].max(1) as f64,
            t[7] as f64 / t[6].max(1) as f64
        );
    }
    Ok(())
}

//! Seed 001's Method 1 (`vision::egomotion`) on synthetic `segway_park` logs: per omni frame
//! the detection's bearing against the followed person's (id 1) true bearing in the omni camera
//! frame (ground truth at the frame stamp, person's chest at 0.6 × height, camera pose from TF
//! at the stamp), and the robot speed from the nearest odometry. Prints the loss rate per
//! robot-speed bin (0.25 m/s) at two loss thresholds. A measurement, never a tuning loop: the
//! parameters are `Method1Params::default()`.
//!
//! Usage: `cargo run --release --example method1_probe [-- [--dump DIR] LOG.mcap …]`
//! (`--dump`: every 20th frame's omni image with the true and detected bearings, and the
//! difference views, as PNGs in DIR)
//! (default: `datasets/segway_park/segway_park_00.mcap` and `_01`).

use nalgebra::Point3;
use peopletrack::Nanos;
use peopletrack::frames::{camera, motion, rig, truth};
use peopletrack::geometry::camera::CameraModel;
use peopletrack::log::{SessionLog, TfBuffer};
use peopletrack::vision::egomotion::{Method1, Method1Params, is_lost, loss_by_speed};

type Res<T> = Result<T, Box<dyn std::error::Error>>;

const CAMERA: &str = "omni_camera";
const TARGET_ID: u32 = 1;
/// Loss thresholds on the azimuth error (rad): 10° and 20°.
const THRESHOLDS: [f64; 2] = [0.1745, 0.349];

struct Sample {
    speed: f64,
    error: Option<f64>,
    /// The target's visible fraction in the omni image (ground truth; 0 when not listed).
    visibility: f64,
}

/// Truth check: the TF-derived bearing against the bearing of the person's projected head in
/// the omni image (ground truth's `head_px`): largest difference seen (rad).
fn head_px_bearing(p: &peopletrack::groundtruth::PersonTruth, xc: f64, yc: f64) -> Option<f64> {
    let v = p.cameras.iter().find(|c| c.camera == CAMERA)?;
    let h = v.head_px?;
    Some((h[1] - yc).atan2(h[0] - xc))
}

/// Writes the omni image with the true (green) and detected (red) bearings drawn as rays from
/// the centre, and the 8 difference views side by side.
fn dump(
    dir: &str,
    k: usize,
    rgb: &image::RgbImage,
    m: &Method1,
    true_az: f64,
    det: Option<f64>,
) -> Res<()> {
    let model = m.views().omni();
    let mut img = rgb.clone();
    for (az, colour) in [(Some(true_az), [0, 255, 0]), (det, [255, 0, 0])] {
        let Some(az) = az else { continue };
        for r in (model.r_min as i32)..(model.r_max as i32) {
            let (x, y) = (
                model.xc + f64::from(r) * az.cos(),
                model.yc + f64::from(r) * az.sin(),
            );
            if x >= 0.0 && y >= 0.0 && (x as u32) < img.width() && (y as u32) < img.height() {
                img.put_pixel(x as u32, y as u32, image::Rgb(colour));
            }
        }
    }
    img.save(format!("{dir}/omni_{k:04}.png"))?;
    let d = m.differences();
    if let Some(first) = d.first() {
        let (w, h) = (first.width as u32, first.height as u32);
        let tiles = image::GrayImage::from_fn(w * d.len() as u32, h, |x, y| {
            let p = &d[(x / w) as usize];
            image::Luma([p.at((x % w) as usize, y as usize).min(255.0) as u8])
        });
        tiles.save(format!("{dir}/diff_{k:04}.png"))?;
    }
    Ok(())
}

fn session(path: &str, seed: u64, dump_dir: Option<&str>) -> Res<(Vec<Sample>, [f64; 3])> {
    let log = SessionLog::open(path)?;
    let tf = TfBuffer::from_log(&log, 0.0)?;
    let cam = rig::camera(
        &log,
        &tf,
        CAMERA,
        &format!("/{CAMERA}/camera_info"),
        "map",
        None,
    )?;
    let CameraModel::Paracatadioptric(model) = cam.model()? else {
        return Err(format!("{path}: {CAMERA} is not paracatadioptric").into());
    };
    let (people, _) = truth::people(&log, peopletrack::groundtruth::PEOPLE_TOPIC)?;
    let odom = motion::odometry(&log, "/odom")?;
    let topic = camera::image_topic(&log, CAMERA).ok_or("no omni image topic")?;
    let mut m = Method1::new(&model, &Method1Params::default(), seed)?;
    let mut out = Vec::new();
    let (mut features, mut fallbacks, mut steps) = (0usize, 0usize, 0usize);
    let mut worst_truth_check = 0.0f64;
    for f in &mut camera::frames(&log, &topic, None)? {
        let f = f?;
        let res = m.step(&f.rgb)?;
        features += res.features_tracked;
        fallbacks += res.fallback_views;
        steps += 1;
        if steps == 1 {
            continue; // no previous frame yet
        }
        let Some(frame) = people.nearest(f.stamp, 60_000_000) else {
            continue;
        };
        let Some(p) = frame.people.iter().find(|p| p.id == TARGET_ID) else {
            continue;
        };
        let Ok(map_from_cam) = tf.lookup("map", &cam.frame, Nanos(f.stamp.0)) else {
            continue;
        };
        let q = map_from_cam.inverse_transform_point(&Point3::new(p.x, p.y, 0.6 * p.height));
        let true_az = q.y.atan2(q.x);
        if let Some(b) = head_px_bearing(p, model.xc, model.yc) {
            worst_truth_check = worst_truth_check
                .max(peopletrack::vision::egomotion::views::wrap_angle(b - true_az).abs());
        }
        let Some(o) = odom.samples.nearest(f.stamp, 100_000_000) else {
            continue;
        };
        let speed = o.linear.x.hypot(o.linear.y);
        let error = res
            .detection
            .map(|d| peopletrack::vision::egomotion::views::wrap_angle(d.azimuth - true_az).abs());
        if let Some(dir) = dump_dir
            && steps % 20 == 0
        {
            dump(
                dir,
                steps,
                &f.rgb,
                &m,
                true_az,
                res.detection.map(|d| d.azimuth),
            )?;
        }
        let visibility = p
            .cameras
            .iter()
            .find(|c| c.camera == CAMERA)
            .map_or(0.0, |c| c.visibility);
        out.push(Sample {
            speed,
            error,
            visibility,
        });
    }
    println!(
        "{path}: truth check, TF bearing vs head_px bearing: worst {:.2} deg",
        worst_truth_check.to_degrees()
    );
    let n = steps.saturating_sub(1).max(1) as f64;
    Ok((
        out,
        [features as f64 / n, fallbacks as f64 / n, steps as f64],
    ))
}

fn main() -> Res<()> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let dump_dir = match args.iter().position(|a| a == "--dump") {
        Some(i) if i + 1 < args.len() => {
            let d = args.remove(i + 1);
            args.remove(i);
            Some(d)
        }
        _ => None,
    };
    let mut logs = args;
    if logs.is_empty() {
        logs = ["00", "01"]
            .iter()
            .map(|s| format!("datasets/segway_park/segway_park_{s}.mcap"))
            .collect();
    }
    let mut all = Vec::new();
    for (i, path) in logs.iter().enumerate() {
        let (samples, [feat, fb, frames]) = session(path, i as u64, dump_dir.as_deref())?;
        let detected = samples.iter().filter(|s| s.error.is_some()).count();
        let mut errs: Vec<f64> = samples.iter().filter_map(|s| s.error).collect();
        errs.sort_by(f64::total_cmp);
        let median = errs.get(errs.len() / 2).copied().unwrap_or(f64::NAN);
        println!(
            "{path}: {frames} frames, {} scored, {detected} with a detection, median |az error| {:.1} deg, {feat:.0} features/frame, {fb:.2} fallback views/frame",
            samples.len(),
            median.to_degrees()
        );
        all.extend(samples);
    }
    for th in THRESHOLDS {
        let lost: Vec<(f64, bool)> = all
            .iter()
            .map(|s| (s.speed, is_lost(s.error, 0.0, th)))
            .collect();
        let total = lost.iter().filter(|l| l.1).count();
        let visible: Vec<&Sample> = all.iter().filter(|s| s.visibility >= 0.5).collect();
        let lost_visible = visible.iter().filter(|s| is_lost(s.error, 0.0, th)).count();
        println!(
            "\nthreshold {:.0} deg: a uniformly random bearing would be lost in {:.1} % of frames; frames with the target at least half visible: {} ({lost_visible} lost)",
            th.to_degrees(),
            100.0 * (1.0 - th / std::f64::consts::PI),
            visible.len()
        );
        println!(
            "threshold {:.0} deg: lost {total} of {} frames ({:.1} %)",
            th.to_degrees(),
            lost.len(),
            100.0 * total as f64 / lost.len().max(1) as f64
        );
        println!("speed m/s     frames  lost  rate");
        for b in loss_by_speed(&lost, 0.25) {
            println!(
                "{:.2}-{:.2}  {:>8} {:>5}  {:.3}",
                b.lo, b.hi, b.frames, b.lost, b.rate
            );
        }
    }
    Ok(())
}

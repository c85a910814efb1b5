//! Seed 001's Method 1 (`vision::egomotion`) on synthetic `segway_park` logs: per omni frame
//! the detection's bearing against the followed person's (id 1) true bearing in the omni camera
//! frame (ground truth at the frame stamp, person's chest at 0.6 × height, camera pose from TF
//! at the stamp), and the robot speed from the nearest odometry. Prints the loss rate per
//! robot-speed bin (0.25 m/s) at two loss thresholds. A measurement, never a tuning loop: the
//! parameters are `Method1Params::default()`.
//!
//! Usage: `cargo run --release --example method1_probe [-- LOG.mcap …]`
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
}

fn session(path: &str, seed: u64) -> Res<(Vec<Sample>, [f64; 3])> {
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
        let Some(o) = odom.samples.nearest(f.stamp, 100_000_000) else {
            continue;
        };
        let speed = o.linear.x.hypot(o.linear.y);
        let error = res
            .detection
            .map(|d| peopletrack::vision::egomotion::views::wrap_angle(d.azimuth - true_az).abs());
        out.push(Sample { speed, error });
    }
    let n = steps.saturating_sub(1).max(1) as f64;
    Ok((
        out,
        [features as f64 / n, fallbacks as f64 / n, steps as f64],
    ))
}

fn main() -> Res<()> {
    let mut logs: Vec<String> = std::env::args().skip(1).collect();
    if logs.is_empty() {
        logs = ["00", "01"]
            .iter()
            .map(|s| format!("datasets/segway_park/segway_park_{s}.mcap"))
            .collect();
    }
    let mut all = Vec::new();
    for (i, path) in logs.iter().enumerate() {
        let (samples, [feat, fb, frames]) = session(path, i as u64)?;
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
        println!(
            "\nthreshold {:.0} deg: lost {total} of {} frames ({:.1} %)",
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

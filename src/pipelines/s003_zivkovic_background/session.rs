//! One session: a single pass over the camera's frames in time order, each frame handed to
//! the sub-experiments that run on this session (ROC and timing on the dynamic-background
//! scenes with exact masks, the colour trackers on `colour.datasets`, local tracks on every
//! session); then their cached tables and the `session` row. At aggregation, the `sessions`
//! table of what was read and skipped.

use std::collections::BTreeMap;

use image::RgbImage;

use super::colour::ColourRun;
use super::local_tracks::LocalRun;
use super::moving::MovingRun;
use super::params::{LocalEvalParams, Params, topics_of};
use super::reid::ReidRun;
use super::roc::RocRun;
use super::shared::{Frame, SESSION_TABLE, SessionRow, session_row};
use super::timing::TimingRun;
use crate::Nanos;
use crate::frames::{Stamped, camera, motion, truth};
use crate::groundtruth::PeopleFrame;
use crate::log::msgs::Odometry;
use crate::log::tf::TfBuffer;
use crate::progress::Progress;
use crate::report::Table;
use crate::report::rows::Rows;
use crate::run::{Aggregate, Products, Session, SessionTables};
use crate::table_row;
use crate::vision::ImageView;

/// Ground truth is joined to a frame when its stamp is this close (ns).
const GT_TOLERANCE_NS: u64 = 20_000_000;
/// Odometry is joined to a frame when its stamp is this close (ns).
const ODOM_TOLERANCE_NS: u64 = 200_000_000;

/// What a session has besides its frames: ground truth and camera motion.
struct Context {
    ground_truth: Stamped<PeopleFrame>,
    bad_ground_truth: i64,
    bad_odometry: i64,
    /// The first undecodable odometry message's error, if any.
    odometry_error: Option<String>,
    /// Odometry by stamp; empty for a camera that does not ride the robot.
    odometry: Stamped<Odometry>,
    camera_rides_robot: bool,
}

fn context(s: &Session, p: &Params, gt_topic: &str, odom_topic: &str) -> anyhow::Result<Context> {
    let log = &s.log;
    let (ground_truth, gt_skips) = truth::people(log, gt_topic)?;
    let mut odom = motion::odometry(log, odom_topic)?;
    // a TF that cannot be read leaves the odometry trusted, as without TF
    let rides = odom.child_frame.is_empty()
        || TfBuffer::from_log(log, 0.0).map_or(true, |tf| {
            motion::camera_rides_robot(&tf, &p.camera, &odom.child_frame)
        });
    if !rides {
        odom.samples.clear(); // a fixed camera: never moving, whatever the robot does
    }
    Ok(Context {
        ground_truth,
        bad_ground_truth: gt_skips.count(gt_topic) as i64,
        bad_odometry: odom.skips.count(odom_topic) as i64,
        odometry_error: odom.skips.first_error().map(str::to_string),
        odometry: odom.samples,
        camera_rides_robot: rides,
    })
}

/// Odometry says the robot moves at `t`: the mean speed or turn rate of the samples stamped
/// in the `moving_window_s` before `t` (inclusive) above the thresholds; with no sample in
/// the window (or a zero window), the nearest sample within [`ODOM_TOLERANCE_NS`]. Averaging
/// keeps the yaw-rate noise of a robot standing still (σ ≈ 0.01 rad/s per sample on
/// `home_tour`, so a single sample crossed 0.02 rad/s on ~5 % of frames) from restarting the
/// background model.
fn is_moving(odometry: &Stamped<Odometry>, t: Nanos, p: &LocalEvalParams) -> bool {
    let over = |vx: f64, vy: f64, wz: f64| {
        vx.hypot(vy) > p.moving_speed_mps || wz.abs() > p.moving_turn_rad_s
    };
    let window_ns = (p.moving_window_s * 1e9) as u64;
    let stamps = odometry.stamps();
    let hi = stamps.partition_point(|s| s.0 <= t.0);
    let lo = stamps.partition_point(|s| s.0.saturating_add(window_ns) < t.0);
    if window_ns > 0 && lo < hi {
        let items = &odometry.items()[lo..hi];
        let n = items.len() as f64;
        let sum = |f: &dyn Fn(&Odometry) -> f64| items.iter().map(f).sum::<f64>() / n;
        return over(
            sum(&|o| o.linear.x),
            sum(&|o| o.linear.y),
            sum(&|o| o.angular.z),
        );
    }
    odometry
        .nearest(t, ODOM_TOLERANCE_NS)
        .is_some_and(|o| over(o.linear.x, o.linear.y, o.angular.z))
}

/// The per-session stage: every sub-experiment's cached tables and the `session` row.
pub(super) fn process(
    s: &Session,
    p: &Params,
    topics: &BTreeMap<String, String>,
    bar: &dyn Progress,
) -> anyhow::Result<SessionTables> {
    let tp = topics_of(p, topics);
    let log = &s.log;
    let has_mask = log.summary().channel(&tp.mask).is_some();
    // ROC, timing and the components image: the dynamic-background scenes only
    let gmm_scene = has_mask && !p.roc.exclude_datasets.contains(&s.info.dataset);
    let cx = context(s, p, &tp.ground_truth, &tp.odom)?;
    let summary = log.summary();
    if let (Some(ch), Some(st)) = (summary.channel(&tp.image), &summary.statistics) {
        bar.set_length(st.channel_message_counts.get(&ch.id).copied().unwrap_or(0));
    }
    bar.set_message("frames");

    let mut roc = RocRun::new(p, gmm_scene)?;
    let mut timing = gmm_scene.then(|| TimingRun::new(p)).transpose()?;
    let colour_wanted =
        p.colour.datasets.contains(&s.info.dataset) && has_mask && !cx.ground_truth.is_empty();
    let mut colour = ColourRun::new(p, colour_wanted);
    let mut local = LocalRun::new(p)?;
    let mut reid = ReidRun::new(p, &s.info.dataset);
    // a re-identified session without the exact person mask pairs its frames with the
    // per-person id mask instead (re-identification's ceiling row), when it has one
    let ids_topic = (!has_mask && reid.wanted() && summary.channel(&tp.person_ids).is_some())
        .then_some(tp.person_ids.as_str());
    let mut moving = MovingRun::new(p, &p.moving, cx.camera_rides_robot);
    let mut first_stamp: Option<Nanos> = None;
    let mut frame_index: i64 = -1;
    let mut shape = (0u32, 0u32);
    let mut last_rgb: Option<RgbImage> = None;

    let mask_topic = has_mask.then_some(tp.mask.as_str());
    let mut frames = camera::frames(log, &tp.image, mask_topic.or(ids_topic))?;
    for f in &mut frames {
        let f = f?;
        frame_index += 1;
        bar.inc(1);
        let t0 = *first_stamp.get_or_insert(f.stamp);
        let (w, h) = (f.rgb.width(), f.rgb.height());
        if frame_index == 0 {
            shape = (w, h);
        } else if shape != (w, h) {
            anyhow::bail!(
                "{}: {} at {} ns: frame is {w}x{h}, earlier frames were {}x{}",
                log.path().display(),
                tp.image,
                f.stamp.0,
                shape.0,
                shape.1
            );
        }
        let frame = Frame {
            index: frame_index,
            t_s: f.stamp.0.saturating_sub(t0.0) as f64 * 1e-9,
            rgb: &f.rgb,
            view: ImageView::rgb(&f.rgb)?,
            mask: mask_topic
                .and(f.mask.as_ref())
                .map(|m| m.as_raw().as_slice()),
            person_ids: ids_topic
                .and(f.mask.as_ref())
                .map(|m| m.as_raw().as_slice()),
            truth: cx.ground_truth.nearest(f.stamp, GT_TOLERANCE_NS),
            moving: is_moving(&cx.odometry, f.stamp, &p.local_eval),
        };
        roc.step(&frame)?;
        if let Some(t) = timing.as_mut() {
            t.step(&frame)?;
        }
        colour.step(&frame)?;
        local.step(&frame)?;
        reid.step(&frame, local.frame_tracks(frame.index), local.foreground());
        moving.step(&frame);
        last_rgb = Some(f.rgb);
    }
    let frames_without_mask = frames.frames_without_mask() as i64;
    let skips = frames.into_skips();
    let bad_images = skips.count(&tp.image) as i64;
    let first_error = skips
        .first_error()
        .map(str::to_string)
        .or_else(|| cx.odometry_error.clone())
        .unwrap_or_default();
    if frame_index < 0 {
        anyhow::bail!(
            "{}: no decodable frame on {} ({bad_images} bad images; first error: {})",
            log.path().display(),
            tp.image,
            skips.first_error().unwrap_or("none")
        );
    }

    let mut out = SessionTables::new();
    let mut row = SessionRow {
        dataset: s.info.dataset.clone(),
        session: s.info.name.clone(),
        frames: frame_index + 1,
        width: i64::from(shape.0),
        height: i64::from(shape.1),
        has_mask,
        bad_images,
        bad_masks: mask_topic
            .or(ids_topic)
            .map_or(0, |m| skips.count(m) as i64),
        frames_without_mask,
        bad_ground_truth: cx.bad_ground_truth,
        bad_odometry: cx.bad_odometry,
        first_error,
        camera_rides_robot: cx.camera_rides_robot,
        colour_frame0: colour.frame0(),
        ..Default::default()
    };
    roc.finish(&mut out)?;
    if let Some(t) = timing {
        t.finish(last_rgb.as_ref(), &mut out)?;
    }
    colour.finish(&mut out)?;
    local.finish(!cx.ground_truth.is_empty(), &mut row, &mut out)?;
    reid.finish(&mut out)?;
    moving.finish(&s.info.dataset, &s.info.name, &mut out)?;
    out.insert(SESSION_TABLE.into(), SessionRow::frame(&[row])?);
    Ok(out)
}

table_row! {
    /// A row of the `sessions` table.
    #[derive(Debug, Clone, PartialEq)]
    struct SessionsRow {
        dataset: String,
        session: String,
        frames: i64,
        bad_images: i64,
        bad_masks: i64,
        frames_without_mask: i64,
        bad_ground_truth: i64,
        bad_odometry: i64,
        first_error: String,
    }
}

/// The `sessions` table: frames read and the bad messages each session skipped (counted, with
/// the first error, which names the file, topic and log time), and a summary line for every
/// session that skipped any.
pub(super) fn products(ctx: &Aggregate, products: &mut Products) -> anyhow::Result<()> {
    let mut rows = Vec::new();
    for (info, tables) in ctx.sessions {
        if !tables.contains_key(SESSION_TABLE) {
            continue;
        }
        let r = session_row(tables);
        if r.bad_images + r.bad_masks + r.bad_ground_truth + r.bad_odometry > 0 {
            products.summary.push(format!(
                "{}: skipped {} undecodable image(s), {} mask(s), {} ground-truth message(s), {} odometry message(s); first: {}",
                info.path.display(),
                r.bad_images,
                r.bad_masks,
                r.bad_ground_truth,
                r.bad_odometry,
                if r.first_error.is_empty() { "(ground truth JSON)" } else { &r.first_error }
            ));
        }
        rows.push(SessionsRow {
            dataset: info.dataset.clone(),
            session: info.name.clone(),
            frames: r.frames,
            bad_images: r.bad_images,
            bad_masks: r.bad_masks,
            frames_without_mask: r.frames_without_mask,
            bad_ground_truth: r.bad_ground_truth,
            bad_odometry: r.bad_odometry,
            first_error: r.first_error,
        });
    }
    products.tables.push(
        Table::new(
            "sessions",
            "Sessions read: frames and the bad messages skipped (counted, never fatal)",
            SessionsRow::frame(&rows)?,
        )
        .with_note("An image or mask message that does not decode is skipped and counted (as is an unreadable ground-truth or odometry message); first_error names the file, topic and log time of the first one. A log that cannot be read, or lacks the image topic, is skipped by the runner with its reason."),
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Odometry at 50 Hz from t = 0 with the given yaw rates (rad/s).
    fn series(rates: &[f64]) -> Stamped<Odometry> {
        Stamped::new(
            rates
                .iter()
                .enumerate()
                .map(|(i, &w)| {
                    let mut o = Odometry::default();
                    o.angular.z = w;
                    (Nanos(i as u64 * 20_000_000), o)
                })
                .collect(),
        )
    }

    fn at(i: u64) -> Nanos {
        Nanos(i * 20_000_000)
    }

    #[test]
    fn moving_is_the_mean_twist_over_the_window_not_one_noisy_sample() {
        let p = LocalEvalParams::default(); // 0.02 rad/s over 0.3 s
        assert_eq!(p.moving_window_s, 0.3);
        // yaw-rate noise of ±0.03 rad/s: every sample crosses 0.02, the mean is 0
        let noisy: Vec<f64> = (0..50)
            .map(|i| if i % 2 == 0 { 0.03 } else { -0.03 })
            .collect();
        let noisy = series(&noisy);
        assert!(!is_moving(&noisy, at(40), &p));
        let single = LocalEvalParams {
            moving_window_s: 0.0,
            ..p.clone()
        };
        assert!(is_moving(&noisy, at(40), &single));
        // a turn of 0.05 rad/s from sample 30: at sample 40 the 0.3 s window holds 11 of its
        // 15–16 samples (mean ≥ 0.034), at sample 33 only 4 (mean ≤ 0.013)
        let step: Vec<f64> = (0..50).map(|i| if i < 30 { 0.0 } else { 0.05 }).collect();
        let step = series(&step);
        assert!(is_moving(&step, at(40), &p));
        assert!(!is_moving(&step, at(33), &p));
        // no sample in the window: the nearest one within 0.2 s, else still
        let short = LocalEvalParams {
            moving_window_s: 0.1,
            ..p
        };
        assert!(is_moving(&step, Nanos(1_100_000_000), &short));
        assert!(!is_moving(&step, Nanos(1_200_000_000), &short));
    }
}

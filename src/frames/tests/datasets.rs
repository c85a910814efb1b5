//! The layer on the synthetic datasets' logs (symlinked under `datasets/`; SKIPPED when absent).

use std::path::PathBuf;

use crate::frames::{ImageMsg, camera, motion, multicam, rig, truth};
use crate::groundtruth::PEOPLE_TOPIC;
use crate::log::TfBuffer;

fn dataset(rel: &str) -> Option<PathBuf> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(rel);
    if p.exists() {
        Some(p)
    } else {
        println!("SKIPPED: {rel} not found");
        None
    }
}

/// s003's session: one camera, every image paired with its mask and its ground truth; the
/// camera hangs from `map`, not from the robot.
#[test]
fn home_tour_camera_masks_truth_and_motion() {
    let Some(path) = dataset("datasets/home_tour_bg_lab/home_tour_bg_lab_00.mcap") else {
        return;
    };
    let log = super::open(&path);
    let (gt, gt_skips) = truth::people(&log, PEOPLE_TOPIC).expect("truth");
    let mut cam = camera::frames(
        &log,
        "/cam_0/image_raw/compressed",
        Some("/cam_0/ground_truth_mask"),
    )
    .expect("frames");
    let (mut n, mut masked, mut joined) = (0, 0, 0);
    for f in cam.by_ref() {
        let f = f.expect("frame");
        n += 1;
        masked += usize::from(f.mask.is_some());
        joined += usize::from(gt.nearest(f.stamp, 20_000_000).is_some());
    }
    assert_eq!((n, masked, joined, gt.len()), (360, 360, 360, 360));
    assert!(cam.skips().is_empty() && gt_skips.is_empty());
    assert_eq!(
        (cam.frames_without_mask(), cam.masks_without_image()),
        (0, 0)
    );
    let m = motion::odometry(&log, "/odom").expect("odom");
    assert_eq!(
        (m.samples.len(), m.child_frame.as_str()),
        (1200, "base_link")
    );
    let tf = TfBuffer::from_log(&log, 0.0).expect("tf");
    assert!(!motion::camera_rides_robot(&tf, "cam_0", "base_link"));
}

/// s004's session: four cameras grouped at its 15 ms tolerance, calibrated from TF.
#[test]
fn multicam_office_frames_and_rig() {
    let Some(path) = dataset("datasets/multicam_office/multicam_office_00.mcap") else {
        return;
    };
    let log = super::open(&path);
    let names: Vec<String> = (0..4).map(|c| format!("cam_{c}")).collect();
    let topics: Vec<String> = names
        .iter()
        .map(|c| format!("/{c}/image_raw/compressed"))
        .collect();
    let mut frames = multicam::group::<ImageMsg>(&log, &topics, 15_000_000).expect("group");
    let (mut n, mut missing) = (0, 0);
    for f in frames.by_ref() {
        let f = f.expect("frame");
        n += 1;
        missing += f.missing();
    }
    println!("{n} frames, {missing} camera frames missing");
    assert_eq!((n, missing), (300, 0));
    assert!(frames.skips().is_empty());
    let tf = TfBuffer::from_log(&log, 0.0).expect("tf");
    let cams: Vec<(String, String)> = names
        .iter()
        .map(|c| (c.clone(), format!("/{c}/camera_info")))
        .collect();
    let views = rig::views(&log, &tf, &cams, "map").expect("rig");
    assert_eq!(views.len(), 4);
    for v in &views {
        assert!(v.center().coords.norm() > 0.5, "a camera off the origin");
    }
}

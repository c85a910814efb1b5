use std::f64::consts::FRAC_PI_4;

use nalgebra::{Quaternion, UnitQuaternion, Vector3};

use super::{open, s, writer};
use crate::frames::laser::{self, LaserOptions};
use crate::log::msgs::{Header, LaserScan, TfMessage, Transform, TransformStamped};
use crate::time::Nanos;

fn tf(stamp: Nanos, parent: &str, child: &str, xyz: [f64; 3], yaw: f64) -> TransformStamped {
    let q = UnitQuaternion::from_euler_angles(0.0, 0.0, yaw).into_inner();
    TransformStamped {
        header: Header::new(stamp, parent),
        child_frame_id: child.into(),
        transform: Transform {
            translation: Vector3::from(xyz),
            rotation: Quaternion::new(q.w, q.i, q.j, q.k),
        },
    }
}

fn scan(stamp: Nanos, ranges: Vec<f32>) -> LaserScan {
    LaserScan {
        header: Header::new(stamp, "/laser"),
        angle_min: -0.5,
        angle_max: 0.5,
        angle_increment: 0.2,
        range_min: 0.05,
        range_max: 10.0,
        ranges,
        ..Default::default()
    }
}

/// `/odom -> /base_link` (ROS 1 names) at 1.0 s (origin, yaw 0) and 2.0 s (x = 2, yaw 90°);
/// `base_link -> laser` static at (0.5, 0, 0.2), yaw 90°. Scans at 1.5 s, 5.0 s (3 s beyond the
/// TF samples) and one garbage message.
#[test]
fn scans_carry_the_sensor_pose_from_tf_and_no_return_flags() {
    let dir = tempfile::tempdir().expect("tmp");
    let (mut w, path) = writer(dir.path(), "laser");
    let tf_ch = w.add_ros2::<TfMessage>("/tf").expect("ch");
    let st_ch = w.add_ros2::<TfMessage>("/tf_static").expect("ch");
    let sc = w.add_ros2::<LaserScan>("/scan").expect("ch");
    let right = 2.0 * FRAC_PI_4;
    w.write(
        st_ch,
        s(900),
        &TfMessage {
            transforms: vec![tf(s(900), "base_link", "laser", [0.5, 0.0, 0.2], right)],
        },
    )
    .expect("w");
    for (ms, x, yaw) in [(1000, 0.0, 0.0), (2000, 2.0, right)] {
        let t = tf(s(ms), "/odom", "/base_link", [x, 0.0, 0.0], yaw);
        w.write(
            tf_ch,
            s(ms),
            &TfMessage {
                transforms: vec![t],
            },
        )
        .expect("w");
    }
    let ranges = vec![1.0, f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.0, 2.5];
    w.write(sc, s(2100), &scan(s(1500), ranges)).expect("w");
    w.write_bytes(sc, s(2200), &[0, 1]).expect("w");
    w.write(sc, s(5100), &scan(s(5000), vec![3.0])).expect("w");
    w.finish().expect("finish");

    let log = open(&path);
    let mut scans = laser::scans(&log, "/scan", &LaserOptions::default()).expect("scans");
    let a = scans.next().expect("one").expect("ok");
    assert_eq!(scans.fixed_frame(), Some("odom"));
    assert_eq!(
        (a.stamp, a.log_time, a.frame.as_str()),
        (s(1500), s(2100), "laser")
    );
    assert_eq!(a.no_return, vec![false, true, true, true, true, false]);
    assert_eq!(a.scan.ranges.len(), 6);
    assert!(a.scan.ranges[1].is_nan(), "ranges are kept as written");
    // odom <- base_link at 1.5 s: x = 1, yaw 45°; then the laser's offset, rotated by 45°
    let pose = a.pose.expect("posed");
    let t = pose.translation.vector;
    let (c, sn) = (FRAC_PI_4.cos(), FRAC_PI_4.sin());
    assert!(
        (t - Vector3::new(1.0 + 0.5 * c, 0.5 * sn, 0.2)).norm() < 1e-12,
        "{t}"
    );
    let (roll, pitch, yaw) = pose.rotation.euler_angles();
    assert!(roll.abs() < 1e-12 && pitch.abs() < 1e-12);
    assert!((yaw - 3.0 * FRAC_PI_4).abs() < 1e-12, "{yaw}");
    // the laser's x axis (its 0 rad beam) points at 135° in odom
    let beam = pose.rotation * Vector3::x();
    assert!((beam - Vector3::new(-c, sn, 0.0)).norm() < 1e-12);

    let b = scans.next().expect("two").expect("ok");
    assert_eq!((b.stamp, b.pose, b.no_return), (s(5000), None, vec![false]));
    assert!(scans.next().is_none());
    assert_eq!(scans.unposed(), 1);
    assert_eq!(scans.skips().count("/scan"), 1);
    assert!(
        scans
            .skips()
            .first_error()
            .is_some_and(|e| e.contains("/scan at log time 2.200000000 s")),
    );
    assert!(laser::is_no_return(0.0) && !laser::is_no_return(0.01));
}

#[test]
fn without_tf_scans_stay_in_the_sensor_frame() {
    let dir = tempfile::tempdir().expect("tmp");
    let (mut w, path) = writer(dir.path(), "laser_no_tf");
    let sc = w.add_ros2::<LaserScan>("/scan").expect("ch");
    w.write(sc, s(100), &scan(s(90), vec![0.0, 4.0]))
        .expect("w");
    w.finish().expect("finish");
    let log = open(&path);
    let mut scans = laser::scans(&log, "/scan", &LaserOptions::default()).expect("scans");
    let a = scans.next().expect("one").expect("ok");
    assert_eq!(scans.fixed_frame(), Some("laser"));
    assert_eq!(a.pose, Some(nalgebra::Isometry3::identity()));
    assert_eq!(a.no_return, vec![true, false]);
    // a fixed frame TF does not know: no pose
    let asked = LaserOptions {
        fixed_frame: Some("/map".into()),
        ..LaserOptions::default()
    };
    let mut scans = laser::scans(&log, "/scan", &asked).expect("scans");
    assert_eq!(scans.next().expect("one").expect("ok").pose, None);
    assert_eq!((scans.fixed_frame(), scans.unposed()), (Some("map"), 1));
}

/// The real wheelchair log (Leigh et al., ICRA 2015): 873 scans in `left_laser`, placed in
/// `odom` through `/odom -> /base_link -> left_laser` (ROS 1 frame names, all on `/tf`).
#[test]
fn real_laser_log_has_873_posed_scans() {
    let rel = "shared/real/laser/general_tracking_moving_1/general_tracking_moving_1.mcap";
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let Some(path) = [root.join("..").join(rel), root.join("../..").join(rel)]
        .into_iter()
        .find(|p| p.exists())
    else {
        println!("SKIPPED: {rel} not found next to the repository");
        return;
    };
    let log = open(&path);
    let mut scans = laser::scans(&log, "/scan", &LaserOptions::default()).expect("scans");
    let (mut n, mut beams, mut no_return) = (0usize, 0usize, 0usize);
    let mut first = None;
    for f in scans.by_ref() {
        let f = f.expect("scan");
        assert_eq!(f.frame, "left_laser");
        n += 1;
        beams += f.no_return.len();
        no_return += f.no_return.iter().filter(|x| **x).count();
        first.get_or_insert(f);
    }
    println!(
        "{n} scans, {beams} beams, {no_return} no return, {} unposed",
        scans.unposed()
    );
    assert_eq!(n, 873);
    assert_eq!(beams, 873 * 768);
    assert_eq!(scans.fixed_frame(), Some("odom"));
    assert!(scans.skips().is_empty());
    assert_eq!(scans.unposed(), 0);
    let first = first.expect("a scan");
    assert_eq!(first.stamp, Nanos(1_403_024_474_631_777_750));
}

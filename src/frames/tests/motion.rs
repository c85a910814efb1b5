use nalgebra::{Quaternion, Vector3};

use super::{open, s, writer};
use crate::frames::motion::{self, camera_rides_robot};
use crate::log::TfBuffer;
use crate::log::msgs::{Header, Odometry, Pose, Transform, TransformStamped};
use crate::time::Nanos;

fn odom(stamp: Nanos, vx: f64) -> Odometry {
    Odometry {
        header: Header::new(stamp, "odom"),
        child_frame_id: "/base_link".into(),
        pose: Pose::default(),
        pose_covariance: [0.0; 36],
        linear: Vector3::new(vx, 0.0, 0.0),
        angular: Vector3::zeros(),
        twist_covariance: [0.0; 36],
    }
}

#[test]
fn odometry_sorted_by_stamp_with_nearest_lookup() {
    let dir = tempfile::tempdir().expect("tmp");
    let (mut w, path) = writer(dir.path(), "odom");
    let ch = w.add_ros2::<Odometry>("/odom").expect("ch");
    w.write(ch, s(100), &odom(s(200), 2.0)).expect("w");
    w.write(ch, s(110), &odom(s(100), 1.0)).expect("w");
    w.write_bytes(ch, s(120), &[0]).expect("w");
    w.write(ch, s(130), &odom(s(300), 3.0)).expect("w");
    w.finish().expect("finish");
    let log = open(&path);
    let m = motion::odometry(&log, "/odom").expect("odom");
    assert_eq!(m.child_frame, "base_link");
    assert_eq!(m.samples.stamps(), &[s(100), s(200), s(300)]);
    assert_eq!(m.skips.count("/odom"), 1);
    let vx = |ms: u64, tol_ms: u64| {
        m.samples
            .nearest(s(ms), tol_ms * 1_000_000)
            .map(|o| o.linear.x)
    };
    assert_eq!(vx(240, 50), Some(2.0));
    assert_eq!(vx(250, 50), Some(2.0), "tie: the earlier");
    assert_eq!(vx(360, 50), None);
    let none = motion::odometry(&log, "/absent").expect("absent");
    assert!(none.samples.is_empty() && none.child_frame.is_empty());
}

fn tf(edges: &[(&str, &str)]) -> TfBuffer {
    let mut b = TfBuffer::new(0.0);
    for (parent, child) in edges {
        b.insert(
            &TransformStamped {
                header: Header::new(Nanos(1), *parent),
                child_frame_id: (*child).to_string(),
                transform: Transform {
                    translation: Vector3::zeros(),
                    rotation: Quaternion::identity(),
                },
            },
            true,
        );
    }
    b
}

#[test]
fn only_a_camera_below_the_robot_frame_rides_it() {
    let fixed = tf(&[("map", "cam_0"), ("map", "odom"), ("odom", "base_link")]);
    assert!(!camera_rides_robot(&fixed, "cam_0", "base_link"));
    let mounted = tf(&[
        ("map", "odom"),
        ("odom", "base_link"),
        ("base_link", "cam_0"),
    ]);
    assert!(camera_rides_robot(&mounted, "cam_0", "base_link"));
    let deeper = tf(&[
        ("odom", "base_link"),
        ("base_link", "mast"),
        ("mast", "cam_0"),
    ]);
    assert!(camera_rides_robot(&deeper, "cam_0", "base_link"));
    // TF does not know the camera: trust the odometry
    assert!(camera_rides_robot(&fixed, "cam_9", "base_link"));
}

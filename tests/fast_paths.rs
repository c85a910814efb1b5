//! The typed CDR fast paths (`log::fast`) and the flat decoder (`log::cdr::flat`, the
//! project's own `leg_tracker/msg/Person`) against the dynamic decoder on every message of the
//! real logs (written by rosbags, not by us), and on a log we write with every fast type.

use crate::common;

use std::collections::BTreeMap;
use std::path::Path;

use peopletrack::Nanos;
use peopletrack::log::fast::Decoded;
use peopletrack::log::msgs::{
    CameraInfo, CompressedImage, Header, Image, Imu, LaserScan, Odometry, RosMessage, TfMessage,
};
use peopletrack::log::{Decoders, SessionLog, SessionWriter, WriterOptions};

/// Decodes every message both ways; returns how many messages took each fast path.
fn compare_all(path: &Path) -> BTreeMap<&'static str, usize> {
    let log = SessionLog::open(path).expect("opens");
    let mut fast = Decoders::new();
    let mut slow = Decoders::new();
    let mut seen = BTreeMap::new();
    for m in log.messages().expect("stream") {
        let m = m.expect("message");
        let v = slow.value(&log, &m).expect("dynamic decode");
        let d = fast.decode(&log, &m).expect("fast decode");
        let what = format!("{} at {}", m.topic(), m.log_time.0);
        let name = match d {
            Decoded::Tf(t) => {
                assert_eq!(Ok(t), TfMessage::from_value(v).as_ref(), "{what}");
                "tf"
            }
            Decoded::Odometry(o) => {
                assert_eq!(Ok(o), Odometry::from_value(v).as_ref(), "{what}");
                "odometry"
            }
            Decoded::Imu(i) => {
                assert_eq!(Ok(i), Imu::from_value(v).as_ref(), "{what}");
                "imu"
            }
            Decoded::LaserScan(s) => {
                let g = LaserScan::from_value(v).expect("typed");
                // NaN ranges: compare bits
                let bits = |x: &[f32]| x.iter().map(|r| r.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&s.ranges), bits(&g.ranges), "{what}");
                assert_eq!(bits(&s.intensities), bits(&g.intensities), "{what}");
                let strip = |s: &LaserScan| LaserScan {
                    ranges: vec![],
                    intensities: vec![],
                    ..s.clone()
                };
                assert_eq!(strip(s), strip(&g), "{what}");
                "laser_scan"
            }
            Decoded::CameraInfo(c) => {
                assert_eq!(Ok(c), CameraInfo::from_value(v).as_ref(), "{what}");
                "camera_info"
            }
            Decoded::Image(i) => {
                assert_eq!(Ok(i.to_owned()), Image::from_value(v), "{what}");
                "image"
            }
            Decoded::CompressedImage(c) => {
                assert_eq!(Ok(c.to_owned()), CompressedImage::from_value(v), "{what}");
                "compressed_image"
            }
            Decoded::Flat(f) => {
                // NaN fields: compare the printed trees
                assert_eq!(format!("{:?}", f.to_value()), format!("{v:?}"), "{what}");
                "flat"
            }
            Decoded::Value(_) => "dynamic",
        };
        *seen.entry(name).or_insert(0) += 1;
    }
    seen
}

#[test]
fn real_logs_decode_the_same_by_the_fast_paths() {
    let expect: [(&str, &[(&str, usize)]); 2] = [
        (
            "general_tracking_moving_1",
            &[("tf", 21744), ("odometry", 11561), ("laser_scan", 873)],
        ),
        (
            "person_following_outdoor_1",
            &[("laser_scan", 7170), ("flat", 6179)],
        ),
    ];
    for (name, counts) in expect {
        let Some(path) = common::laser_log(name) else {
            return;
        };
        let seen = compare_all(&path);
        assert!(
            seen.get("laser_scan").copied().unwrap_or(0) > 0,
            "{name}: {seen:?}"
        );
        for (kind, n) in counts {
            assert_eq!(seen.get(kind), Some(n), "{name}: {seen:?}");
        }
    }
}

#[test]
fn every_fast_type_round_trips_through_a_log_we_write() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("all.mcap");
    let mut w = SessionWriter::create(&path, &WriterOptions::default()).expect("create");
    let t = Nanos(1_700_000_000_000_000_000);
    let header = Header::new(t, "cam");
    let img = Image {
        header: header.clone(),
        height: 1,
        width: 2,
        encoding: "mono8".into(),
        step: 2,
        data: vec![3, 4],
        ..Default::default()
    };
    let jpg = CompressedImage {
        header: header.clone(),
        format: "jpeg".into(),
        data: vec![0xff, 0xd8],
    };
    let info = CameraInfo {
        header: header.clone(),
        d: vec![0.5; 5],
        ..Default::default()
    };
    let imu = Imu {
        header: header.clone(),
        ..Default::default()
    };
    let c = w.add_ros2::<Image>("/img").expect("channel");
    w.write(c, t, &img).expect("write");
    let c = w.add_ros2::<CompressedImage>("/jpg").expect("channel");
    w.write(c, t, &jpg).expect("write");
    let c = w.add_ros2::<CameraInfo>("/info").expect("channel");
    w.write(c, t, &info).expect("write");
    let c = w.add_ros2::<Imu>("/imu").expect("channel");
    w.write(c, t, &imu).expect("write");
    let path = w.finish().expect("finish");
    let seen = compare_all(&path);
    for kind in ["image", "compressed_image", "camera_info", "imu"] {
        assert_eq!(seen.get(kind), Some(&1), "{seen:?}");
    }
    // and the typed reads take the same path
    let log = SessionLog::open(&path).expect("opens");
    let got: Vec<_> = peopletrack::log::read_topic::<CameraInfo>(&log, "/info")
        .expect("topic")
        .map(|r| r.expect("decodes").1)
        .collect();
    assert_eq!(got, vec![info]);
}

//! What we write reads back equal, in every layout the reader must handle: zstd, lz4 and
//! uncompressed chunks, messages outside chunks, files without a summary section, and chunks
//! that overlap in time (the reader must still yield log-time order).

use std::collections::BTreeMap;

use nalgebra::{Quaternion, Vector3};
use peopletrack::Nanos;
use peopletrack::log::msgs::{
    CameraInfo, CompressedImage, Detection2DArray, Header, Image, Imu, LaserScan, Odometry, Pose,
    PoseArray, PoseStamped, TfMessage, Transform, TransformStamped,
};
use peopletrack::log::{
    Compression, Decoders, SessionLog, SessionWriter, WriterOptions, read_topic,
};

fn scan(i: u64) -> LaserScan {
    LaserScan {
        header: Header::new(Nanos(1_000 + i), "laser"),
        angle_min: -1.0,
        angle_max: 1.0,
        angle_increment: 0.5,
        range_min: 0.1,
        range_max: 10.0,
        ranges: vec![i as f32, f32::NAN, f32::INFINITY, 0.0, 2.5],
        ..Default::default()
    }
}

fn write_all(path: &std::path::Path, options: &WriterOptions, n: u64) {
    let mut w = SessionWriter::create(path, options).expect("create");
    let s = w.add_ros2::<LaserScan>("/scan").expect("scan channel");
    let tf = w.add_ros2::<TfMessage>("/tf").expect("tf channel");
    let img = w
        .add_ros2::<Image>("/cam/image_raw")
        .expect("image channel");
    let gt = w
        .add_json(
            "/ground_truth/people",
            "peopletrack.PeopleGroundTruth",
            r#"{"type":"object"}"#,
        )
        .expect("json channel");
    w.metadata("peopletrack", BTreeMap::from([("seed".into(), "7".into())]))
        .expect("metadata");
    for i in 0..n {
        let t = Nanos(1_000_000_000 + i * 100_000_000);
        w.write(s, t, &scan(i)).expect("write scan");
        w.write(
            tf,
            t,
            &TfMessage {
                transforms: vec![TransformStamped {
                    header: Header::new(t, "odom"),
                    child_frame_id: "base_link".into(),
                    transform: Transform {
                        translation: Vector3::new(i as f64, 0.0, 0.0),
                        rotation: Quaternion::identity(),
                    },
                }],
            },
        )
        .expect("write tf");
        w.write(
            img,
            t,
            &Image {
                header: Header::new(t, "cam"),
                height: 2,
                width: 2,
                encoding: "mono8".into(),
                step: 2,
                data: vec![i as u8; 4],
                ..Default::default()
            },
        )
        .expect("write image");
        w.write_json(gt, t, &serde_json::json!({"people": [{"id": i, "x": 0.5}]}))
            .expect("write json");
    }
    w.finish().expect("finish");
}

fn check(options: WriterOptions, expect_summary: bool) {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("s.mcap");
    write_all(&path, &options, 50);
    assert!(
        !dir.path().join("s.mcap.tmp").exists(),
        "temporary file is renamed away"
    );
    let log = SessionLog::open(&path).expect("opens");
    assert_eq!(log.summary().from_summary_section, expect_summary);
    assert_eq!(log.summary().profile, "ros2");
    assert_eq!(log.summary().metadata[0].entries["seed"], "7");
    let scans: Vec<_> = read_topic::<LaserScan>(&log, "/scan")
        .expect("scan")
        .map(|r| r.expect("ok"))
        .collect();
    assert_eq!(scans.len(), 50);
    for (i, (t, s)) in scans.iter().enumerate() {
        let want = scan(i as u64);
        assert_eq!(*t, Nanos(1_000_000_000 + i as u64 * 100_000_000));
        assert_eq!(s.header, want.header);
        let bits = |s: &LaserScan| s.ranges.iter().map(|r| r.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(s), bits(&want));
    }
    let images: Vec<_> = read_topic::<Image>(&log, "/cam/image_raw")
        .expect("img")
        .map(|r| r.expect("ok"))
        .collect();
    assert_eq!(images[7].1.data, vec![7u8; 4]);
    let mut dec = Decoders::new();
    let m = log
        .messages_on(&["/ground_truth/people"])
        .expect("gt")
        .nth(3)
        .expect("4th")
        .expect("ok");
    let v = dec.value(&log, &m).expect("json decodes");
    assert_eq!(
        v.get("people").map(|p| p.to_json(None)),
        Ok(serde_json::json!([{"id": 3, "x": 0.5}]))
    );
    // all messages come out in non-decreasing log time
    let times: Vec<Nanos> = log
        .messages()
        .expect("all")
        .map(|m| m.expect("ok").log_time)
        .collect();
    assert_eq!(times.len(), 200);
    assert!(times.windows(2).all(|w| w[0] <= w[1]));
}

#[test]
fn zstd_lz4_and_uncompressed_chunks() {
    for c in [Compression::Zstd, Compression::Lz4, Compression::None] {
        check(
            WriterOptions {
                compression: c,
                chunk_size: 2048,
                ..Default::default()
            },
            true,
        );
    }
}

#[test]
fn messages_outside_chunks() {
    check(
        WriterOptions {
            chunked: false,
            ..Default::default()
        },
        true,
    );
}

#[test]
fn no_summary_section() {
    check(
        WriterOptions {
            summary: false,
            chunk_size: 4096,
            ..Default::default()
        },
        false,
    );
}

#[test]
fn overlapping_chunks_are_merged_in_log_time_order() {
    // Two passes over the same time range land in different chunks that overlap in time.
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("o.mcap");
    for summary in [true, false] {
        let mut w = SessionWriter::create(
            &path,
            &WriterOptions {
                chunk_size: 512,
                summary,
                ..Default::default()
            },
        )
        .expect("create");
        let a = w.add_ros2::<LaserScan>("/a").expect("a");
        let b = w.add_ros2::<LaserScan>("/b").expect("b");
        for i in 0..40 {
            w.write(a, Nanos(i * 10), &scan(i)).expect("a");
        }
        for i in 0..40 {
            w.write(b, Nanos(i * 10 + 5), &scan(i)).expect("b");
        }
        w.finish().expect("finish");
        let log = SessionLog::open(&path).expect("opens");
        assert!(log.summary().chunks.len() > 4);
        let got: Vec<(String, Nanos)> = log
            .messages()
            .expect("stream")
            .map(|m| {
                let m = m.expect("ok");
                (m.topic().to_string(), m.log_time)
            })
            .collect();
        let want: Vec<(String, Nanos)> = (0..40)
            .flat_map(|i| {
                [
                    ("/a".to_string(), Nanos(i * 10)),
                    ("/b".to_string(), Nanos(i * 10 + 5)),
                ]
            })
            .collect();
        assert_eq!(got, want, "summary: {summary}");
        // a topic filter skips the other topic's chunks and still yields everything asked for
        assert_eq!(log.messages_on(&["/b"]).expect("b").count(), 40);
    }
}

#[test]
fn every_typed_message_round_trips_through_a_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("t.mcap");
    let h = Header::new(Nanos(5), "f");
    let mut w = SessionWriter::create(&path, &WriterOptions::default()).expect("create");
    macro_rules! put {
        ($t:ty, $topic:expr, $v:expr) => {{
            let ch = w.add_ros2::<$t>($topic).expect("channel");
            w.write(ch, Nanos(5), &$v).expect("write");
        }};
    }
    let cam = CameraInfo {
        header: h.clone(),
        width: 352,
        height: 288,
        distortion_model: "plumb_bob".into(),
        d: vec![-0.3, 0.1, 0.0, 0.0, 0.0],
        ..Default::default()
    };
    let imu = Imu {
        header: h.clone(),
        orientation: Quaternion::new(1.0, 0.0, 0.0, 0.0),
        orientation_covariance: [0.1; 9],
        angular_velocity: Vector3::new(0.0, 0.1, 0.0),
        angular_velocity_covariance: [0.0; 9],
        linear_acceleration: Vector3::new(0.0, 0.0, 9.81),
        linear_acceleration_covariance: [0.0; 9],
    };
    let odom = Odometry {
        header: h.clone(),
        child_frame_id: "base_link".into(),
        pose: Pose::default(),
        pose_covariance: [0.0; 36],
        linear: Vector3::new(0.5, 0.0, 0.0),
        angular: Vector3::zeros(),
        twist_covariance: [0.0; 36],
    };
    let pose = PoseStamped {
        header: h.clone(),
        pose: Pose::default(),
    };
    let poses = PoseArray {
        header: h.clone(),
        poses: vec![Pose::default(); 3],
    };
    let jpeg = CompressedImage {
        header: h.clone(),
        format: "jpeg".into(),
        data: vec![0xff, 0xd8],
    };
    let det = Detection2DArray {
        header: h.clone(),
        detections: vec![],
    };
    put!(CameraInfo, "/cam/camera_info", cam);
    put!(Imu, "/imu", imu);
    put!(Odometry, "/odom", odom);
    put!(PoseStamped, "/pose", pose);
    put!(PoseArray, "/poses", poses);
    put!(CompressedImage, "/cam/image_raw/compressed", jpeg);
    put!(Detection2DArray, "/detections", det);
    w.finish().expect("finish");
    let log = SessionLog::open(&path).expect("opens");
    macro_rules! back {
        ($t:ty, $topic:expr, $v:expr) => {{
            let (_, got) = read_topic::<$t>(&log, $topic)
                .expect("topic")
                .next()
                .expect("one")
                .expect("ok");
            assert_eq!(got, $v, "{}", $topic);
        }};
    }
    back!(CameraInfo, "/cam/camera_info", cam);
    back!(Imu, "/imu", imu);
    back!(Odometry, "/odom", odom);
    back!(PoseStamped, "/pose", pose);
    back!(PoseArray, "/poses", poses);
    back!(CompressedImage, "/cam/image_raw/compressed", jpeg);
    back!(Detection2DArray, "/detections", det);
    // reading a topic as the wrong type names both types
    let e = read_topic::<LaserScan>(&log, "/imu")
        .expect("topic")
        .next()
        .expect("one")
        .expect_err("wrong type");
    assert!(
        e.to_string().contains("sensor_msgs/msg/Imu") && e.to_string().contains("/imu"),
        "{e}"
    );
}

#[test]
fn same_input_gives_byte_identical_files() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (a, b) = (dir.path().join("a.mcap"), dir.path().join("b.mcap"));
    write_all(&a, &WriterOptions::default(), 30);
    write_all(&b, &WriterOptions::default(), 30);
    assert_eq!(std::fs::read(&a).expect("a"), std::fs::read(&b).expect("b"));
}

//! Foxglove protobuf channels: schemas (FileDescriptorSets) and message bytes produced by the
//! Foxglove SDK (`foxglove` crate), read back through our dynamic protobuf decoder into the
//! same typed messages ROS 2 logs give.

use foxglove::Encode;
use foxglove::messages as fg;
use peopletrack::Nanos;
use peopletrack::log::msgs::{
    CameraInfo, CompressedImage, Image, LaserScan, PoseStamped, TfMessage,
};
use peopletrack::log::{SessionLog, SessionWriter, WriterOptions, read_topic};

fn put<T: Encode>(w: &mut SessionWriter, topic: &str, msg: &T, t: u64) {
    let schema = T::get_schema().expect("foxglove types carry schemas");
    let ch = w
        .add_raw(
            topic,
            Some((&schema.name, &schema.encoding, &schema.data)),
            &T::get_message_encoding(),
        )
        .expect("channel");
    let mut buf = Vec::new();
    msg.encode(&mut buf).expect("encode");
    w.write_bytes(ch, Nanos(t), &buf).expect("write");
}

fn ts() -> Option<fg::Timestamp> {
    Some(fg::Timestamp::new(1_700_000_000, 250))
}

#[test]
fn foxglove_sdk_messages_read_as_typed_messages() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("fox.mcap");
    let mut w = SessionWriter::create(&path, &WriterOptions::default()).expect("create");
    put(
        &mut w,
        "/scan",
        &fg::LaserScan {
            timestamp: ts(),
            frame_id: "laser".into(),
            pose: None,
            start_angle: -1.0,
            end_angle: 1.0,
            ranges: vec![1.0, f64::NAN, f64::INFINITY, 2.0, 3.0],
            intensities: vec![],
        },
        1,
    );
    put(
        &mut w,
        "/cam/image",
        &fg::RawImage {
            timestamp: ts(),
            frame_id: "cam".into(),
            width: 2,
            height: 1,
            encoding: "rgb8".into(),
            step: 6,
            data: vec![1, 2, 3, 4, 5, 6].into(),
        },
        2,
    );
    put(
        &mut w,
        "/cam/compressed",
        &fg::CompressedImage {
            timestamp: ts(),
            frame_id: "cam".into(),
            data: vec![0xff, 0xd8, 0xff].into(),
            format: "jpeg".into(),
        },
        3,
    );
    put(
        &mut w,
        "/tf",
        &fg::FrameTransforms {
            transforms: vec![fg::FrameTransform {
                timestamp: ts(),
                parent_frame_id: "map".into(),
                child_frame_id: "base_link".into(),
                translation: Some(fg::Vector3 {
                    x: 1.0,
                    y: 2.0,
                    z: 0.0,
                }),
                rotation: Some(fg::Quaternion {
                    x: 0.0,
                    y: 0.0,
                    z: 0.0,
                    w: 1.0,
                }),
            }],
        },
        4,
    );
    put(
        &mut w,
        "/cam/calibration",
        &fg::CameraCalibration {
            timestamp: ts(),
            frame_id: "cam".into(),
            width: 352,
            height: 288,
            distortion_model: "plumb_bob".into(),
            d: vec![-0.2, 0.05, 0.0, 0.0, 0.0],
            k: vec![400.0, 0.0, 176.0, 0.0, 400.0, 144.0, 0.0, 0.0, 1.0],
            r: vec![1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
            p: vec![
                400.0, 0.0, 176.0, 0.0, 0.0, 400.0, 144.0, 0.0, 0.0, 0.0, 1.0, 0.0,
            ],
        },
        5,
    );
    put(
        &mut w,
        "/pose",
        &fg::PoseInFrame {
            timestamp: ts(),
            frame_id: "map".into(),
            pose: Some(fg::Pose {
                position: Some(fg::Vector3 {
                    x: 3.0,
                    y: 4.0,
                    z: 0.0,
                }),
                orientation: Some(fg::Quaternion {
                    x: 0.0,
                    y: 0.0,
                    z: 0.0,
                    w: 1.0,
                }),
            }),
        },
        6,
    );
    w.finish().expect("finish");

    let log = SessionLog::open(&path).expect("opens");
    let stamp = Some(Nanos(1_700_000_000_000_000_250));
    let (_, scan) = read_topic::<LaserScan>(&log, "/scan")
        .expect("t")
        .next()
        .expect("1")
        .expect("ok");
    assert_eq!(scan.header.stamp.nanos(), stamp);
    assert_eq!(scan.header.frame_id, "laser");
    assert_eq!(scan.angle_increment, 0.5);
    assert!(scan.ranges[1].is_nan() && scan.ranges[2] == f32::INFINITY && scan.ranges[4] == 3.0);

    let (_, img) = read_topic::<Image>(&log, "/cam/image")
        .expect("t")
        .next()
        .expect("1")
        .expect("ok");
    assert_eq!(
        (img.width, img.height, img.encoding.as_str(), img.step),
        (2, 1, "rgb8", 6)
    );
    assert_eq!(img.data, vec![1, 2, 3, 4, 5, 6]);

    let (_, c) = read_topic::<CompressedImage>(&log, "/cam/compressed")
        .expect("t")
        .next()
        .expect("1")
        .expect("ok");
    assert_eq!((c.format.as_str(), c.data.len()), ("jpeg", 3));

    let (_, tf) = read_topic::<TfMessage>(&log, "/tf")
        .expect("t")
        .next()
        .expect("1")
        .expect("ok");
    assert_eq!(tf.transforms[0].header.frame_id, "map");
    assert_eq!(tf.transforms[0].child_frame_id, "base_link");
    assert_eq!(tf.transforms[0].transform.translation.y, 2.0);

    let (_, cal) = read_topic::<CameraInfo>(&log, "/cam/calibration")
        .expect("t")
        .next()
        .expect("1")
        .expect("ok");
    assert_eq!((cal.width, cal.height), (352, 288));
    assert_eq!(cal.k[0], 400.0);
    assert_eq!(cal.p[6], 144.0);
    assert_eq!(cal.d.len(), 5);

    let (_, pose) = read_topic::<PoseStamped>(&log, "/pose")
        .expect("t")
        .next()
        .expect("1")
        .expect("ok");
    assert_eq!(pose.pose.position.x, 3.0);
    assert_eq!(pose.header.stamp.nanos(), stamp);
}

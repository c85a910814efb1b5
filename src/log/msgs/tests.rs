use super::*;
use crate::log::cdr::{self, Endian};
use crate::log::definitions;

fn round_trip<T: RosMessage + PartialEq + std::fmt::Debug>(msg: &T) {
    let reg = definitions::registry(T::TYPE_NAME).expect("canonical definition");
    let bytes = cdr::encode(&reg, &msg.to_value(), Endian::Little).expect("encodes");
    let back = T::from_value(cdr::decode(&reg, &bytes).expect("decodes")).expect("converts");
    assert_eq!(&back, msg);
}

#[test]
fn typed_messages_round_trip_through_cdr() {
    let header = Header::new(Nanos(1_700_000_000_123_456_789), "laser");
    round_trip(&LaserScan {
        header: header.clone(),
        angle_min: -1.0,
        angle_max: 1.0,
        angle_increment: 0.5,
        range_max: 10.0,
        ranges: vec![1.0, 2.0, 0.0, 4.0, 5.0],
        ..Default::default()
    });
    round_trip(&Image {
        header: header.clone(),
        height: 1,
        width: 2,
        encoding: "rgb8".into(),
        step: 6,
        data: vec![1, 2, 3, 4, 5, 6],
        ..Default::default()
    });
    round_trip(&CameraInfo {
        header: header.clone(),
        distortion_model: "plumb_bob".into(),
        d: vec![0.1, -0.2, 0.0, 0.0, 0.0],
        k: [500.0, 0.0, 160.0, 0.0, 500.0, 120.0, 0.0, 0.0, 1.0],
        ..Default::default()
    });
    round_trip(&TfMessage {
        transforms: vec![TransformStamped {
            header: header.clone(),
            child_frame_id: "base_link".into(),
            transform: Transform {
                translation: Vector3::new(1.0, 2.0, 3.0),
                rotation: Quaternion::new(0.5, 0.5, 0.5, 0.5),
            },
        }],
    });
    round_trip(&Odometry {
        header: header.clone(),
        child_frame_id: "base_link".into(),
        pose: Pose::default(),
        pose_covariance: [0.5; 36],
        linear: Vector3::new(1.0, 0.0, 0.0),
        angular: Vector3::new(0.0, 0.0, 0.1),
        twist_covariance: [0.0; 36],
    });
    round_trip(&MarkerArray {
        markers: vec![
            Marker {
                header: header.clone(),
                ns: "people".into(),
                id: 7,
                kind: Marker::CYLINDER,
                scale: Vector3::new(0.4, 0.4, 1.8),
                color: [0.0, 0.5, 1.0, 0.6],
                lifetime: Time {
                    sec: 0,
                    nanosec: 80_000_000,
                },
                ..Default::default()
            },
            Marker {
                kind: Marker::LINE_STRIP,
                points: vec![Point3::new(1.0, 2.0, 0.0), Point3::new(1.5, 2.0, 0.0)],
                colors: vec![[1.0, 0.0, 0.0, 1.0]; 2],
                text: "7".into(),
                ..Default::default()
            },
        ],
    });
    round_trip(&Detection2DArray {
        header: header.clone(),
        detections: vec![Detection2D {
            header,
            results: vec![("person".into(), 0.9)],
            center_x: 10.0,
            center_y: 20.0,
            size_x: 5.0,
            size_y: 8.0,
            id: "3".into(),
            ..Default::default()
        }],
    });
}

//! Writes a session with every message type peopletrack writes (plus a custom type), and a
//! JSON file of the values written, so `tools/check_mcap_ros2.py` can check that Python
//! `mcap-ros2-support` opens the file and decodes the same values. (No `wstring` field: that
//! reader raises `NotImplementedError` for it.)
//!
//! Usage: `cargo run --example interop_fixture -- OUT.mcap OUT.json`

use nalgebra::{Quaternion, Vector3};
use peopletrack::Nanos;
use peopletrack::log::msgs::{
    CameraInfo, Header, Image, LaserScan, Odometry, Pose, TfMessage, Transform, TransformStamped,
};
use peopletrack::log::value::record;
use peopletrack::log::{SessionWriter, Value, WriterOptions};
use serde_json::json;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let (out, expected) = match args.as_slice() {
        [_, a, b] => (a.clone(), b.clone()),
        _ => return Err("usage: interop_fixture OUT.mcap OUT.json".into()),
    };
    let mut w = SessionWriter::create(&out, &WriterOptions::default())?;
    let scan_ch = w.add_ros2::<LaserScan>("/scan")?;
    let img_ch = w.add_ros2::<Image>("/cam_0/image_raw")?;
    let info_ch = w.add_ros2::<CameraInfo>("/cam_0/camera_info")?;
    let tf_ch = w.add_ros2::<TfMessage>("/tf")?;
    let odom_ch = w.add_ros2::<Odometry>("/odom")?;
    let custom = w.add_ros2_dynamic(
        "/custom",
        "my_pkg/msg/Custom",
        "int8 KIND=3\nstring name\nuint16[3] triple\nfloat64[] values\nmy_pkg/Inner[] inner\n\
         ================================================================================\nMSG: my_pkg/Inner\nbool flag\nint64 big\n",
    )?;
    let mut frames = Vec::new();
    for i in 0..20u64 {
        let t = Nanos(1_700_000_000_000_000_000 + i * 100_000_000);
        let ranges: Vec<f32> = (0..16)
            .map(|k| {
                if k % 5 == 4 {
                    f32::NAN
                } else {
                    0.5 + (i + k) as f32 * 0.25
                }
            })
            .collect();
        let scan = LaserScan {
            header: Header::new(t, "laser"),
            angle_min: -1.5,
            angle_max: 1.5,
            angle_increment: 0.2,
            range_min: 0.05,
            range_max: 30.0,
            ranges: ranges.clone(),
            ..Default::default()
        };
        w.write(scan_ch, t, &scan)?;
        let data: Vec<u8> = (0..4 * 3 * 3).map(|k| (k as u64 * 7 + i) as u8).collect();
        w.write(
            img_ch,
            t,
            &Image {
                header: Header::new(t, "cam_0"),
                height: 3,
                width: 4,
                encoding: "rgb8".into(),
                step: 12,
                data: data.clone(),
                ..Default::default()
            },
        )?;
        w.write(
            info_ch,
            t,
            &CameraInfo {
                header: Header::new(t, "cam_0"),
                height: 3,
                width: 4,
                distortion_model: "plumb_bob".into(),
                d: vec![-0.25, 0.1, 0.0, 0.0, 0.0],
                k: [2.0, 0.0, 2.0, 0.0, 2.0, 1.5, 0.0, 0.0, 1.0],
                r: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
                p: [2.0, 0.0, 2.0, 0.0, 0.0, 2.0, 1.5, 0.0, 0.0, 0.0, 1.0, 0.0],
                ..Default::default()
            },
        )?;
        w.write(
            tf_ch,
            t,
            &TfMessage {
                transforms: vec![TransformStamped {
                    header: Header::new(t, "odom"),
                    child_frame_id: "base_link".into(),
                    transform: Transform {
                        translation: Vector3::new(i as f64 * 0.1, 0.0, 0.0),
                        rotation: Quaternion::identity(),
                    },
                }],
            },
        )?;
        w.write(
            odom_ch,
            t,
            &Odometry {
                header: Header::new(t, "odom"),
                child_frame_id: "base_link".into(),
                pose: Pose::default(),
                pose_covariance: [0.01; 36],
                linear: Vector3::new(0.5, 0.0, 0.0),
                angular: Vector3::zeros(),
                twist_covariance: [0.0; 36],
            },
        )?;
        w.write_value(
            custom,
            t,
            &record([
                ("name", Value::String(format!("frame {i}"))),
                ("triple", Value::U16s(vec![1, 2, i as u16])),
                ("values", Value::F64s(vec![0.5; i as usize % 4])),
                (
                    "inner",
                    Value::Array(vec![record([
                        ("flag", Value::Bool(i % 2 == 0)),
                        ("big", Value::I64(-(i as i64) * 1_000_000_007)),
                    ])]),
                ),
            ]),
        )?;
        frames.push(json!({
            "log_time": t.0,
            "stamp": [t.to_stamp().0, t.to_stamp().1],
            "ranges": ranges.iter().map(|r| if r.is_nan() { json!("NaN") } else { json!(r) }).collect::<Vec<_>>(),
            "image": data,
            "tf_x": i as f64 * 0.1,
            "custom_name": format!("frame {i}"),
            "custom_big": -(i as i64) * 1_000_000_007,
            "custom_values": i as usize % 4,
        }));
    }
    w.finish()?;
    let counts = json!({"/scan": 20, "/cam_0/image_raw": 20, "/cam_0/camera_info": 20, "/tf": 20, "/odom": 20, "/custom": 20});
    std::fs::write(
        &expected,
        serde_json::to_string_pretty(&json!({"counts": counts, "frames": frames}))?,
    )?;
    println!("wrote {out} and {expected}");
    Ok(())
}

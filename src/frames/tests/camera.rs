use super::{mask, open, png, s, writer};
use crate::frames::rig::{self, RigError};
use crate::frames::{CameraFrame, camera};
use crate::log::msgs::{CameraInfo, CompressedImage, Header, Image};
use crate::log::{SessionLog, TfBuffer};

const IMAGE: &str = "/cam/image_raw/compressed";
const MASK: &str = "/cam/ground_truth_mask";

/// The hand-made camera log (log times and header stamps in ms):
///
/// | log | topic | stamp | what |
/// |---|---|---|---|
/// | 100 | image | 10 000 | 4×3 |
/// | 110 | mask | 10 000 | 4×3 → frame 10 000 complete |
/// | 200 | image | 30 000 | 4×3 (stamps out of order) |
/// | 210 | image | 20 000 | 4×3 |
/// | 220 | mask | 20 000 | 4×3 (waits behind 30 000) |
/// | 230 | mask | 30 000 | 2×2: wrong size → 30 000 without mask, then 20 000 with |
/// | 300 | image | 40 000 | bad JPEG bytes → skipped |
/// | 310 | mask | 40 000 | its image never comes |
/// | 400 | image | 50 000 | 4×3, its mask is `yuv422` → skipped |
/// | 500 | mask | 50 000 | yuv422 → skipped |
/// | 600 | image | — | three garbage bytes (not CDR) → skipped |
/// | 1320 | image | 60 000 | 5×2; 1.01 s after 310: the lone mask is dropped |
///
/// plus `/cam/camera_info` with no message and no `/cam2/camera_info` at all.
fn camera_log(dir: &std::path::Path) -> std::path::PathBuf {
    let (mut w, _) = writer(dir, "camera");
    let img = w.add_ros2::<CompressedImage>(IMAGE).expect("ch");
    let msk = w.add_ros2::<Image>(MASK).expect("ch");
    w.add_ros2::<CameraInfo>("/cam/camera_info").expect("ch");
    let jpeg_garbage = CompressedImage {
        header: Header::new(s(40_000), "cam"),
        format: "jpeg".into(),
        data: vec![0xff, 0xd8, 0xff, 0x00, 0x01, 0x02],
    };
    let mut yuv = mask(s(50_000), 4, 3, 255);
    yuv.encoding = "yuv422".into();
    w.write(img, s(100), &png(s(10_000), 4, 3, 1)).expect("w");
    w.write(msk, s(110), &mask(s(10_000), 4, 3, 255))
        .expect("w");
    w.write(img, s(200), &png(s(30_000), 4, 3, 3)).expect("w");
    w.write(img, s(210), &png(s(20_000), 4, 3, 2)).expect("w");
    w.write(msk, s(220), &mask(s(20_000), 4, 3, 0)).expect("w");
    w.write(msk, s(230), &mask(s(30_000), 2, 2, 255))
        .expect("w");
    w.write(img, s(300), &jpeg_garbage).expect("w");
    w.write(msk, s(310), &mask(s(40_000), 4, 3, 255))
        .expect("w");
    w.write(img, s(400), &png(s(50_000), 4, 3, 5)).expect("w");
    w.write(msk, s(500), &yuv).expect("w");
    w.write_bytes(img, s(600), &[1, 2, 3]).expect("w");
    w.write(img, s(1320), &png(s(60_000), 5, 2, 6)).expect("w");
    w.finish().expect("finish")
}

fn summary(f: &CameraFrame) -> (u64, u64, (u32, u32), Option<u8>, u8) {
    (
        f.stamp.0 / 1_000_000,
        f.log_time.0 / 1_000_000,
        f.rgb.dimensions(),
        f.mask.as_ref().map(|m| m.get_pixel(0, 0).0[0]),
        f.rgb.get_pixel(0, 0).0[2],
    )
}

#[test]
fn camera_frames_pair_masks_and_count_skips() {
    let dir = tempfile::tempdir().expect("tmp");
    let path = camera_log(dir.path());
    let log = open(&path);
    let file = path.display().to_string();
    let mut cam = camera::frames(&log, IMAGE, Some(MASK)).expect("frames");
    let got: Vec<_> = cam.by_ref().map(|f| summary(&f.expect("frame"))).collect();
    // (stamp ms, image log time ms, size, mask pixel, image tag)
    assert_eq!(
        got,
        vec![
            (10_000, 100, (4, 3), Some(255), 1),
            (30_000, 200, (4, 3), None, 3),
            (20_000, 210, (4, 3), Some(0), 2),
            (50_000, 400, (4, 3), None, 5),
            (60_000, 1320, (5, 2), None, 6),
        ]
    );
    assert_eq!(cam.frames_without_mask(), 3);
    assert_eq!(cam.masks_without_image(), 1);
    let skips = cam.skips();
    assert_eq!(
        (skips.count(IMAGE), skips.count(MASK), skips.total()),
        (2, 1, 3)
    );
    let jpeg_error = format!(
        "{file}: {IMAGE} at 300000000: compressed image does not decode: {}",
        "Format error decoding Jpeg: I/O errors Not enough bytes, expected 1 but found 0\n"
    );
    assert_eq!(skips.first_error(), Some(jpeg_error.as_str()));
    assert_eq!(skips.first_error_on(IMAGE), Some(jpeg_error.as_str()));
    assert_eq!(
        skips.first_error_on(MASK),
        Some(
            format!(
                "{file}: {MASK} at 500000000: unsupported image encoding `yuv422` (supported: rgb8, bgr8, mono8, rgba8, bgra8, mono16, 8UC1, 8UC3, 16UC1)"
            )
            .as_str()
        )
    );
}

#[test]
fn camera_frames_without_mask_topic_keep_log_order() {
    let dir = tempfile::tempdir().expect("tmp");
    let log = open(&camera_log(dir.path()));
    let mut cam = camera::frames(&log, IMAGE, None).expect("frames");
    let got: Vec<_> = cam
        .by_ref()
        .map(|f| summary(&f.expect("frame")).0)
        .collect();
    assert_eq!(got, vec![10_000, 30_000, 20_000, 50_000, 60_000]);
    assert_eq!(cam.frames_without_mask(), 0);
    assert_eq!(cam.into_skips().count(IMAGE), 2);
    assert_eq!(
        camera::image_topic(&log, "cam").as_deref(),
        Some(IMAGE),
        "compressed preferred"
    );
    assert_eq!(camera::image_topic(&log, "nocam"), None);
    // a typo is an error, not an empty stream
    assert!(camera::frames(&log, "/cam/image", None).is_err());
}

#[test]
fn missing_camera_info_is_an_error_naming_file_and_topic() {
    let dir = tempfile::tempdir().expect("tmp");
    let path = camera_log(dir.path());
    let log: SessionLog = open(&path);
    let tf = TfBuffer::new(0.0);
    let file = path.display().to_string();
    for (cam, topic) in [("cam", "/cam/camera_info"), ("cam2", "/cam2/camera_info")] {
        let e = rig::camera(&log, &tf, cam, topic, "map", None).expect_err("no info");
        assert!(matches!(e, RigError::NoCameraInfo { .. }));
        assert_eq!(
            e.to_string(),
            format!("{file}: no CameraInfo on {topic} (camera {cam})")
        );
    }
}

#[test]
fn spread_takes_every_kth_decodable_image() {
    let dir = tempfile::tempdir().expect("tmp");
    let log = open(&camera_log(dir.path()));
    // 7 image messages, n = 2: step 3 takes messages 0, 3 (bad JPEG: passed over) and 6
    let got = camera::spread(&log, &[IMAGE.to_string(), "/absent".to_string()], 2).expect("spread");
    let tags: Vec<u8> = got[0].iter().map(|i| i.get_pixel(0, 0).0[2]).collect();
    assert_eq!(tags, vec![1, 6]);
    assert!(got[1].is_empty());
}

//! Known-answer tests of the frames layer, each on a small log written here with
//! [`SessionWriter`].

mod camera;
mod datasets;
mod laser;
mod motion;
mod multicam;
mod truth;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use image::{DynamicImage, RgbImage};

use crate::log::msgs::{CompressedImage, Header, Image};
use crate::log::{SessionLog, SessionWriter, WriterOptions};
use crate::time::Nanos;

/// Seconds to nanoseconds (exact for the millisecond values the tests use).
pub(super) fn s(ms: u64) -> Nanos {
    Nanos(ms * 1_000_000)
}

/// A writer to `dir/name.mcap`.
pub(super) fn writer(dir: &Path, name: &str) -> (SessionWriter, PathBuf) {
    let path = dir.join(format!("{name}.mcap"));
    let w = SessionWriter::create(&path, &WriterOptions::default()).expect("create");
    (w, path)
}

pub(super) fn open(path: &Path) -> SessionLog {
    SessionLog::open(path).expect("open")
}

/// A `w`×`h` rgb8 raw image stamped `stamp`, pixel (x, y) = (x, y, tag).
pub(super) fn raw_rgb(stamp: Nanos, w: u32, h: u32, tag: u8) -> Image {
    let mut data = Vec::new();
    for y in 0..h {
        for x in 0..w {
            data.extend([x as u8, y as u8, tag]);
        }
    }
    Image {
        header: Header::new(stamp, "cam"),
        height: h,
        width: w,
        encoding: "rgb8".into(),
        is_bigendian: 0,
        step: w * 3,
        data,
    }
}

/// A `w`×`h` mono8 mask stamped `stamp`, every pixel `v`.
pub(super) fn mask(stamp: Nanos, w: u32, h: u32, v: u8) -> Image {
    Image {
        header: Header::new(stamp, "cam"),
        height: h,
        width: w,
        encoding: "mono8".into(),
        is_bigendian: 0,
        step: w,
        data: vec![v; (w * h) as usize],
    }
}

/// A PNG-compressed image (lossless, so pixels are exact).
pub(super) fn png(stamp: Nanos, w: u32, h: u32, tag: u8) -> CompressedImage {
    let rgb = RgbImage::from_fn(w, h, |x, y| image::Rgb([x as u8, y as u8, tag]));
    let mut data = Vec::new();
    DynamicImage::ImageRgb8(rgb)
        .write_to(
            &mut std::io::Cursor::new(&mut data),
            image::ImageFormat::Png,
        )
        .expect("png");
    CompressedImage {
        header: Header::new(stamp, "cam"),
        format: "png".into(),
        data,
    }
}

#[test]
fn topic_remap_or_default() {
    let t = BTreeMap::from([("image".to_string(), "/front/image".to_string())]);
    assert_eq!(
        super::topic(&t, "image", "/cam_0/image_raw"),
        "/front/image"
    );
    assert_eq!(super::topic(&t, "mask", "/cam_0/mask"), "/cam_0/mask");
}

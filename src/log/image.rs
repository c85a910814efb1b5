//! Images from `sensor_msgs/msg/Image` (raw) and `CompressedImage` (JPEG, PNG) into `image`
//! buffers. Raw encodings: `rgb8`, `bgr8`, `mono8`, `rgba8`, `bgra8`, `mono16` (and their
//! OpenCV aliases `8UC1`, `8UC3`, `16UC1`); rows may be padded (`step` > width × pixel size)
//! and 16-bit data may be big-endian. Colour is always returned as RGB(A): `bgr8` is swapped.

use image::{DynamicImage, GrayImage, ImageBuffer, Luma, RgbImage, RgbaImage};

use super::msgs::{CompressedImage, Image};

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ImageError {
    #[error("image is empty ({width}x{height})")]
    Empty { width: u32, height: u32 },
    #[error(
        "unsupported image encoding `{0}` (supported: rgb8, bgr8, mono8, rgba8, bgra8, mono16, 8UC1, 8UC3, 16UC1)"
    )]
    UnsupportedEncoding(String),
    #[error("step {step} is smaller than a row of {width} pixels x {bytes} bytes")]
    BadStep { step: u32, width: u32, bytes: u32 },
    #[error("image data has {have} bytes, {height} rows of step {step} need {need}")]
    ShortData {
        have: usize,
        need: usize,
        height: u32,
        step: u32,
    },
    #[error("compressed image format `{0}` is not jpeg or png")]
    UnsupportedFormat(String),
    #[error("compressed image does not decode: {0}")]
    Codec(String),
}

/// Bytes per pixel of a raw encoding.
fn pixel_bytes(encoding: &str) -> Option<u32> {
    Some(match encoding {
        "mono8" | "8UC1" => 1,
        "mono16" | "16UC1" => 2,
        "rgb8" | "bgr8" | "8UC3" => 3,
        "rgba8" | "bgra8" => 4,
        _ => return None,
    })
}

/// Decode a raw image.
pub fn decode_raw(img: &Image) -> Result<DynamicImage, ImageError> {
    let (w, h) = (img.width, img.height);
    if w == 0 || h == 0 {
        return Err(ImageError::Empty {
            width: w,
            height: h,
        });
    }
    let bpp = pixel_bytes(&img.encoding)
        .ok_or_else(|| ImageError::UnsupportedEncoding(img.encoding.clone()))?;
    let row = w as usize * bpp as usize;
    if (img.step as usize) < row {
        return Err(ImageError::BadStep {
            step: img.step,
            width: w,
            bytes: bpp,
        });
    }
    let need = img.step as usize * (h as usize - 1) + row;
    if img.data.len() < need {
        return Err(ImageError::ShortData {
            have: img.data.len(),
            need,
            height: h,
            step: img.step,
        });
    }
    let mut packed = Vec::with_capacity(row * h as usize);
    for y in 0..h as usize {
        let start = y * img.step as usize;
        packed.extend_from_slice(&img.data[start..start + row]);
    }
    let sized = |v: Vec<u8>| -> Result<DynamicImage, ImageError> {
        Ok(match bpp {
            1 => DynamicImage::ImageLuma8(GrayImage::from_raw(w, h, v).expect("size checked")),
            3 => DynamicImage::ImageRgb8(RgbImage::from_raw(w, h, v).expect("size checked")),
            _ => DynamicImage::ImageRgba8(RgbaImage::from_raw(w, h, v).expect("size checked")),
        })
    };
    match img.encoding.as_str() {
        "bgr8" => {
            for px in packed.chunks_exact_mut(3) {
                px.swap(0, 2);
            }
            sized(packed)
        }
        "bgra8" => {
            for px in packed.chunks_exact_mut(4) {
                px.swap(0, 2);
            }
            sized(packed)
        }
        "mono16" | "16UC1" => {
            let big = img.is_bigendian != 0;
            let v: Vec<u16> = packed
                .chunks_exact(2)
                .map(|c| {
                    if big {
                        u16::from_be_bytes([c[0], c[1]])
                    } else {
                        u16::from_le_bytes([c[0], c[1]])
                    }
                })
                .collect();
            Ok(DynamicImage::ImageLuma16(
                ImageBuffer::<Luma<u16>, Vec<u16>>::from_raw(w, h, v).expect("size checked"),
            ))
        }
        _ => sized(packed),
    }
}

/// Decode a compressed image (`format` mentions `jpeg`/`jpg` or `png`; empty means sniff).
pub fn decode_compressed(img: &CompressedImage) -> Result<DynamicImage, ImageError> {
    if img.data.is_empty() {
        return Err(ImageError::Empty {
            width: 0,
            height: 0,
        });
    }
    let f = img.format.to_ascii_lowercase();
    let format = if f.contains("jpeg") || f.contains("jpg") {
        image::ImageFormat::Jpeg
    } else if f.contains("png") {
        image::ImageFormat::Png
    } else if f.is_empty() {
        image::guess_format(&img.data).map_err(|e| ImageError::Codec(e.to_string()))?
    } else {
        return Err(ImageError::UnsupportedFormat(img.format.clone()));
    };
    let out = image::load_from_memory_with_format(&img.data, format)
        .map_err(|e| ImageError::Codec(e.to_string()))?;
    // image_transport writes `bgr8; jpeg compressed bgr8`: the codec already gives RGB.
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn raw(encoding: &str, w: u32, h: u32, step: u32, data: Vec<u8>) -> Image {
        Image {
            encoding: encoding.into(),
            width: w,
            height: h,
            step,
            data,
            ..Default::default()
        }
    }

    #[test]
    fn bgr_is_swapped_and_row_padding_dropped() {
        // 2x2 bgr8 with step 8 (2 bytes of padding per row)
        let data = vec![1, 2, 3, 4, 5, 6, 0, 0, 7, 8, 9, 10, 11, 12, 0, 0];
        let img = decode_raw(&raw("bgr8", 2, 2, 8, data))
            .expect("decodes")
            .to_rgb8();
        assert_eq!(img.get_pixel(0, 0).0, [3, 2, 1]);
        assert_eq!(img.get_pixel(1, 1).0, [12, 11, 10]);
    }

    #[test]
    fn mono16_honours_endianness() {
        let mut m = raw("mono16", 1, 1, 2, vec![0x01, 0x02]);
        let DynamicImage::ImageLuma16(le) = decode_raw(&m).expect("decodes") else {
            panic!("luma16")
        };
        assert_eq!(le.get_pixel(0, 0).0, [0x0201]);
        m.is_bigendian = 1;
        let DynamicImage::ImageLuma16(be) = decode_raw(&m).expect("decodes") else {
            panic!("luma16")
        };
        assert_eq!(be.get_pixel(0, 0).0, [0x0102]);
    }

    #[test]
    fn bad_images_are_errors() {
        assert!(matches!(
            decode_raw(&raw("rgb8", 0, 5, 0, vec![])),
            Err(ImageError::Empty { .. })
        ));
        assert!(matches!(
            decode_raw(&raw("yuv422", 1, 1, 2, vec![0; 2])),
            Err(ImageError::UnsupportedEncoding(_))
        ));
        assert!(matches!(
            decode_raw(&raw("rgb8", 2, 2, 6, vec![0; 11])),
            Err(ImageError::ShortData { .. })
        ));
        assert!(matches!(
            decode_raw(&raw("rgb8", 2, 2, 5, vec![0; 12])),
            Err(ImageError::BadStep { .. })
        ));
        let c = CompressedImage {
            format: "jpeg".into(),
            data: vec![1, 2, 3],
            ..Default::default()
        };
        assert!(matches!(decode_compressed(&c), Err(ImageError::Codec(_))));
    }

    #[test]
    fn png_round_trip() {
        let mut src = RgbImage::new(3, 2);
        src.put_pixel(2, 1, image::Rgb([10, 20, 30]));
        let mut bytes = Vec::new();
        DynamicImage::ImageRgb8(src.clone())
            .write_to(
                &mut std::io::Cursor::new(&mut bytes),
                image::ImageFormat::Png,
            )
            .expect("encodes");
        let c = CompressedImage {
            format: "png".into(),
            data: bytes,
            ..Default::default()
        };
        assert_eq!(decode_compressed(&c).expect("decodes").to_rgb8(), src);
    }
}

//! [`ImageView`]: a borrowed 8-bit image with its shape, checked once at construction so the
//! kernels that read it can trust `data.len() == width * height * channels`.
//!
//! Rows are tightly packed (no padding), channels interleaved. The view says nothing about
//! colour order: the kernels here treat channels symmetrically, so RGB and BGR data give
//! the same results as long as a model always sees the same order.

use image::{GrayImage, RgbImage};

/// Why bytes cannot be viewed as an image.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ViewError {
    #[error("image is empty ({width}x{height})")]
    Empty { width: usize, height: usize },
    #[error("an image has 1 to 4 channels, not {channels}")]
    Channels { channels: usize },
    #[error("image data has {have} bytes, {width}x{height}x{channels} needs {need}")]
    DataLength {
        have: usize,
        need: usize,
        width: usize,
        height: usize,
        channels: usize,
    },
}

/// A borrowed, tightly packed, interleaved 8-bit image.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ImageView<'a> {
    data: &'a [u8],
    width: usize,
    height: usize,
    channels: usize,
}

impl<'a> ImageView<'a> {
    /// View `data` as `height` rows of `width` pixels of `channels` bytes each.
    pub fn new(
        data: &'a [u8],
        width: usize,
        height: usize,
        channels: usize,
    ) -> Result<Self, ViewError> {
        if width == 0 || height == 0 {
            return Err(ViewError::Empty { width, height });
        }
        if !(1..=4).contains(&channels) {
            return Err(ViewError::Channels { channels });
        }
        let need = width
            .checked_mul(height)
            .and_then(|n| n.checked_mul(channels))
            .unwrap_or(usize::MAX);
        if data.len() != need {
            return Err(ViewError::DataLength {
                have: data.len(),
                need,
                width,
                height,
                channels,
            });
        }
        Ok(Self {
            data,
            width,
            height,
            channels,
        })
    }

    /// View an `image` RGB buffer (never fails: the buffer's shape is already consistent,
    /// but an empty buffer is refused).
    pub fn rgb(img: &'a RgbImage) -> Result<Self, ViewError> {
        Self::new(img.as_raw(), img.width() as usize, img.height() as usize, 3)
    }

    /// View an `image` grey buffer.
    pub fn gray(img: &'a GrayImage) -> Result<Self, ViewError> {
        Self::new(img.as_raw(), img.width() as usize, img.height() as usize, 1)
    }

    pub fn data(&self) -> &'a [u8] {
        self.data
    }
    pub fn width(&self) -> usize {
        self.width
    }
    pub fn height(&self) -> usize {
        self.height
    }
    pub fn channels(&self) -> usize {
        self.channels
    }
    /// Number of pixels, `width * height`.
    pub fn pixels(&self) -> usize {
        self.width * self.height
    }
    /// Row `y` (`width * channels` bytes); `None` past the last row.
    pub fn row(&self, y: usize) -> Option<&'a [u8]> {
        let n = self.width * self.channels;
        self.data.get(y * n..(y + 1) * n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shapes_are_checked() {
        let d = [0u8; 12];
        assert!(ImageView::new(&d, 2, 2, 3).is_ok());
        assert_eq!(
            ImageView::new(&d, 0, 2, 3),
            Err(ViewError::Empty {
                width: 0,
                height: 2
            })
        );
        assert_eq!(
            ImageView::new(&d, 2, 2, 5),
            Err(ViewError::Channels { channels: 5 })
        );
        assert!(matches!(
            ImageView::new(&d, 3, 2, 3),
            Err(ViewError::DataLength { need: 18, .. })
        ));
        assert!(matches!(
            ImageView::new(&d, usize::MAX, 2, 3),
            Err(ViewError::DataLength { .. })
        ));
        let v = ImageView::new(&d, 2, 2, 3).expect("valid");
        assert_eq!(v.row(1), Some(&d[6..12]));
        assert_eq!(v.row(2), None);
    }
}

//! Colour spaces, per-frame bin images and kernel-weighted histograms of the colour trackers
//! (eq. 17–19 of Zivkovic & Kröse), and the trackers' error type.

use serde::{Deserialize, Serialize};

use crate::vision::ellipse::Ellipse;
use crate::vision::view::ImageView;

/// Bins per channel (8: 8×8 HS, 8×8×8 RGB, as in the paper).
pub const BINS_PER_CHANNEL: usize = 8;

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ColorTrackError {
    #[error("colour tracking needs a 3-channel RGB frame, not {channels} channel(s)")]
    Channels { channels: usize },
    #[error(
        "frame is {width}x{height} ({space:?}) but the tracker holds {have_width}x{have_height} ({have_space:?})"
    )]
    FrameMismatch {
        width: usize,
        height: usize,
        space: ColorSpace,
        have_width: usize,
        have_height: usize,
        have_space: ColorSpace,
    },
    #[error("the initial region {0:?} covers no pixel of the frame or is degenerate")]
    EmptyRegion(Ellipse),
    #[error("parameter `{name}` = {value} {why}")]
    BadParam {
        name: &'static str,
        value: f64,
        why: &'static str,
    },
}

/// Which colours the histogram counts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ColorSpace {
    /// Hue and saturation of HSV, 8×8 bins (brightness ignored).
    #[default]
    Hs,
    /// Red, green, blue, 8×8×8 bins.
    Rgb,
}

impl ColorSpace {
    /// Number of histogram bins.
    pub fn bins(self) -> usize {
        match self {
            ColorSpace::Hs => BINS_PER_CHANNEL * BINS_PER_CHANNEL,
            ColorSpace::Rgb => BINS_PER_CHANNEL * BINS_PER_CHANNEL * BINS_PER_CHANNEL,
        }
    }

    /// Short name for tables.
    pub fn name(self) -> &'static str {
        match self {
            ColorSpace::Hs => "HS 8x8",
            ColorSpace::Rgb => "RGB 8x8x8",
        }
    }

    /// Bin of one RGB colour.
    pub fn bin(self, r: u8, g: u8, b: u8) -> u16 {
        let n = BINS_PER_CHANNEL as u16;
        match self {
            ColorSpace::Rgb => {
                let q = |v: u8| u16::from(v) * n / 256;
                (q(r) * n + q(g)) * n + q(b)
            }
            ColorSpace::Hs => {
                let (rf, gf, bf) = (f64::from(r), f64::from(g), f64::from(b));
                let max = rf.max(gf).max(bf);
                let min = rf.min(gf).min(bf);
                let delta = max - min;
                let s = if max > 0.0 { delta / max } else { 0.0 };
                // hue in sextants, [0, 6)
                let h = if delta == 0.0 {
                    0.0
                } else if max == rf {
                    ((gf - bf) / delta).rem_euclid(6.0)
                } else if max == gf {
                    (bf - rf) / delta + 2.0
                } else {
                    (rf - gf) / delta + 4.0
                };
                let nf = f64::from(n);
                let hb = ((h / 6.0 * nf) as u16).min(n - 1);
                let sb = ((s * nf) as u16).min(n - 1);
                hb * n + sb
            }
        }
    }
}

/// Every pixel's histogram bin, for one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct BinImage {
    pub(super) width: usize,
    pub(super) height: usize,
    pub(super) space: ColorSpace,
    pub(super) bins: Vec<u16>,
}

impl BinImage {
    /// Bin an RGB frame.
    pub fn new(frame: ImageView<'_>, space: ColorSpace) -> Result<Self, ColorTrackError> {
        if frame.channels() != 3 {
            return Err(ColorTrackError::Channels {
                channels: frame.channels(),
            });
        }
        let bins = frame
            .data()
            .chunks_exact(3)
            .map(|p| space.bin(p[0], p[1], p[2]))
            .collect();
        Ok(Self {
            width: frame.width(),
            height: frame.height(),
            space,
            bins,
        })
    }

    pub fn width(&self) -> usize {
        self.width
    }
    pub fn height(&self) -> usize {
        self.height
    }
    pub fn space(&self) -> ColorSpace {
        self.space
    }
    pub fn bins(&self) -> &[u16] {
        &self.bins
    }
}

/// A normalised colour histogram (bins sum to 1).
#[derive(Debug, Clone, PartialEq)]
pub struct Histogram {
    pub(super) space: ColorSpace,
    pub(super) values: Vec<f64>,
}

impl Histogram {
    pub fn space(&self) -> ColorSpace {
        self.space
    }
    pub fn values(&self) -> &[f64] {
        &self.values
    }
}

/// Bhattacharyya coefficient of two histograms (eq. 19): 1 for equal ones, 0 for disjoint.
/// Histograms of different colour spaces give 0.
pub fn bhattacharyya(a: &Histogram, b: &Histogram) -> f64 {
    if a.space != b.space {
        return 0.0;
    }
    a.values
        .iter()
        .zip(&b.values)
        .map(|(x, y)| (x * y).sqrt())
        .sum()
}

/// One pixel of a region: position, kernel value `exp(−d²/2)` and bin.
#[derive(Debug, Clone, Copy)]
pub(super) struct Sample {
    pub(super) x: f64,
    pub(super) y: f64,
    pub(super) g: f64,
    pub(super) bin: u16,
}

/// The pixels within `cutoff`σ of `region`, in raster order (empty if none or degenerate).
pub(super) fn samples(bins: &BinImage, region: &Ellipse, cutoff: f64, out: &mut Vec<Sample>) {
    out.clear();
    let Some(inv) = region.precision() else {
        return;
    };
    let c2 = cutoff * cutoff;
    let b = region.bbox(cutoff);
    let (w, h) = (bins.width as f64, bins.height as f64);
    if !(b[2] >= 0.0 && b[3] >= 0.0 && b[0] < w && b[1] < h) {
        return;
    }
    let x0 = b[0].ceil().max(0.0) as usize;
    let y0 = b[1].ceil().max(0.0) as usize;
    let x1 = (b[2].floor().min(w - 1.0)) as usize;
    let y1 = (b[3].floor().min(h - 1.0)) as usize;
    let (a, bxy, d) = (inv[(0, 0)], inv[(0, 1)], inv[(1, 1)]);
    for y in y0..=y1 {
        let dy = y as f64 - region.center.y;
        let row = &bins.bins[y * bins.width..(y + 1) * bins.width];
        for (x, &bin) in row.iter().enumerate().take(x1 + 1).skip(x0) {
            let dx = x as f64 - region.center.x;
            let d2 = a * dx * dx + 2.0 * bxy * dx * dy + d * dy * dy;
            if d2 <= c2 {
                out.push(Sample {
                    x: x as f64,
                    y: y as f64,
                    g: (-0.5 * d2).exp(),
                    bin,
                });
            }
        }
    }
}

pub(super) fn histogram_of(space: ColorSpace, s: &[Sample]) -> Option<Histogram> {
    let mut values = vec![0.0; space.bins()];
    let mut total = 0.0;
    for p in s {
        values[p.bin as usize] += p.g;
        total += p.g;
    }
    if total.is_nan() || total <= 0.0 {
        return None;
    }
    values.iter_mut().for_each(|v| *v /= total);
    Some(Histogram { space, values })
}

/// The kernel-weighted histogram of `region` (eq. 17–18); `None` when the region covers no
/// pixel of the frame.
pub fn kernel_histogram(bins: &BinImage, region: &Ellipse, cutoff_sigma: f64) -> Option<Histogram> {
    let mut s = Vec::new();
    samples(bins, region, cutoff_sigma, &mut s);
    histogram_of(bins.space, &s)
}

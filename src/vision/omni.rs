//! Omnidirectional pre-processing and depth-cue features of seed 000 (sections 4.2–4.3):
//!
//! 1. **Unwrap** the circular image to a panorama by changing Cartesian to polar coordinates
//!    (480 × 120 in the paper): column = azimuth around the image centre, row = radius, the
//!    outer radius at the top and the inner one at the bottom, bilinear sampling.
//! 2. **Background** = mean of a few person-free panoramas; the foreground test and the
//!    histogram thresholds are learned from those same frames (how much they differ from their
//!    own mean), so no threshold is set by hand.
//! 3. **Histograms** of foreground pixels per column (horizontal) and per row (vertical);
//!    the person is the strongest run of columns above the column threshold (the panorama wraps
//!    around), and the rows above the row threshold within it.
//! 4. **Features**: the person's width (columns between the run's limits), the apparent distance
//!    (rows from the lower limit of the vertical histogram to the bottom edge), the number of
//!    foreground pixels; and the **angle** from the mean of the horizontal histogram.

use image::RgbImage;

/// Polar resampling map of a raw circular image.
#[derive(Debug, Clone)]
pub struct Unwrapper {
    pub width: usize,
    pub height: usize,
    /// Raw-image sample positions, row-major.
    map: Vec<(f32, f32)>,
}

impl Unwrapper {
    /// Columns sweep the image angle `θ = 2π (col + ½) / width` (the angle of `atan2(v − yc,
    /// u − xc)`); rows sweep radius from `r_outer` (top) to `r_inner` (bottom).
    pub fn new(
        xc: f64,
        yc: f64,
        r_inner: f64,
        r_outer: f64,
        width: usize,
        height: usize,
    ) -> Unwrapper {
        let mut map = Vec::with_capacity(width * height);
        for row in 0..height {
            let r = r_outer - (r_outer - r_inner) * (row as f64 + 0.5) / height as f64;
            for col in 0..width {
                let th = std::f64::consts::TAU * (col as f64 + 0.5) / width as f64;
                map.push(((xc + r * th.cos()) as f32, (yc + r * th.sin()) as f32));
            }
        }
        Unwrapper { width, height, map }
    }

    /// Image angle (rad) of a (fractional) panorama column.
    pub fn angle(&self, col: f64) -> f64 {
        std::f64::consts::TAU * (col + 0.5) / self.width as f64
    }

    /// Grey panorama (mean of R, G, B), bilinear; samples outside the image read 0.
    pub fn unwrap_grey(&self, img: &RgbImage) -> Vec<f32> {
        let (w, h) = (img.width() as i64, img.height() as i64);
        let raw = img.as_raw();
        let px = |x: i64, y: i64| -> f32 {
            if x < 0 || y < 0 || x >= w || y >= h {
                return 0.0;
            }
            let i = 3 * (y * w + x) as usize;
            (f32::from(raw[i]) + f32::from(raw[i + 1]) + f32::from(raw[i + 2])) / 3.0
        };
        self.map
            .iter()
            .map(|&(u, v)| {
                let (x, y) = (u - 0.5, v - 0.5);
                let (x0, y0) = (x.floor(), y.floor());
                let (fx, fy) = (x - x0, y - y0);
                let (x0, y0) = (x0 as i64, y0 as i64);
                (px(x0, y0) * (1.0 - fx) + px(x0 + 1, y0) * fx) * (1.0 - fy)
                    + (px(x0, y0 + 1) * (1.0 - fx) + px(x0 + 1, y0 + 1) * fx) * fy
            })
            .collect()
    }
}

/// The background model with thresholds learned from the person-free frames.
#[derive(Debug, Clone, PartialEq)]
pub struct Background {
    pub width: usize,
    pub height: usize,
    pub mean: Vec<f32>,
    /// A pixel is foreground when it differs from the mean by more than this (grey levels).
    pub pixel_threshold: f32,
    /// A column is part of the person when it has more foreground pixels than this.
    pub column_threshold: f32,
    /// A row (within the person's columns) counts when it has more foreground pixels than this.
    pub row_threshold: f32,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OmniError {
    #[error("need at least 2 background frames, got {0}")]
    TooFewFrames(usize),
    #[error("panorama has {got} pixels, the background {want}")]
    Size { got: usize, want: usize },
}

impl Background {
    /// Learn from person-free panoramas: the mean, and thresholds from how those frames differ
    /// from it (pixel: 4σ of the differences, at least 10 grey levels; column and row: the
    /// largest count any background frame produced, plus 2).
    pub fn learn(
        frames: &[Vec<f32>],
        width: usize,
        height: usize,
    ) -> Result<Background, OmniError> {
        if frames.len() < 2 {
            return Err(OmniError::TooFewFrames(frames.len()));
        }
        let n = width * height;
        if let Some(f) = frames.iter().find(|f| f.len() != n) {
            return Err(OmniError::Size {
                got: f.len(),
                want: n,
            });
        }
        let mut mean = vec![0.0f32; n];
        for f in frames {
            for (m, v) in mean.iter_mut().zip(f) {
                *m += v / frames.len() as f32;
            }
        }
        let mut sq = 0.0f64;
        for f in frames {
            for (m, v) in mean.iter().zip(f) {
                sq += f64::from((v - m) * (v - m));
            }
        }
        let sigma = (sq / (n * frames.len()) as f64).sqrt() as f32;
        let mut bg = Background {
            width,
            height,
            mean,
            pixel_threshold: (4.0 * sigma).max(10.0),
            column_threshold: 0.0,
            row_threshold: 0.0,
        };
        let (mut col_max, mut row_max) = (0.0f32, 0.0f32);
        for f in frames {
            let fg = bg.foreground(f);
            let (cols, rows) = bg.histograms(&fg, None);
            col_max = col_max.max(cols.iter().copied().fold(0.0, f32::max));
            row_max = row_max.max(rows.iter().copied().fold(0.0, f32::max));
        }
        bg.column_threshold = col_max + 2.0;
        bg.row_threshold = row_max + 2.0;
        Ok(bg)
    }

    /// Foreground mask of a panorama.
    pub fn foreground(&self, pano: &[f32]) -> Vec<bool> {
        pano.iter()
            .zip(&self.mean)
            .map(|(v, m)| (v - m).abs() > self.pixel_threshold)
            .collect()
    }

    /// Column counts, and row counts within `cols` (a set of columns) or over all columns.
    pub fn histograms(&self, fg: &[bool], cols: Option<&[bool]>) -> (Vec<f32>, Vec<f32>) {
        let mut c = vec![0.0f32; self.width];
        let mut r = vec![0.0f32; self.height];
        for row in 0..self.height {
            for col in 0..self.width {
                if fg[row * self.width + col] {
                    c[col] += 1.0;
                    if cols.is_none_or(|k| k[col]) {
                        r[row] += 1.0;
                    }
                }
            }
        }
        (c, r)
    }
}

/// What the pre-processing finds in one panorama.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Features {
    /// Columns between the limits of the horizontal histogram.
    pub width: f64,
    /// Rows from the lower limit of the vertical histogram to the bottom edge.
    pub apparent_distance: f64,
    /// Foreground pixels within the person's columns.
    pub pixels: f64,
    /// Mean column of the horizontal histogram (fractional, may exceed `width` when the run
    /// wraps; use [`Unwrapper::angle`]).
    pub mean_column: f64,
}

/// Localise the person and compute the features; `None` when no column passes the threshold.
pub fn features(bg: &Background, pano: &[f32]) -> Result<Option<Features>, OmniError> {
    if pano.len() != bg.mean.len() {
        return Err(OmniError::Size {
            got: pano.len(),
            want: bg.mean.len(),
        });
    }
    let fg = bg.foreground(pano);
    let (cols, _) = bg.histograms(&fg, None);
    let w = bg.width;
    let above: Vec<bool> = cols.iter().map(|c| *c > bg.column_threshold).collect();
    if !above.iter().any(|a| *a) {
        return Ok(None);
    }
    // runs of columns above threshold on the circle, gaps of up to 3 columns bridged;
    // the run with the most foreground pixels is the person
    let start = (0..w).find(|&k| !above[k]).unwrap_or(0);
    let mut runs: Vec<(usize, usize, f32)> = Vec::new(); // (first, length, mass) in unwrapped index
    let mut cur: Option<(usize, usize, f32, usize)> = None; // first, last, mass, gap
    for step in 0..w {
        let k = (start + step) % w;
        match (&mut cur, above[k]) {
            (None, true) => cur = Some((step, step, cols[k], 0)),
            (Some(c), true) => {
                c.1 = step;
                c.2 += cols[k];
                c.3 = 0;
            }
            (Some(c), false) => {
                c.3 += 1;
                if c.3 > 3 {
                    runs.push((c.0, c.1 - c.0 + 1, c.2));
                    cur = None;
                }
            }
            (None, false) => {}
        }
    }
    if let Some(c) = cur {
        runs.push((c.0, c.1 - c.0 + 1, c.2));
    }
    let Some(&(first, len, _)) = runs.iter().max_by(|a, b| a.2.total_cmp(&b.2)) else {
        return Ok(None);
    };
    let mut member = vec![false; w];
    let (mut wsum, mut csum) = (0.0f64, 0.0f64);
    for s in first..first + len {
        let k = (start + s) % w;
        member[k] = true;
        wsum += f64::from(cols[k]);
        csum += f64::from(cols[k]) * (start + s) as f64;
    }
    let (_, rows) = bg.histograms(&fg, Some(&member));
    let lower = (0..bg.height).rev().find(|&r| rows[r] > bg.row_threshold);
    let Some(lower) = lower else { return Ok(None) };
    let pixels: f32 = member
        .iter()
        .zip(&cols)
        .filter(|(m, _)| **m)
        .map(|(_, c)| c)
        .sum();
    Ok(Some(Features {
        width: len as f64,
        apparent_distance: (bg.height - 1 - lower) as f64,
        pixels: f64::from(pixels),
        mean_column: (csum / wsum.max(1e-9)).rem_euclid(w as f64),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unwrap_maps_a_known_pixel_to_the_known_panorama_cell() {
        // a 101x101 image, centre (50.5, 50.5); radius 20..40 over 20 rows, 36 columns
        let u = Unwrapper::new(50.5, 50.5, 20.0, 40.0, 36, 20);
        // the raw pixel at angle 0 (to the right) and radius 30.5: column 0 is centred at
        // θ = 5°; row 9 is centred at r = 40 − 20·9.5/20 = 30.5
        let mut img = RgbImage::new(101, 101);
        let th = std::f64::consts::TAU * 0.5 / 36.0;
        let (x, y) = (50.5 + 30.5 * th.cos(), 50.5 + 30.5 * th.sin());
        img.put_pixel(
            x.floor() as u32,
            y.floor() as u32,
            image::Rgb([255, 255, 255]),
        );
        let pano = u.unwrap_grey(&img);
        let best = pano
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .map(|(i, _)| i)
            .expect("pixels");
        assert_eq!((best % 36, best / 36), (0, 9));
        assert!((u.angle(0.0) - th).abs() < 1e-12);
    }

    #[test]
    fn a_block_in_the_panorama_gives_its_width_position_and_pixels() {
        let (w, h) = (48, 20);
        let base: Vec<f32> = (0..w * h).map(|i| 100.0 + (i % 7) as f32).collect();
        let frames: Vec<Vec<f32>> = (0..5)
            .map(|k| base.iter().map(|v| v + (k as f32 - 2.0)).collect())
            .collect();
        let bg = Background::learn(&frames, w, h).expect("learns");
        // a person: columns 46..=49 (wrapping to 0, 1), rows 6..=15 → lower limit row 15
        let mut pano = base.clone();
        for row in 6..16 {
            for col in [46usize, 47, 0, 1] {
                pano[row * w + col] += 80.0;
            }
        }
        let f = features(&bg, &pano).expect("sizes").expect("found");
        assert_eq!(f.width, 4.0);
        assert_eq!(f.apparent_distance, (h - 1 - 15) as f64);
        assert_eq!(f.pixels, 40.0);
        // mean of columns 46, 47, 48 (= 0), 49 (= 1) is 47.5
        assert!((f.mean_column - 47.5).abs() < 1e-9, "{}", f.mean_column);
        assert_eq!(features(&bg, &base).expect("sizes"), None);
    }
}

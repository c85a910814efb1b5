//! The external measurement system of seed 000 (section 3): webcams that find a coloured hat,
//! turn its image column into a bearing, and triangulate every pair of cameras that sees the
//! whole hat; the pair estimates are averaged into one position. Each camera is described only
//! by its heading `α`, position `(X, Y)` and angular range `Δα` (a linear column → bearing
//! model, as the paper does; lens distortion is left to the calibration to absorb).
//!
//! Calibration estimates every camera's `(α, X, Y, Δα)` by minimising the mean distance `d̄`
//! between measured and known positions over a calibration segment, with the Nelder–Mead
//! simplex of `argmin` (restarted from its own best point until it stops improving).

use argmin::core::{CostFunction, Executor};
use argmin::solver::neldermead::NelderMead;
use image::RgbImage;

/// One webcam of the measurement system.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BearingCamera {
    /// Heading of the image centre (rad, counter-clockwise from map +x).
    pub alpha: f64,
    pub x: f64,
    pub y: f64,
    /// Angular range of the image width (rad).
    pub range: f64,
    /// Image width (pixels).
    pub width: f64,
}

impl BearingCamera {
    /// Bearing of an image column (pixel coordinates, 0 at the left edge).
    pub fn bearing(&self, u: f64) -> f64 {
        self.alpha + self.range * (0.5 - u / self.width)
    }

    /// Image column of a bearing (inverse of [`Self::bearing`]).
    pub fn column(&self, bearing: f64) -> f64 {
        let d = wrap(bearing - self.alpha);
        (0.5 - d / self.range) * self.width
    }
}

pub fn wrap(a: f64) -> f64 {
    (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
}

/// Where the rays of two cameras cross, if they cross in front of both and not at a grazing
/// angle (below `min_angle` rad the position is too ill-conditioned to use).
pub fn intersect(
    a: &BearingCamera,
    pa: f64,
    b: &BearingCamera,
    pb: f64,
    min_angle: f64,
) -> Option<(f64, f64)> {
    let (da, db) = ((pa.cos(), pa.sin()), (pb.cos(), pb.sin()));
    let det = da.0 * (-db.1) - da.1 * (-db.0);
    if det.abs() < min_angle.sin() {
        return None;
    }
    let (rx, ry) = (b.x - a.x, b.y - a.y);
    let s = (rx * (-db.1) - ry * (-db.0)) / det;
    let t = (da.0 * ry - da.1 * rx) / det;
    (s > 0.0 && t > 0.0).then_some((a.x + s * da.0, a.y + s * da.1))
}

/// Position from the cameras that see the whole hat: `(camera index, column)` pairs. Every
/// pair of cameras gives an estimate; the final position is their mean.
pub fn locate(cams: &[BearingCamera], seen: &[(usize, f64)]) -> Option<(f64, f64)> {
    let mut sum = (0.0, 0.0);
    let mut n = 0;
    for i in 0..seen.len() {
        for j in i + 1..seen.len() {
            let (ci, ui) = seen[i];
            let (cj, uj) = seen[j];
            if let Some(p) = intersect(
                &cams[ci],
                cams[ci].bearing(ui),
                &cams[cj],
                cams[cj].bearing(uj),
                10f64.to_radians(),
            ) {
                sum = (sum.0 + p.0, sum.1 + p.1);
                n += 1;
            }
        }
    }
    (n > 0).then(|| (sum.0 / n as f64, sum.1 / n as f64))
}

/// A calibration sample: what the cameras saw while the hat was at a known position.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    pub seen: Vec<(usize, f64)>,
    pub known: (f64, f64),
}

/// Mean distance between measured and known positions (samples that give no position count
/// as a 1 m error, so the optimiser cannot gain by losing them).
pub fn mean_distance(cams: &[BearingCamera], samples: &[Sample]) -> f64 {
    if samples.is_empty() {
        return f64::NAN;
    }
    samples
        .iter()
        .map(|s| match locate(cams, &s.seen) {
            Some(p) => (p.0 - s.known.0).hypot(p.1 - s.known.1),
            None => 1.0,
        })
        .sum::<f64>()
        / samples.len() as f64
}

struct Problem<'a> {
    start: &'a [BearingCamera],
    samples: &'a [Sample],
}

fn unpack(start: &[BearingCamera], p: &[f64]) -> Vec<BearingCamera> {
    start
        .iter()
        .enumerate()
        .map(|(i, c)| BearingCamera {
            alpha: p[4 * i],
            x: p[4 * i + 1],
            y: p[4 * i + 2],
            range: p[4 * i + 3],
            width: c.width,
        })
        .collect()
}

impl CostFunction for Problem<'_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, p: &Self::Param) -> Result<f64, argmin::core::Error> {
        Ok(mean_distance(&unpack(self.start, p), self.samples))
    }
}

/// Estimate every camera's parameters from `start` (e.g. the installer's nominal poses).
/// Returns the cameras and `d̄` after calibration.
pub fn calibrate(
    start: &[BearingCamera],
    samples: &[Sample],
) -> Result<(Vec<BearingCamera>, f64), String> {
    let mut best: Vec<f64> = start
        .iter()
        .flat_map(|c| [c.alpha, c.x, c.y, c.range])
        .collect();
    let mut best_cost = mean_distance(start, samples);
    // simplex steps: 3° for angles, 0.15 m for positions
    let steps = [3f64.to_radians(), 0.15, 0.15, 3f64.to_radians()];
    for _round in 0..40 {
        let n = best.len();
        let mut simplex = vec![best.clone()];
        for k in 0..n {
            let mut v = best.clone();
            v[k] += steps[k % 4];
            simplex.push(v);
        }
        let solver = NelderMead::new(simplex)
            .with_sd_tolerance(1e-13)
            .map_err(|e| e.to_string())?;
        let problem = Problem { start, samples };
        let res = Executor::new(problem, solver)
            .configure(|s| s.max_iters(4000))
            .run()
            .map_err(|e| e.to_string())?;
        let state = res.state();
        let (Some(p), cost) = (state.best_param.clone(), state.best_cost) else {
            break;
        };
        if cost < best_cost - 1e-9 {
            best = p;
            best_cost = cost;
        } else {
            break;
        }
    }
    Ok((unpack(start, &best), best_cost))
}

/// A coloured blob: centre, bounding box, area, and whether it touches the image border (then
/// the whole hat is not visible).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Blob {
    pub u: f64,
    pub v: f64,
    pub area: u32,
    pub bbox: [u32; 4],
    pub touches_border: bool,
}

/// Find the pixels of a hue band (degrees, e.g. 90..150 for green) with at least `min_sat`
/// saturation and `min_val` value, and return their centroid (one hat per image).
pub fn find_hue_blob(
    img: &RgbImage,
    hue: (f64, f64),
    min_sat: f64,
    min_val: f64,
    min_area: u32,
) -> Option<Blob> {
    let (w, h) = img.dimensions();
    let (mut su, mut sv, mut n) = (0.0f64, 0.0f64, 0u32);
    let (mut x0, mut y0, mut x1, mut y1) = (u32::MAX, u32::MAX, 0, 0);
    for (x, y, p) in img.enumerate_pixels() {
        let [r, g, b] = p.0.map(|c| f64::from(c) / 255.0);
        let max = r.max(g).max(b);
        let min = r.min(g).min(b);
        let c = max - min;
        if max < min_val || c / max.max(1e-9) < min_sat {
            continue;
        }
        let hdeg = if max == r {
            60.0 * ((g - b) / c).rem_euclid(6.0)
        } else if max == g {
            60.0 * ((b - r) / c + 2.0)
        } else {
            60.0 * ((r - g) / c + 4.0)
        };
        if hdeg >= hue.0 && hdeg <= hue.1 {
            su += f64::from(x) + 0.5;
            sv += f64::from(y) + 0.5;
            n += 1;
            x0 = x0.min(x);
            y0 = y0.min(y);
            x1 = x1.max(x);
            y1 = y1.max(y);
        }
    }
    (n >= min_area).then(|| Blob {
        u: su / f64::from(n),
        v: sv / f64::from(n),
        area: n,
        bbox: [x0, y0, x1, y1],
        touches_border: x0 == 0 || y0 == 0 || x1 + 1 >= w || y1 + 1 >= h,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cams() -> Vec<BearingCamera> {
        // four corners of a 10 x 5 m room, looking at its centre, 58° wide, 320 px
        [(0.1f64, 0.1f64), (9.9, 0.1), (9.9, 4.9), (0.1, 4.9)]
            .iter()
            .map(|&(x, y)| BearingCamera {
                alpha: (2.5 - y).atan2(5.0 - x),
                x,
                y,
                range: 58f64.to_radians(),
                width: 320.0,
            })
            .collect()
    }

    #[test]
    fn two_bearings_on_noise_free_data_triangulate_exactly() {
        let c = cams();
        let p = (6.3, 1.7);
        let seen: Vec<(usize, f64)> = c
            .iter()
            .enumerate()
            .map(|(i, k)| (i, k.column((p.1 - k.y).atan2(p.0 - k.x))))
            .collect();
        let (x, y) = locate(&c, &seen[..2]).expect("two cameras");
        assert!((x - p.0).abs() < 1e-9 && (y - p.1).abs() < 1e-9);
        let (x, y) = locate(&c, &seen).expect("four cameras");
        assert!((x - p.0).abs() < 1e-9 && (y - p.1).abs() < 1e-9);
    }

    #[test]
    fn calibration_recovers_known_parameters_from_noise_free_bearings() {
        let truth = cams();
        // nominal (start) values off by up to 4° and 0.15 m and a wrong angular range
        let start: Vec<BearingCamera> = truth
            .iter()
            .enumerate()
            .map(|(i, c)| BearingCamera {
                alpha: c.alpha + (if i % 2 == 0 { 1.0 } else { -1.0 }) * 4f64.to_radians(),
                x: c.x + 0.12,
                y: c.y - 0.1,
                range: 52f64.to_radians(),
                width: c.width,
            })
            .collect();
        let mut samples = Vec::new();
        for i in 0..5 {
            for j in 0..3 {
                let p = (1.5 + 1.7 * i as f64, 1.0 + 1.4 * j as f64);
                let seen = truth
                    .iter()
                    .enumerate()
                    .map(|(k, c)| (k, c.column((p.1 - c.y).atan2(p.0 - c.x))))
                    .collect();
                samples.push(Sample { seen, known: p });
            }
        }
        let before = mean_distance(&start, &samples);
        let (est, after) = calibrate(&start, &samples).expect("calibrates");
        assert!(before > 0.1, "{before}");
        assert!(after < 2e-3, "d̄ after calibration {after}");
        for (e, t) in est.iter().zip(&truth) {
            assert!(
                wrap(e.alpha - t.alpha).abs() < 0.3f64.to_radians(),
                "{} vs {}",
                e.alpha,
                t.alpha
            );
            assert!((e.x - t.x).abs() < 0.02 && (e.y - t.y).abs() < 0.02);
            assert!((e.range - t.range).abs() < 0.5f64.to_radians());
        }
    }

    #[test]
    fn finds_a_green_blob_and_knows_when_it_is_cut_off() {
        let mut img = RgbImage::from_pixel(40, 30, image::Rgb([120, 110, 100]));
        for x in 10..16 {
            for y in 5..9 {
                img.put_pixel(x, y, image::Rgb([30, 200, 40]));
            }
        }
        let b = find_hue_blob(&img, (90.0, 150.0), 0.45, 0.25, 5).expect("blob");
        assert!(
            (b.u - 13.0).abs() < 1e-9
                && (b.v - 7.0).abs() < 1e-9
                && b.area == 24
                && !b.touches_border
        );
        for y in 0..4 {
            img.put_pixel(39, y, image::Rgb([30, 200, 40]));
        }
        assert!(
            find_hue_blob(&img, (90.0, 150.0), 0.45, 0.25, 5)
                .expect("blob")
                .touches_border
        );
    }
}

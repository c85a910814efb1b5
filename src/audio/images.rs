//! The direct sound and its floor and ceiling images fitted together on a GCC curve (issue 33,
//! round 9).
//!
//! Two microphones on a horizontal axis hear a talker's floor image (mirrored below the floor)
//! and ceiling image (mirrored above the ceiling) at the talker's own azimuth and a steeper
//! elevation: their lags are `κ = cos ε_image / cos ε_direct` times the direct lag, `0 < κ < 1`,
//! on the same side of zero. Under a weighting whose lobes are wide (speech's energy lies in
//! its low harmonics) the direct peak and the images' merge into one peak between them, read
//! too near broadside (round 8's diagnosis). The curve of a block is modelled as
//!
//! ```text
//! r(τ) ≈ a·h(τ − τ_d) + b·h(τ − κ·τ_d),   a, b ≥ 0
//! ```
//!
//! with `h` the lobe of the block's own weights (the correlation a pure delay would give, the
//! inverse FFT of the weights' magnitudes: exact, no shape assumed), and `(τ_d, κ)` searched on
//! the lag grid × [`IMAGE_RATIOS`] by least squares (`a`, `b` by 2 × 2 normal equations; where
//! either comes out negative, the one-lobe fit). One `κ` stands for the floor's and the
//! ceiling's images together (theirs differ by a few hundredths in a living room). Wall images
//! are not modelled. Written by hand: no crate fits this.

/// The image-to-direct lag ratios searched: 0.35 to 0.85 by 0.05, a priori from the geometry —
/// microphones at 1.06 m, a mouth at 1.0–1.8 m, a ceiling at 2.4–3 m and talkers 0.8–4 m away
/// give κ from about 0.35 (near, floor) to 0.85 (far).
pub const IMAGE_RATIOS: [f64; 11] = [
    0.35, 0.40, 0.45, 0.50, 0.55, 0.60, 0.65, 0.70, 0.75, 0.80, 0.85,
];

/// The direct lag's grid index in `r` (zero lag at index `zero`) fitted with its image, given
/// the lobe `h` (zero offset at index `h_zero`, covering every offset between two indices of
/// `r`); `None` where `r` is empty or the lobe too short.
pub fn fit(r: &[f64], zero: usize, h: &[f64], h_zero: usize, ratios: &[f64]) -> Option<usize> {
    let n = r.len();
    if n == 0 || zero >= n || h_zero + 1 < n || h.len() < h_zero + n {
        return None;
    }
    // the lobe centred on index `at`, read at index `i`
    let lobe = |i: usize, at: usize| h[(h_zero + i) - at];
    let dot = |f: &dyn Fn(usize) -> f64, g: &dyn Fn(usize) -> f64| (0..n).map(|i| f(i) * g(i)).sum::<f64>();
    let rr = dot(&|i| r[i], &|i| r[i]);
    let mut best: Option<(f64, usize)> = None;
    for d in 0..n {
        let h1 = |i: usize| lobe(i, d);
        let (s11, r1) = (dot(&h1, &h1), dot(&|i| r[i], &h1));
        if s11 <= 0.0 {
            continue;
        }
        // the one-lobe fit, then each image ratio
        let mut res = if r1 > 0.0 { rr - r1 * r1 / s11 } else { rr };
        let lag = d as f64 - zero as f64;
        for &k in ratios {
            let img = (zero as f64 + (k * lag).round()) as usize;
            if img == d || img >= n {
                continue;
            }
            let h2 = |i: usize| lobe(i, img);
            let (s22, s12, r2) = (dot(&h2, &h2), dot(&h1, &h2), dot(&|i| r[i], &h2));
            let det = s11 * s22 - s12 * s12;
            if det <= 1e-12 * s11 * s22 {
                continue;
            }
            let a = (r1 * s22 - r2 * s12) / det;
            let b = (r2 * s11 - r1 * s12) / det;
            if a > 0.0 && b > 0.0 {
                res = res.min(rr - a * r1 - b * r2);
            }
        }
        if r1 > 0.0 && best.is_none_or(|(e, _)| res < e) {
            best = Some((res, d));
        }
    }
    best.map(|(_, d)| d)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A wide lobe on a 1/16-sample grid: a Gaussian of 2.5 samples' spread.
    fn lobe(offsets: usize) -> (Vec<f64>, usize) {
        let h = (0..2 * offsets + 1)
            .map(|j| {
                let m = (j as f64 - offsets as f64) / 16.0;
                (-m * m / (2.0 * 2.5 * 2.5)).exp()
            })
            .collect();
        (h, offsets)
    }

    #[test]
    fn a_direct_lobe_merged_with_its_image_is_split_and_the_direct_lag_found() {
        let max_k = 208; // ±13 samples
        let n = 2 * max_k + 1;
        let (h, h_zero) = lobe(n);
        let at = |i: usize, c: usize| h[h_zero + i - c];
        for (lag, ratio, gain) in [(160i64, 0.6, 0.9), (-120, 0.75, 0.7), (200, 0.4, 1.2)] {
            let d = (max_k as i64 + lag) as usize;
            let img = (max_k as f64 + ratio * lag as f64).round() as usize;
            let r: Vec<f64> = (0..n).map(|i| at(i, d) + gain * at(i, img)).collect();
            // the highest point of the merged curve lies between the two
            let top = (0..n).max_by(|a, b| r[*a].total_cmp(&r[*b])).expect("curve");
            assert!(top != d, "merged: the top {top} is not the direct {d}");
            let got = fit(&r, max_k, &h, h_zero, &IMAGE_RATIOS).expect("fit");
            assert_eq!(got, d, "lag {lag} ratio {ratio}");
        }
    }

    #[test]
    fn a_lone_lobe_is_found_where_it_is() {
        let max_k = 208;
        let n = 2 * max_k + 1;
        let (h, h_zero) = lobe(n);
        for d in [max_k, max_k + 37, max_k - 150, 3] {
            let r: Vec<f64> = (0..n).map(|i| 0.8 * h[h_zero + i - d]).collect();
            assert_eq!(fit(&r, max_k, &h, h_zero, &IMAGE_RATIOS), Some(d));
        }
        assert_eq!(fit(&[], 0, &h, h_zero, &IMAGE_RATIOS), None);
        assert_eq!(fit(&[1.0; 5], 2, &[1.0; 3], 1, &IMAGE_RATIOS), None, "lobe too short");
    }
}

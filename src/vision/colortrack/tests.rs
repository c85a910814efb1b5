//! Known answers for the colour-histogram trackers on synthetic frames.

use super::*;
use crate::vision::blobs::{Connectivity, label};
use crate::vision::ellipse::Ellipse;
use crate::vision::view::ImageView;

const W: usize = 200;
const H: usize = 200;

fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

fn noise(x: usize, y: usize, k: u64) -> i32 {
    (mix((y * W + x) as u64 * 7 + k) % 21) as i32 - 10
}

/// A frame with a two-colour object whose body frame maps to the image by `a` (2×2) around
/// `center`: object pixels are those with `|a⁻¹(p − c)|` inside the ellipse with semi-axes
/// 24 (x) and 40 (y) — red above, yellow below. The background is a patchwork of 5×5 cells
/// of green, grey and blue. Returns the RGB bytes and the object mask (255 on the object).
fn frame(center: (f64, f64), a: Matrix2<f64>, seed: u64) -> (Vec<u8>, Vec<u8>) {
    let inv = a.try_inverse().expect("invertible");
    let palette = [
        [60, 130, 60],
        [128, 128, 128],
        [70, 90, 160],
        [150, 160, 120],
    ];
    let (mut rgb, mut mask) = (vec![0u8; W * H * 3], vec![0u8; W * H]);
    for y in 0..H {
        for x in 0..W {
            let p = inv * Vector2::new(x as f64 - center.0, y as f64 - center.1);
            let inside = (p.x / 24.0).powi(2) + (p.y / 40.0).powi(2) <= 1.0;
            let base = if inside {
                mask[y * W + x] = 255;
                if p.y < 0.0 {
                    [200, 30, 40]
                } else {
                    [230, 200, 40]
                }
            } else {
                palette[(mix(((y / 5) * 1000 + x / 5) as u64 + seed) % 4) as usize]
            };
            for c in 0..3 {
                rgb[(y * W + x) * 3 + c] =
                    (base[c] + noise(x, y, seed * 3 + c as u64)).clamp(0, 255) as u8;
            }
        }
    }
    (rgb, mask)
}

/// The ellipse of the object's pixel moments (eq. 16).
fn truth(mask: &[u8]) -> Ellipse {
    let mut labels = vec![0; W * H];
    let blobs = label(mask, W, H, Connectivity::Eight, 255, &mut labels).expect("sizes");
    assert_eq!(blobs.len(), 1);
    blobs[0].ellipse()
}

fn bins(rgb: &[u8], space: ColorSpace) -> BinImage {
    BinImage::new(ImageView::new(rgb, W, H, 3).expect("view"), space).expect("bins")
}

fn angle_error_deg(a: &Ellipse, b: &Ellipse) -> f64 {
    let d = (a.axes().angle - b.axes().angle).rem_euclid(std::f64::consts::PI);
    d.min(std::f64::consts::PI - d).to_degrees()
}

fn ratio(e: &Ellipse) -> f64 {
    let ax = e.axes();
    ax.major_sigma / ax.minor_sigma
}

fn size(e: &Ellipse) -> f64 {
    e.cov.determinant().sqrt().sqrt()
}

/// The paper's figure 2 set-up: the object is scaled 1.5× vertically and rotated by 45°;
/// the tracker starts from the original shape at an offset position.
struct Case {
    model_frame: BinImage,
    model_region: Ellipse,
    target: BinImage,
    target_truth: Ellipse,
    start: Ellipse,
}

fn case(space: ColorSpace) -> Case {
    let (rgb_a, mask_a) = frame((100.0, 100.0), Matrix2::identity(), 1);
    let angle = std::f64::consts::FRAC_PI_4;
    let rot = Matrix2::new(angle.cos(), -angle.sin(), angle.sin(), angle.cos());
    let a = rot * Matrix2::new(1.0, 0.0, 0.0, 1.5);
    let (rgb_b, mask_b) = frame((104.0, 96.0), a, 2);
    let model_region = truth(&mask_a);
    let target_truth = truth(&mask_b);
    let start = Ellipse::new(
        target_truth.center + Vector2::new(6.0, -5.0),
        model_region.cov,
    );
    Case {
        model_frame: bins(&rgb_a, space),
        model_region,
        target: bins(&rgb_b, space),
        target_truth,
        start,
    }
}

#[test]
fn bins_of_known_colours() {
    assert_eq!(ColorSpace::Hs.bin(255, 0, 0), 7); // hue 0, saturation 1
    assert_eq!(ColorSpace::Hs.bin(128, 128, 128), 0); // grey: hue 0, saturation 0
    assert_eq!(ColorSpace::Hs.bin(0, 255, 0), 2 * 8 + 7); // hue 120° → bin 2
    assert_eq!(ColorSpace::Hs.bin(0, 0, 255), 5 * 8 + 7); // hue 240° → bin 5
    assert_eq!(ColorSpace::Hs.bin(255, 0, 255), 6 * 8 + 7); // hue 300° → bin 6
    assert_eq!(ColorSpace::Rgb.bin(255, 0, 0), 7 * 64);
    assert_eq!(ColorSpace::Rgb.bin(31, 32, 255), 8 + 7);
    assert_eq!(ColorSpace::Hs.bins(), 64);
    assert_eq!(ColorSpace::Rgb.bins(), 512);
}

#[test]
fn histograms_are_normalised_and_bhattacharyya_is_bounded() {
    let c = case(ColorSpace::Rgb);
    let h = kernel_histogram(&c.model_frame, &c.model_region, DEFAULT_CUTOFF_SIGMA)
        .expect("covers pixels");
    assert!((h.values().iter().sum::<f64>() - 1.0).abs() < 1e-12);
    assert!((bhattacharyya(&h, &h) - 1.0).abs() < 1e-12);
    let far = Ellipse::from_parts(15.0, 15.0, 9.0, 0.0, 9.0);
    let bg = kernel_histogram(&c.model_frame, &far, DEFAULT_CUTOFF_SIGMA).expect("pixels");
    assert!(bhattacharyya(&h, &bg) < 0.5);
    let outside = Ellipse::from_parts(-500.0, -500.0, 9.0, 0.0, 9.0);
    assert_eq!(kernel_histogram(&c.model_frame, &outside, 2.5), None);
}

fn report(label: &str, r: &TrackResult, want: &Ellipse) {
    let got = r.region;
    eprintln!(
        "{label}: {} iterations (converged {}), centre error {:.2} px, angle error {:.2}°, \
         ratio {:.3} vs {:.3}, size {:.2} vs {:.2}, rho {:.3}, overlap {:.3}",
        r.iterations,
        r.converged,
        (got.center - want.center).norm(),
        angle_error_deg(&got, want),
        ratio(&got),
        ratio(want),
        size(&got),
        size(want),
        r.similarity,
        got.overlap(want)
    );
}

#[test]
fn consistent_beta_is_the_truncated_gaussian_moment() {
    // 2-D: 1 / (1 − c² e^(−c²/2) / (2 (1 − e^(−c²/2)))) = 1.1677 at c = 2.5; no cut-off → 1
    assert!((consistent_beta(2.5) - 1.167_696).abs() < 1e-6);
    assert!((consistent_beta(40.0) - 1.0).abs() < 1e-12);
    // Monte Carlo check on a pixel grid: the β-scaled second moment of a wide isotropic
    // Gaussian cut at 2.5σ returns the variance
    let sigma: f64 = 30.0;
    let (mut m, mut t) = (0.0, 0.0);
    for y in -100i32..=100 {
        for x in -100i32..=100 {
            let d2 = f64::from(x * x + y * y) / (sigma * sigma);
            if d2 <= 6.25 {
                let g = (-0.5 * d2).exp();
                m += g * f64::from(x * x);
                t += g;
            }
        }
    }
    let v = consistent_beta(2.5) * m / t;
    assert!((v / (sigma * sigma) - 1.0).abs() < 0.005, "{v}");
}

/// Known answer: the EM-like tracker recovers position and full covariance (orientation and
/// shape) of the rotated, stretched object from an offset start of the right orientation but a
/// wrong size (×0.8, ×1, ×1.2 in σ), with β consistent with the 2-D 2.5σ cut-off. Stated
/// tolerances: centre within 1.5 px, orientation within 5°, size (⁴√det V) within 5 % and axis
/// ratio within 20 % of the object's pixel moments, overlap of the 2σ ellipses above 0.85
/// (measured: centre 1.2–1.4 px, angle ≤ 3.1°, size within 1.3 %, ratio within 16 % — the
/// ×0.8 start stays too slender —, overlap ≥ 0.88).
/// Regression (stop rule): on this 7000-pixel region the exact pixel-set rule alone never
/// fired within the 30-iteration cap. The settled-boundary rule stops the ×0.8 and ×1 starts
/// after 18 iterations (HS) once their steps contract; from ×1.2 the boundary keeps moving
/// ~0.075 px per iteration without contracting (a drift along the flat ridge of ρ), so that
/// run is, correctly, still stopped by the cap.
#[test]
fn em_like_recovers_a_rotated_stretched_ellipse() {
    let p = EmParams {
        beta: consistent_beta(DEFAULT_CUTOFF_SIGMA),
        ..EmParams::default()
    };
    for space in [ColorSpace::Hs, ColorSpace::Rgb] {
        let c = case(space);
        let want = c.target_truth;
        for scale in [0.8, 1.0, 1.2] {
            let start = Ellipse::new(
                want.center + Vector2::new(5.0, -4.0),
                want.cov * (scale * scale),
            );
            let mut t = ColorTracker::new(&c.model_frame, c.model_region, Method::EmLike(p))
                .expect("model");
            t.region = start;
            let r = t.track(&c.target).expect("tracks");
            report(&format!("{space:?} EM-like from ×{scale}"), &r, &want);
            let got = r.region;
            assert!(!r.lost && r.iterations >= 1);
            assert!(
                scale > 1.0 || (r.converged && r.iterations < p.max_iterations),
                "{space:?} ×{scale}: ran into the cap ({} iterations)",
                r.iterations
            );
            let centre = (got.center - want.center).norm();
            assert!(centre < 1.5, "{space:?} ×{scale}: centre error {centre}");
            assert!(angle_error_deg(&got, &want) < 5.0);
            assert!((size(&got) / size(&want) - 1.0).abs() < 0.05);
            assert!((ratio(&got) / ratio(&want) - 1.0).abs() < 0.20);
            assert!(got.overlap(&want) > 0.85);
        }
    }
}

/// The paper's β = 1.1 with our 2-D elliptical cut-off: started *on* the object, the region
/// shrinks well below it (the bias documented at [`consistent_beta`]); β = 1.168 stays.
#[test]
fn paper_beta_shrinks_the_region_with_a_2d_cutoff() {
    let c = case(ColorSpace::Hs);
    let model =
        kernel_histogram(&c.model_frame, &c.model_region, DEFAULT_CUTOFF_SIGMA).expect("pixels");
    let want = c.target_truth;
    let paper = em_like(&c.target, &model, &want, &EmParams::default()).expect("runs");
    let ours = EmParams {
        beta: consistent_beta(DEFAULT_CUTOFF_SIGMA),
        ..EmParams::default()
    };
    let consistent = em_like(&c.target, &model, &want, &ours).expect("runs");
    report("β = 1.1 from the truth", &paper, &want);
    report("β = 1.168 from the truth", &consistent, &want);
    assert!(size(&paper.region) < 0.85 * size(&want));
    assert!((size(&consistent.region) / size(&want) - 1.0).abs() < 0.05);
}

/// The paper's figure 2 set-up (object scaled 1.5× vertically and rotated 45°, tracker started
/// from the original shape at an offset): measured, not a known answer. Neither tracker
/// recovers the 45° rotation here — a region of the old shape over the object's middle has
/// nearly the same histogram (ρ ≈ 0.999), so ρ is flat along that direction — but the EM-like
/// tracker turns part of the way and overlaps the object more than mean shift.
#[test]
fn papers_figure_2_case_em_like_overlaps_more_than_mean_shift() {
    for space in [ColorSpace::Hs, ColorSpace::Rgb] {
        let c = case(space);
        let model = kernel_histogram(&c.model_frame, &c.model_region, DEFAULT_CUTOFF_SIGMA)
            .expect("pixels");
        let p = EmParams {
            beta: consistent_beta(DEFAULT_CUTOFF_SIGMA),
            ..EmParams::default()
        };
        let em = em_like(&c.target, &model, &c.start, &p).expect("runs");
        let ms =
            mean_shift(&c.target, &model, &c.start, &MeanShiftParams::default()).expect("runs");
        report(&format!("{space:?} fig. 2 EM-like"), &em, &c.target_truth);
        report(
            &format!("{space:?} fig. 2 mean shift"),
            &ms,
            &c.target_truth,
        );
        assert!(
            angle_error_deg(&em.region, &c.target_truth)
                < angle_error_deg(&ms.region, &c.target_truth)
        );
        assert!(em.region.overlap(&c.target_truth) > ms.region.overlap(&c.target_truth));
    }
}

/// Plain mean shift finds the position but keeps the old shape; with the ±10 % scale test it
/// may change size but never orientation or aspect ratio.
#[test]
fn mean_shift_recovers_position_but_not_shape() {
    let c = case(ColorSpace::Hs);
    let model =
        kernel_histogram(&c.model_frame, &c.model_region, DEFAULT_CUTOFF_SIGMA).expect("pixels");
    let p = MeanShiftParams::default();
    let plain = mean_shift(&c.target, &model, &c.start, &p).expect("runs");
    let scaled = mean_shift_scaled(&c.target, &model, &c.start, &p).expect("runs");
    for (name, r) in [("plain", plain), ("scaled", scaled)] {
        let centre = (r.region.center - c.target_truth.center).norm();
        eprintln!(
            "mean shift {name}: {} iterations ({} in all), centre error {centre:.2} px, overlap {:.3}",
            r.iterations,
            r.total_iterations,
            r.region.overlap(&c.target_truth)
        );
        assert!(r.converged && r.iterations >= 1 && r.iterations <= DEFAULT_MAX_ITERATIONS);
        assert!(centre < 3.0, "{name}: centre error {centre}");
        // the shape is the start's, up to the size: orientation stays vertical
        assert!(angle_error_deg(&r.region, &c.start) < 1e-6);
        assert!((ratio(&r.region) - ratio(&c.start)).abs() < 1e-9);
        assert!(angle_error_deg(&r.region, &c.target_truth) > 30.0);
    }
    assert_eq!(plain.region.cov, c.start.cov);
    assert!(scaled.total_iterations >= scaled.iterations);
}

#[test]
fn diagonal_shape_stays_axis_aligned_and_lost_objects_do_not_move() {
    let c = case(ColorSpace::Hs);
    let model =
        kernel_histogram(&c.model_frame, &c.model_region, DEFAULT_CUTOFF_SIGMA).expect("pixels");
    let p = EmParams {
        shape: Shape::Diagonal,
        ..EmParams::default()
    };
    let r = em_like(&c.target, &model, &c.start, &p).expect("runs");
    assert_eq!(r.region.cov[(0, 1)], 0.0);
    assert!((r.region.center - c.target_truth.center).norm() < 3.0);
    // a frame of one colour the model does not hold (the model's 2.5σ region also covers
    // some background, so the patchwork's colours are in it): every weight is 0, the object
    // is lost and nothing moves
    let cyan: Vec<u8> = [0u8, 170, 255].repeat(W * H);
    let cyan = bins(&cyan, ColorSpace::Hs);
    assert_eq!(
        model.values()[usize::from(ColorSpace::Hs.bin(0, 170, 255))],
        0.0
    );
    let away = Ellipse::from_parts(12.0, 12.0, 4.0, 0.0, 4.0);
    for method in [
        Method::EmLike(EmParams::default()),
        Method::MeanShift(MeanShiftParams::default()),
    ] {
        let lost = match method {
            Method::EmLike(p) => em_like(&cyan, &model, &away, &p),
            Method::MeanShift(p) => mean_shift_scaled(&cyan, &model, &away, &p),
        }
        .expect("runs");
        assert!(lost.lost, "{method:?}: {lost:?}");
        assert_eq!(lost.region, away);
    }
}

#[test]
fn bad_parameters_and_frames_are_errors() {
    let c = case(ColorSpace::Hs);
    let model = kernel_histogram(&c.model_frame, &c.model_region, 2.5).expect("pixels");
    let bad_beta = EmParams {
        beta: f64::NAN,
        ..EmParams::default()
    };
    assert!(em_like(&c.target, &model, &c.start, &bad_beta).is_err());
    let rgb = case(ColorSpace::Rgb);
    assert!(em_like(&rgb.target, &model, &c.start, &EmParams::default()).is_err());
    let grey = vec![0u8; W * H];
    assert!(matches!(
        BinImage::new(
            ImageView::new(&grey, W, H, 1).expect("view"),
            ColorSpace::Hs
        ),
        Err(ColorTrackError::Channels { channels: 1 })
    ));
}

/// Known answers for the boundary shift of the stop rule: exact for a translation and for a
/// circle that grows, zero for the same ellipse, symmetric, and an upper bound on the true
/// boundary distance of a rotated ellipse.
#[test]
fn boundary_shift_known_answers() {
    let c = 2.5;
    let a = Ellipse::from_parts(50.0, 60.0, 9.0, 2.0, 4.0);
    let moved = Ellipse::new(a.center + Vector2::new(3.0, 4.0), a.cov);
    assert!((boundary_shift_px(&a, &moved, c) - 5.0).abs() < 1e-12);
    assert!(boundary_shift_px(&a, &a, c).abs() < 1e-12);
    let small = Ellipse::from_parts(0.0, 0.0, 16.0, 0.0, 16.0);
    let large = Ellipse::from_parts(0.0, 0.0, 25.0, 0.0, 25.0);
    assert!((boundary_shift_px(&small, &large, c) - 2.5).abs() < 1e-12);
    assert!((boundary_shift_px(&large, &small, c) - 2.5).abs() < 1e-12);
    // a 3:1 ellipse turned by 90°: the boundaries are c(σ1 − σ2) = 2.5 × 2 = 5 px apart at
    // most (on the axes); the bound may be larger but never smaller
    let e = Ellipse::from_axes(0.0, 0.0, 3.0, 1.0, 0.0);
    let turned = Ellipse::from_axes(0.0, 0.0, 3.0, 1.0, std::f64::consts::FRAC_PI_2);
    let b = boundary_shift_px(&e, &turned, c);
    assert!((5.0 - 1e-9..=10.0).contains(&b), "{b}");
}

/// The settled test predicts the geometric tail of a linearly converging iteration.
#[test]
fn settled_predicts_the_geometric_tail() {
    let eps = DEFAULT_EPSILON_PX;
    assert!(!settled(0.1, None, eps)); // first step: no contraction known yet
    assert!(settled(0.1, Some(0.2), eps)); // ρ = 0.5: 0.1 more to go
    assert!(settled(0.02, Some(0.021), eps)); // ρ = 0.95: 0.4 px more to go
    assert!(!settled(0.03, Some(0.031), eps)); // ρ = 0.97: ~0.9 px more to go
    assert!(!settled(0.3, Some(0.2), eps)); // growing steps: not converging
    assert!(settled(0.0, Some(0.2), eps)); // nothing moved
}

use super::*;

/// A flat background and the same with a blue square over `xs × ys`.
fn square_scene(
    (w, h): (u32, u32),
    xs: std::ops::Range<u32>,
    ys: std::ops::Range<u32>,
) -> (RgbImage, RgbImage) {
    let bg = RgbImage::from_pixel(w, h, image::Rgb([120, 110, 100]));
    let mut fg = bg.clone();
    for y in ys {
        for x in xs.clone() {
            fg.put_pixel(x, y, image::Rgb([30, 60, 200]));
        }
    }
    (bg, fg)
}

/// `img` with 0–4 grey levels of deterministic noise that changes from frame to frame (a
/// hash of x, y and the frame `t`), so that the MAD is not zero.
fn noisy(img: &RgbImage, t: u32) -> RgbImage {
    let mut o = img.clone();
    for (x, y, p) in o.enumerate_pixels_mut() {
        let d =
            ((x.wrapping_mul(73_856_093) ^ y.wrapping_mul(19_349_663) ^ t.wrapping_mul(83_492_791))
                % 5) as u8;
        p.0 = p.0.map(|c| c.saturating_add(d));
    }
    o
}

#[test]
fn separable_kernels_match_the_closed_form() {
    for p in [
        GaborParams::default(),
        GaborParams {
            sigma_px: 1.3,
            wavelength_px: 5.0,
        },
    ] {
        let bank = GaborBank::new(p).expect("bank");
        for (m, deg) in ORIENTATIONS_DEG.iter().enumerate() {
            let closed = gabor_kernel(p, deg.to_radians(), bank.radius());
            let sep = bank.kernel(m);
            for (a, b) in closed.iter().zip(&sep) {
                assert!((a - b).abs() < 1e-12, "θ = {deg}: {a} vs {b}");
            }
        }
    }
}

#[test]
fn kernel_spot_values() {
    // centre: 1/(2πσ²); one step along the carrier at θ = 0: envelope · cos(2π/λ)
    let p = GaborParams::default();
    let k = gabor_kernel(p, 0.0, 6);
    let c = 1.0 / (2.0 * std::f64::consts::PI * 4.0);
    assert!((k[6 * 13 + 6] - c).abs() < 1e-15);
    let e = c * (-1.0f64 / 8.0).exp() * (std::f64::consts::PI / 4.0).cos();
    assert!((k[6 * 13 + 7] - e).abs() < 1e-15);
    // θ = 90° turns the carrier to y
    let k90 = gabor_kernel(p, std::f64::consts::FRAC_PI_2, 6);
    assert!((k90[7 * 13 + 6] - e).abs() < 1e-15);
    assert!((k90[6 * 13 + 7] - c * (-1.0f64 / 8.0).exp()).abs() < 1e-15);
}

/// Direct 2-D correlation with replicated borders.
fn direct(plane: &[f32], w: usize, h: usize, kernel: &[f64], r: usize) -> Vec<f64> {
    let n = 2 * r + 1;
    let mut out = vec![0.0; w * h];
    for y in 0..h {
        for x in 0..w {
            let mut acc = 0.0;
            for j in 0..n {
                for i in 0..n {
                    let yy = (y + j).saturating_sub(r).min(h - 1);
                    let xx = (x + i).saturating_sub(r).min(w - 1);
                    acc += kernel[j * n + i] * f64::from(plane[yy * w + xx]);
                }
            }
            out[y * w + x] = acc;
        }
    }
    out
}

#[test]
fn separable_filtering_equals_direct_2d_filtering() {
    let (w, h) = (23u32, 17u32);
    let mut img = RgbImage::new(w, h);
    for (x, y, p) in img.enumerate_pixels_mut() {
        // deterministic texture with edges at every orientation
        let v = ((x * 37 + y * 91 + x * y * 13) % 251) as u8;
        *p = image::Rgb([v, v.wrapping_mul(3), 255 - v]);
    }
    let bank = GaborBank::new(GaborParams::default()).expect("bank");
    let mut f = Features::default();
    bank.features(&img, &mut f, &mut Scratch::default())
        .expect("features");
    let r = bank.radius();
    for ch in 0..4 {
        let plane: Vec<f32> = img
            .pixels()
            .map(|p| {
                let [r, g, b] = p.0.map(f32::from);
                match ch {
                    0 => (0.299 * r + 0.587 * g + 0.114 * b) / 255.0,
                    1 => r / 255.0,
                    2 => g / 255.0,
                    _ => b / 255.0,
                }
            })
            .collect();
        for (m, deg) in ORIENTATIONS_DEG.iter().enumerate() {
            let k = gabor_kernel(bank.params(), deg.to_radians(), r);
            let want = direct(&plane, w as usize, h as usize, &k, r);
            for (i, (a, b)) in want.iter().zip(&f.planes[4 * ch + m]).enumerate() {
                let a = if ch > 0 { a.max(0.0) } else { *a };
                assert!(
                    (a - f64::from(*b)).abs() < 2e-5,
                    "channel {ch} θ {deg} pixel {i}: {a} vs {b}"
                );
            }
        }
    }
}

#[test]
fn median_and_mad_on_known_samples() {
    let check = |v: &[f32], k: f64, want: (f64, f64, f64)| {
        let got = mad_threshold(v, k).expect("non-empty");
        assert!(
            (got.0 - want.0).abs() < 1e-9
                && (got.1 - want.1).abs() < 1e-9
                && (got.2 - want.2).abs() < 1e-9,
            "{v:?}: {got:?} vs {want:?}"
        );
    };
    // median 3, |v − 3| = [2, 1, 0, 1, 97] → MAD 1
    check(
        &[1.0, 2.0, 3.0, 4.0, 100.0],
        3.0,
        (3.0 + 3.0 * MAD_TO_SIGMA, 3.0, 1.0),
    );
    // even count: median (2 + 4) / 2 = 3, |v − 3| = [2, 1, 1, 5] → MAD 1.5
    check(
        &[8.0, 1.0, 4.0, 2.0],
        2.0,
        (3.0 + 2.0 * MAD_TO_SIGMA * 1.5, 3.0, 1.5),
    );
    // constant sample: MAD 0, threshold = median
    check(&[0.5; 7], 3.0, (0.5, 0.5, 0.0));
    assert!(mad_threshold(&[], 3.0).is_none());
    assert!(mad_threshold(&[1.0, f32::NAN], 3.0).is_none());
}

#[test]
fn a_new_object_is_segmented_and_the_background_absorbs_it_at_rate_alpha() {
    let (bg, fg) = square_scene((40, 30), 15..25, 10..22);
    let bank = GaborBank::new(GaborParams::default()).expect("bank");
    let mut model = GaborBackground::new(bank, 0.05, 3.0).expect("model");
    let mut mask = Mask::default();
    let first = model.apply(&noisy(&bg, 0), &mut mask).expect("first");
    assert_eq!(first.foreground, 0);
    for t in 1..5 {
        model.apply(&noisy(&bg, t), &mut mask).expect("bg");
    }
    let s = model.apply(&noisy(&fg, 5), &mut mask).expect("fg");
    assert!(s.foreground > 60, "{s:?}");
    // every pixel well inside the square is foreground; far corners are not
    assert_eq!(mask.get(20, 16), 1);
    assert_eq!(mask.get(1, 1), 0);
    assert_eq!(mask.get(38, 28), 0);
}
#[test]
fn bootstrap_leaves_out_a_person_present_in_a_minority_of_frames() {
    let (w, h) = (36u32, 28u32);
    let bg = RgbImage::from_fn(w, h, |x, y| {
        image::Rgb([
            (100 + x * 3) as u8,
            (90 + y * 4) as u8,
            ((x * y) % 50 + 60) as u8,
        ])
    });
    // a "person" square in 2 of 5 frames, at two places
    let with_square = |x0: u32| {
        let mut o = bg.clone();
        for y in 8..20 {
            for x in x0..x0 + 8 {
                o.put_pixel(x, y, image::Rgb([20, 40, 220]));
            }
        }
        o
    };
    let frames = vec![
        bg.clone(),
        with_square(4),
        bg.clone(),
        with_square(20),
        bg.clone(),
    ];
    let bank = GaborBank::new(GaborParams::default()).expect("bank");
    let mut booted = GaborBackground::new(bank.clone(), 0.02, 3.0).expect("model");
    booted.bootstrap(&frames).expect("bootstrap");
    // the model is exactly the features of the empty background
    let mut want = Features::default();
    bank.features(&bg, &mut want, &mut Scratch::default())
        .expect("features");
    assert_eq!(booted.model(), Some(&want));
    // so the first frame with the square is segmented at once (the first-frame start
    // would give an empty mask and keep the square as a ghost)
    let mut mask = Mask::default();
    let s = booted.apply(&with_square(4), &mut mask).expect("frame");
    assert!(s.foreground > 50, "{s:?}");
    assert_eq!(mask.get(8, 14), 1);
    // errors: nothing, or frames of different sizes
    assert_eq!(booted.bootstrap(&[]), Err(GaborError::Empty));
    assert!(matches!(
        booted.bootstrap(&[bg.clone(), RgbImage::new(10, 10)]),
        Err(GaborError::SizeMismatch { .. })
    ));
}

#[test]
fn dilation_equals_the_brute_force_square() {
    let (w, h) = (23usize, 17usize);
    let src: Vec<u8> = (0..w * h)
        .map(|i| u8::from((i * 7919) % 61 == 0 || i == 0 || i == w * h - 1))
        .collect();
    for r in [0usize, 1, 2, 6, 30] {
        let (mut rows, mut out) = (Vec::new(), Vec::new());
        dilate(&src, w, r, &mut rows, &mut out);
        for y in 0..h {
            for x in 0..w {
                let want = (y.saturating_sub(r)..(y + r + 1).min(h)).any(|yy| {
                    (x.saturating_sub(r)..(x + r + 1).min(w)).any(|xx| src[yy * w + xx] == 1)
                });
                assert_eq!(out[y * w + x], u8::from(want), "r {r} at ({x}, {y})");
            }
        }
    }
    // one pixel in the middle grows into exactly a (2r + 1)² square
    let mut one = vec![0u8; w * h];
    one[8 * w + 11] = 1;
    let (mut rows, mut out) = (Vec::new(), Vec::new());
    dilate(&one, w, 3, &mut rows, &mut out);
    assert_eq!(out.iter().map(|&v| usize::from(v)).sum::<usize>(), 49);
}

#[test]
fn selective_update_leaves_no_trail_where_eq2_does() {
    let w = 48u32;
    let (bg, fg) = square_scene((w, 32), 16..32, 8..24);
    let bank = GaborBank::new(GaborParams::default()).expect("bank");
    let r = bank.radius() as u32;
    let alpha = 0.05;
    let all = GaborBackground::new(bank.clone(), alpha, 3.0).expect("all");
    let selective = all
        .clone()
        .with_update(Update::Selective {
            foreground_alpha: 0.0,
            dilate_px: r,
        })
        .expect("selective");
    let centre = 16 * w as usize + 24;
    // the 16 background features of the square's centre pixel
    let at_centre = |m: &GaborBackground| -> Vec<f32> {
        let planes = &m.model().expect("model").planes;
        planes.iter().map(|p| p[centre]).collect()
    };
    let mut results = Vec::new();
    for mut model in [all, selective] {
        let mut mask = Mask::default();
        for t in 0..10 {
            model.apply(&noisy(&bg, t), &mut mask).expect("bg");
        }
        let before = at_centre(&model);
        // the square stays 10 frames, then leaves
        for t in 10..20 {
            model.apply(&noisy(&fg, t), &mut mask).expect("fg");
            assert_eq!(mask.data[centre], 1);
        }
        let after = at_centre(&model);
        let s = model.apply(&noisy(&bg, 20), &mut mask).expect("gone");
        results.push((before, after, mask.data[centre], s.foreground));
    }
    let (before, after, trail, _) = &results[0];
    // eq. 2: 1 − (1 − α)^10 = 40 % of the square's contrast is in the model
    let mut mf = Features::default();
    bank.features(&noisy(&fg, 10), &mut mf, &mut Scratch::default())
        .expect("features");
    let kept = 1.0 - (1.0f32 - alpha as f32).powi(10);
    for f in 0..FILTERS {
        let contrast = mf.planes[f][centre] - before[f];
        if contrast.abs() > 1e-3 {
            let got = (after[f] - before[f]) / contrast;
            assert!((got - kept).abs() < 0.02, "filter {f}: {got} vs {kept}");
        }
    }
    assert_eq!(*trail, 1, "eq. 2 leaves the square's trail");
    // selective with α_fg = 0: the model under the square did not move at all
    let (before, after, trail, fg_count) = &results[1];
    assert_eq!(before, after);
    assert_eq!(*trail, 0);
    assert!(
        *fg_count < results[0].3 / 4,
        "{fg_count} vs {}",
        results[0].3
    );
    // a bad α_fg is refused
    let bank = GaborBank::new(GaborParams::default()).expect("bank");
    let m = GaborBackground::new(bank, 0.02, 3.0).expect("model");
    for bad in [-0.1, 1.0, f64::NAN] {
        assert!(
            m.clone()
                .with_update(Update::Selective {
                    foreground_alpha: bad,
                    dilate_px: 1
                })
                .is_err()
        );
    }
}

#[test]
fn sobel_magnitude_of_a_ramp_is_eight_times_its_slope() {
    // v = 0.1·x: Gx = (1 + 2 + 1)·(v(x+1) − v(x−1)) = 0.8 inside, 0.4 at the replicated
    // borders, Gy = 0
    let (w, h) = (6usize, 4usize);
    let plane: Vec<f32> = (0..w * h).map(|i| 0.1 * (i % w) as f32).collect();
    let mut g = Vec::new();
    sobel_magnitude(&plane, w, h, &mut g);
    for y in 0..h {
        for x in 0..w {
            let want = if x == 0 || x == w - 1 { 0.4 } else { 0.8 };
            assert!(
                (g[y * w + x] - want).abs() < 1e-5,
                "({x}, {y}): {}",
                g[y * w + x]
            );
        }
    }
}

/// A smooth ramp background and the same with a dark square over `x0..x0 + 8`, rows 8..20.
fn ramp_scene(x0: Option<u32>) -> RgbImage {
    let mut o = RgbImage::from_fn(40, 30, |x, y| {
        image::Rgb([(100 + x * 3) as u8, (90 + y * 4) as u8, 120])
    });
    if let Some(x0) = x0 {
        for y in 8..20 {
            for x in x0..x0 + 8 {
                o.put_pixel(x, y, image::Rgb([20, 40, 220]));
            }
        }
    }
    o
}

fn selective_model(ghosts: Option<u32>) -> GaborBackground {
    let bank = GaborBank::new(GaborParams::default()).expect("bank");
    let update = Update::Selective {
        foreground_alpha: 0.0,
        dilate_px: bank.radius() as u32,
    };
    let m = GaborBackground::new(bank, 0.02, 3.0)
        .expect("model")
        .with_update(update)
        .expect("update");
    match ghosts {
        Some(frames) => m.with_ghost_removal(GhostTest {
            band_px: 4,
            frames,
            grow_px: 0,
        }),
        None => m,
    }
}

#[test]
fn a_person_who_left_the_first_frame_is_a_ghost_that_the_test_learns_away() {
    // causal start with the square in the first frame; then it is gone
    for ghosts in [false, true] {
        let mut model = selective_model(ghosts.then_some(1));
        let mut mask = Mask::default();
        model
            .apply(&noisy(&ramp_scene(Some(6)), 0), &mut mask)
            .expect("first");
        let s = model
            .apply(&noisy(&ramp_scene(None), 1), &mut mask)
            .expect("gone");
        if ghosts {
            assert_eq!(s.ghosts, 1, "{s:?}");
            assert_eq!(s.foreground, 0, "{s:?}");
        } else {
            // frozen under the foreground: the ghost stays
            assert_eq!(s.ghosts, 0);
            assert!(s.foreground > 50, "{s:?}");
        }
        let later = model
            .apply(&noisy(&ramp_scene(None), 2), &mut mask)
            .expect("later");
        assert_eq!(mask.get(10, 14), u8::from(!ghosts), "{later:?}");
    }
}

#[test]
fn a_person_who_arrives_is_not_a_ghost() {
    let mut model = selective_model(Some(1));
    let mut mask = Mask::default();
    for t in 0..3 {
        model
            .apply(&noisy(&ramp_scene(None), t), &mut mask)
            .expect("empty");
    }
    // the same square, now in front of the background: its edge is in the frame
    for t in 3..6 {
        let s = model
            .apply(&noisy(&ramp_scene(Some(22)), t), &mut mask)
            .expect("here");
        assert_eq!(s.ghosts, 0, "frame {t}: {s:?}");
        assert!(s.foreground > 50, "frame {t}: {s:?}");
        assert_eq!(mask.get(26, 14), 1);
    }
}

#[test]
fn a_ghost_is_learnt_after_the_frames_it_must_persist() {
    // frames = 3: the ghost stays foreground for two frames, then is learnt on the third
    let mut model = selective_model(Some(3));
    let mut mask = Mask::default();
    model
        .apply(&noisy(&ramp_scene(Some(6)), 0), &mut mask)
        .expect("first");
    for t in 1..=3 {
        let s = model
            .apply(&noisy(&ramp_scene(None), t), &mut mask)
            .expect("gone");
        assert_eq!(s.ghosts, 1, "frame {t}: {s:?}");
        assert_eq!(mask.get(10, 14), u8::from(t < 3), "frame {t}: {s:?}");
    }
    // learnt: the square's place stays background in the frames after (the MAD threshold
    // still marks a few noise pixels anywhere, about 2 % of them in these frames)
    for t in 4..=8 {
        model
            .apply(&noisy(&ramp_scene(None), t), &mut mask)
            .expect("after");
        let inside = (8..20)
            .flat_map(|y| (6..14).map(move |x| (x, y)))
            .filter(|&(x, y)| mask.get(x, y) == 1)
            .count();
        assert!(inside <= 5, "frame {t}: {inside} of 96");
    }
}

#[test]
fn the_learnt_ghost_pixels_are_the_region_grown_by_the_band_and_then_by_grow_px() {
    // a ghost square: its edge in the background's luminance, none in the frame's
    let (w, h) = (40usize, 30usize);
    let inside = |x: usize, y: usize| (6..14).contains(&x) && (8..20).contains(&y);
    let mask: Vec<u8> = (0..w * h).map(|i| u8::from(inside(i % w, i / w))).collect();
    let cur = vec![0.5f32; w * h];
    let bg: Vec<f32> = (0..w * h)
        .map(|i| if inside(i % w, i / w) { 0.1 } else { 0.5 })
        .collect();
    // pixels within Chebyshev distance d of the square
    let near = |d: usize| {
        (0..w * h)
            .filter(|&i| {
                let (x, y) = (i % w, i / w);
                x + d >= 6 && x < 14 + d && y + d >= 8 && y < 20 + d
            })
            .count()
    };
    for grow_px in [0u32, 3] {
        let test = GhostTest {
            band_px: 4,
            frames: 1,
            grow_px,
        };
        let mut s = ghosts::GhostScratch::default();
        assert_eq!(ghosts::find(&mask, w, &cur, &bg, test, &mut s), 1);
        let healed = s.heal.iter().filter(|&&v| v == 1).count();
        assert_eq!(healed, near(4 + grow_px as usize), "grow_px {grow_px}");
    }
    // the same square in the frame and not in the background is no ghost
    let mut s = ghosts::GhostScratch::default();
    let test = GhostTest {
        band_px: 4,
        frames: 1,
        grow_px: 3,
    };
    assert_eq!(ghosts::find(&mask, w, &bg, &cur, test, &mut s), 0);
    assert!(!s.heal.contains(&1));
}

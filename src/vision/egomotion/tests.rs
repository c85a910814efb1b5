use super::*;
use views::tests::omni;

#[test]
fn loss_rate_per_speed_bin() {
    let samples = [
        (0.1, false),
        (0.4, true),
        (0.45, false),
        (0.5, true), // a bin's lower edge belongs to it
        (0.99, true),
        (1.7, false),
        (-0.2, true), // a magnitude
        (f64::NAN, true),
    ];
    let got = loss_by_speed(&samples, 0.5);
    let want = [(0.0, 0.5, 4, 2), (0.5, 1.0, 2, 2), (1.5, 2.0, 1, 0)];
    assert_eq!(got.len(), want.len(), "{got:?}");
    for (g, (lo, hi, frames, lost)) in got.iter().zip(want) {
        assert_eq!((g.lo, g.hi, g.frames, g.lost), (lo, hi, frames, lost));
        assert!((g.rate - lost as f64 / frames as f64).abs() < 1e-15);
    }
    assert!(loss_by_speed(&samples, 0.0).is_empty());
    assert!(loss_by_speed(&[], 0.5).is_empty());
}

#[test]
fn lost_is_no_estimate_or_too_far_across_the_seam() {
    let pi = std::f64::consts::PI;
    assert!(is_lost(None, 0.3, 0.2));
    assert!(!is_lost(Some(0.45), 0.3, 0.2));
    assert!(is_lost(Some(0.55), 0.3, 0.2));
    assert!(!is_lost(Some(pi - 0.05), -pi + 0.05, 0.2));
    assert!(is_lost(Some(f64::NAN), 0.0, 0.2));
}

/// A static scene painted on the sphere of directions (smooth texture in azimuth and
/// elevation), plus a bright square patch of half-size `half` rad at `(az, el)` when given.
fn omni_frame(patch: Option<(f64, f64)>, half: f64) -> RgbImage {
    let o = omni();
    RgbImage::from_fn(o.width, o.height, |x, y| {
        let Some(r) = o.ray(&Point2::new(f64::from(x) + 0.5, f64::from(y) + 0.5)) else {
            return image::Rgb([0, 0, 0]);
        };
        let (az, el) = (r.dir.y.atan2(r.dir.x), r.dir.z.asin());
        let inside = patch
            .is_some_and(|(pa, pe)| wrap_angle(az - pa).abs() < half && (el - pe).abs() < half);
        let v = if inside {
            250.0
        } else {
            // a smoothed checkerboard (corners every 0.08 rad) over a slow shading
            110.0
                + 25.0 * (3.0 * az).sin()
                + 70.0 * (4.0 * (39.3 * az).sin() * (39.3 * el).sin()).tanh()
        };
        let g = v.round().clamp(0.0, 255.0) as u8;
        image::Rgb([g, g, g])
    })
}

#[test]
fn a_patch_moving_in_a_static_scene_is_detected_at_its_bearing() {
    let mut m = Method1::new(&omni(), &Method1Params::default(), 5).expect("valid");
    let (az, el) = (2.2, -0.1);
    let mut last = None;
    for frame in 0..8 {
        // the patch blinks: every difference image holds the whole square
        let img = omni_frame((frame % 2 == 1).then_some((az, el)), 0.05);
        let out = m.step(&img).expect("right size");
        if frame == 0 {
            assert_eq!(out.features_tracked, 0);
            continue;
        }
        assert!(out.features_tracked > 50, "frame {frame}: {out:?}");
        assert_eq!(out.fallback_views, 0, "frame {frame}: {out:?}");
        last = out.detection;
    }
    let d = last.expect("a detection");
    assert!(wrap_angle(d.azimuth - az).abs() < 0.02, "{d:?}");
    assert!((d.elevation - el).abs() < 0.02, "{d:?}");
    // the static scene is compensated away: nothing but the patch differs much
    let strong: usize = m
        .differences()
        .iter()
        .map(|p| p.v.iter().filter(|&&v| v > 15.0).count())
        .sum();
    assert!(
        strong > 100 && strong < 4000,
        "{strong} strong difference pixels"
    );
}

#[test]
fn a_wrong_image_size_is_an_error_and_bad_parameters_are_refused() {
    let mut m = Method1::new(&omni(), &Method1Params::default(), 5).expect("valid");
    assert!(matches!(
        m.step(&RgbImage::new(320, 240)),
        Err(EgomotionError::ImageSize { .. })
    ));
    let p = Method1Params {
        min_bilinear: 2,
        ..Method1Params::default()
    };
    assert!(Method1::new(&omni(), &p, 5).is_err());
    let toml_params: Method1Params =
        toml::from_str("diff_threshold = 20.0\n[views]\ncount = 6\n").expect("parses");
    assert_eq!(toml_params.views.count, 6);
    assert_eq!(toml_params.max_features, 150);
    assert!(toml::from_str::<Method1Params>("no_such_key = 1\n").is_err());
}

use super::*;

/// A known bilinear map (a small rotation, scale, shear and keystone).
const T: Bilinear = Bilinear {
    a: [3.25, 1.02, -0.031, 0.00042],
    b: [-1.75, 0.027, 0.985, -0.00031],
};

/// Scattered positions over a 160 × 120 view (a fixed pseudo-random layout).
fn points(n: usize) -> Vec<[f64; 2]> {
    (0..n as u64)
        .map(|i| {
            [
                160.0 * f64::from(crate::rng::unit(crate::rng::hash(5, &[i, 0]))),
                120.0 * f64::from(crate::rng::unit(crate::rng::hash(5, &[i, 1]))),
            ]
        })
        .collect()
}

fn mapped(t: &Bilinear, pts: &[[f64; 2]]) -> Vec<[f64; 2]> {
    pts.iter()
        .map(|p| {
            let (x, y) = t.apply(p[0], p[1]);
            [x, y]
        })
        .collect()
}

fn assert_coefficients(got: &Bilinear, want: &Bilinear, tol: f64) {
    for (g, w) in got.a.iter().chain(&got.b).zip(want.a.iter().chain(&want.b)) {
        assert!((g - w).abs() <= tol, "{got:?} vs {want:?}");
    }
}

#[test]
fn noise_free_bilinear_correspondences_are_recovered() {
    let src = points(40);
    let (got, kind) = fit(&src, &mapped(&T, &src), 8, 4);
    assert_eq!(kind, FitKind::Bilinear);
    assert_coefficients(&got, &T, 1e-9);
}

#[test]
fn one_gross_outlier_moves_the_fit_by_its_least_squares_share() {
    // Plain regression (the paper's): the coefficients move by A⁺ (δ e_i), A the raw design
    // [1, x, y, xy] — computed here without the fit's normalisation.
    let src = points(40);
    let mut dst = mapped(&T, &src);
    let (i, delta) = (17, [25.0, -40.0]);
    dst[i][0] += delta[0];
    dst[i][1] += delta[1];
    let (got, kind) = fit(&src, &dst, 8, 4);
    assert_eq!(kind, FitKind::Bilinear);
    let a = DMatrix::from_fn(src.len(), 4, |r, c| {
        let (x, y) = (src[r][0], src[r][1]);
        [1.0, x, y, x * y][c]
    });
    let svd = a.svd(true, true);
    let shift = |d: f64| {
        let mut e = DVector::zeros(src.len());
        e[i] = d;
        svd.solve(&e, 0.0).expect("full rank")
    };
    let (sa, sb) = (shift(delta[0]), shift(delta[1]));
    let mut want = T;
    for c in 0..4 {
        want.a[c] += sa[c];
        want.b[c] += sb[c];
    }
    assert_coefficients(&got, &want, 1e-7);
    // not robust: the inliers are no longer mapped exactly
    let worst = src
        .iter()
        .enumerate()
        .filter(|&(j, _)| j != i)
        .map(|(_, p)| {
            let (gx, gy) = got.apply(p[0], p[1]);
            let (tx, ty) = T.apply(p[0], p[1]);
            (gx - tx).hypot(gy - ty)
        })
        .fold(0.0, f64::max);
    assert!(
        worst > 0.5,
        "one outlier of 47 px moved the inliers by only {worst} px"
    );
}

#[test]
fn too_few_or_degenerate_pairs_fall_back() {
    let affine = Bilinear {
        a: [2.0, 0.99, 0.05, 0.0],
        b: [-3.0, -0.04, 1.01, 0.0],
    };
    let src = points(5);
    let (got, kind) = fit(&src, &mapped(&affine, &src), 8, 4);
    assert_eq!(kind, FitKind::Affine);
    assert_coefficients(&got, &affine, 1e-9);

    let shift = Bilinear {
        a: [1.5, 1.0, 0.0, 0.0],
        b: [-0.5, 0.0, 1.0, 0.0],
    };
    let (got, kind) = fit(&src[..2], &mapped(&shift, &src[..2]), 8, 4);
    assert_eq!(kind, FitKind::Translation);
    assert_coefficients(&got, &shift, 1e-12);

    // collinear pairs: neither bilinear nor affine is determined
    let line: Vec<[f64; 2]> = (0..12)
        .map(|k| [10.0 + 5.0 * k as f64, 20.0 + 2.0 * k as f64])
        .collect();
    let (got, kind) = fit(&line, &mapped(&shift, &line), 8, 4);
    assert_eq!(kind, FitKind::Translation);
    assert_coefficients(&got, &shift, 1e-12);

    assert_eq!(fit(&[], &[], 8, 4), (Bilinear::IDENTITY, FitKind::Identity));
}

/// A smooth texture seen shifted by `(sx, sy)` px, as an unrounded plane.
fn texture(sx: f64, sy: f64) -> Plane {
    let (w, h) = (160, 120);
    let mut p = Plane::new(w, h, 0.0);
    for y in 0..h {
        for x in 0..w {
            let (u, v) = (x as f64 + 0.5 - sx, y as f64 + 0.5 - sy);
            p.v[y * w + x] = (128.0
                + 40.0 * (0.21 * u + 0.05 * v).sin()
                + 35.0 * (0.07 * u - 0.19 * v).cos()
                + 25.0 * (0.13 * u + 0.11 * v).sin()) as f32;
        }
    }
    p
}

#[test]
fn a_shifted_texture_differenced_after_compensation_is_zero_inside() {
    let (sx, sy) = (2.3, -1.4);
    let (previous, current) = (texture(0.0, 0.0), texture(sx, sy));
    // current(x) = previous(x − s): the current → previous map is a translation by −s
    let t = Bilinear {
        a: [-sx, 1.0, 0.0, 0.0],
        b: [-sy, 0.0, 1.0, 0.0],
    };
    let mut diff = Plane::new(0, 0, 0.0);
    compensated_difference(&current, &previous, &t, &mut diff);
    let inside = |x: usize, y: usize| (4..156).contains(&x) && (4..116).contains(&y);
    let mut worst = 0.0f32;
    for y in 0..120 {
        for x in 0..160 {
            if inside(x, y) {
                worst = worst.max(diff.at(x, y));
            }
        }
    }
    // bilinear interpolation of the smooth texture: error ≤ h²/8 · |f''| ≈ 0.3 grey levels
    assert!(worst < 0.5, "compensated difference up to {worst}");
    // the uncompensated difference is large, so the test can fail
    compensated_difference(&current, &previous, &Bilinear::IDENTITY, &mut diff);
    assert!(diff.v.iter().copied().fold(0.0, f32::max) > 30.0);
    // pixels mapped off the previous image have no difference
    let off = Bilinear {
        a: [-500.0, 1.0, 0.0, 0.0],
        b: [0.0, 0.0, 1.0, 0.0],
    };
    compensated_difference(&current, &previous, &off, &mut diff);
    assert!(diff.v.iter().all(|&d| d == 0.0));
}

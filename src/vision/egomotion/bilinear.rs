//! Seed 001 §IV after Jung & Sukhatme (IAS 2004): egomotion compensation of one perspective
//! view by a bilinear pixel transform
//!
//! `x′ = a0 + a1·x + a2·y + a3·x·y`,  `y′ = b0 + b1·x + b2·y + b3·x·y`,
//!
//! fitted by plain linear least squares (regression) on the view's tracked correspondences —
//! no RANSAC and no robust loss, as in the paper, so one gross outlier moves the fit (the test
//! `one_gross_outlier_moves_the_fit_by_its_least_squares_share` pins by how much). With too few
//! correspondences, or a degenerate layout, the fit falls back to an affine map, then a pure
//! translation, then the identity ([`FitKind`] says which; Method 1 counts the fallbacks).
//!
//! The fit here maps the *current* view's positions to the *previous* view's, so the previous
//! image is warped onto the current one by sampling it at `T(x)`; the compensated difference is
//! `|I_t(x) − I_{t−1}(T(x))|`, zero where either has no value.

use nalgebra::{DMatrix, DVector};

use super::views::Plane;

/// A bilinear pixel transform; `a` gives x′ and `b` gives y′, coefficients of `[1, x, y, xy]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bilinear {
    pub a: [f64; 4],
    pub b: [f64; 4],
}

impl Bilinear {
    pub const IDENTITY: Bilinear = Bilinear {
        a: [0.0, 1.0, 0.0, 0.0],
        b: [0.0, 0.0, 1.0, 0.0],
    };

    pub fn apply(&self, x: f64, y: f64) -> (f64, f64) {
        let (a, b) = (&self.a, &self.b);
        (
            a[0] + a[1] * x + a[2] * y + a[3] * x * y,
            b[0] + b[1] * x + b[2] * y + b[3] * x * y,
        )
    }
}

/// Which model the correspondences supported.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FitKind {
    Bilinear,
    Affine,
    Translation,
    /// No correspondence at all.
    Identity,
}

/// Relative singular-value floor below which the design is taken as rank-deficient.
const RANK_TOLERANCE: f64 = 1e-9;

/// Least-squares fit of `dst ≈ T(src)`: bilinear with at least `min_bilinear` (≥ 4) pairs,
/// else affine with at least `min_affine` (≥ 3), else the mean translation, else the identity.
/// Coordinates are centred and scaled before solving (SVD) and the coefficients mapped back.
pub fn fit(
    src: &[[f64; 2]],
    dst: &[[f64; 2]],
    min_bilinear: usize,
    min_affine: usize,
) -> (Bilinear, FitKind) {
    let n = src.len().min(dst.len());
    if n == 0 {
        return (Bilinear::IDENTITY, FitKind::Identity);
    }
    let (src, dst) = (&src[..n], &dst[..n]);
    if n >= min_bilinear.max(4)
        && let Some(t) = solve(src, dst, 4)
    {
        return (t, FitKind::Bilinear);
    }
    if n >= min_affine.max(3)
        && let Some(t) = solve(src, dst, 3)
    {
        return (t, FitKind::Affine);
    }
    let (mut dx, mut dy) = (0.0, 0.0);
    for (s, d) in src.iter().zip(dst) {
        dx += d[0] - s[0];
        dy += d[1] - s[1];
    }
    let mut t = Bilinear::IDENTITY;
    t.a[0] = dx / n as f64;
    t.b[0] = dy / n as f64;
    (t, FitKind::Translation)
}

/// Least squares with the first `terms` of `[1, x̃, ỹ, x̃ỹ]` in normalised coordinates
/// `x̃ = (x − mx)/s`; `None` when the design is rank-deficient.
fn solve(src: &[[f64; 2]], dst: &[[f64; 2]], terms: usize) -> Option<Bilinear> {
    let n = src.len();
    let (mx, my) = (
        src.iter().map(|p| p[0]).sum::<f64>() / n as f64,
        src.iter().map(|p| p[1]).sum::<f64>() / n as f64,
    );
    let s = src
        .iter()
        .map(|p| (p[0] - mx).hypot(p[1] - my))
        .fold(0.0, f64::max);
    if !(s > 0.0 && s.is_finite()) {
        return None;
    }
    let design = DMatrix::from_fn(n, terms, |i, j| {
        let (x, y) = ((src[i][0] - mx) / s, (src[i][1] - my) / s);
        [1.0, x, y, x * y][j]
    });
    let svd = design.svd(true, true);
    let sv = &svd.singular_values;
    let (max, min) = (sv.max(), sv.min());
    if min.is_nan() || min <= RANK_TOLERANCE * max {
        return None;
    }
    let solve_for = |k: usize| -> Option<[f64; 4]> {
        let rhs = DVector::from_iterator(n, dst.iter().map(|d| d[k]));
        let c = svd.solve(&rhs, 0.0).ok()?;
        let mut out = [0.0; 4];
        for (o, v) in out.iter_mut().zip(c.iter()) {
            *o = *v;
        }
        Some(out)
    };
    let (ca, cb) = (solve_for(0)?, solve_for(1)?);
    Some(Bilinear {
        a: denormalise(ca, mx, my, s),
        b: denormalise(cb, mx, my, s),
    })
}

/// Coefficients of `[1, x̃, ỹ, x̃ỹ]` with `x̃ = (x − mx)/s`, `ỹ = (y − my)/s` as coefficients of
/// `[1, x, y, xy]`.
fn denormalise(c: [f64; 4], mx: f64, my: f64, s: f64) -> [f64; 4] {
    let s2 = s * s;
    [
        c[0] - c[1] * mx / s - c[2] * my / s + c[3] * mx * my / s2,
        c[1] / s - c[3] * my / s2,
        c[2] / s - c[3] * mx / s2,
        c[3] / s2,
    ]
}

/// `out = |current(x) − previous(T(x))|` per pixel, `T` mapping current positions (pixel
/// centres) to previous ones; 0 where either image has no value. `out` takes `current`'s size.
pub fn compensated_difference(
    current: &Plane,
    previous: &Plane,
    current_to_previous: &Bilinear,
    out: &mut Plane,
) {
    if out.width != current.width || out.height != current.height {
        *out = Plane::new(current.width, current.height, 0.0);
    }
    for y in 0..current.height {
        for x in 0..current.width {
            let (px, py) = current_to_previous.apply(x as f64 + 0.5, y as f64 + 0.5);
            let d = (current.at(x, y) - previous.sample(px, py)).abs();
            out.v[y * current.width + x] = if d.is_nan() { 0.0 } else { d };
        }
    }
}

#[cfg(test)]
mod tests;

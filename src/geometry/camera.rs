//! Camera models as the papers use them, each as pixel → ray ([`CameraModel::ray`]) and
//! point → pixel ([`CameraModel::project`]), so one renderer and one set of pipelines serve
//! them all:
//!
//! - [`Pinhole`] with `plumb_bob` radial-tangential distortion (k1, k2, p1, p2, k3), in the ROS
//!   optical frame (x right, y down, z forward);
//! - [`Paracatadioptric`] (seed 001): parabolic mirror + orthographic lens, a single viewpoint,
//!   `r = f(√(tan²φ + 1) − tanφ)` with φ the elevation and θ the azimuth of the point in the
//!   camera frame (x forward, y left, z up along the mirror axis), `u = xc + r cosθ`,
//!   `v = yc + r sinθ`;
//! - [`ConicalMirror`] (seed 000): a pinhole looking up (+z) at a cone mirror whose apex points
//!   down at height `d` above the pinhole, half-angle `alpha` between surface and axis, mirror
//!   top at height `z_top`. Not a central camera: rays start on the mirror. A pixel at radius
//!   `r` from the image centre looks along `tanβ = r / f` from the axis, hits the cone, and is
//!   reflected; the reflected elevation is `β + 90° − 2α`. Projection solves the reflection in
//!   closed form by mirroring the pinhole across the cone's generatrix (the virtual viewpoint).
//!
//! `CameraInfo` encodings: pinhole uses `plumb_bob`; the omni models use `distortion_model`
//! `paracatadioptric` with `D = [xc, yc, f, r_min, r_max]` (the image ring holding the mirror;
//! readers accept the first three alone) and `conical_mirror` with
//! `D = [xc, yc, f, d, alpha, z_top]` (metres and radians). `K` repeats f and the centre.

use nalgebra::{Point2, Point3, Vector3};

/// A ray in the camera frame: `origin + t · dir`, `dir` unit length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    pub origin: Point3<f64>,
    pub dir: Vector3<f64>,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CameraError {
    #[error(
        "camera_info distortion model `{0}` is not one of plumb_bob, paracatadioptric, conical_mirror"
    )]
    UnknownModel(String),
    #[error("camera_info for `{model}` needs {need} distortion coefficients, has {have}")]
    Coefficients {
        model: String,
        need: usize,
        have: usize,
    },
    #[error("camera_info has a zero focal length or image size")]
    Degenerate,
}

/// Pinhole with plumb_bob distortion.
#[derive(Debug, Clone, PartialEq)]
pub struct Pinhole {
    pub width: u32,
    pub height: u32,
    pub fx: f64,
    pub fy: f64,
    pub cx: f64,
    pub cy: f64,
    /// k1, k2, p1, p2, k3.
    pub dist: [f64; 5],
}

impl Pinhole {
    /// An ideal camera with a horizontal field of view (degrees).
    pub fn from_fov(width: u32, height: u32, hfov_deg: f64) -> Pinhole {
        let f = f64::from(width) / 2.0 / (hfov_deg.to_radians() / 2.0).tan();
        Pinhole {
            width,
            height,
            fx: f,
            fy: f,
            cx: f64::from(width) / 2.0,
            cy: f64::from(height) / 2.0,
            dist: [0.0; 5],
        }
    }

    /// Apply distortion to normalised coordinates.
    pub fn distort(&self, x: f64, y: f64) -> (f64, f64) {
        let [k1, k2, p1, p2, k3] = self.dist;
        let r2 = x * x + y * y;
        let radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
        (
            x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
            y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y,
        )
    }

    /// Invert [`Self::distort`] (Newton's method on the 2×2 system; converges in a few steps
    /// for the distortions of real lenses).
    pub fn undistort(&self, xd: f64, yd: f64) -> (f64, f64) {
        let (mut x, mut y) = (xd, yd);
        for _ in 0..20 {
            let (fx, fy) = self.distort(x, y);
            let (ex, ey) = (fx - xd, fy - yd);
            if ex.abs() < 1e-14 && ey.abs() < 1e-14 {
                break;
            }
            // numerical Jacobian (the analytic one is long and this is not a hot path)
            let h = 1e-7;
            let (ax, ay) = self.distort(x + h, y);
            let (bx, by) = self.distort(x, y + h);
            let (j11, j21, j12, j22) = ((ax - fx) / h, (ay - fy) / h, (bx - fx) / h, (by - fy) / h);
            let det = j11 * j22 - j12 * j21;
            if det.abs() < 1e-12 {
                break;
            }
            x -= (j22 * ex - j12 * ey) / det;
            y -= (-j21 * ex + j11 * ey) / det;
        }
        (x, y)
    }

    pub fn project(&self, p: &Point3<f64>) -> Option<Point2<f64>> {
        if p.z <= 1e-9 {
            return None;
        }
        let (xd, yd) = self.distort(p.x / p.z, p.y / p.z);
        Some(Point2::new(self.fx * xd + self.cx, self.fy * yd + self.cy))
    }

    pub fn ray(&self, px: &Point2<f64>) -> Ray {
        let (x, y) = self.undistort((px.x - self.cx) / self.fx, (px.y - self.cy) / self.fy);
        Ray {
            origin: Point3::origin(),
            dir: Vector3::new(x, y, 1.0).normalize(),
        }
    }
}

/// Parabolic mirror + orthographic lens (single viewpoint).
#[derive(Debug, Clone, PartialEq)]
pub struct Paracatadioptric {
    pub width: u32,
    pub height: u32,
    pub xc: f64,
    pub yc: f64,
    pub f: f64,
    /// Image ring that holds the mirror (pixels from the centre).
    pub r_min: f64,
    pub r_max: f64,
}

impl Paracatadioptric {
    pub fn project(&self, p: &Point3<f64>) -> Option<Point2<f64>> {
        let rho = p.x.hypot(p.y);
        if rho < 1e-12 && p.z >= 0.0 {
            return None;
        }
        let theta = p.y.atan2(p.x);
        let tan_phi = p.z / rho;
        let r = if rho < 1e-12 {
            f64::INFINITY
        } else {
            self.f * ((tan_phi * tan_phi + 1.0).sqrt() - tan_phi)
        };
        if !(r >= self.r_min && r <= self.r_max) {
            return None;
        }
        Some(Point2::new(
            self.xc + r * theta.cos(),
            self.yc + r * theta.sin(),
        ))
    }

    /// `None` outside the mirror ring.
    pub fn ray(&self, px: &Point2<f64>) -> Option<Ray> {
        let (du, dv) = (px.x - self.xc, px.y - self.yc);
        let r = du.hypot(dv);
        if r < self.r_min.max(1e-9) || r > self.r_max {
            return None;
        }
        let theta = dv.atan2(du);
        // inverse of r = f(√(t²+1) − t): t = (f² − r²) / (2 r f)
        let tan_phi = (self.f * self.f - r * r) / (2.0 * r * self.f);
        let phi = tan_phi.atan();
        Some(Ray {
            origin: Point3::origin(),
            dir: Vector3::new(phi.cos() * theta.cos(), phi.cos() * theta.sin(), phi.sin()),
        })
    }
}

/// Pinhole looking up into a cone mirror (apex down).
#[derive(Debug, Clone, PartialEq)]
pub struct ConicalMirror {
    pub width: u32,
    pub height: u32,
    pub xc: f64,
    pub yc: f64,
    /// Focal length of the pinhole (pixels).
    pub f: f64,
    /// Height of the cone apex above the pinhole (m).
    pub d: f64,
    /// Half-angle between the cone surface and its axis (rad).
    pub alpha: f64,
    /// Height of the mirror's top rim above the pinhole (m).
    pub z_top: f64,
}

impl ConicalMirror {
    /// Image radius (pixels) of the mirror rim and apex: pixels outside `(0, r_rim)` see no mirror.
    pub fn r_rim(&self) -> f64 {
        // the rim is at height z_top, radius (z_top − d) tanα
        self.f * (self.z_top - self.d) * self.alpha.tan() / self.z_top
    }

    /// Reflect `i` about the cone normal in the meridional plane; returns (radial, z).
    fn reflect(&self, i_rho: f64, i_z: f64) -> (f64, f64) {
        // generatrix direction (sinα, cosα); outward normal (cosα, −sinα)
        let (s, c) = self.alpha.sin_cos();
        let (n_rho, n_z) = (c, -s);
        let dot = i_rho * n_rho + i_z * n_z;
        (i_rho - 2.0 * dot * n_rho, i_z - 2.0 * dot * n_z)
    }

    pub fn ray(&self, px: &Point2<f64>) -> Option<Ray> {
        let (du, dv) = (px.x - self.xc, px.y - self.yc);
        let r = du.hypot(dv);
        if r < 1e-9 || r > self.r_rim() {
            return None;
        }
        let theta = dv.atan2(du);
        let s = r / self.f; // tan of the angle from the axis
        let ta = self.alpha.tan();
        if s >= ta {
            return None;
        }
        let t = self.d * ta / (ta - s); // height of the hit point
        let (rho_h, z_h) = (t * s, t);
        let n = (s * s + 1.0).sqrt();
        let (o_rho, o_z) = self.reflect(s / n, 1.0 / n);
        let (ct, st) = (theta.cos(), theta.sin());
        Some(Ray {
            origin: Point3::new(rho_h * ct, rho_h * st, z_h),
            dir: Vector3::new(o_rho * ct, o_rho * st, o_z).normalize(),
        })
    }

    pub fn project(&self, p: &Point3<f64>) -> Option<Point2<f64>> {
        let rho_p = p.x.hypot(p.y);
        if rho_p < 1e-9 {
            return None;
        }
        let theta = p.y.atan2(p.x);
        let (s2, c2) = (2.0 * self.alpha).sin_cos();
        // virtual viewpoint: the pinhole mirrored across the generatrix, in (ρ, z)
        let (vr, vz) = (-self.d * s2, self.d * (1.0 - c2));
        // intersect the segment virtual → P with the generatrix ρ = (z − d) tanα
        let ta = self.alpha.tan();
        let (dr, dz) = (rho_p - vr, p.z - vz);
        let denom = dr - dz * ta;
        if denom.abs() < 1e-12 {
            return None;
        }
        let u = ((vz - self.d) * ta - vr) / denom;
        if !(0.0..=1.0).contains(&u) {
            return None;
        }
        let (rho_m, z_m) = (vr + u * dr, vz + u * dz);
        if z_m <= self.d || z_m > self.z_top {
            return None;
        }
        // P must be in front of the reflecting side (outside the cone)
        if rho_p <= (p.z - self.d) * ta && p.z > self.d {
            return None;
        }
        let r = self.f * rho_m / z_m;
        Some(Point2::new(
            self.xc + r * theta.cos(),
            self.yc + r * theta.sin(),
        ))
    }
}

/// Any camera model.
#[derive(Debug, Clone, PartialEq)]
pub enum CameraModel {
    Pinhole(Pinhole),
    Paracatadioptric(Paracatadioptric),
    ConicalMirror(ConicalMirror),
}

impl CameraModel {
    pub fn size(&self) -> (u32, u32) {
        match self {
            CameraModel::Pinhole(c) => (c.width, c.height),
            CameraModel::Paracatadioptric(c) => (c.width, c.height),
            CameraModel::ConicalMirror(c) => (c.width, c.height),
        }
    }

    /// The ray through a pixel position (pixel centres are at `i + 0.5`), in the camera frame.
    pub fn ray(&self, px: &Point2<f64>) -> Option<Ray> {
        match self {
            CameraModel::Pinhole(c) => Some(c.ray(px)),
            CameraModel::Paracatadioptric(c) => c.ray(px),
            CameraModel::ConicalMirror(c) => c.ray(px),
        }
    }

    /// Where a point in the camera frame appears, if it is visible to the model (it may still
    /// fall outside the image).
    pub fn project(&self, p: &Point3<f64>) -> Option<Point2<f64>> {
        match self {
            CameraModel::Pinhole(c) => c.project(p),
            CameraModel::Paracatadioptric(c) => c.project(p),
            CameraModel::ConicalMirror(c) => c.project(p),
        }
    }

    /// True if a pixel position lies inside the image.
    pub fn in_image(&self, px: &Point2<f64>) -> bool {
        let (w, h) = self.size();
        px.x >= 0.0 && px.y >= 0.0 && px.x < f64::from(w) && px.y < f64::from(h)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Test cameras, shared with `log::camera_info`'s tests.
    pub(crate) fn pinhole() -> Pinhole {
        Pinhole {
            width: 352,
            height: 288,
            fx: 300.0,
            fy: 302.0,
            cx: 176.3,
            cy: 143.1,
            dist: [-0.28, 0.09, 0.001, -0.0005, -0.01],
        }
    }

    pub(crate) fn para() -> Paracatadioptric {
        Paracatadioptric {
            width: 640,
            height: 480,
            xc: 320.5,
            yc: 240.2,
            f: 140.0,
            r_min: 20.0,
            r_max: 250.0,
        }
    }

    pub(crate) fn cone() -> ConicalMirror {
        ConicalMirror {
            width: 480,
            height: 480,
            xc: 240.0,
            yc: 240.0,
            f: 400.0,
            d: 0.05,
            alpha: 77.5_f64.to_radians(),
            z_top: 0.09,
        }
    }

    /// Points in front of a model, pushed through project → ray: the ray passes through the point.
    fn check_round_trip(m: &CameraModel, points: &[Point3<f64>]) {
        let mut checked = 0;
        for p in points {
            let Some(px) = m.project(p) else { continue };
            let ray = m
                .ray(&px)
                .unwrap_or_else(|| panic!("{px} projects but has no ray"));
            let to_p = p - ray.origin;
            let along = to_p.dot(&ray.dir);
            let miss = (to_p - ray.dir * along).norm();
            assert!(
                along > 0.0 && miss < 1e-7 * to_p.norm().max(1.0),
                "{p}: ray misses by {miss}"
            );
            // and the ray's pixel is where the point projects
            let back = m.project(&(ray.origin + ray.dir * along * 0.5 + ray.dir * along * 0.5));
            assert!((back.expect("projects") - px).norm() < 1e-6);
            checked += 1;
        }
        assert!(
            checked >= points.len() / 3,
            "only {checked} of {} points were visible",
            points.len()
        );
    }

    fn grid(z_range: (f64, f64)) -> Vec<Point3<f64>> {
        let mut pts = Vec::new();
        for i in 0..9 {
            for j in 0..9 {
                for k in 0..5 {
                    let z = z_range.0 + (z_range.1 - z_range.0) * k as f64 / 4.0;
                    pts.push(Point3::new(
                        -3.0 + 0.75 * i as f64,
                        -3.0 + 0.75 * j as f64,
                        z,
                    ));
                }
            }
        }
        pts
    }

    #[test]
    fn pinhole_round_trip_with_distortion() {
        let m = CameraModel::Pinhole(pinhole());
        check_round_trip(
            &m,
            &grid((1.0, 8.0))
                .into_iter()
                .map(|p| Point3::new(p.x * 0.3, p.y * 0.3, p.z))
                .collect::<Vec<_>>(),
        );
        // the principal point is where the optical axis lands
        let px = m.project(&Point3::new(0.0, 0.0, 5.0)).expect("on axis");
        assert!((px - Point2::new(176.3, 143.1)).norm() < 1e-12);
    }

    #[test]
    fn paracatadioptric_matches_the_paper_formula_and_round_trips() {
        let c = para();
        // a point on the horizon (φ = 0) lands at r = f
        let px = c.project(&Point3::new(3.0, 0.0, 0.0)).expect("horizon");
        assert!((px.x - (c.xc + c.f)).abs() < 1e-12 && (px.y - c.yc).abs() < 1e-12);
        // φ = −30°: r = f(√(tan²φ+1) − tanφ) = f(2/√3 + 1/√3) = f√3
        let p = Point3::new(0.0, 2.0, -2.0 * 30f64.to_radians().tan());
        let px = c.project(&p).expect("below horizon");
        assert!(((px.y - c.yc) - c.f * 3f64.sqrt()).abs() < 1e-9);
        check_round_trip(&CameraModel::Paracatadioptric(c), &grid((-1.6, 0.6)));
    }

    #[test]
    fn conical_mirror_reflects_as_designed_and_round_trips() {
        let c = cone();
        // a ray near the axis (β ≈ 0) leaves at elevation 90° − 2α
        let r = c.ray(&Point2::new(c.xc + 1e-3, c.yc)).expect("near axis");
        let elev = r.dir.z.atan2(r.dir.x.hypot(r.dir.y));
        assert!(
            (elev - (90f64.to_radians() - 2.0 * c.alpha)).abs() < 1e-5,
            "{}",
            elev.to_degrees()
        );
        // every ray starts on the cone surface
        for k in 1..10 {
            let ray = c
                .ray(&Point2::new(c.xc + k as f64 * c.r_rim() / 10.0, c.yc))
                .expect("on mirror");
            let on_cone = (ray.origin.z - c.d) * c.alpha.tan();
            assert!((ray.origin.x.hypot(ray.origin.y) - on_cone).abs() < 1e-12);
        }
        check_round_trip(&CameraModel::ConicalMirror(c), &grid((-1.6, 0.0)));
    }
}

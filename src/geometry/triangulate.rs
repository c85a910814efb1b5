//! Linear (DLT) triangulation of one 3D point from its pixels in two or more calibrated
//! cameras (Hartley & Zisserman, *Multiple View Geometry*, 2nd ed., §12.2), as seed 004 §5
//! triangulates head points: lens distortion is removed first (each pixel becomes the ray of
//! the camera model through it), then every view contributes the rows of
//! `[d]ₓ · (R·X + t) = 0` (the ray direction `d` crossed with the point in the camera frame),
//! and the homogeneous point `X` is the right singular vector of the stacked system with the
//! smallest singular value.
//!
//! Using the ray (not the pixel) makes the same code serve every central camera model in
//! [`super::camera`]. [`CalibratedView`] also gives the *ideal* (distortion-free) pixel of a
//! point, the space in which seed 004 measures reprojection errors (eq. 4, "radial distortion
//! has been previously compensated").
//!
//! What it does not do: no non-linear refinement (the paper uses the linear method), no
//! outlier rejection, no uncertainty.

use nalgebra::{Isometry3, Matrix3, Matrix3x4, Matrix4, Point2, Point3, Vector3};

use super::camera::CameraModel;

/// Why a point could not be triangulated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TriangulateError {
    #[error("triangulation needs at least 2 views, got {0}")]
    TooFewViews(usize),
    #[error("pixel ({x:.2}, {y:.2}) has no ray in view {view}")]
    NoRay { view: usize, x: f64, y: f64 },
    #[error("the rays are degenerate (parallel, or the solution lies at infinity)")]
    Degenerate,
}

/// A camera with its pose: `world_from_camera` maps camera-frame points (ROS optical frame for
/// pinholes) to the world (`map`).
#[derive(Debug, Clone, PartialEq)]
pub struct CalibratedView {
    pub model: CameraModel,
    pub world_from_camera: Isometry3<f64>,
}

impl CalibratedView {
    pub fn new(model: CameraModel, world_from_camera: Isometry3<f64>) -> CalibratedView {
        CalibratedView {
            model,
            world_from_camera,
        }
    }

    /// The optical centre in the world.
    pub fn center(&self) -> Point3<f64> {
        Point3::from(self.world_from_camera.translation.vector)
    }

    /// Focal length and principal point `(β, p)` of seed 004 eq. 6–7; for non-pinhole models the
    /// `K` entries their `CameraInfo` repeats.
    pub fn focal_and_principal(&self) -> (f64, Point2<f64>) {
        match &self.model {
            CameraModel::Pinhole(c) => (0.5 * (c.fx + c.fy), Point2::new(c.cx, c.cy)),
            CameraModel::Paracatadioptric(c) => (c.f, Point2::new(c.xc, c.yc)),
            CameraModel::ConicalMirror(c) => (c.f, Point2::new(c.xc, c.yc)),
        }
    }

    /// The ray through a (distorted, raw) pixel in the world: origin and unit direction.
    pub fn ray_in_world(&self, px: &Point2<f64>) -> Option<(Point3<f64>, Vector3<f64>)> {
        let ray = self.model.ray(px)?;
        Some((
            self.world_from_camera * ray.origin,
            self.world_from_camera.rotation * ray.dir,
        ))
    }

    /// The raw (distorted) pixel of a world point, if the model sees it.
    pub fn project(&self, point_in_world: &Point3<f64>) -> Option<Point2<f64>> {
        self.model
            .project(&(self.world_from_camera.inverse() * point_in_world))
    }

    /// The ideal pixel of a world point: pinholes without distortion; other models unchanged.
    pub fn project_ideal(&self, point_in_world: &Point3<f64>) -> Option<Point2<f64>> {
        let p = self.world_from_camera.inverse() * point_in_world;
        match &self.model {
            CameraModel::Pinhole(c) => {
                (p.z > 1e-9).then(|| Point2::new(c.fx * p.x / p.z + c.cx, c.fy * p.y / p.z + c.cy))
            }
            m => m.project(&p),
        }
    }

    /// A raw pixel with the lens distortion removed (pinholes); other models unchanged.
    pub fn ideal_px(&self, px: &Point2<f64>) -> Option<Point2<f64>> {
        match &self.model {
            CameraModel::Pinhole(c) => {
                let (x, y) = c.undistort((px.x - c.cx) / c.fx, (px.y - c.cy) / c.fy);
                Some(Point2::new(c.fx * x + c.cx, c.fy * y + c.cy))
            }
            _ => Some(*px),
        }
    }
}

/// Triangulate one point from `(view, raw pixel)` pairs by the linear method.
pub fn triangulate_dlt(
    observations: &[(&CalibratedView, Point2<f64>)],
) -> Result<Point3<f64>, TriangulateError> {
    if observations.len() < 2 {
        return Err(TriangulateError::TooFewViews(observations.len()));
    }
    let mut rays = Vec::with_capacity(observations.len());
    for (k, (view, px)) in observations.iter().enumerate() {
        rays.push(view.ray_in_world(px).ok_or(TriangulateError::NoRay {
            view: k,
            x: px.x,
            y: px.y,
        })?);
    }
    triangulate_rays(&rays)
}

/// The DLT on rays already in the world (`origin`, unit `direction`): each contributes the
/// three rows of `[d]ₓ · (X − o) = 0`, and `X` is the null vector of the stacked homogeneous
/// system (smallest singular value, computed as the smallest eigenvector of its 4 × 4 normal
/// matrix). For speed when the same pixels are tried in many
/// combinations (seed 004's exhaustive search), rays are computed once by the caller.
pub fn triangulate_rays(
    rays: &[(Point3<f64>, Vector3<f64>)],
) -> Result<Point3<f64>, TriangulateError> {
    if rays.len() < 2 {
        return Err(TriangulateError::TooFewViews(rays.len()));
    }
    // Condition the system (Hartley's normalisation on the unknown side): centre the world
    // on the mean ray origin and scale it to unit mean distance, X = s·X' + m.
    let n = rays.len() as f64;
    let mean = rays.iter().fold(Vector3::zeros(), |a, (o, _)| a + o.coords) / n;
    let spread = rays
        .iter()
        .map(|(o, _)| (o.coords - mean).norm())
        .sum::<f64>()
        / n;
    let scale = if spread > 1e-12 { spread } else { 1.0 };
    // X is the right singular vector of the stacked 3k × 4 system A with the smallest
    // singular value, i.e. the eigenvector of the 4 × 4 AᵀA with the smallest eigenvalue:
    // accumulated row block by row block, no allocation (the exhaustive search of seed 004
    // triangulates millions of combinations).
    let mut ata = Matrix4::<f64>::zeros();
    for (origin, d) in rays {
        let cross = Matrix3::new(0.0, -d.z, d.y, d.z, 0.0, -d.x, -d.y, d.x, 0.0);
        let rhs = cross * (mean - origin.coords);
        let mut block = Matrix3x4::<f64>::zeros();
        block
            .fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(cross * scale));
        block.set_column(3, &rhs);
        ata += block.transpose() * block;
    }
    let eig = ata.symmetric_eigen();
    if !eig.eigenvalues.iter().all(|v| v.is_finite()) {
        return Err(TriangulateError::Degenerate);
    }
    let imin = eig.eigenvalues.imin();
    // degenerate rays (parallel, or one ray only in effect): a second eigenvalue near zero
    let mut sorted = [
        eig.eigenvalues[0],
        eig.eigenvalues[1],
        eig.eigenvalues[2],
        eig.eigenvalues[3],
    ];
    sorted.sort_by(f64::total_cmp);
    if sorted[1] <= 1e-12 * sorted[3].max(1e-300) {
        return Err(TriangulateError::Degenerate);
    }
    let x = eig.eigenvectors.column(imin);
    if x[3].abs() < 1e-12 {
        return Err(TriangulateError::Degenerate);
    }
    let p = Vector3::new(x[0], x[1], x[2]) / x[3] * scale + mean;
    if p.iter().all(|v| v.is_finite()) {
        Ok(Point3::from(p))
    } else {
        Err(TriangulateError::Degenerate)
    }
}

/// Mean distance in ideal pixels between each observation and the reprojection of `point`
/// (seed 004 eq. 4, `E_m`); `None` if a view does not see the point.
pub fn mean_reprojection_error_px(
    observations: &[(&CalibratedView, Point2<f64>)],
    point: &Point3<f64>,
) -> Option<f64> {
    let mut sum = 0.0;
    for (view, px) in observations {
        // behind the camera: no reprojection (and no person)
        let in_camera = view.world_from_camera.inverse() * point;
        if let CameraModel::Pinhole(_) = view.model
            && in_camera.z <= 0.0
        {
            return None;
        }
        let seen = view.project_ideal(point)?;
        let observed = view.ideal_px(px)?;
        sum += (seen - observed).norm();
    }
    Some(sum / observations.len().max(1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::camera::Pinhole;
    use crate::geometry::look_at;

    fn corner_views(dist: bool) -> Vec<CalibratedView> {
        let corners = [
            [0.15, 0.15, 2.85],
            [7.85, 0.15, 2.85],
            [7.85, 8.35, 2.85],
            [0.15, 8.35, 2.85],
        ];
        let dists = [
            [-0.24, 0.06, 0.0, 0.0, 0.0],
            [-0.22, 0.05, 0.001, -0.0005, 0.0],
            [-0.25, 0.07, 0.0, 0.0, -0.01],
            [-0.23, 0.06, 0.0, 0.0, 0.0],
        ];
        corners
            .iter()
            .zip(dists)
            .map(|(c, d)| {
                let mut pin = Pinhole::from_fov(352, 288, 78.0);
                pin.cx += 1.7;
                pin.cy -= 2.3;
                pin.fy *= 1.01;
                if dist {
                    pin.dist = d;
                }
                CalibratedView::new(
                    CameraModel::Pinhole(pin),
                    look_at(Point3::from(*c), Point3::new(4.0, 4.25, 0.7)),
                )
            })
            .collect()
    }

    fn check(views: &[CalibratedView], point: Point3<f64>) {
        let obs: Vec<(&CalibratedView, Point2<f64>)> = views
            .iter()
            .map(|v| (v, v.project(&point).expect("visible")))
            .collect();
        let x = triangulate_dlt(&obs).expect("triangulates");
        assert!(
            (x - point).norm() < 1e-9,
            "{} views: {x} vs {point}",
            views.len()
        );
        let e = mean_reprojection_error_px(&obs, &x).expect("reprojects");
        assert!(e < 1e-6, "E_m = {e}");
    }

    #[test]
    fn noise_free_projections_triangulate_exactly_with_2_3_4_cameras() {
        for dist in [false, true] {
            let views = corner_views(dist);
            for p in [
                Point3::new(4.0, 4.25, 1.75),
                Point3::new(2.1, 5.9, 1.62),
                Point3::new(6.3, 1.4, 1.88),
            ] {
                for n in 2..=4 {
                    check(&views[..n], p);
                }
                check(&[views[1].clone(), views[3].clone()], p);
            }
        }
    }

    #[test]
    fn parallel_rays_are_degenerate() {
        let d = Vector3::new(0.0, 0.6, 0.8);
        let rays = [
            (Point3::new(0.0, 0.0, 0.0), d),
            (Point3::new(1.0, 0.0, 0.0), d),
        ];
        assert_eq!(triangulate_rays(&rays), Err(TriangulateError::Degenerate));
    }

    #[test]
    fn one_view_is_not_enough() {
        let views = corner_views(false);
        let p = Point3::new(4.0, 4.0, 1.7);
        let obs = [(&views[0], views[0].project(&p).expect("visible"))];
        assert_eq!(triangulate_dlt(&obs), Err(TriangulateError::TooFewViews(1)));
    }

    #[test]
    fn ideal_pixels_undo_the_distortion() {
        let views = corner_views(true);
        let p = Point3::new(1.0, 6.0, 1.0);
        for v in &views {
            let raw = v.project(&p).expect("visible");
            let ideal = v.project_ideal(&p).expect("visible");
            let back = v.ideal_px(&raw).expect("undistorts");
            assert!((back - ideal).norm() < 1e-8);
        }
    }

    #[test]
    fn reprojection_error_is_the_mean_pixel_distance() {
        let views = corner_views(false);
        let p = Point3::new(3.0, 3.0, 1.7);
        let mut obs: Vec<(&CalibratedView, Point2<f64>)> = views
            .iter()
            .take(2)
            .map(|v| (v, v.project(&p).expect("visible")))
            .collect();
        // moving one observation by 4 px along x: E_m is the mean of the two distances
        obs[0].1.x += 4.0;
        let e = mean_reprojection_error_px(&obs, &p).expect("reprojects");
        assert!((e - 2.0).abs() < 1e-9);
    }
}

//! The camera at one frame: its pinhole model and its pose in the world (the pan-tilt unit's
//! angles included), with the conversions anchoring needs — a pixel to a world bearing and
//! elevation, a face box to a distance from its width, a world point to a pixel.

use nalgebra::{Isometry3, Point2, Point3};

use crate::geometry::camera::Pinhole;

/// Width of a face box as the detector draws it (m): wider than the face between the ears
/// (adult bizygomatic breadth ≈ 14 cm). Chosen on the face probe's renders
/// (`examples/face_probe.rs`, 640×480: boxes 1.07–1.4 times 0.15 m wide at 1.3–2.4 m), not on
/// the evaluated sessions.
pub const FACE_WIDTH_M: f64 = 0.18;

/// The camera at one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct CameraView {
    pub model: Pinhole,
    /// `world_from_optical` (z forward, x right, y down).
    pub pose: Isometry3<f64>,
}

impl CameraView {
    /// The camera centre in the world.
    pub fn origin(&self) -> Point3<f64> {
        Point3::from(self.pose.translation.vector)
    }

    /// World azimuth and elevation (rad) of the ray through pixel `px`.
    pub fn bearing_elevation(&self, px: [f64; 2]) -> (f64, f64) {
        let ray = self.model.ray(&Point2::new(px[0], px[1]));
        let d = self.pose.rotation * ray.dir;
        (d.y.atan2(d.x), d.z.atan2(d.x.hypot(d.y)))
    }

    /// The pixel of a world point, when it is in front of the camera and inside the image
    /// by at least `margin_px`.
    pub fn pixel(&self, p: &Point3<f64>, margin_px: f64) -> Option<[f64; 2]> {
        let q = self.model.project(&(self.pose.inverse() * p))?;
        let (w, h) = (f64::from(self.model.width), f64::from(self.model.height));
        (q.x >= margin_px && q.y >= margin_px && q.x <= w - margin_px && q.y <= h - margin_px)
            .then_some([q.x, q.y])
    }

    /// Distance (m, along the ray) of a face whose box is `width_px` wide.
    pub fn face_distance(&self, width_px: f64) -> f64 {
        self.model.fx * FACE_WIDTH_M / width_px.max(1.0)
    }

    /// Focal length (px).
    pub fn focal_px(&self) -> f64 {
        self.model.fx
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry;
    use nalgebra::Translation3;

    #[test]
    fn a_pixel_gives_back_the_bearing_of_the_point_it_shows() {
        let pose = geometry::pose_xyz_rpy([1.0, 2.0, 1.41], [0.0, 0.1, 0.6])
            * Isometry3::from_parts(Translation3::identity(), geometry::body_from_optical());
        let v = CameraView {
            model: Pinhole::from_fov(320, 240, 48.8),
            pose,
        };
        let p = Point3::new(3.0, 3.5, 1.2);
        let px = v.pixel(&p, 0.0).expect("in view");
        let (az, el) = v.bearing_elevation(px);
        let d = p - v.origin();
        assert!((az - d.y.atan2(d.x)).abs() < 1e-9);
        assert!((el - d.z.atan2(d.x.hypot(d.y))).abs() < 1e-9);
        assert!(
            v.pixel(&Point3::new(-3.0, 2.0, 1.4), 0.0).is_none(),
            "behind"
        );
    }
}

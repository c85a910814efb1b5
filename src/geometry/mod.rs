//! Geometry shared by the synthesizer and the pipelines: camera models (pixel ↔ ray) and pose
//! helpers. Frames follow REP 103/105: world `map` z up; bodies x forward, y left, z up; pinhole
//! cameras use the optical frame (x right, y down, z forward).

pub mod camera;
pub mod fundamental;
pub mod rect;
pub mod triangulate;

use nalgebra::{Isometry3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};

/// `world_from_optical` for a pinhole at `from` looking at `to` (image up ≈ world +z).
pub fn look_at(from: Point3<f64>, to: Point3<f64>) -> Isometry3<f64> {
    let z = (to - from).normalize();
    let up = if z.cross(&Vector3::z()).norm() < 1e-6 {
        Vector3::y()
    } else {
        Vector3::z()
    };
    let x = z.cross(&up).normalize(); // forward × up points right: optical x
    let y = z.cross(&x); // forward × right points down: optical y
    let r = Rotation3::from_matrix_unchecked(nalgebra::Matrix3::from_columns(&[x, y, z]));
    Isometry3::from_parts(
        Translation3::from(from.coords),
        UnitQuaternion::from_rotation_matrix(&r),
    )
}

/// Pose from position and roll/pitch/yaw (rad, ZYX convention as ROS).
pub fn pose_xyz_rpy(xyz: [f64; 3], rpy: [f64; 3]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(xyz[0], xyz[1], xyz[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    )
}

/// Rotation from a body frame (x forward, y left, z up) to the optical frame of a camera looking
/// along the body's +x: `body_from_optical`.
pub fn body_from_optical() -> UnitQuaternion<f64> {
    let r = Rotation3::from_matrix_unchecked(nalgebra::Matrix3::new(
        0.0, 0.0, 1.0, //
        -1.0, 0.0, 0.0, //
        0.0, -1.0, 0.0,
    ));
    UnitQuaternion::from_rotation_matrix(&r)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn look_at_points_the_optical_axis_at_the_target() {
        let from = Point3::new(0.0, 0.0, 2.5);
        let to = Point3::new(4.0, 3.0, 0.0);
        let w = look_at(from, to);
        // the target lies on the optical (+z) axis
        let p = w.inverse() * to;
        assert!(p.x.abs() < 1e-12 && p.y.abs() < 1e-12 && p.z > 0.0);
        // a point above the target appears higher in the image (smaller optical y)
        let above = w.inverse() * Point3::new(4.0, 3.0, 1.0);
        assert!(above.y / above.z < 0.0);
        // a point to the right (seen from the camera) has positive optical x
        let right = w.inverse() * Point3::new(4.0 + 0.6, 3.0 - 0.8, 0.0);
        assert!(right.x > 0.0);
    }

    #[test]
    fn body_to_optical_axes() {
        let q = body_from_optical();
        // optical z (forward) is body x; optical x (right) is body −y; optical y (down) is body −z
        assert!((q * Vector3::z() - Vector3::x()).norm() < 1e-12);
        assert!((q * Vector3::x() + Vector3::y()).norm() < 1e-12);
        assert!((q * Vector3::y() + Vector3::z()).norm() < 1e-12);
    }
}

//! Scan → 2-D points, in the sensor frame and in the fixed frame.
//!
//! Beam `k` has bearing `angle_min + k·angle_increment` (counter-clockwise from the sensor's
//! x axis) and range `r_k`; its sensor-frame point is `(r cos θ, r sin θ)`. The fixed-frame
//! point is the sensor pose (`fixed <- sensor`, a 3-D isometry) applied to `(x, y, 0)`, keeping
//! `x, y` (exact for a level scanner; the projection onto the ground plane otherwise). Without
//! a pose (logs without odometry) the fixed frame is the sensor frame.
//!
//! A beam is a **no return** when its range is NaN, ±inf, 0.0 or ≤ 0, or lies outside
//! `[range_min, range_max]` (bounds inclusive, as drivers clamp to them). No-returns produce no
//! point, but each point keeps its beam index, so [`crate::laser::segment`] sees the gap.

use nalgebra::{Isometry3, Point2, Point3};

use crate::log::msgs::LaserScan;

/// The beam geometry of a scan (the `sensor_msgs/LaserScan` fields that place beams).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanGeometry {
    pub angle_min: f64,
    pub angle_increment: f64,
    pub range_min: f64,
    pub range_max: f64,
}

impl ScanGeometry {
    /// The beam geometry of a decoded `sensor_msgs/LaserScan`.
    pub fn of(scan: &LaserScan) -> Self {
        ScanGeometry {
            angle_min: f64::from(scan.angle_min),
            angle_increment: f64::from(scan.angle_increment),
            range_min: f64::from(scan.range_min),
            range_max: f64::from(scan.range_max),
        }
    }

    /// Bearing of beam `k` (rad).
    pub fn angle(&self, k: usize) -> f64 {
        self.angle_min + k as f64 * self.angle_increment
    }

    /// True when `r` is a real return (see the module doc).
    pub fn is_return(&self, r: f64) -> bool {
        r.is_finite() && r > 0.0 && r >= self.range_min && r <= self.range_max
    }
}

/// One return.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanPoint {
    /// Index of the beam in the scan.
    pub beam: usize,
    pub range: f64,
    pub angle: f64,
    /// In the sensor frame (m).
    pub sensor: Point2<f64>,
    /// In the fixed frame (m); equal to `sensor` without a pose.
    pub fixed: Point2<f64>,
}

/// The returns of one scan, in beam order. A pose with non-finite entries is treated as absent.
pub fn project(
    ranges: &[f32],
    geometry: &ScanGeometry,
    pose: Option<&Isometry3<f64>>,
) -> Vec<ScanPoint> {
    let pose = pose.filter(|p| pose_is_finite(p));
    ranges
        .iter()
        .enumerate()
        .filter_map(|(beam, &r)| {
            let range = f64::from(r);
            if !geometry.is_return(range) {
                return None;
            }
            let angle = geometry.angle(beam);
            let sensor = Point2::new(range * angle.cos(), range * angle.sin());
            if !(sensor.x.is_finite() && sensor.y.is_finite()) {
                return None;
            }
            Some(ScanPoint {
                beam,
                range,
                angle,
                sensor,
                fixed: to_fixed(pose, sensor),
            })
        })
        .collect()
}

/// The points whose return lies at least `min_z` above the fixed frame's `z = 0` (the ground
/// plane of `odom` on a wheeled robot), with the pose the scan was placed with — a pitched
/// laser's ground hits removed. Returns the kept points and how many were dropped.
pub fn above_ground(
    points: &[ScanPoint],
    pose: &Isometry3<f64>,
    min_z: f64,
) -> (Vec<ScanPoint>, usize) {
    let kept: Vec<ScanPoint> = points
        .iter()
        .filter(|q| (pose * Point3::new(q.sensor.x, q.sensor.y, 0.0)).z >= min_z)
        .copied()
        .collect();
    let dropped = points.len() - kept.len();
    (kept, dropped)
}

/// A sensor-frame point in the fixed frame (identity without a pose).
pub fn to_fixed(pose: Option<&Isometry3<f64>>, p: Point2<f64>) -> Point2<f64> {
    match pose {
        Some(pose) => {
            let q = pose * Point3::new(p.x, p.y, 0.0);
            Point2::new(q.x, q.y)
        }
        None => p,
    }
}

fn pose_is_finite(p: &Isometry3<f64>) -> bool {
    p.translation.vector.iter().all(|v| v.is_finite())
        && p.rotation.coords.iter().all(|v| v.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};

    fn geometry() -> ScanGeometry {
        ScanGeometry {
            angle_min: -std::f64::consts::FRAC_PI_2,
            angle_increment: std::f64::consts::FRAC_PI_2,
            range_min: 0.05,
            range_max: 10.0,
        }
    }

    #[test]
    fn no_returns_are_skipped_and_beams_kept() {
        let ranges = [
            1.0,
            f32::NAN,
            2.0,
            f32::INFINITY,
            0.0,
            0.01,
            11.0,
            f32::NEG_INFINITY,
        ];
        let g = ScanGeometry {
            angle_increment: 0.1,
            ..geometry()
        };
        let beams: Vec<usize> = project(&ranges, &g, None).iter().map(|p| p.beam).collect();
        assert_eq!(beams, vec![0, 2]);
    }

    #[test]
    fn sensor_and_fixed_points_follow_the_pose() {
        // beams at -90°, 0°, +90°; pose: yaw +90° and translation (1, 2, 0.5)
        let pose = Isometry3::from_parts(
            Translation3::new(1.0, 2.0, 0.5),
            UnitQuaternion::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_2),
        );
        let pts = project(&[1.0, 2.0, 3.0], &geometry(), Some(&pose));
        let expect_sensor = [[0.0, -1.0], [2.0, 0.0], [0.0, 3.0]];
        let expect_fixed = [[2.0, 2.0], [1.0, 4.0], [-2.0, 2.0]];
        for (i, p) in pts.iter().enumerate() {
            assert!(
                (p.sensor - Point2::from(expect_sensor[i])).norm() < 1e-12,
                "{p:?}"
            );
            assert!(
                (p.fixed - Point2::from(expect_fixed[i])).norm() < 1e-12,
                "{p:?}"
            );
        }
        let no_pose = project(&[1.0, 2.0, 3.0], &geometry(), None);
        assert!(no_pose.iter().all(|p| p.fixed == p.sensor));
    }

    /// A laser 0.45 m up, pitched 10° nose down: a beam straight ahead meets the ground at
    /// 0.45 / sin 10° = 2.591 m, so a return at 2 m is 0.103 m up (kept at 0.1 m) and one at
    /// 3 m is 0.071 m below the ground plane (dropped); the beams at ±90° stay at 0.45 m.
    #[test]
    fn above_ground_drops_the_returns_of_a_pitched_laser_on_the_ground() {
        let pitch = 10f64.to_radians();
        let pose = Isometry3::from_parts(
            Translation3::new(0.0, 0.0, 0.45),
            UnitQuaternion::from_euler_angles(0.0, pitch, 0.0),
        );
        let g = ScanGeometry {
            angle_min: 0.0,
            angle_increment: 0.0,
            ..geometry()
        };
        let two = project(&[2.0], &g, Some(&pose));
        let z = (pose * Point3::new(two[0].sensor.x, two[0].sensor.y, 0.0)).z;
        assert!((z - (0.45 - 2.0 * pitch.sin())).abs() < 1e-12, "{z}");
        assert!((0.45 / pitch.sin() - 2.591).abs() < 1e-3);
        let three = project(&[3.0], &g, Some(&pose));
        let sides = project(&[3.0, 3.0, 3.0], &geometry(), Some(&pose));
        assert_eq!(above_ground(&two, &pose, 0.1), (two.clone(), 0));
        assert_eq!(above_ground(&three, &pose, 0.1), (vec![], 1));
        let (kept, dropped) = above_ground(&sides, &pose, 0.1);
        assert_eq!(dropped, 1, "{kept:?}");
        assert_eq!(kept.iter().map(|q| q.beam).collect::<Vec<_>>(), vec![0, 2]);
    }

    #[test]
    fn a_non_finite_pose_counts_as_absent() {
        let pose = Isometry3::translation(f64::NAN, 0.0, 0.0);
        let pts = project(&[1.0], &geometry(), Some(&pose));
        assert_eq!(pts[0].fixed, pts[0].sensor);
    }
}

//! What the ground truth says about a scan: where the laser's beam towards the target meets
//! the ground (the paper's "gnd": a balancing robot that pitches forward sees the ground
//! between itself and the person), whether another person stands in the line of sight (the
//! paper's "x"), whether the target is outside the laser's field of view or range — pure
//! geometry on the true poses — and whether the scan itself returns short of the target on
//! every beam towards it ([`short_of`]: something stands in the way, a tree or a bush
//! included, which the people's ground truth does not list).

use nalgebra::{Isometry3, Point2, Point3, Vector3};

use crate::groundtruth::PersonTruth;

/// Distance along the beam from the laser at which a beam of the laser's scan plane towards
/// the ground point `target` (map frame) meets the ground, `None` when it does not descend.
/// `map_from_laser` is the laser's true pose.
pub fn ground_hit_distance(map_from_laser: &Isometry3<f64>, target: Point2<f64>) -> Option<f64> {
    let laser_from_map = map_from_laser.inverse();
    let local = laser_from_map * Point3::new(target.x, target.y, 0.0);
    let bearing = local.y.atan2(local.x);
    let dir = map_from_laser.rotation * Vector3::new(bearing.cos(), bearing.sin(), 0.0);
    let z0 = map_from_laser.translation.vector.z;
    (dir.z < -1e-12 && z0 > 0.0).then(|| -z0 / dir.z)
}

/// The laser's view of the target: `(ground, occluded, out_of_view)`. The beam reaches the
/// target's body at its horizontal distance minus the body radius.
pub fn view(
    map_from_laser: &Isometry3<f64>,
    target: &PersonTruth,
    others: &[&PersonTruth],
    fov_half_rad: f64,
    range_max: f64,
    margin_m: f64,
) -> (bool, bool, bool) {
    let o = map_from_laser.translation.vector;
    let lp = Point2::new(o.x, o.y);
    let tp = Point2::new(target.x, target.y);
    let dist = (tp - lp).norm();
    let reach = (dist - target.radius).max(0.0);
    let ground = ground_hit_distance(map_from_laser, tp).is_some_and(|d| d < reach);
    let local = map_from_laser.inverse() * Point3::new(target.x, target.y, 0.0);
    let bearing = local.y.atan2(local.x);
    let out_of_view = bearing.abs() > fov_half_rad || dist > range_max;
    let dir = (tp - lp) / dist.max(1e-9);
    let occluded = others.iter().any(|p| {
        let q = Point2::new(p.x, p.y) - lp;
        let along = q.dot(&dir);
        let across = (q - dir * along).norm();
        along > 0.0 && along < dist && across < p.radius + margin_m
    });
    (ground, occluded, out_of_view)
}

/// A scan's beams: the first beam's angle, the step (rad), the ranges (m; NaN, ±inf and 0:
/// no return).
#[derive(Debug, Clone, Copy)]
pub struct Beams<'a> {
    pub angle_min: f64,
    pub increment: f64,
    pub ranges: &'a [f32],
}

/// Whether every beam of the scan towards the target's body (bearings within
/// asin(radius / distance) of its centre, seen from the laser) returns more than `margin_m`
/// short of the body's near side: something stands between laser and target. `false` when no
/// beam points at the target (out of the scan) or any such beam has no return or reaches it.
pub fn short_of(
    map_from_laser: &Isometry3<f64>,
    target: &PersonTruth,
    beams: Beams<'_>,
    margin_m: f64,
) -> bool {
    let local = map_from_laser.inverse() * Point3::new(target.x, target.y, 0.0);
    let dist = local.x.hypot(local.y);
    if !(dist > target.radius && beams.increment > 0.0) {
        return false;
    }
    let bearing = local.y.atan2(local.x);
    let half = (target.radius / dist).min(1.0).asin();
    let first = ((bearing - half - beams.angle_min) / beams.increment).ceil();
    let last = ((bearing + half - beams.angle_min) / beams.increment).floor();
    if !(first.is_finite() && last.is_finite()) || last < 0.0 || first > last {
        return false;
    }
    let n = beams.ranges.len() as f64;
    if first >= n {
        return false;
    }
    let limit = dist - target.radius - margin_m;
    (first.max(0.0) as usize..=(last.min(n - 1.0) as usize)).all(|i| {
        let r = f64::from(beams.ranges[i]);
        r.is_finite() && r > 0.0 && r < limit
    })
}

/// Yaw and pitch (positive nose down, REP 103) of a pose.
pub fn yaw_pitch(pose: &Isometry3<f64>) -> (f64, f64) {
    let (_, pitch, yaw) = pose.rotation.euler_angles();
    (yaw, pitch)
}

/// Range and bearing (relative to the heading) of a point from a planar pose.
pub fn range_bearing(x: f64, y: f64, yaw: f64, p: (f64, f64)) -> (f64, f64) {
    let (dx, dy) = (p.0 - x, p.1 - y);
    let b = dy.atan2(dx) - yaw;
    let b = (b + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
    (dx.hypot(dy), b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};

    fn person(id: u32, x: f64, y: f64) -> PersonTruth {
        PersonTruth {
            id,
            x,
            y,
            vx: 0.0,
            vy: 0.0,
            height: 1.8,
            head_z: 1.7,
            radius: 0.2,
            legs: [[x, y - 0.1], [x, y + 0.1]],
            leg_radius: 0.06,
            cameras: Vec::new(),
        }
    }

    /// A laser 0.45 m up pitched 10° nose down meets the ground 0.45 / tan 10° = 2.552 m ahead.
    #[test]
    fn a_pitched_laser_meets_the_ground_at_the_closed_form_distance() {
        let pitch = 10f64.to_radians();
        let pose = Isometry3::from_parts(
            Translation3::new(1.0, 2.0, 0.45),
            UnitQuaternion::from_euler_angles(0.0, pitch, 0.3),
        );
        let ahead = Point2::new(1.0 + 5.0 * 0.3f64.cos(), 2.0 + 5.0 * 0.3f64.sin());
        let d = ground_hit_distance(&pose, ahead).expect("descends");
        assert!((d - 0.45 / pitch.sin()).abs() < 1e-9, "{d}");
        let level = Isometry3::translation(0.0, 0.0, 0.45);
        assert!(ground_hit_distance(&level, Point2::new(3.0, 0.0)).is_none());
        // a target 3 m ahead is behind the ground hit (2.55 m horizontal): gnd
        let t = person(1, 1.0 + 3.0 * 0.3f64.cos(), 2.0 + 3.0 * 0.3f64.sin());
        let (g, o, out) = view(&pose, &t, &[], 1.6, 20.0, 0.1);
        assert!(g && !o && !out);
    }

    #[test]
    fn a_person_on_the_line_of_sight_occludes() {
        let pose = Isometry3::translation(0.0, 0.0, 0.45);
        let t = person(1, 4.0, 0.0);
        let near = person(2, 2.0, 0.25);
        let aside = person(3, 2.0, 0.6);
        let behind = person(4, 6.0, 0.0);
        assert!(view(&pose, &t, &[&near], 1.6, 20.0, 0.1).1);
        assert!(!view(&pose, &t, &[&aside, &behind], 1.6, 20.0, 0.1).1);
        // behind the laser: out of its 180° view
        assert!(view(&pose, &person(1, -3.0, 0.0), &[], 1.6, 20.0, 0.1).2);
    }

    /// A level laser at the origin, beams every 0.5° from −90°: a target 4 m ahead (radius
    /// 0.2 m) spans the beams within asin(0.05) = 2.87° of 0°, i.e. 175..=185 (beam 180 at 0°).
    #[test]
    fn a_scan_short_of_the_target_on_every_beam_towards_it() {
        let pose = Isometry3::translation(0.0, 0.0, 0.45);
        let t = person(1, 4.0, 0.0);
        fn beams(r: &[f32]) -> Beams<'_> {
            Beams {
                angle_min: -std::f64::consts::FRAC_PI_2,
                increment: 0.5f64.to_radians(),
                ranges: r,
            }
        }
        let mut r = vec![f32::INFINITY; 361];
        r[174] = 5.0; // just outside the body's beams (a return beyond it): not looked at
        r[186] = 5.0;
        for x in &mut r[175..=185] {
            *x = 3.79; // the body's near side 3.8 m: the target itself
        }
        assert!(!short_of(&pose, &t, beams(&r), 0.1));
        for x in &mut r[175..=185] {
            *x = 2.0; // a bush at 2 m covering the whole body
        }
        assert!(short_of(&pose, &t, beams(&r), 0.1));
        r[175] = 3.79; // one edge beam reaches the body: not hidden
        assert!(!short_of(&pose, &t, beams(&r), 0.1));
        r[175] = 2.0;
        r[185] = f32::INFINITY; // a beam without a return: not evidence of an obstacle
        assert!(!short_of(&pose, &t, beams(&r), 0.1));
        r[185] = 3.65; // 0.15 m short of the near side, beyond the 0.1 m margin
        assert!(short_of(&pose, &t, beams(&r), 0.1));
        // behind the scan (no beam points there)
        assert!(!short_of(&pose, &person(1, -4.0, 0.0), beams(&r), 0.1));
    }

    #[test]
    fn range_and_bearing_of_a_point() {
        let (r, b) = range_bearing(1.0, 1.0, std::f64::consts::FRAC_PI_2, (0.0, 1.0));
        assert!((r - 1.0).abs() < 1e-12 && (b - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    }
}

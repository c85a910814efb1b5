//! The robot's pose as the robot itself knew it, the paper's way (§III: "pitch and roll from
//! the on-board gyros, yaw and position from odometry"): `odom <- base_link` from TF (the
//! odometry: position and yaw) with the roll and pitch of the IMU's orientation, interpolated
//! at the stamp, then the sensor's mount from TF. The closed loop placed its scans the same way,
//! so the replay reads what the robot read. Without an IMU topic the TF pose is used alone.

use nalgebra::{Isometry3, UnitQuaternion};

use crate::log::msgs::Imu;
use crate::log::{SessionLog, TfBuffer, read_topic};
use crate::time::Nanos;

/// Roll and pitch over time, from the IMU's orientation.
#[derive(Debug, Clone, Default)]
pub struct Tilt {
    stamps: Vec<u64>,
    roll_pitch: Vec<(f64, f64)>,
}

impl Tilt {
    /// The IMU's samples (header stamps); an absent topic gives none.
    pub fn read(log: &SessionLog, topic: &str) -> anyhow::Result<Tilt> {
        let mut out = Tilt::default();
        if log.summary().channel(topic).is_none() {
            return Ok(out);
        }
        let mut pairs: Vec<(u64, (f64, f64))> = Vec::new();
        for r in read_topic::<Imu>(log, topic)? {
            let (log_time, m) = r?;
            let q = m.orientation;
            if ![q.i, q.j, q.k, q.w].iter().all(|c| c.is_finite()) || q.norm() < 1e-9 {
                continue;
            }
            let (roll, pitch, _) = UnitQuaternion::from_quaternion(q).euler_angles();
            let stamp = m
                .header
                .stamp
                .nanos()
                .filter(|s| s.0 > 0)
                .unwrap_or(log_time);
            pairs.push((stamp.0, (roll, pitch)));
        }
        pairs.sort_by_key(|p| p.0);
        (out.stamps, out.roll_pitch) = pairs.into_iter().unzip();
        Ok(out)
    }

    /// Roll and pitch at `t`, linear between samples (the nearest end outside them).
    pub fn at(&self, t: Nanos) -> Option<(f64, f64)> {
        let k = self.stamps.partition_point(|s| *s <= t.0);
        match (k.checked_sub(1), self.stamps.get(k)) {
            (Some(i), Some(&s1)) => {
                let s0 = self.stamps[i];
                let w = (t.0 - s0) as f64 / (s1 - s0).max(1) as f64;
                let (a, b) = (self.roll_pitch[i], self.roll_pitch[k]);
                Some((a.0 + (b.0 - a.0) * w, a.1 + (b.1 - a.1) * w))
            }
            (Some(i), None) => self.roll_pitch.get(i).copied(),
            (None, Some(_)) => self.roll_pitch.first().copied(),
            (None, None) => None,
        }
    }
}

/// `fixed <- frame` at `at`: odometry from TF, the IMU's roll and pitch on the base, the mount.
pub fn fixed_from(
    tf: &TfBuffer,
    tilt: &Tilt,
    fixed: &str,
    base: &str,
    frame: &str,
    at: Nanos,
) -> Option<Isometry3<f64>> {
    match tilt.at(at) {
        Some((roll, pitch)) => {
            let odom_base = tf.lookup(fixed, base, at).ok()?;
            let mount = tf.lookup(base, frame, at).ok()?;
            let tilted = Isometry3::from_parts(
                odom_base.translation,
                odom_base.rotation * UnitQuaternion::from_euler_angles(roll, pitch, 0.0),
            );
            Some(tilted * mount)
        }
        None => tf.lookup(fixed, frame, at).ok(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tilt_interpolates_between_samples() {
        let t = Tilt {
            stamps: vec![100, 200],
            roll_pitch: vec![(0.0, 0.1), (0.2, 0.3)],
        };
        let (r, p) = t.at(Nanos(150)).expect("inside");
        assert!((r - 0.1).abs() < 1e-12 && (p - 0.2).abs() < 1e-12);
        assert_eq!(t.at(Nanos(50)), Some((0.0, 0.1)));
        assert_eq!(t.at(Nanos(250)), Some((0.2, 0.3)));
        assert_eq!(Tilt::default().at(Nanos(5)), None);
    }
}

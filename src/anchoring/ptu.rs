//! The pan-tilt unit that carries BIRON's camera (a Sony EVI-D31, seed 003 §III, at 141 cm):
//! its limits and speeds, and the attention's control of it — pan toward the focus's bearing
//! and tilt toward its head, each at most its top speed per step; with no focus the camera
//! returns to straight ahead. Angles in radians, pan counter-clockwise (left) positive in the
//! robot frame, tilt up positive.
//!
//! The EVI-D31's range (pan ±100°, tilt ±25°) and top speeds (80°/s and 50°/s) are from
//! Sony's data sheet as we recall it; chosen a priori.

/// Pan range (rad).
pub const PAN_LIMIT: f64 = 100.0 * std::f64::consts::PI / 180.0;
/// Tilt range (rad).
pub const TILT_LIMIT: f64 = 25.0 * std::f64::consts::PI / 180.0;
/// Top pan speed (rad/s).
pub const PAN_RATE: f64 = 80.0 * std::f64::consts::PI / 180.0;
/// Top tilt speed (rad/s).
pub const TILT_RATE: f64 = 50.0 * std::f64::consts::PI / 180.0;
/// Height of the camera on BIRON (m), seed 003 §III.
pub const CAMERA_HEIGHT_M: f64 = 1.41;

/// The unit's angles.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct PanTilt {
    pub pan: f64,
    pub tilt: f64,
}

impl PanTilt {
    /// Move toward `target` for `dt_s` at the top speeds, within the limits.
    pub fn toward(self, target: PanTilt, dt_s: f64) -> PanTilt {
        let step = |from: f64, to: f64, rate: f64, limit: f64| {
            let to = to.clamp(-limit, limit);
            from + (to - from).clamp(-rate * dt_s, rate * dt_s)
        };
        PanTilt {
            pan: step(self.pan, target.pan, PAN_RATE, PAN_LIMIT),
            tilt: step(self.tilt, target.tilt, TILT_RATE, TILT_LIMIT),
        }
    }
}

/// Where to point for a head at robot-frame bearing `bearing` (rad), horizontal distance
/// `range_m` from the camera and head-centre height `head_z_m`.
pub fn aim(bearing: f64, range_m: f64, head_z_m: f64) -> PanTilt {
    PanTilt {
        pan: bearing,
        tilt: (head_z_m - CAMERA_HEIGHT_M).atan2(range_m.max(0.3)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_unit_moves_at_its_top_speed_and_stops_at_its_limits() {
        let p = PanTilt::default().toward(
            PanTilt {
                pan: 2.0,
                tilt: -1.0,
            },
            0.1,
        );
        assert!((p.pan - PAN_RATE * 0.1).abs() < 1e-12);
        assert!((p.tilt + TILT_RATE * 0.1).abs() < 1e-12);
        let mut q = p;
        for _ in 0..100 {
            q = q.toward(
                PanTilt {
                    pan: 2.0,
                    tilt: -1.0,
                },
                0.1,
            );
        }
        assert!((q.pan - PAN_LIMIT).abs() < 1e-12 && (q.tilt + TILT_LIMIT).abs() < 1e-12);
    }

    #[test]
    fn aiming_at_a_head_below_the_camera_tilts_down() {
        let a = aim(0.3, 2.0, 1.6);
        assert_eq!(a.pan, 0.3);
        assert!((a.tilt - (0.19f64).atan2(2.0)).abs() < 1e-12);
    }
}

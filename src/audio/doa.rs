//! Direction of arrival from a two-microphone delay (BIRON, seed 003: two microphones
//! 28.1 cm apart at 106 cm, locating "sound sources in front of the robot").
//!
//! Frames: the microphones lie on the robot's y axis (x forward, y left, z up), microphone 0
//! at `+d/2` (left), microphone 1 at `−d/2` (right), both at height `h_mic`. A far source at
//! azimuth φ (counter-clockwise from x) and elevation ε reaches microphone 1 later by
//! `τ = d·sin φ·cos ε / c`. Two microphones measure only the **cone angle**
//! `θ = asin(c·τ/d)` (the angle between the source and the plane normal to the microphone
//! axis): a source at φ and its **mirror** at π − φ (behind the robot) give the same τ, and so
//! does a source above or below the microphones at a smaller |φ|. Once the person anchor gives
//! the source's range and the mouth height, [`azimuth`] removes the elevation:
//! `sin φ = sin θ / cos ε`, and the front solution is kept (the seed's "in front of the
//! robot"); [`mirror`] gives the other.
//!
//! Near-field effects (the true hyperbola rather than the far-field cone) are not modelled:
//! at 1 m the far-field angle errs by under 0.3° for these 28 cm (see the tests).

use super::SPEED_OF_SOUND_M_S;

/// BIRON's microphone spacing (m), seed 003 §III.
pub const BIRON_SPACING_M: f64 = 0.281;
/// BIRON's microphone height (m), seed 003 §III.
pub const BIRON_MIC_HEIGHT_M: f64 = 1.06;

/// The cone angle θ (rad) of a delay τ (s) between microphones `spacing_m` apart; a delay
/// beyond the physical ±d/c (noise) is clamped to ±90°.
pub fn cone_angle(tau_s: f64, spacing_m: f64) -> f64 {
    (SPEED_OF_SOUND_M_S * tau_s / spacing_m)
        .clamp(-1.0, 1.0)
        .asin()
}

/// The delay (s) a far source at azimuth `azimuth` and elevation `elevation` (rad) gives.
pub fn delay_of(azimuth: f64, elevation: f64, spacing_m: f64) -> f64 {
    spacing_m * azimuth.sin() * elevation.cos() / SPEED_OF_SOUND_M_S
}

/// Elevation (rad) of a mouth at height `mouth_z_m` and horizontal range `range_m` seen from
/// microphones at `mic_z_m`.
pub fn elevation(mouth_z_m: f64, mic_z_m: f64, range_m: f64) -> f64 {
    (mouth_z_m - mic_z_m).atan2(range_m.max(1e-6))
}

/// The front azimuth (rad, in [−π/2, π/2]) of cone angle θ for a source at elevation ε:
/// `asin(sin θ / cos ε)`, clamped to ±90° where the elevation makes the cone miss the
/// source's height.
pub fn azimuth(cone: f64, elevation: f64) -> f64 {
    (cone.sin() / elevation.cos().max(1e-9))
        .clamp(-1.0, 1.0)
        .asin()
}

/// The mirror of a front azimuth behind the microphone axis: π − φ, wrapped to (−π, π].
pub fn mirror(azimuth: f64) -> f64 {
    wrap(std::f64::consts::PI - azimuth)
}

/// An angle wrapped to (−π, π].
pub fn wrap(a: f64) -> f64 {
    let t = std::f64::consts::TAU;
    let r = a.rem_euclid(t);
    if r > std::f64::consts::PI { r - t } else { r }
}

/// The largest cone-angle error (rad) that reading the delay on a grid of `step_s` alone can
/// cause for a source at true cone angle `cone` (half a grid step of delay, mapped through
/// asin); near broadside this is about `asin(c·step/(2d))`.
pub fn quantisation_bound(cone: f64, step_s: f64, spacing_m: f64) -> f64 {
    let half = SPEED_OF_SOUND_M_S * step_s / (2.0 * spacing_m);
    let s = cone.sin();
    let lo = (s - half).clamp(-1.0, 1.0).asin();
    let hi = (s + half).clamp(-1.0, 1.0).asin();
    (cone - lo).max(hi - cone)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_source_on_the_left_reaches_microphone_1_later_and_gives_a_positive_angle() {
        let tau = delay_of(30f64.to_radians(), 0.0, BIRON_SPACING_M);
        assert!(tau > 0.0);
        assert!((cone_angle(tau, BIRON_SPACING_M) - 30f64.to_radians()).abs() < 1e-12);
        let tau = delay_of(-50f64.to_radians(), 0.0, BIRON_SPACING_M);
        assert!((cone_angle(tau, BIRON_SPACING_M) + 50f64.to_radians()).abs() < 1e-12);
    }

    #[test]
    fn a_source_behind_gives_the_same_delay_as_its_mirror_in_front() {
        for deg in [10.0f64, 45.0, 80.0, -35.0] {
            let front = deg.to_radians();
            let back = mirror(front);
            let (a, b) = (
                delay_of(front, 0.0, BIRON_SPACING_M),
                delay_of(back, 0.0, BIRON_SPACING_M),
            );
            assert!((a - b).abs() < 1e-15, "{deg}");
            assert!((mirror(back) - front).abs() < 1e-12);
            assert!(back.cos() < 0.0, "{deg}: the mirror is behind");
        }
    }

    #[test]
    fn the_elevation_correction_recovers_the_azimuth_of_a_raised_mouth() {
        // a mouth at 1.60 m, 1.5 m away, 40° left: elevation atan(0.54 / 1.5) = 19.80°, and
        // the cone angle asin(sin 40° · cos 19.80°) = 37.20°, 2.8° short of the azimuth
        let el = elevation(1.60, BIRON_MIC_HEIGHT_M, 1.5);
        assert!((el - (0.54f64 / 1.5).atan()).abs() < 1e-12);
        let tau = delay_of(40f64.to_radians(), el, BIRON_SPACING_M);
        let cone = cone_angle(tau, BIRON_SPACING_M);
        let want = (40f64.to_radians().sin() * el.cos()).asin();
        assert!(
            (cone - want).abs() < 1e-9,
            "{} vs {}",
            cone.to_degrees(),
            want.to_degrees()
        );
        assert!((40.0 - cone.to_degrees() - 2.8).abs() < 0.05);
        assert!((azimuth(cone, el) - 40f64.to_radians()).abs() < 1e-12);
    }

    #[test]
    fn the_far_field_angle_of_a_source_one_metre_away_errs_by_under_0_3_degrees() {
        let d = BIRON_SPACING_M;
        for deg in [0.0f64, 20.0, 45.0, 70.0] {
            let a = deg.to_radians();
            let src = [a.cos(), a.sin()];
            let r0 = (src[0].powi(2) + (src[1] - d / 2.0).powi(2)).sqrt();
            let r1 = (src[0].powi(2) + (src[1] + d / 2.0).powi(2)).sqrt();
            let tau = (r1 - r0) / SPEED_OF_SOUND_M_S;
            let err = (cone_angle(tau, d) - a).abs().to_degrees();
            assert!(err < 0.3, "{deg}: {err}");
        }
    }

    #[test]
    fn the_quantisation_bound_near_broadside_is_asin_of_half_a_step() {
        let step = 1.0 / 16_000.0;
        let b = quantisation_bound(0.0, step, BIRON_SPACING_M);
        let want = (SPEED_OF_SOUND_M_S * step / (2.0 * BIRON_SPACING_M)).asin();
        assert!((b - want).abs() < 1e-15);
        assert!((b.to_degrees() - 2.19).abs() < 0.01, "{}", b.to_degrees());
        // it grows toward endfire
        assert!(quantisation_bound(1.2, step, BIRON_SPACING_M) > b);
    }

    #[test]
    fn wrap_keeps_angles_in_the_half_open_interval() {
        assert!((wrap(3.0 * std::f64::consts::PI) - std::f64::consts::PI).abs() < 1e-12);
        assert!((wrap(-std::f64::consts::PI) - std::f64::consts::PI).abs() < 1e-12);
        assert!((wrap(0.5) - 0.5).abs() < 1e-15);
    }
}

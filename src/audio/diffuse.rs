//! The diffuse sound field at two microphones, and how much of a bin's coherence is the
//! direct sound (issue 33, round 8).
//!
//! In a spherically isotropic field — the late reverberation of a room, and most room noise —
//! two omnidirectional microphones `d` apart are coherent by the real function
//! `Γ_n(f) = sin(kd)/(kd)`, `k = 2πf/c` (Cook et al. 1955). A direct sound from one direction
//! is coherent by the unit phasor `e^{jα}`, `α = 2πf·τ`. A bin whose sound is both, with
//! coherent-to-diffuse power ratio `CDR`, has the coherence
//!
//! ```text
//! Γ_x = (CDR·e^{jα} + Γ_n) / (CDR + 1)
//! ```
//!
//! Given a measured `Γ_x` and the known `Γ_n`, `|(CDR + 1)·Γ_x − Γ_n| = CDR` (the direct
//! part has unit magnitude) is a quadratic in `u = CDR + 1` whose larger root is the ratio,
//! whatever the direction — the DOA-independent estimator of Schwarz & Kellermann (2015,
//! "Coherent-to-diffuse power ratio estimation for dereverberation", IEEE/ACM TASLP 23(6)),
//! derived here from that constraint — and `(CDR + 1)·Γ_x − Γ_n` is then the direct sound's
//! coherence, its phase the delay's without the diffuse part's pull towards zero lag
//! ([`cdr`], [`direct_phasor`]). Written by hand: no crate does it.
//!
//! What it cannot remove: single early reflections (the floor's and the ceiling's images are
//! point sources, not diffuse), and the upward bias of a coherence measured from few frames.

use realfft::num_complex::Complex;

use super::SPEED_OF_SOUND_M_S;

/// Coherence of a spherically isotropic field at `f_hz` between microphones `spacing_m` apart.
pub fn diffuse_coherence(f_hz: f64, spacing_m: f64) -> f64 {
    let x = std::f64::consts::TAU * f_hz * spacing_m / SPEED_OF_SOUND_M_S;
    if x.abs() < 1e-9 { 1.0 } else { x.sin() / x }
}

/// The coherent-to-diffuse power ratio (≥ 0) of a bin with measured coherence `gx` where the
/// diffuse field's coherence is `gn` (real, |gn| < 1); a coherence of magnitude 1 (a pure
/// direct sound) gives `f64::INFINITY`, one equal to `gn` gives 0.
pub fn cdr(gx: Complex<f64>, gn: f64) -> f64 {
    // u²(|Γx|² − 1) + u(2 − 2·Γn·Re Γx) + (Γn² − 1) = 0, u = CDR + 1: with |Γx| < 1 and
    // |Γn| < 1 both roots are positive and the larger is the ratio (the smaller is below 1)
    let a = 1.0 - gx.norm_sqr();
    if a <= 1e-12 {
        return f64::INFINITY;
    }
    let b = 1.0 - gn * gx.re;
    // b² − a·(1 − Γn²) ≥ (|Γn| − |Γx|)² ≥ 0 for |Γx|, |Γn| ≤ 1; clamped against rounding
    let disc = (b * b - a * (1.0 - gn * gn)).max(0.0);
    let u = (b + disc.sqrt()) / a;
    (u - 1.0).max(0.0)
}

/// The direct sound's coherence `(CDR + 1)·Γ_x − Γ_n` of a bin: magnitude `CDR`, phase the
/// direct path's. For an infinite ratio the measured coherence itself (already a phasor).
pub fn direct_phasor(gx: Complex<f64>, gn: f64, ratio: f64) -> Complex<f64> {
    if ratio.is_infinite() {
        gx
    } else {
        gx * (ratio + 1.0) - gn
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mixed(ratio: f64, alpha: f64, gn: f64) -> Complex<f64> {
        (Complex::from_polar(ratio, alpha) + gn) / (ratio + 1.0)
    }

    #[test]
    fn the_ratio_and_the_direct_phase_are_recovered_from_a_mixed_coherence() {
        for (ratio, alpha, gn) in [
            (1.0, 1.0, 0.5),
            (3.0, 2.5, -0.2),
            (0.2, 0.3, 0.9),
            (10.0, -1.0, 0.1),
            (0.5, 3.0, 0.0),
            (2.0, 0.05, 0.8),
            (0.05, -2.9, -0.21),
        ] {
            let gx = mixed(ratio, alpha, gn);
            let got = cdr(gx, gn);
            assert!(
                (got - ratio).abs() < 1e-9 * ratio.max(1.0),
                "{ratio}: {got}"
            );
            let d = direct_phasor(gx, gn, got);
            assert!((d.norm() - ratio).abs() < 1e-9, "{}", d.norm());
            assert!((d.arg() - alpha).abs() < 1e-9, "{alpha}: {}", d.arg());
        }
    }

    #[test]
    fn a_purely_diffuse_bin_has_ratio_zero_and_a_pure_delay_an_infinite_one() {
        for gn in [-0.2, 0.0, 0.4, 0.95] {
            assert!(cdr(Complex::new(gn, 0.0), gn) < 1e-9, "{gn}");
        }
        let pure = Complex::from_polar(1.0, 0.7);
        assert!(cdr(pure, 0.3).is_infinite());
        assert_eq!(direct_phasor(pure, 0.3, f64::INFINITY), pure);
    }

    #[test]
    fn the_diffuse_coherence_is_one_at_dc_and_zero_at_half_a_wavelength() {
        assert_eq!(diffuse_coherence(0.0, 0.281), 1.0);
        // kd = π at f = c / (2d)
        let f = SPEED_OF_SOUND_M_S / (2.0 * 0.281);
        assert!(diffuse_coherence(f, 0.281).abs() < 1e-12);
        let x = std::f64::consts::TAU * 1000.0 * 0.281 / SPEED_OF_SOUND_M_S;
        assert!((diffuse_coherence(1000.0, 0.281) - x.sin() / x).abs() < 1e-15);
    }
}

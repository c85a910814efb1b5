//! Room acoustics by the image-source method for a shoebox room (Allen & Berkley 1979, "Image
//! method for efficiently simulating small-room acoustics"): the impulse response from a
//! source to a microphone is the sum over mirror images of the source, each delayed by its
//! distance over c, attenuated by 1/(4πr) and by the wall reflection coefficient β once per
//! wall it was mirrored in. All six walls share one β. Sabine's formula, α = 0.161·V/(S·T60),
//! β = √(1 − α), gives a first β ([`Room::from_rt60`]); but one β on all six walls of a shoebox
//! leaves a non-diffuse field running between the walls that decays more slowly than Sabine's
//! diffuse field (measured: T20 0.40 s for Sabine's 0.3 s, 0.90 s for 0.6 s in a 6 × 5 × 2.7 m
//! room). [`Room::calibrated`] therefore sets β so that the **measured** reverberation time —
//! Schroeder's backward-integrated decay from −5 to −25 dB extrapolated to 60 dB (T20, ISO
//! 3382) of the response between a reference source and microphone ([`reference_pair`]) —
//! equals the asked one: the room a dataset labels "RT60 0.3 s" then has a 0.3 s decay. T60 = 0
//! is free field (the direct path alone).
//!
//! Each image's delay is fractional: the direct path and the images within [`EARLY_S`] of it
//! are placed with a Hann-windowed sinc of [`SINC_TAPS`] taps (Peterson 1986), later ones —
//! whose exact sub-sample timing no localiser resolves — by linear interpolation between the
//! two nearest samples. The response is cut at `max(T60, direct + 50 ms)`.
//!
//! Not modelled: frequency-dependent absorption, air absorption, source and microphone
//! directivity, furniture and people as reflectors.

use crate::audio::SPEED_OF_SOUND_M_S;

/// Taps of the windowed-sinc fractional delay.
pub const SINC_TAPS: usize = 32;
/// Images arriving within this long after the direct path get the windowed sinc (s).
pub const EARLY_S: f64 = 0.025;

/// A shoebox room `[0, L]³` with one reflection coefficient.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Room {
    pub size: [f64; 3],
    pub beta: f64,
    pub rt60_s: f64,
}

impl Room {
    /// The room whose Sabine reverberation time is `rt60_s` (0: free field).
    pub fn from_rt60(size: [f64; 3], rt60_s: f64) -> Room {
        let [x, y, z] = size;
        let v = x * y * z;
        let s = 2.0 * (x * y + x * z + y * z);
        let beta = if rt60_s <= 0.0 {
            0.0
        } else {
            let alpha = (0.161 * v / (s * rt60_s)).min(1.0);
            (1.0 - alpha).sqrt()
        };
        Room { size, beta, rt60_s }
    }

    /// The room whose measured T20 ([`schroeder_t20`] of the response between the
    /// [`reference_pair`]) is `rt60_s` within 0.5 % (0: free field). The measured time grows
    /// with β; Sabine's β measures too long (module doc), so β is bisected in (0, Sabine's β]
    /// — 30 halvings, the β whose T20 is nearest the asked one kept.
    pub fn calibrated(size: [f64; 3], rt60_s: f64, fs: f64) -> Room {
        let sabine = Room::from_rt60(size, rt60_s);
        if sabine.beta <= 0.0 {
            return sabine;
        }
        let (src, mic) = reference_pair(size);
        let measure = |beta: f64| {
            let room = Room { beta, ..sabine };
            schroeder_t20(&room.rir(src, mic, fs), fs).unwrap_or(0.0)
        };
        let (mut lo, mut hi) = (0.0, sabine.beta);
        let mut best = (f64::INFINITY, sabine.beta);
        for _ in 0..30 {
            let mid = 0.5 * (lo + hi);
            let t = measure(mid);
            let miss = (t / rt60_s - 1.0).abs();
            if miss < best.0 {
                best = (miss, mid);
            }
            if miss < 0.001 {
                break;
            }
            if t > rt60_s {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        Room {
            beta: best.1,
            ..sabine
        }
    }

    /// The impulse response (samples at `fs`) from `src` to `mic` (both inside the room).
    pub fn rir(&self, src: [f64; 3], mic: [f64; 3], fs: f64) -> Vec<f32> {
        let direct = dist(src, mic);
        let t_max = self.rt60_s.max(direct / SPEED_OF_SOUND_M_S + 0.05);
        let len = (t_max * fs).ceil() as usize + SINC_TAPS;
        let mut h = vec![0.0f64; len];
        let r_max = t_max * SPEED_OF_SOUND_M_S;
        let early = direct + EARLY_S * SPEED_OF_SOUND_M_S;
        let n: [i64; 3] = std::array::from_fn(|a| (r_max / (2.0 * self.size[a])).ceil() as i64 + 1);
        let order_max = if self.beta > 0.0 { i64::MAX } else { 0 };
        for nx in -n[0]..=n[0] {
            for ny in -n[1]..=n[1] {
                for nz in -n[2]..=n[2] {
                    for q in 0..8u8 {
                        let qs = [q & 1, (q >> 1) & 1, (q >> 2) & 1];
                        let ns = [nx, ny, nz];
                        let mut img = [0.0; 3];
                        let mut order = 0i64;
                        for a in 0..3 {
                            let sign = if qs[a] == 1 { -1.0 } else { 1.0 };
                            img[a] = sign * src[a] + 2.0 * ns[a] as f64 * self.size[a];
                            order += (ns[a] - i64::from(qs[a])).abs() + ns[a].abs();
                        }
                        if order > order_max {
                            continue;
                        }
                        let r = dist(img, mic);
                        if r > r_max {
                            continue;
                        }
                        let gain = self.beta.powi(order as i32) / (4.0 * std::f64::consts::PI * r);
                        let delay = r / SPEED_OF_SOUND_M_S * fs;
                        if r <= early {
                            add_sinc(&mut h, delay, gain);
                        } else {
                            add_linear(&mut h, delay, gain);
                        }
                    }
                }
            }
        }
        h.into_iter().map(|v| v as f32).collect()
    }
}

/// The source and microphone [`Room::calibrated`] measures between: the source at (0.7, 0.62,
/// 0.6) and the microphone at (0.22, 0.44, 0.39) of the room's size — off every symmetry
/// plane, about 3 m apart in a living room, the microphone near BIRON's 1.06 m in a 2.7 m
/// room (a priori).
pub fn reference_pair(size: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let at = |f: [f64; 3]| std::array::from_fn(|a| f[a] * size[a]);
    (at([0.7, 0.62, 0.6]), at([0.22, 0.44, 0.39]))
}

/// Reverberation time (s) of an impulse response from its Schroeder energy decay curve: the
/// time from −5 to −25 dB times 3 (T20). `None` when the curve does not fall 25 dB.
pub fn schroeder_t20(h: &[f32], fs: f64) -> Option<f64> {
    let mut edc: Vec<f64> = h.iter().map(|&v| f64::from(v).powi(2)).collect();
    for i in (0..edc.len().saturating_sub(1)).rev() {
        edc[i] += edc[i + 1];
    }
    let total = *edc.first()?;
    if total <= 0.0 {
        return None;
    }
    let db = |i: usize| 10.0 * (edc[i] / total).log10();
    let t5 = (0..edc.len()).find(|&i| db(i) < -5.0)?;
    let t25 = (t5..edc.len()).find(|&i| db(i) < -25.0)?;
    Some(3.0 * (t25 - t5) as f64 / fs)
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Add `gain` at fractional sample `delay` with a Hann-windowed sinc.
fn add_sinc(h: &mut [f64], delay: f64, gain: f64) {
    let half = (SINC_TAPS / 2) as i64;
    let centre = delay.floor() as i64;
    for k in (centre - half + 1)..=(centre + half) {
        if k < 0 || k as usize >= h.len() {
            continue;
        }
        let x = k as f64 - delay;
        let sinc = if x.abs() < 1e-12 {
            1.0
        } else {
            (std::f64::consts::PI * x).sin() / (std::f64::consts::PI * x)
        };
        let w = 0.5 + 0.5 * (std::f64::consts::PI * x / half as f64).cos();
        h[k as usize] += gain * sinc * w;
    }
}

/// Add `gain` at fractional sample `delay`, split between the two nearest samples.
fn add_linear(h: &mut [f64], delay: f64, gain: f64) {
    let k = delay.floor() as usize;
    let f = delay - k as f64;
    if k + 1 < h.len() {
        h[k] += gain * (1.0 - f);
        h[k + 1] += gain * f;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FS: f64 = 16_000.0;

    #[test]
    fn free_field_is_the_direct_path_alone_with_its_delay_and_spreading_loss() {
        let room = Room::from_rt60([6.0, 5.0, 2.7], 0.0);
        assert_eq!(room.beta, 0.0);
        let (src, mic) = ([4.0, 2.5, 1.6], [1.0, 2.5, 1.6]);
        let h = room.rir(src, mic, FS);
        // 3 m: 8.746 ms = 139.94 samples; the windowed sinc sums to the gain
        let total: f64 = h.iter().map(|&v| f64::from(v)).sum();
        assert!(
            (total - 1.0 / (4.0 * std::f64::consts::PI * 3.0)).abs() < 2e-4,
            "{total}"
        );
        let peak = (0..h.len())
            .max_by(|&a, &b| h[a].total_cmp(&h[b]))
            .expect("samples");
        assert_eq!(peak, (3.0 / SPEED_OF_SOUND_M_S * FS).round() as usize);
    }

    #[test]
    fn sabine_gives_the_reflection_coefficient_of_the_asked_reverberation_time() {
        let room = Room::from_rt60([6.0, 5.0, 2.7], 0.3);
        let (v, s): (f64, f64) = (81.0, 2.0 * (30.0 + 16.2 + 13.5));
        let alpha = 0.161 * v / (s * 0.3);
        assert!((room.beta - (1.0 - alpha).sqrt()).abs() < 1e-12);
    }

    /// The decay of the energy–time curve (Schroeder's backward integral) from −5 to −25 dB,
    /// extrapolated to 60 dB (T20), lies between the decay of a diffuse field with this β
    /// (Eyring: a reflection every 4V/S metres, each losing β², 0.241 s for 0.3 s asked)
    /// and that of sound running along the room's longest axis (a reflection every L_x, 0.53 s):
    /// one β on all six walls of a shoebox leaves a slow, non-diffuse field running between
    /// the walls, so the measured T20 of Sabine's β is longer than the Sabine time (printed).
    #[test]
    fn the_schroeder_decay_of_the_response_lies_between_the_diffuse_and_the_axial_decay() {
        let size = [6.0, 5.0, 2.7];
        let (src, mic) = reference_pair(size);
        assert!((src[0] - 4.2).abs() < 1e-12 && (mic[2] - 1.053).abs() < 1e-12);
        for rt in [0.3, 0.6] {
            let room = Room::from_rt60(size, rt);
            let t60 = schroeder_t20(&room.rir(src, mic, FS), FS).expect("decays 25 dB");
            let [x, y, z] = room.size;
            let (v, s) = (x * y * z, 2.0 * (x * y + x * z + y * z));
            // 60 dB = ln(10⁶) nepers of energy at c · (reflections per metre) · (−ln β²)
            let t_at =
                |per_m: f64| 1e6f64.ln() / (SPEED_OF_SOUND_M_S * per_m * -(room.beta.powi(2)).ln());
            let (lo, hi) = (t_at(s / (4.0 * v)), t_at(1.0 / x.max(y).max(z)));
            eprintln!("asked (Sabine) {rt} s: T20 {t60:.3} s, Eyring {lo:.3} s, axial {hi:.3} s");
            assert!(
                t60 > lo && t60 > rt * 1.2 && t60 < hi,
                "asked {rt} s: T20 {t60} s outside [{lo}, {hi}] or not 20 % above Sabine"
            );
        }
    }

    #[test]
    fn schroeder_t20_of_an_exponential_decay_is_its_time_constant_times_ln_10_to_the_6() {
        // energy e^{-t/τ}: 60 dB after τ · ln(10⁶); amplitude e^{-t/(2τ)}
        let tau = 0.05;
        let h: Vec<f32> = (0..(3.0 * FS) as usize)
            .map(|i| (-(i as f64 / FS) / (2.0 * tau)).exp() as f32)
            .collect();
        let t = schroeder_t20(&h, FS).expect("decays");
        assert!((t - tau * 1e6f64.ln()).abs() < 1e-3, "{t}");
        assert_eq!(schroeder_t20(&[0.0; 10], FS), None);
        assert_eq!(schroeder_t20(&[], FS), None);
        assert_eq!(
            schroeder_t20(&[1.0, 1.0, 1.0], FS),
            None,
            "never falls 25 dB"
        );
    }

    #[test]
    fn a_calibrated_room_measures_the_asked_reverberation_time_with_a_smaller_beta_than_sabine() {
        for (size, rt) in [
            ([6.0, 5.0, 2.7], 0.3),
            ([7.0, 6.0, 2.6], 0.3),
            ([7.0, 6.0, 2.6], 0.6),
        ] {
            let sabine = Room::from_rt60(size, rt);
            let room = Room::calibrated(size, rt, FS);
            let (src, mic) = reference_pair(size);
            let t = schroeder_t20(&room.rir(src, mic, FS), FS).expect("decays");
            eprintln!(
                "{size:?} {rt} s: beta {:.4} (Sabine {:.4}), T20 {t:.4} s",
                room.beta, sabine.beta
            );
            assert!((t / rt - 1.0).abs() < 0.005, "{size:?} {rt}: T20 {t}");
            assert!(room.beta < sabine.beta);
            assert_eq!(room.rt60_s, rt);
        }
        assert_eq!(Room::calibrated([6.0, 5.0, 2.7], 0.0, FS).beta, 0.0);
    }
}

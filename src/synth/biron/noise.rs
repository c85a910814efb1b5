//! Diffuse background noise at two microphones: the noise of a room whose sound comes from
//! every direction at once (air conditioning, traffic, a fridge). In a spherically isotropic
//! field two omnidirectional microphones `d` apart are coherent by Γ(f) = sin(kd)/(kd),
//! k = 2πf/c (Cook et al. 1955). Two independent Gaussian noises are mixed per frequency bin
//! so the pair has exactly that coherence (the two-sensor case of Habets, Cohen & Gannot
//! 2008): X₀ = N₀, X₁ = Γ·N₀ + √(1 − Γ²)·N₁. The spectrum is pink (−3 dB per octave) above
//! 100 Hz and flat below, like most room noise.
//!
//! Not modelled: non-stationary noise, point noise sources, microphone self-noise.

use rand::RngExt;
use realfft::RealFftPlanner;
use realfft::num_complex::Complex;

/// Coherence of a spherically isotropic field (one definition, shared with the estimator).
pub use crate::audio::diffuse::diffuse_coherence;

/// `n` samples of diffuse noise at two microphones `spacing_m` apart, unit mean power per
/// channel, deterministic in `rng`.
pub fn diffuse_pair(n: usize, fs: f64, spacing_m: f64, rng: &mut impl rand::Rng) -> [Vec<f32>; 2] {
    let len = n.max(2).next_power_of_two();
    let mut planner = RealFftPlanner::<f64>::new();
    let fwd = planner.plan_fft_forward(len);
    let inv = planner.plan_fft_inverse(len);
    let mut gauss = |_: usize| {
        // Box–Muller
        let u1: f64 = rng.random::<f64>().max(1e-300);
        let u2: f64 = rng.random();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    };
    let mut a: Vec<f64> = (0..len).map(&mut gauss).collect();
    let mut b: Vec<f64> = (0..len).map(&mut gauss).collect();
    let mut sa = fwd.make_output_vec();
    let mut sb = fwd.make_output_vec();
    // the forward FFT cannot fail on buffers it made itself
    let _ = fwd.process(&mut a, &mut sa);
    let _ = fwd.process(&mut b, &mut sb);
    let bin_hz = fs / len as f64;
    let mut x0 = Vec::with_capacity(sa.len());
    let mut x1 = Vec::with_capacity(sa.len());
    for (k, (na, nb)) in sa.iter().zip(&sb).enumerate() {
        let f = k as f64 * bin_hz;
        let pink = if f > 100.0 { (100.0 / f).sqrt() } else { 1.0 };
        let g = diffuse_coherence(f, spacing_m);
        x0.push(na * pink);
        x1.push((na * g + nb * (1.0 - g * g).max(0.0).sqrt()) * pink);
    }
    let fix = |s: &mut Vec<Complex<f64>>| {
        s[0].im = 0.0;
        let l = s.len() - 1;
        s[l].im = 0.0;
    };
    fix(&mut x0);
    fix(&mut x1);
    let mut y0 = inv.make_output_vec();
    let mut y1 = inv.make_output_vec();
    let _ = inv.process(&mut x0, &mut y0);
    let _ = inv.process(&mut x1, &mut y1);
    let power = |y: &[f64]| y[..n].iter().map(|v| v * v).sum::<f64>() / n as f64;
    let p = 0.5 * (power(&y0) + power(&y1));
    let k = if p > 0.0 { 1.0 / p.sqrt() } else { 0.0 };
    [
        y0[..n].iter().map(|v| (v * k) as f32).collect(),
        y1[..n].iter().map(|v| (v * k) as f32).collect(),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    /// The coherence measured from 64 blocks of the pair matches sin(kd)/(kd) per band.
    #[test]
    fn the_pair_has_the_coherence_of_a_diffuse_field() {
        let fs = 16_000.0;
        let d = 0.281;
        let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let [x0, x1] = diffuse_pair(256 * 512, fs, d, &mut r);
        let mut planner = RealFftPlanner::<f64>::new();
        let fwd = planner.plan_fft_forward(512);
        let bins = 257;
        let (mut s00, mut s11) = (vec![0.0; bins], vec![0.0; bins]);
        let mut s01 = vec![Complex::new(0.0, 0.0); bins];
        for blk in 0..256 {
            let mut a: Vec<f64> = x0[blk * 512..(blk + 1) * 512]
                .iter()
                .map(|&v| f64::from(v))
                .collect();
            let mut b: Vec<f64> = x1[blk * 512..(blk + 1) * 512]
                .iter()
                .map(|&v| f64::from(v))
                .collect();
            let (mut fa, mut fb) = (fwd.make_output_vec(), fwd.make_output_vec());
            fwd.process(&mut a, &mut fa).expect("fft");
            fwd.process(&mut b, &mut fb).expect("fft");
            for k in 0..bins {
                s00[k] += fa[k].norm_sqr();
                s11[k] += fb[k].norm_sqr();
                s01[k] += fa[k].conj() * fb[k];
            }
        }
        for f in [250.0, 600.0, 1000.0, 2000.0] {
            let k = (f / fs * 512.0) as usize;
            let measured = s01[k].re / (s00[k] * s11[k]).sqrt();
            let want = diffuse_coherence(k as f64 * fs / 512.0, d);
            assert!(
                (measured - want).abs() < 0.15,
                "{f} Hz: {measured} vs {want}"
            );
        }
        let p0 = x0.iter().map(|v| f64::from(*v).powi(2)).sum::<f64>() / x0.len() as f64;
        assert!((p0 - 1.0).abs() < 0.1, "{p0}");
    }
}

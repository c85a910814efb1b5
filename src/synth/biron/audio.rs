//! The two microphone channels of a `biron_home` session under every acoustic condition of
//! the grid (reverberation time × signal-to-noise ratio): each utterance's dry voice
//! ([`super::speech`]) convolved with the image-source responses ([`super::room`], the room's
//! β calibrated so that its measured T20 is the condition's RT60) from the
//! speaker's mouth (where it is when the utterance starts) to each microphone, summed, plus
//! diffuse noise ([`super::noise`]) scaled to the condition's SNR, quantised to 16 bits.
//!
//! Levels: a voice has RMS 1 at 1 m before the room (each person ±3 dB); the SNR is the mean
//! power of the reverberant speech at the microphones over the samples where someone speaks,
//! over the noise's mean power; one gain per session puts the anechoic speech at −26 dBFS RMS
//! (clipped samples are counted).

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use realfft::RealFftPlanner;

use super::room::Room;
use super::script::{Script, Stage};
use super::speech;
use crate::rng;

/// The microphones and the acoustic grid.
#[derive(Debug, Clone, PartialEq)]
pub struct AudioSetup {
    pub sample_rate: u32,
    /// Microphone spacing (m) and height (m), and how far in front of the robot's centre.
    pub spacing_m: f64,
    pub height_m: f64,
    pub forward_m: f64,
    /// Room `[x, y, z]` (m).
    pub room: [f64; 3],
    pub rt60_s: Vec<f64>,
    pub snr_db: Vec<f64>,
}

/// One condition's two channels.
pub struct Condition {
    pub rt60_s: f64,
    pub snr_db: f64,
    /// Interleaved left (microphone 0), right (microphone 1).
    pub samples: Vec<i16>,
    pub clipped: u64,
}

/// Anechoic speech level after the session gain (dBFS RMS).
pub const SPEECH_DBFS: f64 = -26.0;

impl AudioSetup {
    /// Microphone `k` (0 left, 1 right) in the world for a robot at `[x, y, yaw]`.
    pub fn mic(&self, robot: [f64; 3], k: usize) -> [f64; 3] {
        let side = if k == 0 { 0.5 } else { -0.5 } * self.spacing_m;
        let (s, c) = robot[2].sin_cos();
        [
            robot[0] + self.forward_m * c - side * s,
            robot[1] + self.forward_m * s + side * c,
            self.height_m,
        ]
    }
}

/// Add `x` convolved with `h` into `out` from sample `at` (FFT convolution).
fn convolve_into(
    planner: &mut RealFftPlanner<f64>,
    x: &[f32],
    h: &[f32],
    out: &mut [f64],
    at: usize,
) {
    let len = (x.len() + h.len()).next_power_of_two();
    let fwd = planner.plan_fft_forward(len);
    let inv = planner.plan_fft_inverse(len);
    let mut a = vec![0.0f64; len];
    let mut b = vec![0.0f64; len];
    for (d, s) in a.iter_mut().zip(x) {
        *d = f64::from(*s);
    }
    for (d, s) in b.iter_mut().zip(h) {
        *d = f64::from(*s);
    }
    let mut fa = fwd.make_output_vec();
    let mut fb = fwd.make_output_vec();
    // plans and buffers made together: the FFTs cannot fail on sizes
    let _ = fwd.process(&mut a, &mut fa);
    let _ = fwd.process(&mut b, &mut fb);
    for (p, q) in fa.iter_mut().zip(&fb) {
        *p *= q;
    }
    let mut y = inv.make_output_vec();
    let _ = inv.process(&mut fa, &mut y);
    let n = x.len() + h.len() - 1;
    for (i, v) in y.iter().take(n).enumerate() {
        if let Some(o) = out.get_mut(at + i) {
            *o += v / len as f64;
        }
    }
}

/// Every condition of the grid, in `rt60_s`-major order.
pub fn render(script: &Script, stage: &Stage, setup: &AudioSetup, seed: u64) -> Vec<Condition> {
    let fs = f64::from(setup.sample_rate);
    let n = (stage.duration * fs) as usize;
    let mics = [setup.mic(stage.robot, 0), setup.mic(stage.robot, 1)];
    // dry voices and their mouths, once
    let mut dry = Vec::new();
    for (k, u) in script.utterances.iter().enumerate() {
        let Some(v) = script.visitors.iter().find(|v| v.body.id == u.speaker) else {
            continue;
        };
        let Some((st, yaw)) = v.at(u.start) else {
            continue;
        };
        let mut r = ChaCha8Rng::seed_from_u64(rng::hash(seed, &[0x5bee, k as u64]));
        let level = 10f64.powf(r.random_range(-3.0..3.0) / 20.0);
        let mut x = speech::utterance(&v.voice, u.end - u.start, fs, &mut r);
        x.iter_mut().for_each(|s| *s *= level as f32);
        dry.push((
            x,
            v.mouth(&st, yaw),
            (u.start * fs) as usize,
            (u.end * fs) as usize,
        ));
    }
    let mut active = vec![false; n];
    for (_, _, a, b) in &dry {
        active[(*a).min(n)..(*b).min(n)]
            .iter_mut()
            .for_each(|s| *s = true);
    }
    let mut noise_rng = ChaCha8Rng::seed_from_u64(rng::hash(seed, &[0x401e]));
    let noise = super::noise::diffuse_pair(n, fs, setup.spacing_m, &mut noise_rng);
    let mut planner = RealFftPlanner::<f64>::new();
    let mut gain = None;
    let mut out = Vec::new();
    for &rt60 in &setup.rt60_s {
        let room = Room::calibrated(setup.room, rt60, fs);
        let mut ch = [vec![0.0f64; n], vec![0.0f64; n]];
        for (x, mouth, at, _) in &dry {
            for (k, c) in ch.iter_mut().enumerate() {
                let h = room.rir(*mouth, mics[k], fs);
                convolve_into(&mut planner, x, &h, c, *at);
            }
        }
        let speech_power = {
            let (mut s, mut m) = (0.0, 0usize);
            for (i, a) in active.iter().enumerate() {
                if *a {
                    s += ch[0][i].powi(2) + ch[1][i].powi(2);
                    m += 2;
                }
            }
            if m > 0 { s / m as f64 } else { 0.0 }
        };
        let g = *gain.get_or_insert_with(|| {
            let target = 32767.0 * 10f64.powf(SPEECH_DBFS / 20.0);
            if speech_power > 0.0 {
                target / speech_power.sqrt()
            } else {
                1.0
            }
        });
        for &snr in &setup.snr_db {
            let noise_amp = (speech_power / 10f64.powf(snr / 10.0)).sqrt();
            let mut samples = Vec::with_capacity(2 * n);
            let mut clipped = 0u64;
            for i in 0..n {
                for k in 0..2 {
                    let v = (ch[k][i] + noise_amp * f64::from(noise[k][i])) * g;
                    let q = v.round();
                    if q.abs() > 32767.0 {
                        clipped += 1;
                    }
                    samples.push(q.clamp(-32768.0, 32767.0) as i16);
                }
            }
            out.push(Condition {
                rt60_s: rt60,
                snr_db: snr,
                samples,
                clipped,
            });
        }
    }
    out
}

//! Speech-like sound made by the synthesizer itself (no recording, no downloaded model): a
//! source–filter voice. Glottal pulses (Rosenberg 1971's trigonometric pulse, differentiated
//! for lip radiation) at a pitch that falls over the utterance and wavers, plus a little
//! aspiration noise, pass through three formant resonators (a cascade of two-pole filters,
//! Klatt 1980) whose frequencies glide between the vowels of successive syllables (Peterson &
//! Barney 1952's averages for men, scaled for women's shorter vocal tracts); syllables of
//! 160–280 ms are shaped by an attack/release envelope, many open with a fricative burst
//! (high-passed noise), and short pauses separate them.
//!
//! What matters downstream is that it is voiced, harmonic, broadband up to ~5 kHz and
//! modulated at the syllable rate like speech — what GCC-PHAT and an energy detector see. It
//! is not intelligible and has no prosody model beyond the falling pitch.

use rand::{Rng, RngExt};

/// A person's voice.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Voice {
    /// Mean pitch (Hz): about 100–130 for men, 190–230 for women.
    pub f0_hz: f64,
    /// Formant scale (1 for men, about 1.15 for women).
    pub formant_scale: f64,
}

/// Peterson & Barney (1952) formant averages of men, F1–F3 (Hz): /a/, /e/, /i/, /o/, /u/.
const VOWELS: [[f64; 3]; 5] = [
    [730.0, 1090.0, 2440.0],
    [530.0, 1840.0, 2480.0],
    [270.0, 2290.0, 3010.0],
    [570.0, 840.0, 2410.0],
    [300.0, 870.0, 2240.0],
];
/// Formant bandwidths (Hz).
const BANDWIDTHS: [f64; 3] = [80.0, 100.0, 140.0];

/// A two-pole resonator (Klatt 1980, eq. for the digital resonator) with unit gain at DC.
#[derive(Debug, Clone, Copy, Default)]
struct Resonator {
    y1: f64,
    y2: f64,
}

impl Resonator {
    fn step(&mut self, x: f64, f_hz: f64, bw_hz: f64, fs: f64) -> f64 {
        let c = -(-2.0 * std::f64::consts::PI * bw_hz / fs).exp();
        let b = 2.0
            * (-std::f64::consts::PI * bw_hz / fs).exp()
            * (2.0 * std::f64::consts::PI * f_hz / fs).cos();
        let a = 1.0 - b - c;
        let y = a * x + b * self.y1 + c * self.y2;
        self.y2 = self.y1;
        self.y1 = y;
        y
    }
}

/// Rosenberg's glottal flow at phase `p` in [0, 1) of a period (opening 40 %, closing 16 %).
fn glottal_flow(p: f64) -> f64 {
    const OPEN: f64 = 0.4;
    const CLOSE: f64 = 0.16;
    if p < OPEN {
        0.5 * (1.0 - (std::f64::consts::PI * p / OPEN).cos())
    } else if p < OPEN + CLOSE {
        (std::f64::consts::FRAC_PI_2 * (p - OPEN) / CLOSE).cos()
    } else {
        0.0
    }
}

/// One syllable's plan: start and length (samples), vowel, level, fricative onset length.
struct Syllable {
    start: usize,
    len: usize,
    vowel: usize,
    level: f64,
    fricative: usize,
}

fn plan(duration_s: f64, fs: f64, rng: &mut impl Rng) -> Vec<Syllable> {
    let total = (duration_s * fs) as usize;
    let mut out = Vec::new();
    let mut t = 0usize;
    loop {
        let len = (rng.random_range(0.16..0.28) * fs) as usize;
        if t + len > total {
            break;
        }
        let fricative = if rng.random::<f64>() < 0.6 {
            (rng.random_range(0.03..0.06) * fs) as usize
        } else {
            0
        };
        out.push(Syllable {
            start: t,
            len,
            vowel: rng.random_range(0..VOWELS.len()),
            level: rng.random_range(0.7..1.0),
            fricative,
        });
        let pause = if rng.random::<f64>() < 0.15 {
            rng.random_range(0.12..0.2)
        } else {
            rng.random_range(0.02..0.06)
        };
        t += len + (pause * fs) as usize;
    }
    out
}

/// An utterance of about `duration_s` seconds at `fs` Hz, RMS 1 over its voiced samples
/// (silence between syllables stays silent). Deterministic in `rng`.
pub fn utterance(voice: &Voice, duration_s: f64, fs: f64, rng: &mut impl Rng) -> Vec<f32> {
    let total = (duration_s * fs).max(1.0) as usize;
    let syllables = plan(duration_s, fs, rng);
    let mut out = vec![0.0f64; total];
    let mut res = [Resonator::default(); 3];
    let mut phase = 0.0f64;
    let mut last_flow = 0.0f64;
    let wobble = rng.random_range(0.0..std::f64::consts::TAU);
    for (k, syl) in syllables.iter().enumerate() {
        let next = syllables.get(k + 1).map_or(syl.vowel, |s| s.vowel);
        let attack = (0.02 * fs) as usize;
        let release = (0.04 * fs) as usize;
        for i in 0..syl.len {
            let n = syl.start + i;
            let t = n as f64 / fs;
            let env = (i as f64 / attack as f64).min(1.0)
                * ((syl.len - i) as f64 / release as f64).min(1.0)
                * syl.level;
            // formants glide toward the next vowel over the last 30 % of the syllable
            let glide = ((i as f64 / syl.len as f64 - 0.7) / 0.3).clamp(0.0, 1.0);
            let f0 = voice.f0_hz
                * (1.1 - 0.2 * t / duration_s)
                * (1.0 + 0.03 * (std::f64::consts::TAU * 4.5 * t + wobble).sin());
            phase = (phase + f0 / fs).fract();
            let flow = glottal_flow(phase);
            let mut x = (flow - last_flow) * fs / f0; // differentiated: lip radiation
            last_flow = flow;
            x += 0.04 * (rng.random::<f64>() * 2.0 - 1.0); // aspiration
            let voiced = i >= syl.fricative;
            let mut y = if voiced { x } else { 0.0 };
            for (j, r) in res.iter_mut().enumerate() {
                let f = (VOWELS[syl.vowel][j] * (1.0 - glide) + VOWELS[next][j] * glide)
                    * voice.formant_scale;
                y = r.step(y, f, BANDWIDTHS[j], fs);
            }
            if !voiced {
                // fricative onset: white noise, unvoiced
                y = 0.6 * (rng.random::<f64>() - rng.random::<f64>());
            }
            out[n] = y * env;
        }
    }
    let energy: f64 = out.iter().map(|v| v * v).sum();
    let voiced: usize = syllables.iter().map(|s| s.len).sum();
    let rms = (energy / voiced.max(1) as f64).sqrt();
    let k = if rms > 0.0 { 1.0 / rms } else { 0.0 };
    out.into_iter().map(|v| (v * k) as f32).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    fn zero_crossings_per_s(x: &[f32], fs: f64) -> f64 {
        let z = x
            .windows(2)
            .filter(|w| (w[0] < 0.0) != (w[1] < 0.0))
            .count();
        z as f64 / (x.len() as f64 / fs)
    }

    #[test]
    fn an_utterance_is_deterministic_unit_rms_and_has_pauses() {
        let v = Voice {
            f0_hz: 120.0,
            formant_scale: 1.0,
        };
        let mk = || {
            let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(4);
            utterance(&v, 2.0, 16_000.0, &mut r)
        };
        let a = mk();
        assert_eq!(a, mk());
        assert_eq!(a.len(), 32_000);
        // silent gaps between syllables
        let silent = a
            .chunks(160)
            .filter(|c| c.iter().all(|v| *v == 0.0))
            .count();
        assert!(silent >= 3, "{silent} silent 10 ms blocks");
        let voiced: Vec<f64> = a
            .chunks(160)
            .map(|c| c.iter().map(|v| f64::from(*v).powi(2)).sum::<f64>() / 160.0)
            .filter(|e| *e > 0.0)
            .collect();
        let mean = voiced.iter().sum::<f64>() / voiced.len() as f64;
        assert!((0.5..1.5).contains(&mean), "{mean}");
        assert!(zero_crossings_per_s(&a, 16_000.0) > 200.0);
    }

    #[test]
    fn the_glottal_pulse_opens_and_closes_and_rests() {
        assert_eq!(glottal_flow(0.0), 0.0);
        assert!((glottal_flow(0.4) - 1.0).abs() < 1e-12);
        assert!(glottal_flow(0.56).abs() < 1e-12);
        assert_eq!(glottal_flow(0.8), 0.0);
    }

    #[test]
    fn a_resonator_rings_at_its_frequency() {
        let fs = 16_000.0;
        let mut r = Resonator::default();
        let mut y = Vec::new();
        for n in 0..4000 {
            y.push(r.step(if n == 0 { 1.0 } else { 0.0 }, 1000.0, 50.0, fs) as f32);
        }
        // 1 kHz ringing: about 2000 zero crossings per second
        let z = zero_crossings_per_s(&y[10..800], fs);
        assert!((z - 2000.0).abs() < 100.0, "{z}");
    }
}

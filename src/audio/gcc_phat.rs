//! GCC-PHAT: the generalised cross-correlation of two microphone signals with the phase
//! transform (Knapp & Carter 1976, "The generalized correlation method for estimation of time
//! delay", the PHAT weighting 1/|G|), the time-delay estimator of two-microphone speaker
//! localisation (BIRON, seed 003; Lang et al. 2003 do not print their estimator).
//!
//! A block of the two channels is cut into Hann-windowed frames; their cross-spectra
//! `G(ω) = X₁(ω)·X₀*(ω)` are summed over the block (each bin onset-weighted, below), each bin
//! of the sum is divided by its
//! magnitude raised to [`GccParams::phat_beta`] (1: PHAT, the phase alone; below 1 "PHAT-β",
//! Donohue et al. 2007: louder bins keep part of their weight), bins outside
//! `[band_lo, band_hi]` are set to zero, and the inverse FFT —
//! zero-padded by `interp` for a finer lag grid — is the correlation `r(τ)`. With this sign
//! convention a signal that reaches microphone 1 `τ` seconds after microphone 0 peaks at
//! `+τ`. The peak is searched within the physically possible lags `±d/c` and refined by a
//! parabola through the peak and its two neighbours ([`Refine::Parabolic`]), or left on the
//! grid ([`Refine::Grid`], for the quantisation bound). The peak height divided by the kept
//! bins' weights is 1 for a pure delay and near 0 for incoherent noise.
//!
//! **Onset weighting** ([`GccParams::onset`], [`onset_weight`]): each frame's bin enters the
//! sum weighted by how steeply its power rose since the previous frame — the precedence
//! effect's cue: the direct sound of a new syllable reaches the microphones before the room
//! answers, while the reverberant tail of earlier syllables (and stationary noise) holds or
//! decays. A simplified form of the learned precedence weighting of Wilson & Darrell (2006,
//! "Learning a precedence effect-like weighting function for the generalized
//! cross-correlation framework"); written here by hand, one rule per bin.
//!
//! **Weighting and frames, chosen on the quick profile** (`biron_home_00`–`01`, rooms
//! calibrated to their measured T20, 0.5 s single-talker blocks, `examples/doa_sweep.rs`; the
//! criterion the nominal condition's median error, RT60 0.3 s / SNR 10 dB, 22 blocks):
//! round 2 chose PHAT-β 0.7 over every frame of 1024 samples at a 512 hop (3.53°; PHAT with
//! the louder half of the frames, the earlier default: 10.8°). Round 5 (issue 33): the
//! errors left were a bias towards broadside in the reverberant cells (20 of 22 blocks at
//! RT60 0.3 s / 30 dB read too small a cone: the floor and ceiling images and the late field
//! lie nearer zero lag) and noise in the 10 dB cells (no bias anechoic). Tried and not kept:
//! the noise's cross-spectrum learned from quiet blocks and subtracted (nominal 6.2°),
//! coherence weights and Knapp & Carter's ML weighting (best anechoic at 10 dB, 0.36°, but
//! 9.8° nominal: the late field is coherent at low frequencies too), a per-bin Wiener gain
//! before or after the weighting (2.3–5.5°). Kept, from the declared grid of onset weighting
//! at a 256-sample hop × Wiener exponent {0, 1, 2} × β {0.5, 0.6, 0.7}: **onset weighting,
//! hop 256, β 0.5** — nominal median 2.10° (p95 16.3°, 72.7 % within 5°; before 3.53° /
//! 23.7° / 68.2 %), RT60 0.6 s / 10 dB 13.7° → 5.5°, anechoic 10 dB 1.43° → 0.99°; RT60 0.3 s
//! / 30 dB 2.01° → 2.22° (β 0.7 with onsets: 0.99°, but 3.91° nominal). The louder-half
//! selection ([`GccParams::loud_share`]) stays a setting; the onset weight then compares each
//! kept frame with the one kept before it.
//!
//! Round 8 (issue 33) added the diffuse-field-aware weightings ([`Weighting`],
//! [`super::diffuse`]) and the outermost strong peak ([`GccParams::outer_share`]); swept on the
//! development split with quick (131 blocks per cell) neither met the declared rule at the
//! nominal cell (best 2.92° against 2.96°), so both stay settings, off by default. The
//! diffuse ML weighting with β 0.5 is far better without reverberation (anechoic 10 dB 0.91° →
//! 0.21°) and the flat one at RT60 0.3 s / 30 dB (1.59° → 0.80°): docs/s003_biron_anchoring.md.
//!
//! FFTs by `realfft`/`rustfft`. Not here: frame-wise tracking, several sources per block.

use std::sync::Arc;

use realfft::num_complex::Complex;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};

use super::diffuse;

/// The largest coherent-to-diffuse ratio [`Weighting::DiffuseMl`] weighs a bin by (a bin of
/// coherence 1 would weigh infinitely).
const MAX_CDR: f64 = 1e6;

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GccError {
    #[error("GCC-PHAT settings: {0}")]
    Settings(String),
    #[error("GCC-PHAT: channels differ in length ({left} vs {right} samples)")]
    Lengths { left: usize, right: usize },
    #[error("GCC-PHAT: a block of {samples} samples is shorter than one frame ({frame})")]
    Short { samples: usize, frame: usize },
    #[error("GCC-PHAT: FFT failed: {0}")]
    Fft(String),
}

/// How the peak lag is read off the correlation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refine {
    /// The lag of the largest grid value (grid step `1 / (fs · interp)`).
    Grid,
    /// A parabola through the largest grid value and its neighbours.
    Parabolic,
}

/// How the block's summed cross-spectrum is weighted, bin by bin, before the inverse FFT.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Weighting {
    /// `1/|G|^β` with [`GccParams::phat_beta`] (1: PHAT; rounds 2–7's estimator).
    PhatBeta,
    /// Diffuse-field aware ([`super::diffuse`]): each bin's coherence rid of the diffuse
    /// field's `sin(kd)/(kd)`, its direct phase weighted by the direct share `CDR/(CDR + 1)`
    /// (a Wiener gain on the phase). Every `Diffuse*` weight is also multiplied by the bin's
    /// level `√(P₀P₁)^(1 − β)` ([`GccParams::phat_beta`]; β = 1: the weight alone).
    DiffuseShare,
    /// The direct phase weighted by `CDR` itself: Knapp & Carter's maximum-likelihood (SNR)
    /// weight with the noise diffuse instead of incoherent between the microphones.
    DiffuseMl,
    /// The direct phase alone, every kept bin weight 1 (PHAT of the direct sound).
    DiffusePhase,
}

impl Weighting {
    /// The name used by `examples/doa_sweep.rs` and `examples/doa_curve.rs`.
    pub fn name(self) -> &'static str {
        match self {
            Weighting::PhatBeta => "phat_beta",
            Weighting::DiffuseShare => "diffuse_share",
            Weighting::DiffuseMl => "diffuse_ml",
            Weighting::DiffusePhase => "diffuse_phase",
        }
    }

    /// The weighting called `name` ([`Weighting::name`]).
    pub fn from_name(name: &str) -> Option<Weighting> {
        [
            Weighting::PhatBeta,
            Weighting::DiffuseShare,
            Weighting::DiffuseMl,
            Weighting::DiffusePhase,
        ]
        .into_iter()
        .find(|w| w.name() == name)
    }
}

/// GCC-PHAT settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GccParams {
    /// Sample rate (Hz).
    pub sample_rate: f64,
    /// Frame length (samples, a power of two).
    pub frame: usize,
    /// Hop between frames (samples).
    pub hop: usize,
    /// Zero-padding factor of the inverse FFT (lag grid step `1 / (fs · interp)`).
    pub interp: usize,
    /// Frequency band kept (Hz).
    pub band_lo: f64,
    pub band_hi: f64,
    pub refine: Refine,
    /// Share of the block's frames summed, the loudest first (see the module doc); 1: all.
    pub loud_share: f64,
    /// Exponent of the weighting `1/|G|^β` of the summed cross-spectrum: 1 is PHAT, 0 the
    /// plain cross-correlation.
    pub phat_beta: f64,
    /// Onset weighting ([`onset_weight`]): each frame's bin enters the sum with weight
    /// `clamp(1 − ρ·P_{t−1}/P_t, 0, 1)` of its power against the previous frame's, the
    /// block's first frame only setting `P`; 0 turns it off (every frame weight 1).
    pub onset: f64,
    /// The per-bin weighting of the summed cross-spectrum ([`Weighting`]).
    pub weighting: Weighting,
    /// Microphone spacing (m): the diffuse field's coherence for the `Diffuse*` weightings.
    pub spacing_m: f64,
    /// Which peak is the direct sound ([`outermost_peak`]): 1 takes the highest; below 1 the
    /// local maximum farthest from zero lag, on the highest one's side, whose height is at
    /// least this share of the highest (the floor's and the ceiling's images lie nearer zero).
    pub outer_share: f64,
}

impl Default for GccParams {
    /// 16 kHz; 1024-sample frames (64 ms, the chunk length of the logged audio); lags on a
    /// 1/16-sample grid refined by a parabola; the band 200–6000 Hz where voiced speech
    /// carries its energy, chosen a priori (Knapp & Carter give no numbers; the seed none);
    /// a 256-sample hop, onset weighting with ρ 1 and PHAT-β 0.5 over every frame, chosen on
    /// the quick profile (module doc).
    fn default() -> Self {
        GccParams {
            sample_rate: 16_000.0,
            frame: 1024,
            hop: 256,
            interp: 16,
            band_lo: 200.0,
            band_hi: 6000.0,
            refine: Refine::Parabolic,
            loud_share: 1.0,
            phat_beta: 0.5,
            onset: 1.0,
            weighting: Weighting::PhatBeta,
            spacing_m: super::doa::BIRON_SPACING_M,
            outer_share: 1.0,
        }
    }
}

/// The result of one block.
#[derive(Debug, Clone, PartialEq)]
pub struct Delay {
    /// Arrival at microphone 1 minus arrival at microphone 0 (s).
    pub tau_s: f64,
    /// PHAT peak height: 1 for a pure delay, near 0 for incoherent noise.
    pub peak: f64,
    /// Frames summed.
    pub frames: usize,
}

/// A GCC-PHAT estimator with its FFT plans and buffers.
pub struct GccPhat {
    pub params: GccParams,
    window: Vec<f64>,
    r2c: Arc<dyn RealToComplex<f64>>,
    c2r: Arc<dyn ComplexToReal<f64>>,
    frame_in: Vec<f64>,
    spec0: Vec<Complex<f64>>,
    spec1: Vec<Complex<f64>>,
    padded: Vec<Complex<f64>>,
    corr: Vec<f64>,
}

impl GccPhat {
    pub fn new(params: GccParams) -> Result<GccPhat, GccError> {
        let p = &params;
        if !p.frame.is_power_of_two() || p.frame < 16 {
            return Err(GccError::Settings(format!(
                "frame {} is not a power of two >= 16",
                p.frame
            )));
        }
        if p.hop == 0 || p.hop > p.frame {
            return Err(GccError::Settings(format!(
                "hop {} not in [1, frame]",
                p.hop
            )));
        }
        if p.interp == 0 || p.interp > 64 {
            return Err(GccError::Settings(format!(
                "interp {} not in [1, 64]",
                p.interp
            )));
        }
        if !(p.loud_share > 0.0 && p.loud_share <= 1.0) {
            return Err(GccError::Settings(format!(
                "loud_share {} not in (0, 1]",
                p.loud_share
            )));
        }
        if !(p.onset >= 0.0 && p.onset.is_finite()) {
            return Err(GccError::Settings(format!(
                "onset {} is not a finite value >= 0",
                p.onset
            )));
        }
        if !(0.0..=1.0).contains(&p.phat_beta) {
            return Err(GccError::Settings(format!(
                "phat_beta {} not in [0, 1]",
                p.phat_beta
            )));
        }
        if !(p.outer_share > 0.0 && p.outer_share <= 1.0) {
            return Err(GccError::Settings(format!(
                "outer_share {} not in (0, 1]",
                p.outer_share
            )));
        }
        if !(p.spacing_m > 0.0 && p.spacing_m.is_finite()) {
            return Err(GccError::Settings(format!(
                "spacing_m {} is not a positive length",
                p.spacing_m
            )));
        }
        if !(p.sample_rate > 0.0 && p.band_lo >= 0.0 && p.band_lo < p.band_hi) {
            return Err(GccError::Settings(
                "needs a positive sample rate and band_lo < band_hi".into(),
            ));
        }
        let mut planner = RealFftPlanner::<f64>::new();
        let r2c = planner.plan_fft_forward(p.frame);
        let c2r = planner.plan_fft_inverse(p.frame * p.interp);
        let n = p.frame;
        let window = (0..n)
            .map(|i| 0.5 - 0.5 * (std::f64::consts::TAU * i as f64 / n as f64).cos())
            .collect();
        Ok(GccPhat {
            window,
            frame_in: vec![0.0; n],
            spec0: r2c.make_output_vec(),
            spec1: r2c.make_output_vec(),
            padded: c2r.make_input_vec(),
            corr: c2r.make_output_vec(),
            r2c,
            c2r,
            params,
        })
    }

    /// Largest lag (s) two microphones `spacing_m` apart can show.
    pub fn max_lag_s(spacing_m: f64) -> f64 {
        spacing_m / super::SPEED_OF_SOUND_M_S
    }

    /// The PHAT-weighted cross-spectrum of a block (`x0`, `x1`: microphones 0 and 1), one
    /// value per bin `0..=frame/2`, and the number of frames summed.
    pub fn cross_spectrum(
        &mut self,
        x0: &[f32],
        x1: &[f32],
    ) -> Result<(Vec<Complex<f64>>, usize), GccError> {
        if x0.len() != x1.len() {
            return Err(GccError::Lengths {
                left: x0.len(),
                right: x1.len(),
            });
        }
        let n = self.params.frame;
        if x0.len() < n {
            return Err(GccError::Short {
                samples: x0.len(),
                frame: n,
            });
        }
        let starts: Vec<usize> = (0..)
            .map(|k| k * self.params.hop)
            .take_while(|s| s + n <= x0.len())
            .collect();
        let energy = |s: usize| {
            x0[s..s + n]
                .iter()
                .map(|v| f64::from(*v).powi(2))
                .sum::<f64>()
        };
        let share = self.params.loud_share;
        let keep: Vec<usize> = if share < 1.0 && starts.len() > 1 {
            let mut by: Vec<(f64, usize)> = starts.iter().map(|&s| (energy(s), s)).collect();
            by.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
            let n_keep = ((starts.len() as f64 * share).ceil() as usize).clamp(1, starts.len());
            let mut k: Vec<usize> = by[..n_keep].iter().map(|x| x.1).collect();
            k.sort_unstable();
            k
        } else {
            starts
        };
        let bins = n / 2 + 1;
        let mut sum = vec![Complex::new(0.0, 0.0); bins];
        // the channels' (weighted) powers, for the diffuse weightings' coherence only
        let coherence = self.params.weighting != Weighting::PhatBeta;
        let (mut pow0, mut pow1) = (vec![0.0; bins], vec![0.0; bins]);
        let rho = self.params.onset;
        // each frame's bin powers and the previous frame's, two buffers swapped per frame
        let (mut power, mut before) = (vec![0.0; bins], vec![0.0; bins]);
        let mut frames = 0;
        for (i, &start) in keep.iter().enumerate() {
            self.fft_frame(&x0[start..start + n], true)?;
            self.fft_frame(&x1[start..start + n], false)?;
            let spectra = self.spec0.iter().zip(&self.spec1);
            if rho > 0.0 {
                for (p, (a, b)) in power.iter_mut().zip(spectra.clone()) {
                    *p = 0.5 * (a.norm_sqr() + b.norm_sqr());
                }
            }
            if rho == 0.0 || i > 0 {
                for (k, (a, b)) in spectra.enumerate() {
                    let w = if rho == 0.0 {
                        1.0
                    } else {
                        onset_weight(power[k], before[k], rho)
                    };
                    sum[k] += b * a.conj() * w;
                    if coherence {
                        pow0[k] += a.norm_sqr() * w;
                        pow1[k] += b.norm_sqr() * w;
                    }
                }
                frames += 1;
            }
            std::mem::swap(&mut power, &mut before);
        }
        self.weigh(&mut sum, &pow0, &pow1);
        Ok((sum, frames))
    }

    /// The per-bin weighting ([`Weighting`]) of a summed cross-spectrum, in place; bins
    /// outside the band and silent bins become zero.
    fn weigh(&self, sum: &mut [Complex<f64>], pow0: &[f64], pow1: &[f64]) {
        let p = &self.params;
        let bin_hz = p.sample_rate / p.frame as f64;
        for (k, s) in sum.iter_mut().enumerate() {
            let f = k as f64 * bin_hz;
            let m = s.norm();
            if f < p.band_lo || f > p.band_hi || m <= 1e-300 {
                *s = Complex::new(0.0, 0.0);
                continue;
            }
            *s = match p.weighting {
                Weighting::PhatBeta if p.phat_beta == 1.0 => *s / m,
                Weighting::PhatBeta => *s / m.powf(p.phat_beta),
                w => {
                    let level = (pow0[k] * pow1[k]).sqrt().max(m);
                    let gx = *s / level;
                    let gn = diffuse::diffuse_coherence(f, p.spacing_m);
                    let ratio = diffuse::cdr(gx, gn);
                    let direct = diffuse::direct_phasor(gx, gn, ratio);
                    let dm = direct.norm();
                    if dm <= 1e-300 {
                        Complex::new(0.0, 0.0)
                    } else {
                        // PHAT-β's kept magnitude: the bins' level^(1 − β)
                        let unit = direct / dm * level.powf(1.0 - p.phat_beta);
                        match w {
                            Weighting::DiffuseShare if ratio.is_infinite() => unit,
                            Weighting::DiffuseShare => unit * (ratio / (ratio + 1.0)),
                            Weighting::DiffuseMl => unit * ratio.min(MAX_CDR),
                            _ => unit,
                        }
                    }
                }
            };
        }
    }

    fn fft_frame(&mut self, x: &[f32], first: bool) -> Result<(), GccError> {
        for ((d, &s), w) in self.frame_in.iter_mut().zip(x).zip(&self.window) {
            *d = f64::from(s) * w;
        }
        let out = if first {
            &mut self.spec0
        } else {
            &mut self.spec1
        };
        self.r2c
            .process(&mut self.frame_in, out)
            .map_err(|e| GccError::Fft(e.to_string()))
    }

    /// The correlation of a PHAT cross-spectrum on the lag grid within `±max_lag_s`: the
    /// first lag (s), the grid step (s) and the values (divided by the kept bins' weights,
    /// so a pure delay peaks at 1).
    pub fn correlation(
        &mut self,
        cross: &[Complex<f64>],
        max_lag_s: f64,
    ) -> Result<(f64, f64, Vec<f64>), GccError> {
        let n = self.params.frame;
        let big = n * self.params.interp;
        self.padded
            .iter_mut()
            .for_each(|c| *c = Complex::new(0.0, 0.0));
        for (d, s) in self.padded.iter_mut().zip(cross) {
            *d = *s;
        }
        // the inverse real FFT needs real DC and Nyquist bins
        self.padded[0].im = 0.0;
        let last = self.padded.len() - 1;
        self.padded[last].im = 0.0;
        self.c2r
            .process(&mut self.padded, &mut self.corr)
            .map_err(|e| GccError::Fft(e.to_string()))?;
        // a pure delay sums to 2 per kept bin's weight (its mirror included), 1 at DC and
        // Nyquist; PHAT's weight is 1 per bin, PHAT-β's the bin's weighted magnitude
        let phat = self.params.weighting == Weighting::PhatBeta && self.params.phat_beta == 1.0;
        let kept: f64 = cross
            .iter()
            .enumerate()
            .filter(|(_, c)| c.norm() > 0.0)
            .map(|(k, c)| {
                let w = if phat { 1.0 } else { c.norm() };
                if k == 0 || k == n / 2 { w } else { 2.0 * w }
            })
            .sum();
        let scale = if kept > 0.0 { kept } else { 1.0 };
        let step = 1.0 / (self.params.sample_rate * self.params.interp as f64);
        let max_k = ((max_lag_s / step).ceil() as usize).min(big / 2 - 1);
        let values: Vec<f64> = (0..=2 * max_k)
            .map(|i| {
                let k = i as isize - max_k as isize;
                self.corr[k.rem_euclid(big as isize) as usize] / scale
            })
            .collect();
        Ok((-(max_k as f64) * step, step, values))
    }

    /// The delay of a block within `±max_lag_s` (see the module doc).
    pub fn delay(&mut self, x0: &[f32], x1: &[f32], max_lag_s: f64) -> Result<Delay, GccError> {
        let (cross, frames) = self.cross_spectrum(x0, x1)?;
        let (first, step, r) = self.correlation(&cross, max_lag_s)?;
        let (tau_s, peak) = outermost_peak(
            &r,
            first,
            step,
            max_lag_s,
            self.params.refine,
            self.params.outer_share,
        );
        Ok(Delay {
            tau_s,
            peak,
            frames,
        })
    }
}

/// The onset weight of a bin whose power is `now` after `before` in the previous frame:
/// `clamp(1 − ρ·before/now, 0, 1)` — 1 where the bin's power rises steeply (the direct sound
/// of a new syllable), 0 where it holds or decays (the reverberant tail, stationary noise
/// with ρ ≥ 1 half the time); a silent bin weighs 0.
pub fn onset_weight(now: f64, before: f64, rho: f64) -> f64 {
    if now > 0.0 {
        (1.0 - rho * before / now).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// The largest value of `r` (grid from `first`, step `step`) within `±max_lag`, and its lag.
pub fn peak(r: &[f64], first: f64, step: f64, max_lag: f64, refine: Refine) -> (f64, f64) {
    outermost_peak(r, first, step, max_lag, refine, 1.0)
}

/// The direct sound's peak of `r` within `±max_lag` and its lag: with `share` 1 the largest
/// value ([`peak`]); below 1 the local maximum farthest from zero lag on the largest one's
/// side whose height is at least `share` times the largest. A talker above the floor and
/// below the ceiling has its floor and ceiling images at the same azimuth and a steeper
/// elevation, so at a lag `cos ε_image / cos ε_direct` (< 1) times the direct one: nearer
/// zero, on the same side. Where the images' peaks outgrow the direct sound's, the highest
/// peak reads too small a cone; the outermost strong one does not (issue 33, round 8).
pub fn outermost_peak(
    r: &[f64],
    first: f64,
    step: f64,
    max_lag: f64,
    refine: Refine,
    share: f64,
) -> (f64, f64) {
    let lag = |i: usize| first + i as f64 * step;
    let inside = |i: usize| lag(i).abs() <= max_lag + 1e-12;
    let mut best: Option<usize> = None;
    for (i, v) in r.iter().enumerate() {
        if inside(i) && best.is_none_or(|b| *v > r[b]) {
            best = Some(i);
        }
    }
    let Some(mut b) = best else {
        return (0.0, 0.0);
    };
    // at zero lag the highest peak has no side to look out on
    if share < 1.0 && r[b] > 0.0 && lag(b).abs() > 0.5 * step {
        let floor = share * r[b];
        let side = lag(b).signum();
        // scanning outwards from the highest peak, the last strong local maximum
        let outwards: Box<dyn Iterator<Item = usize>> = if side > 0.0 {
            Box::new(b + 1..r.len().saturating_sub(1))
        } else {
            Box::new((1..b).rev())
        };
        let mut outer = b;
        for i in outwards {
            if inside(i) && r[i] >= floor && r[i] > r[i - 1] && r[i] >= r[i + 1] {
                outer = i;
            }
        }
        b = outer;
    }
    if refine == Refine::Grid || b == 0 || b + 1 >= r.len() {
        return (lag(b), r[b]);
    }
    let (ym, y0, yp) = (r[b - 1], r[b], r[b + 1]);
    let den = ym - 2.0 * y0 + yp;
    if den >= 0.0 {
        return (lag(b), y0);
    }
    let delta = (0.5 * (ym - yp) / den).clamp(-0.5, 0.5);
    let tau = (lag(b) + delta * step).clamp(-max_lag, max_lag);
    (tau, y0 - 0.25 * (ym - yp) * delta)
}

#[cfg(test)]
#[path = "gcc_tests.rs"]
mod tests;

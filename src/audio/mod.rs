//! Two-microphone audio: the direction of a sound source from the time delay between two
//! microphones (seed 003, BIRON: "the stereo microphones are applied to locate sound sources
//! in front of the robot"; Lang et al. 2003). Pure functions of sample buffers; no file I/O
//! (a WAV file's bytes are built in memory, the caller writes them).
//!
//! - [`gcc_phat`]: the generalised cross-correlation with the phase transform (Knapp & Carter
//!   1976) over a block of frames, its correlogram, and the sub-sample peak.
//! - [`doa`]: the cone angle asin(c·τ/d), its front/back mirror, the correction for a source
//!   above or below the microphones, and the bound integer-lag quantisation alone gives.
//! - [`diffuse`]: the diffuse field's coherence sin(kd)/(kd), a bin's coherent-to-diffuse
//!   ratio and its direct sound's phase (the `Weighting::Diffuse*` GCC weightings).
//! - [`activity`]: which blocks hold a directional sound (energy over a minimum-statistics
//!   noise floor and the PHAT peak height).
//! - [`wav`]: interleaved 16-bit samples as WAV bytes (`hound`).
//!
//! Not here: beam-forming, speech recognition, more than two microphones.

pub mod activity;
pub mod diffuse;
pub mod doa;
pub mod gcc_phat;
pub mod wav;

/// Speed of sound in air at 20 °C (m/s).
pub const SPEED_OF_SOUND_M_S: f64 = 343.0;

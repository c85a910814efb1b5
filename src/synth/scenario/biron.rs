//! `[biron]`: seed 003's BIRON home tour (issue 33). A scenario with this table is written by
//! `synth::biron` (visitors drawn per session, two-microphone audio under an acoustic grid,
//! a pan-tilt camera driven in closed loop by the attention system); `[world]` gives the room
//! and `[[people]]`, `[robot]` and `[[sensors]]` are not used.

use serde::{Deserialize, Serialize};

/// `[biron]`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BironSpec {
    /// Visitors per session `[least, most]`.
    pub visitors: [u32; 2],
    /// Robot `[x, y, yaw_deg]` (it stands; its pan-tilt unit turns).
    pub robot: [f64; 3],
    /// Where visitors enter and leave `[x, y]`.
    pub door: [f64; 2],
    /// The acoustic grid: reverberation times (s) × SNRs (dB); `/audio` carries `nominal`.
    pub rt60_s: Vec<f64>,
    pub snr_db: Vec<f64>,
    pub nominal: [f64; 2],
    /// Camera image size and horizontal field of view (deg), frame rate (Hz).
    pub camera: [u32; 2],
    pub hfov_deg: f64,
    #[serde(default = "default_rate")]
    pub rate_hz: f64,
}

fn default_rate() -> f64 {
    10.0
}

impl BironSpec {
    /// `(key, reason)` of the first problem.
    pub fn problem(&self) -> Option<(String, String)> {
        let bad = |k: &str, r: &str| Some((k.to_string(), r.to_string()));
        if self.visitors[0] == 0 || self.visitors[0] > self.visitors[1] || self.visitors[1] > 8 {
            return bad("visitors", "needs 1 <= least <= most <= 8");
        }
        if self.rt60_s.is_empty() || self.rt60_s.iter().any(|r| !(0.0..=2.0).contains(r)) {
            return bad("rt60_s", "needs reverberation times in [0, 2] s");
        }
        if self.snr_db.is_empty() || self.snr_db.iter().any(|s| !(-20.0..=80.0).contains(s)) {
            return bad("snr_db", "needs SNRs in [-20, 80] dB");
        }
        if !self.rt60_s.contains(&self.nominal[0]) || !self.snr_db.contains(&self.nominal[1]) {
            return bad("nominal", "must be a cell of rt60_s x snr_db");
        }
        if self.camera[0] < 32 || self.camera[1] < 32 || !(10.0..=120.0).contains(&self.hfov_deg) {
            return bad("camera", "needs at least 32x32 px and 10-120 deg");
        }
        if !(1.0..=30.0).contains(&self.rate_hz) {
            return bad("rate_hz", "needs 1-30 Hz");
        }
        None
    }
}

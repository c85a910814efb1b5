//! Direction of arrival under every acoustic condition (the `/audio_grid/…` streams): the
//! session cut into [`Params::doa_block_s`] blocks; a block with one talker (one utterance
//! covering at least [`Params::doa_single_share`] of it, no other touching it) is scored —
//! GCC-PHAT's cone angle against the talker's true cone angle at the microphones (the
//! direction of the mouth, its height included: what two microphones can measure; a talker
//! behind the robot has the same cone as the mirror in front). And the correlogram of the
//! nominal stream: GCC-PHAT per 0.1 s step over the first [`Params::correlogram_s`] seconds,
//! the true lags of whoever speaks drawn over it.

use std::collections::BTreeMap;

use image::{Rgb, RgbImage};

use super::params::Params;
use super::tables::DoaRow;
use crate::audio::doa::{self, BIRON_SPACING_M};
use crate::audio::gcc_phat::{GccParams, GccPhat};
use crate::frames::Skips;
use crate::frames::audio::{self, AudioStream};
use crate::groundtruth::biron::UtteranceTruth;
use crate::log::{SessionLog, TfBuffer};
use crate::time::Nanos;

/// The microphones' centre (world) and the robot's yaw.
#[derive(Debug, Clone, Copy)]
pub struct Mics {
    pub center: [f64; 3],
    pub yaw: f64,
}

impl Mics {
    /// The microphones (`microphones` frame) and the robot's yaw (`base_link`) in `map` at `t`.
    pub fn at(tf: &TfBuffer, t: Nanos) -> anyhow::Result<Mics> {
        let mic = tf.lookup("map", "microphones", t)?;
        let base = tf.lookup("map", "base_link", t)?;
        Ok(Mics {
            center: [mic.translation.x, mic.translation.y, mic.translation.z],
            yaw: base.rotation.euler_angles().2,
        })
    }
}

/// Every `/audio_grid/…/audio` stream of a log, by topic.
pub fn grid_streams(
    log: &SessionLog,
    skips: &mut Skips,
) -> anyhow::Result<BTreeMap<String, AudioStream>> {
    let mut out = BTreeMap::new();
    let topics: Vec<String> = log
        .summary()
        .topics()
        .into_iter()
        .filter(|t| t.starts_with("/audio_grid/") && t.ends_with("/audio"))
        .map(str::to_string)
        .collect();
    for topic in topics {
        let (st, sk) = audio::read(log, &topic)?;
        skips.merge(sk);
        out.insert(topic, st);
    }
    Ok(out)
}

/// `(rt60 ms, snr dB)` of a grid topic `/audio_grid/rt60_<ms>ms_snr_<dB>db/audio`.
pub fn condition(topic: &str) -> Option<(i64, i64)> {
    let cell = topic.strip_prefix("/audio_grid/")?.strip_suffix("/audio")?;
    let rest = cell.strip_prefix("rt60_")?;
    let (rt, snr) = rest.split_once("ms_snr_")?;
    Some((rt.parse().ok()?, snr.strip_suffix("db")?.parse().ok()?))
}

/// The true cone angle (rad) of a mouth, and whether it is behind the microphone axis.
pub fn true_cone(m: &Mics, mouth: [f64; 3]) -> (f64, bool) {
    let (dx, dy, dz) = (
        mouth[0] - m.center[0],
        mouth[1] - m.center[1],
        mouth[2] - m.center[2],
    );
    let (s, c) = m.yaw.sin_cos();
    let fwd = dx * c + dy * s;
    let left = -dx * s + dy * c;
    let r = (dx * dx + dy * dy + dz * dz).sqrt().max(1e-9);
    ((left / r).clamp(-1.0, 1.0).asin(), fwd < 0.0)
}

fn secs(ns: u64, t0: u64) -> f64 {
    ns.saturating_sub(t0) as f64 * 1e-9
}

/// Every scored block of every condition, located by GCC-PHAT with `gcc` (the system's own
/// settings in the pipeline).
pub fn blocks(
    grid: &BTreeMap<String, AudioStream>,
    utt: &[UtteranceTruth],
    mics: &Mics,
    gcc: &GccParams,
    p: &Params,
) -> anyhow::Result<Vec<DoaRow>> {
    let mut gcc = GccPhat::new(*gcc)?;
    let max = GccPhat::max_lag_s(BIRON_SPACING_M);
    let mut out = Vec::new();
    for (topic, s) in grid {
        let Some((rt60_ms, snr_db)) = condition(topic) else {
            continue;
        };
        let fs = f64::from(s.sample_rate);
        let len = (p.doa_block_s * fs) as usize;
        let t0 = s.start.0;
        let mut b = 0;
        while (b + 1) * len <= s.channels[0].len() {
            let (a, e) = (b as f64 * p.doa_block_s, (b + 1) as f64 * p.doa_block_s);
            let over = |u: &UtteranceTruth| {
                (secs(u.end_ns, t0).min(e) - secs(u.start_ns, t0).max(a)).max(0.0)
            };
            let touching: Vec<&UtteranceTruth> = utt.iter().filter(|u| over(u) > 0.0).collect();
            if let [u] = touching.as_slice()
                && over(u) >= p.doa_single_share * p.doa_block_s
            {
                let r = b * len..(b + 1) * len;
                let d = gcc.delay(&s.channels[0][r.clone()], &s.channels[1][r], max)?;
                let est = doa::cone_angle(d.tau_s, BIRON_SPACING_M);
                let (truth, behind) = true_cone(mics, u.mouth);
                out.push(DoaRow {
                    rt60_ms,
                    snr_db,
                    t_s: a,
                    speaker: i64::from(u.speaker),
                    true_cone_deg: truth.to_degrees(),
                    est_cone_deg: est.to_degrees(),
                    err_deg: (est - truth).abs().to_degrees(),
                    peak: d.peak,
                    behind,
                });
            }
            b += 1;
        }
    }
    Ok(out)
}

/// Viridis-like colour of a value in [0, 1].
fn colour(v: f64) -> Rgb<u8> {
    let v = v.clamp(0.0, 1.0);
    let stops = [
        [68.0, 1.0, 84.0],
        [59.0, 82.0, 139.0],
        [33.0, 145.0, 140.0],
        [94.0, 201.0, 98.0],
        [253.0, 231.0, 37.0],
    ];
    let x = v * 4.0;
    let i = (x.floor() as usize).min(3);
    let f = x - i as f64;
    let c = |k: usize| (stops[i][k] + (stops[i + 1][k] - stops[i][k]) * f).round() as u8;
    Rgb([c(0), c(1), c(2)])
}

/// The correlogram of the nominal stream (module doc): time left to right (3 px per 0.1 s
/// step), lag top (+d/c) to bottom (−d/c), 2 px per 1/64 ms; the true lags of the talkers
/// as white dots.
pub fn correlogram(
    s: &AudioStream,
    utt: &[UtteranceTruth],
    mics: &Mics,
    p: &Params,
) -> anyhow::Result<RgbImage> {
    let params = GccParams {
        interp: 4,
        ..GccParams::default()
    };
    let mut gcc = GccPhat::new(params)?;
    let fs = f64::from(s.sample_rate);
    let block = (0.256 * fs) as usize;
    let max = GccPhat::max_lag_s(BIRON_SPACING_M);
    let steps = (p.correlogram_s * 10.0) as usize;
    let mut cols: Vec<(f64, f64, Vec<f64>)> = Vec::new();
    for k in 1..=steps {
        let end = (k as f64 * 0.1 * fs).round() as usize;
        if end < block || end > s.channels[0].len() {
            continue;
        }
        let (cross, _) = gcc.cross_spectrum(
            &s.channels[0][end - block..end],
            &s.channels[1][end - block..end],
        )?;
        cols.push(gcc.correlation(&cross, max)?);
    }
    let rows = cols.first().map_or(1, |c| c.2.len());
    let (cw, rh) = (3u32, 2u32);
    let mut img = RgbImage::new((steps as u32 * cw).max(1), (rows as u32 * rh).max(1));
    for (i, (_, _, vals)) in cols.iter().enumerate() {
        let k = i + (steps - cols.len());
        let top = vals.iter().copied().fold(1e-9, f64::max);
        for (j, v) in vals.iter().enumerate() {
            let y = (rows - 1 - j) as u32 * rh;
            for dx in 0..cw {
                for dy in 0..rh {
                    img.put_pixel(k as u32 * cw + dx, y + dy, colour(v.max(0.0) / top));
                }
            }
        }
    }
    if let Some((first, step, _)) = cols.first() {
        let t0 = s.start.0;
        for k in 1..=steps {
            let t = k as f64 * 0.1;
            for u in utt
                .iter()
                .filter(|u| secs(u.start_ns, t0) <= t && t < secs(u.end_ns, t0))
            {
                let (cone, _) = true_cone(mics, u.mouth);
                let tau = cone.sin() * BIRON_SPACING_M / crate::audio::SPEED_OF_SOUND_M_S;
                let j = ((tau - first) / step).round();
                if j >= 0.0 && (j as usize) < rows {
                    let y = (rows - 1 - j as usize) as u32 * rh;
                    img.put_pixel(
                        ((k - 1) as u32 * cw + 1).min(img.width() - 1),
                        y,
                        Rgb([255, 255, 255]),
                    );
                }
            }
        }
    }
    Ok(img)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_topics_name_their_condition() {
        assert_eq!(
            condition("/audio_grid/rt60_300ms_snr_10db/audio"),
            Some((300, 10))
        );
        assert_eq!(
            condition("/audio_grid/rt60_0ms_snr_0db/audio"),
            Some((0, 0))
        );
        assert_eq!(condition("/audio"), None);
    }

    #[test]
    fn a_mouth_to_the_left_and_above_has_a_smaller_cone_than_its_azimuth() {
        let m = Mics {
            center: [0.0, 0.0, 1.06],
            yaw: 0.0,
        };
        let (cone, behind) = true_cone(&m, [1.0, 1.0, 1.6]);
        assert!(!behind);
        assert!(cone > 0.0 && cone < std::f64::consts::FRAC_PI_4);
        let (back, behind) = true_cone(&m, [-1.0, 1.0, 1.6]);
        assert!(behind);
        assert!((back - cone).abs() < 1e-12, "the mirror has the same cone");
    }
}

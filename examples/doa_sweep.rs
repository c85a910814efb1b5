//! Sweep (development aid, not part of the pipeline): the direction-of-arrival error of
//! GCC-PHAT variants on the `/audio_grid/…` streams of `biron_home` logs, scored exactly as the
//! pipeline's `doa_grid` (0.5 s blocks with one talker, cone angle against the mouth's).
//! Prints, per variant and acoustic condition, the median / 95th percentile error and the
//! share within 5°, pooled over the logs given.
//!
//! Usage: `cargo run --release --example doa_sweep -- LOG.mcap... [NAME:key=value,...]...`
//! with keys `band_lo`, `band_hi`, `frame`, `hop`, `loud_share`, `phat_beta`, `onset`, `outer_share` and
//! `weighting` (`phat_beta`, `diffuse_share`, `diffuse_ml`, `diffuse_phase`); the system's
//! default settings are always the first row. `DUMP=NAME` prints that variant's every block.

use std::collections::BTreeMap;

use peopletrack::anchoring::system::SystemParams;
use peopletrack::audio::gcc_phat::{GccParams, Weighting};
use peopletrack::frames::{Skips, truth};
use peopletrack::groundtruth::biron::UTTERANCES_TOPIC;
use peopletrack::log::{SessionLog, TfBuffer};
use peopletrack::pipelines::s003_biron_anchoring::doa::{Mics, blocks, grid_streams};
use peopletrack::pipelines::s003_biron_anchoring::params::Params;

fn variant(spec: &str, base: GccParams) -> Result<(String, GccParams), String> {
    let (name, kv) = spec
        .split_once(':')
        .ok_or(format!("{spec}: NAME:key=value,..."))?;
    let mut g = base;
    for pair in kv.split(',').filter(|s| !s.is_empty()) {
        let (k, v) = pair.split_once('=').ok_or(format!("{pair}: key=value"))?;
        if k == "weighting" {
            g.weighting = Weighting::from_name(v).ok_or(format!("{pair}: unknown weighting"))?;
            continue;
        }
        let x: f64 = v.parse().map_err(|e| format!("{pair}: {e}"))?;
        match k {
            "band_lo" => g.band_lo = x,
            "band_hi" => g.band_hi = x,
            "frame" => g.frame = x as usize,
            "hop" => g.hop = x as usize,
            "loud_share" => g.loud_share = x,
            "phat_beta" => g.phat_beta = x,
            "onset" => g.onset = x,
            "outer_share" => g.outer_share = x,
            _ => return Err(format!("unknown key {k}")),
        }
    }
    Ok((name.to_string(), g))
}

fn quantile(v: &[f64], q: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let i = ((s.len() - 1) as f64 * q).round() as usize;
    s[i]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let base = SystemParams::default().gcc;
    let mut variants = vec![("default".to_string(), base)];
    let mut logs = Vec::new();
    for a in &args {
        if a.ends_with(".mcap") {
            logs.push(a.clone());
        } else {
            variants.push(variant(a, base)?);
        }
    }
    let p = Params::default();
    let mut errs: BTreeMap<(usize, i64, i64), Vec<f64>> = BTreeMap::new();
    // |est| − |true| cone (°): negative reads nearer broadside
    let mut signed: BTreeMap<(usize, i64, i64), Vec<f64>> = BTreeMap::new();
    for path in &logs {
        let log = SessionLog::open(path)?;
        let mut skips = Skips::new();
        let grid = grid_streams(&log, &mut skips)?;
        let (utter, _) = truth::utterances(&log, UTTERANCES_TOPIC)?;
        let utt = utter
            .iter()
            .next()
            .map(|(_, f)| f.utterances.clone())
            .unwrap_or_default();
        let t0 = grid.values().next().ok_or("no grid stream")?.start;
        let tf = TfBuffer::from_log(&log, 0.5)?;
        let mics = Mics::at(&tf, t0)?;
        for (i, (_, g)) in variants.iter().enumerate() {
            for r in blocks(&grid, &utt, &mics, g, &p)? {
                if std::env::var("DUMP").is_ok_and(|d| d == variants[i].0) {
                    println!(
                        "dump {path} {} {} t {:.1} spk {} true {:.2} est {:.2} peak {:.3}",
                        r.rt60_ms,
                        r.snr_db,
                        r.t_s,
                        r.speaker,
                        r.true_cone_deg,
                        r.est_cone_deg,
                        r.peak
                    );
                }
                errs.entry((i, r.rt60_ms, r.snr_db))
                    .or_default()
                    .push(r.err_deg);
                signed
                    .entry((i, r.rt60_ms, r.snr_db))
                    .or_default()
                    .push(r.est_cone_deg.abs() - r.true_cone_deg.abs());
            }
        }
    }
    println!(
        "variant | rt60 ms | snr dB | blocks | median deg | p95 deg | within 5 deg | median |est|-|true| deg"
    );
    for ((i, rt, snr), e) in &errs {
        let within = e.iter().filter(|x| **x <= 5.0).count() as f64 / e.len() as f64;
        println!(
            "{} | {rt} | {snr} | {} | {:.2} | {:.1} | {:.3} | {:+.2}",
            variants[*i].0,
            e.len(),
            quantile(e, 0.5),
            quantile(e, 0.95),
            within,
            quantile(&signed[&(*i, *rt, *snr)], 0.5)
        );
    }
    Ok(())
}

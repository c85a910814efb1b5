//! Probe (development aid, issue 33 round 8): the GCC curve of one 0.5 s block of one
//! `/audio_grid/…` stream under the system's settings or another weighting, as text — lag
//! (samples), cone angle (°), value and a bar — to see whether the direct sound and the floor's
//! and ceiling's images are resolved or merged.
//! Usage: `cargo run --release --example doa_curve -- LOG.mcap TOPIC T_S [weighting]`.
use peopletrack::audio::doa::BIRON_SPACING_M;
use peopletrack::audio::gcc_phat::{GccParams, GccPhat, Weighting};
use peopletrack::frames::audio;
use peopletrack::log::SessionLog;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().skip(1).collect();
    if a.len() < 3 {
        return Err("usage: doa_curve LOG.mcap TOPIC T_S [weighting]".into());
    }
    let log = SessionLog::open(&a[0])?;
    let (s, _) = audio::read(&log, &a[1])?;
    let t: f64 = a[2].parse()?;
    let mut p = GccParams::default();
    if let Some(w) = a.get(3) {
        p.weighting = Weighting::from_name(w).ok_or("weighting")?;
    }
    let mut g = GccPhat::new(p)?;
    let i0 = (t * 16000.0) as usize;
    if i0 + 8000 > s.channels[0].len() {
        return Err(format!("{}: no 0.5 s block at {t} s", a[1]).into());
    }
    let r = i0..i0 + 8000;
    let (cross, _) = g.cross_spectrum(&s.channels[0][r.clone()], &s.channels[1][r])?;
    let (first, step, v) = g.correlation(&cross, GccPhat::max_lag_s(BIRON_SPACING_M))?;
    for (i, x) in v.iter().enumerate().step_by(4) {
        let lag = (first + i as f64 * step) * 16000.0;
        let cone = (343.0 * lag / 16000.0 / BIRON_SPACING_M)
            .clamp(-1.0, 1.0)
            .asin()
            .to_degrees();
        println!(
            "{lag:6.2} {cone:6.1} {x:.3} {}",
            "#".repeat((x.max(0.0) * 60.0) as usize)
        );
    }
    Ok(())
}

//! Writes a log with two-channel S16LE audio (`audio_common_msgs` AudioInfo + AudioDataStamped,
//! 1024-frame chunks) of known samples — a chirp on the left, its negative ramp on the right,
//! the extremes −32768 and 32767 included — and the JSON of what was written, for
//! `tools/check_audio_ros2.py fixture` (Python mcap-ros2-support reads it back).
//!
//! Usage: `cargo run --example audio_fixture -- OUT.mcap OUT.json`

use peopletrack::Nanos;
use peopletrack::log::msgs::{AudioDataStamped, AudioInfo, Header};
use peopletrack::log::{SessionWriter, WriterOptions};
use serde_json::json;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let (out, expected) = match args.as_slice() {
        [_, a, b] => (a.clone(), b.clone()),
        _ => return Err("usage: audio_fixture OUT.mcap OUT.json".into()),
    };
    let mut w = SessionWriter::create(&out, &WriterOptions::default())?;
    let info = w.add_ros2::<AudioInfo>("/audio_info")?;
    let audio = w.add_ros2::<AudioDataStamped>("/audio")?;
    let t0 = 1_700_000_000_000_000_000u64;
    w.write(
        info,
        Nanos(t0),
        &AudioInfo {
            channels: 2,
            sample_rate: 16_000,
            sample_format: "S16LE".into(),
            bitrate: 512_000,
            coding_format: "wave".into(),
        },
    )?;
    let mut samples: Vec<i16> = Vec::new();
    let mut stamps = Vec::new();
    for k in 0..20u64 {
        let mut data = Vec::with_capacity(4096);
        for i in 0..1024u64 {
            let n = (k * 1024 + i) as f64;
            let l = (20000.0 * (n * n * 1e-6).sin()).round() as i16;
            let r = match n as u64 % 5000 {
                0 => i16::MIN,
                1 => i16::MAX,
                m => (-(m as i64) * 13 % 32768) as i16,
            };
            for s in [l, r] {
                samples.push(s);
                data.extend_from_slice(&s.to_le_bytes());
            }
        }
        let stamp = t0 + k * 64_000_000;
        stamps.push(stamp);
        w.write(
            audio,
            Nanos(stamp + 64_000_000),
            &AudioDataStamped {
                header: Header::new(Nanos(stamp), "microphones"),
                data,
            },
        )?;
    }
    w.finish()?;
    let doc = json!({
        "topic": "/audio",
        "info": [2, 16000, "S16LE", 512000, "wave"],
        "samples": samples,
        "stamps": stamps,
    });
    std::fs::write(expected, serde_json::to_string(&doc)?)?;
    Ok(())
}

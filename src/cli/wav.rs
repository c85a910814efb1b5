//! `peopletrack wav LOG -o FILE.wav [--topic /audio]`: a session's two-channel audio
//! (`audio_common_msgs/AudioDataStamped`, S16LE, through [`peopletrack::frames::audio`]) as a
//! WAV file a person can listen to; gaps (dropped chunks) are silence and are reported.

use std::path::PathBuf;

use anyhow::Context;

use peopletrack::audio::wav::wav_bytes;
use peopletrack::frames::audio;
use peopletrack::log::SessionLog;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// MCAP session log to read.
    #[arg(value_name = "LOG")]
    pub log: PathBuf,
    /// The audio topic (its `AudioInfo` is the `…audio_info` topic beside it).
    #[arg(long, short, default_value = "/audio")]
    pub topic: String,
    /// WAV file to write.
    #[arg(long, short)]
    pub output: PathBuf,
}

pub fn run(args: &Args, out: &mut dyn std::io::Write) -> anyhow::Result<()> {
    let log = SessionLog::open(&args.log)?;
    let (stream, skips) = audio::read(&log, &args.topic)?;
    let n = stream.channels[0].len();
    let mut samples = Vec::with_capacity(2 * n);
    for i in 0..n {
        for c in &stream.channels {
            samples.push((c[i] * 32768.0).round().clamp(-32768.0, 32767.0) as i16);
        }
    }
    let bytes = wav_bytes(&samples, 2, stream.sample_rate)?;
    peopletrack::report::atomic::write_atomic(&args.output, &bytes, None)
        .with_context(|| format!("writing {}", args.output.display()))?;
    writeln!(
        out,
        "{}: {} s of 2-channel audio at {} Hz from {} ({} samples of silence for gaps; {skips})",
        args.output.display(),
        n as f64 / f64::from(stream.sample_rate),
        stream.sample_rate,
        args.topic,
        stream.gap_samples
    )?;
    Ok(())
}

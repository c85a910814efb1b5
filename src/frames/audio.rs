//! Two-channel audio from `audio_common_msgs/AudioDataStamped` chunks (the ros-drivers
//! `audio_capture` layout) with their `AudioInfo` (the topic beside it named `…audio_info`,
//! latched: its first message counts): the whole stream as one float channel per microphone
//! in [−1, 1), starting at the first chunk's header stamp.
//!
//! Only interleaved 16-bit little-endian PCM (`S16LE`) is read. A stream whose info is
//! missing or names another format or channel count is an error naming file and topic. A
//! chunk that does not decode, whose byte count is not whole frames, or that starts before
//! the previous chunk ended is skipped and counted; a gap between chunks (a dropped chunk) is
//! filled with silence and its samples counted ([`AudioStream::gap_samples`]).

use super::skips::Skips;
use crate::log::msgs::{AudioDataStamped, AudioInfo};
use crate::log::value::FieldError;
use crate::log::{Decoders, LogError, LogErrorKind, SessionLog};
use crate::time::Nanos;

/// A decoded stream.
#[derive(Debug, Clone, PartialEq)]
pub struct AudioStream {
    pub topic: String,
    /// Header stamp of the first chunk.
    pub start: Nanos,
    pub sample_rate: u32,
    /// Microphone 0 and 1 (the interleaving order), in [−1, 1).
    pub channels: [Vec<f32>; 2],
    /// Samples (per channel) of silence put in for missing chunks.
    pub gap_samples: u64,
}

impl AudioStream {
    /// The sample index of log-stamp `t` (rounded), which may lie beyond the end.
    pub fn index(&self, t: Nanos) -> Option<usize> {
        let dt = t.0.checked_sub(self.start.0)?;
        Some((dt as f64 * 1e-9 * f64::from(self.sample_rate)).round() as usize)
    }
}

fn bad(log: &SessionLog, topic: &str, why: String) -> LogError {
    LogError::new(log.path(), LogErrorKind::Field(FieldError::new(why))).on_topic(topic)
}

/// The `audio_info` topic beside an audio topic (`/x/audio` → `/x/audio_info`).
pub fn info_topic(audio_topic: &str) -> String {
    match audio_topic.strip_suffix("audio") {
        Some(prefix) => format!("{prefix}audio_info"),
        None => format!("{audio_topic}_info"),
    }
}

/// Read `topic` (see the module doc) and the bad chunks skipped.
pub fn read(log: &SessionLog, topic: &str) -> Result<(AudioStream, Skips), LogError> {
    let info_t = info_topic(topic);
    let mut dec = Decoders::new();
    let mut info: Option<AudioInfo> = None;
    if log.summary().channel(&info_t).is_some()
        && let Some(m) = log.messages_on(&[info_t.as_str()])?.next()
    {
        let m = m?;
        info = Some(dec.typed::<AudioInfo>(log, &m)?);
    }
    let info = info.ok_or_else(|| bad(log, topic, format!("no AudioInfo on {info_t}")))?;
    if info.sample_format != "S16LE" || info.channels != 2 || info.sample_rate == 0 {
        return Err(bad(
            log,
            topic,
            format!(
                "audio is {} x {} ch at {} Hz; only S16LE, 2 channels is read",
                info.sample_format, info.channels, info.sample_rate
            ),
        ));
    }
    let mut skips = Skips::new();
    let mut stream = AudioStream {
        topic: topic.to_string(),
        start: Nanos(0),
        sample_rate: info.sample_rate,
        channels: [Vec::new(), Vec::new()],
        gap_samples: 0,
    };
    let mut started = false;
    for m in log.messages_on(&[topic])? {
        let m = m?;
        let chunk = match dec.typed::<AudioDataStamped>(log, &m) {
            Ok(c) => c,
            Err(e) => {
                skips.note(topic, e);
                continue;
            }
        };
        if chunk.data.len() % 4 != 0 {
            skips.note(
                topic,
                format!(
                    "{}: {topic} at {} ns: {} bytes are not whole frames",
                    log.path().display(),
                    m.log_time.0,
                    chunk.data.len()
                ),
            );
            continue;
        }
        let stamp = chunk.header.stamp.nanos().unwrap_or(m.log_time);
        if !started {
            stream.start = stamp;
            started = true;
        }
        let have = stream.channels[0].len();
        let Some(at) = stream.index(stamp) else {
            skips.note(
                topic,
                format!(
                    "{}: {topic} at {} ns: chunk stamped before the stream's start",
                    log.path().display(),
                    m.log_time.0
                ),
            );
            continue;
        };
        if at + 1 < have {
            skips.note(
                topic,
                format!(
                    "{}: {topic} at {} ns: chunk overlaps the previous one",
                    log.path().display(),
                    m.log_time.0
                ),
            );
            continue;
        }
        if at > have {
            let gap = at - have;
            stream.gap_samples += gap as u64;
            for c in &mut stream.channels {
                c.resize(at, 0.0);
            }
        }
        for frame in chunk.data.chunks_exact(4) {
            let l = i16::from_le_bytes([frame[0], frame[1]]);
            let r = i16::from_le_bytes([frame[2], frame[3]]);
            stream.channels[0].push(f32::from(l) / 32768.0);
            stream.channels[1].push(f32::from(r) / 32768.0);
        }
    }
    Ok((stream, skips))
}

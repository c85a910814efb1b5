//! Reading the log: camera payloads, their stamps, image decoding, the bootstrap images of
//! the background and the images at one stamp (for the camera-view figure).

use image::RgbImage;

use crate::log::msgs::{CompressedImage, Detection2DArray, Image};
use crate::log::{Decoders, Message, SessionLog};
use crate::time::Nanos;

/// What one camera contributes to one frame.
pub(crate) enum Payload {
    Compressed(CompressedImage),
    Raw(Image),
    Detections(Detection2DArray),
}

/// The image of a payload (`None` for detections).
pub(crate) fn decode_image(p: &Payload) -> Option<Result<RgbImage, String>> {
    match p {
        Payload::Compressed(c) => Some(
            crate::log::image::decode_compressed(c)
                .map(|i| i.to_rgb8())
                .map_err(|e| e.to_string()),
        ),
        Payload::Raw(r) => Some(
            crate::log::image::decode_raw(r)
                .map(|i| i.to_rgb8())
                .map_err(|e| e.to_string()),
        ),
        Payload::Detections(_) => None,
    }
}

/// A message's header stamp, or its log time when the header has none.
pub(crate) fn stamp_of(m: &Message, header: Option<Nanos>) -> Nanos {
    header.filter(|s| s.0 > 0).unwrap_or(m.log_time)
}

/// An image message as a payload with its stamp.
pub(crate) fn image_payload(
    log: &SessionLog,
    decoders: &mut Decoders,
    m: &Message,
) -> Result<(Nanos, Payload), crate::log::LogError> {
    match m.channel.schema_name() {
        "sensor_msgs/msg/Image" | "foxglove.RawImage" => decoders
            .typed::<Image>(log, m)
            .map(|i| (stamp_of(m, i.header.stamp.nanos()), Payload::Raw(i))),
        _ => decoders
            .typed::<CompressedImage>(log, m)
            .map(|i| (stamp_of(m, i.header.stamp.nanos()), Payload::Compressed(i))),
    }
}

/// Up to `n` images per camera topic, evenly spread over the log (the message counts of the
/// summary pick which), for `GaborBackground::bootstrap`. Undecodable ones are skipped here:
/// the main pass counts and reports them.
pub(crate) fn bootstrap_images(
    log: &SessionLog,
    topics: &[String],
    n: usize,
) -> anyhow::Result<Vec<Vec<RgbImage>>> {
    let mut out: Vec<Vec<RgbImage>> = vec![Vec::new(); topics.len()];
    if n == 0 {
        return Ok(out);
    }
    let counts: Vec<u64> = topics.iter().map(|tp| message_count(log, tp)).collect();
    let present: Vec<&str> = topics
        .iter()
        .map(String::as_str)
        .filter(|tp| log.summary().channel(tp).is_some())
        .collect();
    if present.is_empty() {
        return Ok(out);
    }
    let mut seen = vec![0u64; topics.len()];
    let mut decoders = Decoders::new();
    for m in log.messages_on(&present)? {
        let m = m?;
        let Some(c) = topics.iter().position(|tp| tp == m.topic()) else {
            continue;
        };
        let k = seen[c];
        seen[c] += 1;
        // message k is taken when it is the first at or after j · count / n for some j
        let step = (counts[c] / n as u64).max(1);
        if !k.is_multiple_of(step) || out[c].len() >= n {
            continue;
        }
        if let Ok((_, p)) = image_payload(log, &mut decoders, &m)
            && let Some(Ok(rgb)) = decode_image(&p)
        {
            out[c].push(rgb);
        }
    }
    Ok(out)
}

/// Messages on `topic` according to the summary's statistics (0 when unknown).
pub(crate) fn message_count(log: &SessionLog, topic: &str) -> u64 {
    let ch = log.summary().channel(topic);
    log.summary()
        .statistics
        .as_ref()
        .zip(ch)
        .and_then(|(st, ch)| st.channel_message_counts.get(&ch.id).copied())
        .unwrap_or(0)
}

/// The images of all cameras whose stamp is exactly `stamp`, in camera order (the last one
/// per camera; the search stops when every camera has one or 5 s of log time later).
pub(crate) fn images_at(
    log: &SessionLog,
    image_topics: &[String],
    stamp: Nanos,
) -> anyhow::Result<Vec<Option<RgbImage>>> {
    let mut out: Vec<Option<RgbImage>> = vec![None; image_topics.len()];
    let topics: Vec<&str> = image_topics
        .iter()
        .map(String::as_str)
        .filter(|tp| log.summary().channel(tp).is_some())
        .collect();
    if topics.is_empty() {
        return Ok(out);
    }
    let mut decoders = Decoders::new();
    for m in log.messages_on(&topics)? {
        let m = m?;
        let Some(c) = image_topics.iter().position(|tp| tp == m.topic()) else {
            continue;
        };
        let (at, payload) = image_payload(log, &mut decoders, &m)?;
        if at != stamp {
            continue;
        }
        if let Some(Ok(rgb)) = decode_image(&payload) {
            out[c] = Some(rgb);
        }
        if out.iter().all(Option::is_some) || m.log_time.0 > stamp.0 + 5_000_000_000 {
            break;
        }
    }
    Ok(out)
}

//! What one camera contributes to one multi-camera frame (`frames::multicam`), and the
//! images of one frame for the camera-view figure.

use image::RgbImage;

use crate::frames::{ImageMsg, multicam};
use crate::log::SessionLog;
use crate::log::msgs::Detection2DArray;
use crate::time::Nanos;

/// Frames later than this after the wanted stamp end the search for it (ns).
const SEARCH_NS: u64 = 5_000_000_000;

/// What one camera contributes to one frame.
pub(crate) enum Payload {
    Image(ImageMsg),
    Detections(Detection2DArray),
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

/// The decoded images of the multi-camera frame (grouped as the main pass groups them) whose
/// stamp is `stamp`, in camera order; `None` for a camera without an image there (or whose
/// topic the log lacks).
pub(crate) fn images_at(
    log: &SessionLog,
    image_topics: &[String],
    stamp: Nanos,
    tol_ns: u64,
) -> anyhow::Result<Vec<Option<RgbImage>>> {
    let mut out: Vec<Option<RgbImage>> = vec![None; image_topics.len()];
    let present: Vec<(usize, String)> = image_topics
        .iter()
        .enumerate()
        .filter(|(_, tp)| log.summary().channel(tp).is_some())
        .map(|(c, tp)| (c, tp.clone()))
        .collect();
    if present.is_empty() {
        return Ok(out);
    }
    let topics: Vec<String> = present.iter().map(|x| x.1.clone()).collect();
    for f in multicam::group::<ImageMsg>(log, &topics, tol_ns)? {
        let f = f?;
        if f.stamp == stamp {
            for ((c, _), msg) in present.iter().zip(f.cameras) {
                out[*c] = msg.and_then(|m| m.decode().ok());
            }
            break;
        }
        if f.stamp.0 > stamp.0.saturating_add(SEARCH_NS) {
            break;
        }
    }
    Ok(out)
}

//! One camera's decoded images, in log-time order, optionally paired with a mask topic.
//!
//! - [`ImageMsg`]: an undecoded image message, raw (`sensor_msgs/Image`, `foxglove.RawImage`)
//!   or compressed (any schema whose name contains `CompressedImage`), chosen by schema.
//! - [`frames`] → [`CameraFrames`]: an iterator of [`CameraFrame`]s (RGB image, header stamp,
//!   log time, the mask when one pairs). Streaming: memory holds only the frames waiting for
//!   their mask.
//! - [`image_topic`]: `/<camera>/image_raw/compressed`, else `/<camera>/image_raw`.
//! - [`spread`]: up to `n` decoded images per topic, evenly spread over the log.
//!
//! **Pairing with a mask** (a `mono8` `sensor_msgs/Image` with the image's header stamp):
//! messages of both topics are read in log-time order into a queue keyed by header stamp; the
//! queue's front is handed out when it is complete (image and mask) or when a message arrives
//! more than [`PAIR_WAIT_NS`] (1 s of log time) after the front's first message. A mask that
//! never meets its image is dropped ([`CameraFrames::masks_without_image`]); an image whose
//! mask does not come, or comes with another size than the image, is handed out without a mask
//! ([`CameraFrames::frames_without_mask`]). Within one stamp a later message replaces an
//! earlier one of the same topic.
//!
//! **Bad messages** (wrong type, undecodable CDR, bad JPEG/PNG bytes, unsupported encodings)
//! are skipped and counted in [`Skips`] under their topic. A decode error reads
//! `<file>: topic <topic> at log time <s> s: <why>`; an image codec error reads
//! `<file>: <topic> at <log time ns>: <why>`. A message that cannot be read at all (a corrupt
//! chunk) ends the iteration with its [`LogError`].
//!
//! **Stamps**: the header stamp, or the log time when the header stamp is unset (zero or
//! invalid).

use std::collections::VecDeque;

use image::{GrayImage, RgbImage};

use super::skips::Skips;
use crate::log::image::{ImageError, decode_compressed, decode_raw};
use crate::log::msgs::{CompressedImage, Header, Image};
use crate::log::{Decoders, LogError, Message, MessageStream, SessionLog};
use crate::time::Nanos;

/// An image and its mask are paired by header stamp; one left alone this long (log time) is
/// handed out without its partner (ns).
pub const PAIR_WAIT_NS: u64 = 1_000_000_000;

/// The stamp of a message: its header stamp, or its log time when the header stamp is unset.
pub fn stamp_of(m: &Message, header: &Header) -> Nanos {
    header
        .stamp
        .nanos()
        .filter(|s| s.0 > 0)
        .unwrap_or(m.log_time)
}

/// `/<camera>/image_raw/compressed` if the log has it, else `/<camera>/image_raw`, else none.
pub fn image_topic(log: &SessionLog, camera: &str) -> Option<String> {
    [
        format!("/{camera}/image_raw/compressed"),
        format!("/{camera}/image_raw"),
    ]
    .into_iter()
    .find(|t| log.summary().channel(t).is_some())
}

/// An image message, not yet decoded.
#[derive(Debug, Clone, PartialEq)]
pub enum ImageMsg {
    Raw(Image),
    Compressed(CompressedImage),
}

impl ImageMsg {
    /// Read a message as raw or compressed image according to its channel's schema name.
    pub fn read(dec: &mut Decoders, log: &SessionLog, m: &Message) -> Result<ImageMsg, LogError> {
        if m.channel.schema_name().contains("CompressedImage") {
            dec.typed::<CompressedImage>(log, m)
                .map(ImageMsg::Compressed)
        } else {
            dec.typed::<Image>(log, m).map(ImageMsg::Raw)
        }
    }

    pub fn header(&self) -> &Header {
        match self {
            ImageMsg::Raw(i) => &i.header,
            ImageMsg::Compressed(c) => &c.header,
        }
    }

    /// Decode to 8-bit RGB (grey and 16-bit images are converted).
    pub fn decode(&self) -> Result<RgbImage, ImageError> {
        match self {
            ImageMsg::Raw(i) => decode_raw(i).map(|d| d.to_rgb8()),
            ImageMsg::Compressed(c) => decode_compressed(c).map(|d| d.to_rgb8()),
        }
    }
}

/// One decoded camera image.
#[derive(Debug, Clone, PartialEq)]
pub struct CameraFrame {
    /// Header stamp (see the module doc).
    pub stamp: Nanos,
    /// Log time of the image message.
    pub log_time: Nanos,
    pub rgb: RgbImage,
    /// The mask with the same stamp and size, when a mask topic was given and it came.
    pub mask: Option<GrayImage>,
}

struct Pending {
    stamp: Nanos,
    /// Log time of the first message of this stamp (for the wait).
    first_seen: Nanos,
    image: Option<(Nanos, RgbImage)>,
    mask: Option<GrayImage>,
}

/// Iterator over one camera's frames; see the module doc.
pub struct CameraFrames<'a> {
    log: &'a SessionLog,
    stream: MessageStream,
    decoders: Decoders,
    image_topic: String,
    mask_topic: Option<String>,
    pending: VecDeque<Pending>,
    ready: VecDeque<CameraFrame>,
    skips: Skips,
    frames_without_mask: u64,
    masks_without_image: u64,
    done: bool,
}

/// Stream `image_topic`'s frames, paired with `mask_topic`'s masks when given. Both topics
/// must be in the log (a typo is an error, not an empty stream).
pub fn frames<'a>(
    log: &'a SessionLog,
    image_topic: &str,
    mask_topic: Option<&str>,
) -> Result<CameraFrames<'a>, LogError> {
    let mut topics = vec![image_topic];
    topics.extend(mask_topic);
    Ok(CameraFrames {
        log,
        stream: log.messages_on(&topics)?,
        decoders: Decoders::new(),
        image_topic: image_topic.to_string(),
        mask_topic: mask_topic.map(str::to_string),
        pending: VecDeque::new(),
        ready: VecDeque::new(),
        skips: Skips::new(),
        frames_without_mask: 0,
        masks_without_image: 0,
        done: false,
    })
}

/// What one message decoded to.
enum Part {
    Image(RgbImage),
    Mask(GrayImage),
}

impl CameraFrames<'_> {
    /// Bad messages skipped so far.
    pub fn skips(&self) -> &Skips {
        &self.skips
    }

    pub fn into_skips(self) -> Skips {
        self.skips
    }

    /// Frames handed out without a mask although a mask topic was given (the mask never came
    /// within the wait, or had another size than the image).
    pub fn frames_without_mask(&self) -> u64 {
        self.frames_without_mask
    }

    /// Masks dropped because no image with their stamp came within the wait.
    pub fn masks_without_image(&self) -> u64 {
        self.masks_without_image
    }

    fn decode(&mut self, m: &Message) -> Result<(Nanos, Part), String> {
        let log = self.log;
        let codec_err = |e: ImageError| {
            format!(
                "{}: {} at {}: {e}",
                log.path().display(),
                m.topic(),
                m.log_time.0
            )
        };
        if m.topic() == self.image_topic {
            let msg = ImageMsg::read(&mut self.decoders, log, m).map_err(|e| e.to_string())?;
            let rgb = msg.decode().map_err(codec_err)?;
            Ok((stamp_of(m, msg.header()), Part::Image(rgb)))
        } else {
            let msg = self
                .decoders
                .typed::<Image>(log, m)
                .map_err(|e| e.to_string())?;
            let mask = decode_raw(&msg).map_err(codec_err)?.to_luma8();
            Ok((stamp_of(m, &msg.header), Part::Mask(mask)))
        }
    }

    fn emit(&mut self, p: Pending) {
        let Some((log_time, rgb)) = p.image else {
            self.masks_without_image += 1;
            return;
        };
        let mask = p.mask.filter(|m| m.dimensions() == rgb.dimensions());
        if self.mask_topic.is_some() && mask.is_none() {
            self.frames_without_mask += 1;
        }
        self.ready.push_back(CameraFrame {
            stamp: p.stamp,
            log_time,
            rgb,
            mask,
        });
    }

    fn accept(&mut self, m: &Message) {
        let (stamp, part) = match self.decode(m) {
            Ok(x) => x,
            Err(e) => {
                self.skips.note(m.topic(), e);
                return;
            }
        };
        let idx = match self.pending.iter().position(|p| p.stamp == stamp) {
            Some(i) => i,
            None => {
                self.pending.push_back(Pending {
                    stamp,
                    first_seen: m.log_time,
                    image: None,
                    mask: None,
                });
                self.pending.len() - 1
            }
        };
        if let Some(p) = self.pending.get_mut(idx) {
            match part {
                Part::Image(rgb) => p.image = Some((m.log_time, rgb)),
                Part::Mask(mask) => p.mask = Some(mask),
            }
        }
        // hand out complete frames from the front, and any left waiting too long
        let paired = self.mask_topic.is_some();
        while let Some(front) = self.pending.front() {
            let complete = front.image.is_some() && (!paired || front.mask.is_some());
            let stale = m.log_time.0.saturating_sub(front.first_seen.0) > PAIR_WAIT_NS;
            if !(complete || stale) {
                break;
            }
            if let Some(p) = self.pending.pop_front() {
                self.emit(p);
            }
        }
    }
}

impl Iterator for CameraFrames<'_> {
    type Item = Result<CameraFrame, LogError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(f) = self.ready.pop_front() {
                return Some(Ok(f));
            }
            if self.done {
                let p = self.pending.pop_front()?;
                self.emit(p);
                continue;
            }
            match self.stream.next() {
                Some(Ok(m)) => self.accept(&m),
                Some(Err(e)) => {
                    self.done = true;
                    self.pending.clear();
                    return Some(Err(e));
                }
                None => self.done = true,
            }
        }
    }
}

/// Up to `n` decoded images per topic of `topics`, evenly spread over the log: message `k` of
/// a topic with `count` messages (from the summary's statistics) is taken when `k` is a
/// multiple of `max(count / n, 1)`. Topics absent from the log give no images; messages that
/// do not decode are passed over (the main pass counts them).
pub fn spread(
    log: &SessionLog,
    topics: &[String],
    n: usize,
) -> Result<Vec<Vec<RgbImage>>, LogError> {
    let mut out: Vec<Vec<RgbImage>> = vec![Vec::new(); topics.len()];
    if n == 0 {
        return Ok(out);
    }
    let summary = log.summary();
    let counts: Vec<u64> = topics
        .iter()
        .map(|tp| {
            summary
                .statistics
                .as_ref()
                .zip(summary.channel(tp))
                .and_then(|(st, ch)| st.channel_message_counts.get(&ch.id).copied())
                .unwrap_or(0)
        })
        .collect();
    let present: Vec<&str> = topics
        .iter()
        .map(String::as_str)
        .filter(|tp| summary.channel(tp).is_some())
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
        let step = (counts[c] / n as u64).max(1);
        if !k.is_multiple_of(step) || out[c].len() >= n {
            continue;
        }
        if let Ok(img) = ImageMsg::read(&mut decoders, log, &m)
            && let Ok(rgb) = img.decode()
        {
            out[c].push(rgb);
        }
    }
    Ok(out)
}

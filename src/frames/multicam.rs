//! Several cameras grouped into frames by header stamp: images ([`ImageMsg`], decoded by the
//! caller, e.g. one camera per thread) or detection arrays (`vision_msgs/Detection2DArray`).
//!
//! **Grouping**: the topics' messages are read once, in log-time order. A frame is opened by
//! the first message after the previous frame closed and takes that message's stamp; it
//! closes when a message arrives whose stamp is more than the tolerance away from the frame's
//! stamp, or whose camera already has a message in the frame. A camera without a message in
//! a frame is `None` there. Stamps are header stamps, or log times where unset
//! ([`super::camera::stamp_of`]).
//!
//! Messages that do not decode as their type are skipped and counted in [`Skips`] (text: the
//! [`LogError`], naming file, topic and log time); they neither open nor close a frame.

use std::collections::VecDeque;

use super::camera::{ImageMsg, stamp_of};
use super::skips::Skips;
use crate::log::msgs::{Detection2DArray, Header};
use crate::log::{Decoders, LogError, Message, MessageStream, SessionLog};
use crate::time::Nanos;

/// A message type one camera contributes to a multi-camera frame.
pub trait CameraPayload: Sized {
    /// Read one message of a camera topic.
    fn read(dec: &mut Decoders, log: &SessionLog, m: &Message) -> Result<Self, LogError>;
    fn header(&self) -> &Header;
}

impl CameraPayload for ImageMsg {
    fn read(dec: &mut Decoders, log: &SessionLog, m: &Message) -> Result<Self, LogError> {
        ImageMsg::read(dec, log, m)
    }

    fn header(&self) -> &Header {
        ImageMsg::header(self)
    }
}

impl CameraPayload for Detection2DArray {
    fn read(dec: &mut Decoders, log: &SessionLog, m: &Message) -> Result<Self, LogError> {
        dec.typed::<Detection2DArray>(log, m)
    }

    fn header(&self) -> &Header {
        &self.header
    }
}

/// One multi-camera frame.
#[derive(Debug, Clone, PartialEq)]
pub struct MultiFrame<P> {
    /// The stamp of the frame's first message.
    pub stamp: Nanos,
    /// One entry per topic, in the order the topics were given.
    pub cameras: Vec<Option<P>>,
}

impl<P> MultiFrame<P> {
    /// Cameras without a message in this frame.
    pub fn missing(&self) -> usize {
        self.cameras.iter().filter(|c| c.is_none()).count()
    }
}

/// Iterator over multi-camera frames; see the module doc.
pub struct MultiFrames<'a, P> {
    log: &'a SessionLog,
    stream: MessageStream,
    decoders: Decoders,
    topics: Vec<String>,
    tolerance_ns: u64,
    open: Option<MultiFrame<P>>,
    ready: VecDeque<MultiFrame<P>>,
    skips: Skips,
    done: bool,
}

/// Group `topics` (one per camera, all in the log) into frames whose stamps lie within
/// `tolerance_ns` of the frame's first stamp.
pub fn group<'a, P: CameraPayload>(
    log: &'a SessionLog,
    topics: &[String],
    tolerance_ns: u64,
) -> Result<MultiFrames<'a, P>, LogError> {
    let list: Vec<&str> = topics.iter().map(String::as_str).collect();
    Ok(MultiFrames {
        log,
        stream: log.messages_on(&list)?,
        decoders: Decoders::new(),
        topics: topics.to_vec(),
        tolerance_ns,
        open: None,
        ready: VecDeque::new(),
        skips: Skips::new(),
        done: false,
    })
}

impl<P: CameraPayload> MultiFrames<'_, P> {
    /// Bad messages skipped so far.
    pub fn skips(&self) -> &Skips {
        &self.skips
    }

    pub fn into_skips(self) -> Skips {
        self.skips
    }

    fn accept(&mut self, m: &Message) {
        let Some(c) = self.topics.iter().position(|t| t == m.topic()) else {
            return;
        };
        let payload = match P::read(&mut self.decoders, self.log, m) {
            Ok(p) => p,
            Err(e) => {
                self.skips.note(m.topic(), e);
                return;
            }
        };
        let stamp = stamp_of(m, payload.header());
        if let Some(f) = &self.open
            && (stamp.abs_diff(f.stamp) > self.tolerance_ns || f.cameras[c].is_some())
            && let Some(f) = self.open.take()
        {
            self.ready.push_back(f);
        }
        let n = self.topics.len();
        let frame = self.open.get_or_insert_with(|| MultiFrame {
            stamp,
            cameras: (0..n).map(|_| None).collect(),
        });
        frame.cameras[c] = Some(payload);
    }
}

impl<P: CameraPayload> Iterator for MultiFrames<'_, P> {
    type Item = Result<MultiFrame<P>, LogError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(f) = self.ready.pop_front() {
                return Some(Ok(f));
            }
            if self.done {
                return self.open.take().map(Ok);
            }
            match self.stream.next() {
                Some(Ok(m)) => self.accept(&m),
                Some(Err(e)) => {
                    self.done = true;
                    self.open = None;
                    return Some(Err(e));
                }
                None => self.done = true,
            }
        }
    }
}

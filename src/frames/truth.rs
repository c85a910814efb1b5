//! Ground truth of synthetic sessions ([`crate::groundtruth`]): the people frames and the
//! calibration targets, read whole (they are small), sorted by their `stamp_ns` (ties keep log
//! order), with bad JSON messages skipped and counted. [`Stamped`] is the sorted series with
//! the nearest-stamp join ([`crate::log::sync::nearest`]: nearest stamp within the tolerance,
//! ties to the earlier one).

use super::skips::Skips;
use crate::groundtruth::biron::{AttentionState, BironFrame, UtterancesFrame};
use crate::groundtruth::{PeopleFrame, TargetsFrame};
use crate::log::fast::Decoded;
use crate::log::value::FieldError;
use crate::log::{Decoders, LogError, SessionLog, Value, sync};
use crate::time::Nanos;

/// Items sorted by stamp, with nearest-stamp lookups.
#[derive(Debug, Clone, PartialEq)]
pub struct Stamped<T> {
    stamps: Vec<Nanos>,
    items: Vec<T>,
}

impl<T> Default for Stamped<T> {
    fn default() -> Self {
        Stamped {
            stamps: Vec::new(),
            items: Vec::new(),
        }
    }
}

impl<T> Stamped<T> {
    /// Sort `(stamp, item)` pairs by stamp (stable: equal stamps keep their order).
    pub fn new(mut pairs: Vec<(Nanos, T)>) -> Self {
        pairs.sort_by_key(|p| p.0);
        let (stamps, items) = pairs.into_iter().unzip();
        Stamped { stamps, items }
    }

    /// The item whose stamp is nearest to `t`, if within `tolerance_ns` (ties: the earlier).
    pub fn nearest(&self, t: Nanos, tolerance_ns: u64) -> Option<&T> {
        sync::nearest(&self.stamps, t, tolerance_ns).map(|i| &self.items[i])
    }

    /// Like [`Self::nearest`], with the item's stamp.
    pub fn nearest_with_stamp(&self, t: Nanos, tolerance_ns: u64) -> Option<(Nanos, &T)> {
        sync::nearest(&self.stamps, t, tolerance_ns).map(|i| (self.stamps[i], &self.items[i]))
    }

    pub fn stamps(&self) -> &[Nanos] {
        &self.stamps
    }

    pub fn items(&self) -> &[T] {
        &self.items
    }

    pub fn len(&self) -> usize {
        self.items.len()
    }

    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    pub fn iter(&self) -> impl Iterator<Item = (Nanos, &T)> {
        self.stamps.iter().copied().zip(&self.items)
    }

    /// Drop every item (e.g. odometry of a camera that does not ride the robot).
    pub fn clear(&mut self) {
        self.stamps.clear();
        self.items.clear();
    }
}

/// Every JSON message of `topic` parsed as `T`, keyed by `stamp(&T)`, sorted. A topic absent
/// from the log gives an empty series; a message that does not parse is skipped and counted
/// (`<file>: topic <topic> at log time <s> s: <serde error>`).
fn read_json<T: serde::de::DeserializeOwned>(
    log: &SessionLog,
    topic: &str,
    stamp: impl Fn(&T) -> u64,
) -> Result<(Stamped<T>, Skips), LogError> {
    let mut pairs = Vec::new();
    let mut skips = Skips::new();
    if log.summary().channel(topic).is_none() {
        return Ok((Stamped::default(), skips));
    }
    for m in log.messages_on(&[topic])? {
        let m = m?;
        match serde_json::from_slice::<T>(&m.data) {
            Ok(f) => pairs.push((Nanos(stamp(&f)), f)),
            Err(e) => note_at(&mut skips, log, topic, m.log_time, e),
        }
    }
    Ok((Stamped::new(pairs), skips))
}

/// The people frames of `topic` (normally [`crate::groundtruth::PEOPLE_TOPIC`]).
pub fn people(log: &SessionLog, topic: &str) -> Result<(Stamped<PeopleFrame>, Skips), LogError> {
    read_json(log, topic, |f: &PeopleFrame| f.stamp_ns)
}

/// The BIRON ground truth of `topic` ([`crate::groundtruth::biron::BIRON_TOPIC`]).
pub fn biron(log: &SessionLog, topic: &str) -> Result<(Stamped<BironFrame>, Skips), LogError> {
    read_json(log, topic, |f: &BironFrame| f.stamp_ns)
}

/// The BIRON utterance lists of `topic` ([`crate::groundtruth::biron::UTTERANCES_TOPIC`]).
pub fn utterances(
    log: &SessionLog,
    topic: &str,
) -> Result<(Stamped<UtterancesFrame>, Skips), LogError> {
    read_json(log, topic, |f: &UtterancesFrame| f.stamp_ns)
}

/// A robot's logged attention states of `topic` ([`crate::groundtruth::biron::ATTENTION_TOPIC`]).
pub fn attention_states(
    log: &SessionLog,
    topic: &str,
) -> Result<(Stamped<AttentionState>, Skips), LogError> {
    read_json(log, topic, |f: &AttentionState| f.stamp_ns)
}

/// The calibration targets of `topic` (normally [`crate::groundtruth::TARGETS_TOPIC`]).
pub fn targets(log: &SessionLog, topic: &str) -> Result<(Stamped<TargetsFrame>, Skips), LogError> {
    read_json(log, topic, |f: &TargetsFrame| f.stamp_ns)
}

/// One person position of a `leg_tracker/msg/Person` message (Leigh et al.'s annotated
/// benchmark logs: `geometry_msgs/Pose pose` + `uint32 id`, no header; the position is in the
/// laser frame of the annotated scan). Decoded by the log's own schema, flat
/// ([`crate::log::cdr::flat`]: no tree per message).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PersonPosition {
    /// The message's log time: the annotated scan is the last scan logged before it.
    pub log_time: Nanos,
    pub id: i64,
    pub x: f64,
    pub y: f64,
}

/// Every message of `topic` read as a [`PersonPosition`], in log order. A topic absent from
/// the log gives no rows; a message without `pose.position.{x,y}` and `id`, or with a
/// non-finite position, is skipped and counted.
pub fn person_positions(
    log: &SessionLog,
    topic: &str,
) -> Result<(Vec<PersonPosition>, Skips), LogError> {
    let mut rows = Vec::new();
    let mut skips = Skips::new();
    if log.summary().channel(topic).is_none() {
        return Ok((rows, skips));
    }
    let mut decoders = Decoders::new();
    for m in log.messages_on(&[topic])? {
        let m = m?;
        let read = match decoders.decode(log, &m) {
            Ok(Decoded::Flat(f)) => person_fields(|path| f.get(path)),
            Ok(Decoded::Value(v)) => {
                person_fields(|path| path.split('.').try_fold(&v, |v, name| v.get(name)).cloned())
            }
            Ok(_) => Err(FieldError::new("a standard message type, not a Person")),
            Err(e) => {
                skips.note(topic, e);
                continue;
            }
        };
        match read {
            Ok((id, x, y)) if x.is_finite() && y.is_finite() => rows.push(PersonPosition {
                log_time: m.log_time,
                id,
                x,
                y,
            }),
            Ok(_) => note_at(&mut skips, log, topic, m.log_time, "non-finite position"),
            Err(e) => note_at(&mut skips, log, topic, m.log_time, e),
        }
    }
    Ok((rows, skips))
}

/// `(id, x, y)` of a Person message whose fields `get` reads by dotted path.
fn person_fields(
    get: impl Fn(&str) -> Result<Value, FieldError>,
) -> Result<(i64, f64, f64), FieldError> {
    let id = get("id")?.as_i128()?;
    let id = i64::try_from(id).map_err(|_| FieldError::new("id out of range"))?;
    Ok((
        id,
        get("pose.position.x")?.as_f64()?,
        get("pose.position.y")?.as_f64()?,
    ))
}

/// Count a bad message on `topic`, its text naming the file, topic and log time.
fn note_at(
    skips: &mut Skips,
    log: &SessionLog,
    topic: &str,
    log_time: Nanos,
    reason: impl std::fmt::Display,
) {
    skips.note(
        topic,
        format!(
            "{}: topic {topic} at log time {log_time} s: {reason}",
            log.path().display()
        ),
    );
}

//! Which decoder reads which channel, decided once per channel from its message and schema
//! encodings (the "plan" step of `inspect` and `run --dry-run`), then applied per message:
//!
//! | message encoding | schema encoding | decoder |
//! |---|---|---|
//! | `cdr` | `ros2msg` | [`super::cdr`] with the parsed [`Registry`] |
//! | `protobuf` | `protobuf` | [`super::protobuf`] with the embedded `FileDescriptorSet` |
//! | `json` | `jsonschema` or none | `serde_json` |
//!
//! Channels of the high-rate standard types whose schema has the canonical layout decode by
//! the typed fast paths of [`super::fast`] instead ([`Decoders::decode`], and
//! [`Decoders::typed`] for those types).
//!
//! Typed reads ([`Decoders::typed`]) check that the channel carries the requested type (by ROS
//! 2 name, or by one of its Foxglove equivalents) before converting.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use std::sync::Arc;

use prost_reflect::MessageDescriptor;

use super::cdr;
use super::cdr::flat::{Flat, Plan};
use super::error::{LogError, LogErrorKind};
use super::fast::{self, Decoded, FastKind, Scratch};
use super::msgs::RosMessage;
use super::protobuf::{self, FoxgloveMessage};
use super::reader::{ChannelInfo, Message, SessionLog};
use super::ros2msg::{Registry, normalize_type_name};
use super::value::Value;
use crate::time::Nanos;

/// How one channel's messages are decoded.
#[derive(Debug, Clone)]
pub enum Decoder {
    Cdr(Arc<Registry>),
    Protobuf(MessageDescriptor),
    Json,
}

impl Decoder {
    /// Choose and prepare the decoder for a channel (parses its schema once).
    pub fn for_channel(ch: &ChannelInfo) -> Result<Decoder, LogErrorKind> {
        let schema_encoding = ch.schema.as_deref().map_or("", |s| s.encoding.as_str());
        match (ch.message_encoding.as_str(), schema_encoding) {
            ("cdr", "ros2msg") => {
                let schema = ch.schema.as_deref().expect("ros2msg implies a schema");
                let text = String::from_utf8_lossy(&schema.data);
                let reg =
                    Registry::parse(&schema.name, &text).map_err(|error| LogErrorKind::Schema {
                        schema: schema.name.clone(),
                        error,
                    })?;
                Ok(Decoder::Cdr(Arc::new(reg)))
            }
            ("protobuf", "protobuf") => {
                let schema = ch.schema.as_deref().expect("protobuf implies a schema");
                protobuf::descriptor(&schema.name, &schema.data)
                    .map(Decoder::Protobuf)
                    .map_err(LogErrorKind::Protobuf)
            }
            ("json", "jsonschema" | "") => Ok(Decoder::Json),
            (m, s) => Err(LogErrorKind::UnsupportedEncoding {
                message_encoding: m.to_string(),
                schema_encoding: s.to_string(),
            }),
        }
    }

    /// Decode one payload into a value tree.
    pub fn decode(&self, data: &[u8]) -> Result<Value, LogErrorKind> {
        match self {
            Decoder::Cdr(reg) => Ok(cdr::decode(reg, data)?),
            Decoder::Protobuf(desc) => protobuf::decode(desc, data).map_err(LogErrorKind::Protobuf),
            Decoder::Json => serde_json::from_slice::<serde_json::Value>(data)
                .map(|j| Value::from_json(&j))
                .map_err(|e| LogErrorKind::Json(e.to_string())),
        }
    }

    /// A short description for `inspect`.
    pub fn describe(&self) -> &'static str {
        match self {
            Decoder::Cdr(_) => "ROS 2 CDR (dynamic)",
            Decoder::Protobuf(_) => "protobuf (dynamic)",
            Decoder::Json => "JSON",
        }
    }
}

/// True if a channel's schema names the ROS 2 type `type_name` (`pkg/Type` or `pkg/msg/Type`).
pub fn carries(ch: &ChannelInfo, type_name: &str) -> bool {
    normalize_type_name(ch.schema_name()).is_some_and(|n| n == type_name)
}

/// One channel's decoder and, for a standard type with the canonical layout, its fast path;
/// for the other CDR types, their flat plan.
#[derive(Debug)]
struct Entry {
    decoder: Result<Decoder, String>,
    fast: Option<FastKind>,
    flat: Option<Plan>,
}

impl Entry {
    fn new(ch: &ChannelInfo) -> Entry {
        let decoder = Decoder::for_channel(ch).map_err(|e| e.to_string());
        let (fast, flat) = match &decoder {
            Ok(Decoder::Cdr(reg)) => match FastKind::for_registry(reg) {
                Some(kind) => (Some(kind), None),
                None => (None, Plan::compile(reg)),
            },
            _ => (None, None),
        };
        Entry {
            decoder,
            fast,
            flat,
        }
    }

    /// A message of this channel as a value tree.
    fn tree(&self, msg: &Message) -> Result<Value, LogErrorKind> {
        match &self.decoder {
            Ok(dec) => dec.decode(&msg.data),
            // the parse error is stored as text so it can be reported for every message
            Err(reason) => Err(Decoder::for_channel(&msg.channel)
                .err()
                .unwrap_or(LogErrorKind::Protobuf(reason.clone()))),
        }
    }
}

/// A multiplicative hash of the channel id (Fibonacci hashing: the high bits, which the
/// table also reads, vary too): the map is looked up once per message, and its keys are a
/// log's channel ids, where a keyed hash buys nothing.
#[derive(Default)]
struct ChannelIdHasher(u64);

/// 2^64 / φ, odd.
const FIBONACCI: u64 = 0x9e37_79b9_7f4a_7c15;

impl Hasher for ChannelIdHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0.rotate_left(8) ^ u64::from(b)).wrapping_mul(FIBONACCI);
        }
    }
    fn write_u16(&mut self, v: u16) {
        self.0 = u64::from(v).wrapping_mul(FIBONACCI);
    }
}

/// Decoders per channel, built on first use. One per reading thread.
#[derive(Debug, Default)]
pub struct Decoders {
    by_channel: HashMap<u16, Entry, BuildHasherDefault<ChannelIdHasher>>,
    /// Reused buffers of [`Decoders::decode`]: the typed fast paths' and the flat decoder's.
    scratch: Scratch,
    flat: Flat,
    /// Float texts reused by [`Decoders::write_json`].
    floats: cdr::FloatText,
}

impl Decoders {
    pub fn new() -> Self {
        Self::default()
    }

    fn entry(&mut self, msg: &Message) -> &Entry {
        let ch = &msg.channel;
        self.by_channel
            .entry(ch.id)
            .or_insert_with(|| Entry::new(ch))
    }

    /// Decode a message into a value tree; errors name file, topic and log time.
    pub fn value(&mut self, log: &SessionLog, msg: &Message) -> Result<Value, LogError> {
        self.entry(msg).tree(msg).map_err(|k| {
            LogError::new(log.path(), k)
                .on_topic(msg.topic())
                .at(msg.log_time)
        })
    }

    /// Append a message's JSON rendering (the text of [`Value::json`]) to `out`: CDR channels
    /// straight from the wire bytes ([`cdr::write_json`], no value tree), the others through
    /// the value tree. Errors are the dynamic decoder's, naming file, topic and log time.
    pub fn write_json(
        &mut self,
        log: &SessionLog,
        msg: &Message,
        max_array: Option<usize>,
        out: &mut Vec<u8>,
    ) -> Result<(), LogError> {
        let mark = out.len();
        self.entry(msg);
        if let Some(Entry {
            decoder: Ok(Decoder::Cdr(reg)),
            ..
        }) = self.by_channel.get(&msg.channel.id)
        {
            if cdr::write_json(reg, &msg.data, max_array, &mut self.floats, out).is_ok() {
                return Ok(());
            }
            // the same walk as the dynamic decoder: let it report the error
            out.truncate(mark);
        }
        let v = self.value(log, msg)?;
        serde_json::to_writer(&mut *out, &v.json(max_array)).map_err(|e| {
            LogError::new(log.path(), LogErrorKind::Json(e.to_string()))
                .on_topic(msg.topic())
                .at(msg.log_time)
        })
    }

    /// Decode a message by its channel's typed fast path when it has one, else, for the other
    /// CDR types, flat by its compiled plan ([`cdr::flat`]), else into a value tree. The typed
    /// and flat forms borrow buffers reused from message to message (no allocation once they
    /// have grown); images, strings and packed arrays borrow their bytes from the payload. A
    /// payload the flat walk refuses is decoded to a tree, so its error names the field.
    pub fn decode<'s, 'm>(
        &'s mut self,
        log: &SessionLog,
        msg: &'m Message,
    ) -> Result<Decoded<'s, 'm>, LogError> {
        let err = |k: LogErrorKind| {
            LogError::new(log.path(), k)
                .on_topic(msg.topic())
                .at(msg.log_time)
        };
        self.entry(msg);
        let entry = &self.by_channel[&msg.channel.id];
        if let Some(kind) = entry.fast {
            return self
                .scratch
                .decode(kind, &msg.data)
                .map_err(|e| err(LogErrorKind::from(e)));
        }
        if let Some(plan) = &entry.flat
            && let Ok(r) = self.flat.decode(plan, &msg.data)
        {
            return Ok(Decoded::Flat(r));
        }
        entry.tree(msg).map(Decoded::Value).map_err(err)
    }

    /// Decode a message as the typed `T`, from its ROS 2 type or a Foxglove equivalent.
    pub fn typed<T: RosMessage + FoxgloveMessage + 'static>(
        &mut self,
        log: &SessionLog,
        msg: &Message,
    ) -> Result<T, LogError> {
        let ch = Arc::clone(&msg.channel);
        let err = |k: LogErrorKind| {
            LogError::new(log.path(), k)
                .on_topic(&ch.topic)
                .at(msg.log_time)
        };
        let schema = ch.schema_name().to_string();
        let is_ros = carries(&ch, T::TYPE_NAME);
        let is_foxglove = T::FOXGLOVE_NAMES.contains(&schema.as_str());
        if !is_ros && !is_foxglove {
            return Err(err(LogErrorKind::WrongType {
                expected: T::TYPE_NAME.to_string(),
                found: schema,
            }));
        }
        if let Some(kind) = self.entry(msg).fast.filter(|_| is_ros)
            && let Some(r) = fast::decode_as::<T>(kind, &msg.data)
        {
            return r.map_err(|e| err(e.into()));
        }
        let v = self.value(log, msg)?;
        let typed = if is_ros {
            T::from_value(v)
        } else {
            T::from_foxglove(&schema, v)
        };
        typed.map_err(|e| err(e.into()))
    }
}

/// Read every message of `topic` as `T`, in log-time order, as `(log_time, message)`.
pub fn read_topic<T: RosMessage + FoxgloveMessage + 'static>(
    log: &SessionLog,
    topic: &str,
) -> Result<impl Iterator<Item = Result<(Nanos, T), LogError>>, LogError> {
    let mut decoders = Decoders::new();
    let stream = log.messages_on(&[topic])?;
    Ok(stream.map(move |m| {
        let m = m?;
        decoders.typed::<T>(log, &m).map(|t| (m.log_time, t))
    }))
}

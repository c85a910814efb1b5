//! Writing sessions the way `ros2 bag record -s mcap` does: profile `ros2`, `ros2msg` schemas
//! with full definitions, little-endian CDR messages, zstd chunks with CRCs, a summary with
//! chunk and message indexes, plus metadata records (scenario, seed, tool version) and JSON
//! channels with a jsonschema for ground truth.
//!
//! Files are written to `<name>.tmp` beside the target and renamed into place by
//! [`SessionWriter::finish`]; a writer dropped before `finish` removes its temporary file, so
//! an interrupted run never leaves a half-written log under the real name. Compression runs on
//! the calling thread (zstd worker threads off), so the bytes do not depend on the machine.

use std::collections::{BTreeMap, HashMap};
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use mcap::records::MessageHeader;

use super::cdr::{self, Endian};
use super::definitions;
use super::error::{LogError, LogErrorKind};
use super::msgs::RosMessage;
use super::ros2msg::Registry;
use super::value::Value;
use crate::time::Nanos;

/// Chunk compression of written logs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Compression {
    Zstd,
    Lz4,
    None,
}

/// How to write a session.
#[derive(Debug, Clone)]
pub struct WriterOptions {
    pub compression: Compression,
    /// Target uncompressed chunk size in bytes.
    pub chunk_size: u64,
    /// Put messages in chunks (the usual layout) or straight into the data section.
    pub chunked: bool,
    /// Write the summary section (indexes, statistics). Off only to test readers.
    pub summary: bool,
}

impl Default for WriterOptions {
    fn default() -> Self {
        WriterOptions {
            compression: Compression::Zstd,
            chunk_size: 1 << 20,
            chunked: true,
            summary: true,
        }
    }
}

/// A channel added to a [`SessionWriter`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ChannelId(u16);

#[derive(Debug)]
enum ChannelKind {
    Ros2(Arc<Registry>, String),
    Json,
    Raw,
}

/// Writes one session log.
pub struct SessionWriter {
    path: PathBuf,
    tmp: PathBuf,
    inner: Option<mcap::Writer<BufWriter<File>>>,
    registries: HashMap<String, (u16, Arc<Registry>)>,
    channels: HashMap<u16, (ChannelKind, String, u32)>,
}

fn werr(path: &Path, e: impl std::fmt::Display) -> LogError {
    LogError::new(path, LogErrorKind::Write(e.to_string()))
}

/// An error of the `mcap` writer: its I/O errors as themselves (the system's text, e.g. a full
/// disk, which the `mcap` error's own text leaves out), others as text.
fn mcap_err(path: &Path, e: mcap::McapError) -> LogError {
    match e {
        mcap::McapError::Io(io) => LogError::new(path, io),
        other => werr(path, other),
    }
}

impl SessionWriter {
    /// Start writing `path` (through `path.tmp` until [`Self::finish`]).
    pub fn create(
        path: impl AsRef<Path>,
        options: &WriterOptions,
    ) -> Result<SessionWriter, LogError> {
        let path = path.as_ref().to_path_buf();
        let mut tmp = path.clone().into_os_string();
        tmp.push(".tmp");
        let tmp = PathBuf::from(tmp);
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| LogError::new(dir, e))?;
        }
        let file = File::create(&tmp).map_err(|e| LogError::new(&tmp, e))?;
        let compression = match options.compression {
            Compression::Zstd => Some(mcap::Compression::Zstd),
            Compression::Lz4 => Some(mcap::Compression::Lz4),
            Compression::None => None,
        };
        let opts = mcap::WriteOptions::new()
            .profile("ros2")
            .library(format!("peopletrack {}", env!("CARGO_PKG_VERSION")))
            .compression(compression)
            .compression_threads(0)
            .chunk_size(Some(options.chunk_size))
            .use_chunks(options.chunked)
            .emit_summary_records(options.summary)
            .emit_summary_offsets(options.summary)
            .emit_statistics(options.summary)
            .emit_chunk_indexes(options.summary)
            .emit_message_indexes(options.summary)
            .emit_metadata_indexes(options.summary)
            .emit_attachment_indexes(options.summary);
        let inner = mcap::Writer::with_options(BufWriter::with_capacity(1 << 20, file), opts)
            .map_err(|e| mcap_err(&tmp, e))?;
        Ok(SessionWriter {
            path,
            tmp,
            inner: Some(inner),
            registries: HashMap::new(),
            channels: HashMap::new(),
        })
    }

    fn writer(&mut self) -> &mut mcap::Writer<BufWriter<File>> {
        self.inner.as_mut().expect("writer present until finish")
    }

    /// Add a channel for a custom ROS 2 type given its full `ros2msg` definition text.
    pub fn add_ros2_dynamic(
        &mut self,
        topic: &str,
        type_name: &str,
        definition: &str,
    ) -> Result<ChannelId, LogError> {
        let (schema_id, registry) = match self.registries.get(type_name) {
            Some(x) => x.clone(),
            None => {
                let reg = Registry::parse(type_name, definition).map_err(|error| {
                    LogError::new(
                        &self.path,
                        LogErrorKind::Schema {
                            schema: type_name.to_string(),
                            error,
                        },
                    )
                })?;
                let id = self
                    .writer()
                    .add_schema(type_name, "ros2msg", definition.as_bytes())
                    .map_err(|e| mcap_err(&self.tmp, e))?;
                let entry = (id, Arc::new(reg));
                self.registries.insert(type_name.to_string(), entry.clone());
                entry
            }
        };
        let metadata = BTreeMap::from([("offered_qos_profiles".to_string(), String::new())]);
        let id = self
            .writer()
            .add_channel(schema_id, topic, "cdr", &metadata)
            .map_err(|e| mcap_err(&self.tmp, e))?;
        self.channels.insert(
            id,
            (
                ChannelKind::Ros2(registry, type_name.to_string()),
                topic.to_string(),
                0,
            ),
        );
        Ok(ChannelId(id))
    }

    /// Add a channel for a standard ROS 2 type (schema text from [`definitions`]).
    pub fn add_ros2<T: RosMessage>(&mut self, topic: &str) -> Result<ChannelId, LogError> {
        let text = definitions::full_definition(T::TYPE_NAME)
            .ok_or_else(|| werr(&self.path, format!("no definition for {}", T::TYPE_NAME)))?;
        self.add_ros2_dynamic(topic, T::TYPE_NAME, &text)
    }

    /// Add a JSON channel described by a JSON Schema.
    pub fn add_json(
        &mut self,
        topic: &str,
        schema_name: &str,
        json_schema: &str,
    ) -> Result<ChannelId, LogError> {
        let schema_id = self
            .writer()
            .add_schema(schema_name, "jsonschema", json_schema.as_bytes())
            .map_err(|e| mcap_err(&self.tmp, e))?;
        let id = self
            .writer()
            .add_channel(schema_id, topic, "json", &BTreeMap::new())
            .map_err(|e| mcap_err(&self.tmp, e))?;
        self.channels
            .insert(id, (ChannelKind::Json, topic.to_string(), 0));
        Ok(ChannelId(id))
    }

    /// Add a channel with any schema and encodings; messages are written as given bytes.
    pub fn add_raw(
        &mut self,
        topic: &str,
        schema: Option<(&str, &str, &[u8])>,
        message_encoding: &str,
    ) -> Result<ChannelId, LogError> {
        let schema_id = match schema {
            Some((name, encoding, data)) => self
                .writer()
                .add_schema(name, encoding, data)
                .map_err(|e| mcap_err(&self.tmp, e))?,
            None => 0,
        };
        let id = self
            .writer()
            .add_channel(schema_id, topic, message_encoding, &BTreeMap::new())
            .map_err(|e| mcap_err(&self.tmp, e))?;
        self.channels
            .insert(id, (ChannelKind::Raw, topic.to_string(), 0));
        Ok(ChannelId(id))
    }

    /// Write bytes to a channel; the publish time equals the log time.
    pub fn write_bytes(
        &mut self,
        ch: ChannelId,
        log_time: Nanos,
        data: &[u8],
    ) -> Result<(), LogError> {
        let (_, _, seq) = self
            .channels
            .get_mut(&ch.0)
            .ok_or_else(|| werr(&self.path, format!("unknown channel {}", ch.0)))?;
        *seq += 1;
        let header = MessageHeader {
            channel_id: ch.0,
            sequence: *seq,
            log_time: log_time.0,
            publish_time: log_time.0,
        };
        let tmp = self.tmp.clone();
        self.writer()
            .write_to_known_channel(&header, data)
            .map_err(|e| mcap_err(&tmp, e))
    }

    /// Encode a value tree as CDR on a ROS 2 channel.
    pub fn write_value(
        &mut self,
        ch: ChannelId,
        log_time: Nanos,
        value: &Value,
    ) -> Result<(), LogError> {
        let Some((ChannelKind::Ros2(reg, _), topic, _)) = self.channels.get(&ch.0) else {
            return Err(werr(
                &self.path,
                format!("channel {} is not a ROS 2 channel", ch.0),
            ));
        };
        let bytes = cdr::encode(reg, value, Endian::Little)
            .map_err(|e| LogError::new(&self.path, e).on_topic(topic).at(log_time))?;
        self.write_bytes(ch, log_time, &bytes)
    }

    /// Write a typed message.
    pub fn write<T: RosMessage>(
        &mut self,
        ch: ChannelId,
        log_time: Nanos,
        msg: &T,
    ) -> Result<(), LogError> {
        if let Some((ChannelKind::Ros2(_, name), topic, _)) = self.channels.get(&ch.0)
            && name != T::TYPE_NAME
        {
            return Err(LogError::new(
                &self.path,
                LogErrorKind::WrongType {
                    expected: name.clone(),
                    found: T::TYPE_NAME.to_string(),
                },
            )
            .on_topic(topic));
        }
        self.write_value(ch, log_time, &msg.to_value())
    }

    /// Write a serialisable value on a JSON channel.
    pub fn write_json<S: serde::Serialize>(
        &mut self,
        ch: ChannelId,
        log_time: Nanos,
        msg: &S,
    ) -> Result<(), LogError> {
        if !matches!(self.channels.get(&ch.0), Some((ChannelKind::Json, ..))) {
            return Err(werr(
                &self.path,
                format!("channel {} is not a JSON channel", ch.0),
            ));
        }
        let bytes = serde_json::to_vec(msg).map_err(|e| werr(&self.path, e))?;
        self.write_bytes(ch, log_time, &bytes)
    }

    /// Add a metadata record.
    pub fn metadata(
        &mut self,
        name: &str,
        entries: BTreeMap<String, String>,
    ) -> Result<(), LogError> {
        let tmp = self.tmp.clone();
        self.writer()
            .write_metadata(&mcap::records::Metadata {
                name: name.to_string(),
                metadata: entries,
            })
            .map_err(|e| mcap_err(&tmp, e))
    }

    /// Finish the file and move it to its final name.
    pub fn finish(mut self) -> Result<PathBuf, LogError> {
        let mut inner = self.inner.take().expect("finish is called once");
        inner.finish().map_err(|e| mcap_err(&self.tmp, e))?;
        let buf = inner.into_inner();
        let file = buf.into_inner().map_err(|e| werr(&self.tmp, e.error()))?;
        file.sync_all().map_err(|e| LogError::new(&self.tmp, e))?;
        drop(file);
        std::fs::rename(&self.tmp, &self.path).map_err(|e| LogError::new(&self.path, e))?;
        Ok(self.path.clone())
    }
}

impl Drop for SessionWriter {
    fn drop(&mut self) {
        if self.inner.take().is_some() {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

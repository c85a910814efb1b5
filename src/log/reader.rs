//! Streaming MCAP reading in log-time order with bounded memory.
//!
//! Opening a log reads only its index: the summary section when the file has one (schemas,
//! channels, statistics, chunk indexes, metadata), otherwise one linear pass that decompresses
//! each chunk once to learn its channels, time range and message count (files from a recorder
//! that crashed before writing the summary). Reading messages then k-way merges chunks by log
//! time: a chunk is decompressed only when the merge reaches its start time, and freed when its
//! last message is yielded, so memory holds the chunks that overlap in time — not the file.
//! Equal log times keep file order, so the order is deterministic.
//!
//! Every record is parsed here with explicit bounds checks (not through `binrw`), so a corrupt
//! length can give an error but never a huge allocation or a panic. Chunk CRCs are verified when
//! the writer stored one (rosbags writes 0 = not computed). Files whose messages sit outside
//! chunks are read in file order and must already be time-ordered (checked).

use std::cmp::Reverse;
use std::collections::{BTreeMap, BTreeSet, BinaryHeap};
use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::ops::Deref;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::error::{LogError, LogErrorKind};
use crate::time::Nanos;

const MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";

mod op {
    pub const HEADER: u8 = 0x01;
    pub const FOOTER: u8 = 0x02;
    pub const SCHEMA: u8 = 0x03;
    pub const CHANNEL: u8 = 0x04;
    pub const MESSAGE: u8 = 0x05;
    pub const CHUNK: u8 = 0x06;
    pub const CHUNK_INDEX: u8 = 0x08;
    pub const STATISTICS: u8 = 0x0B;
    pub const METADATA: u8 = 0x0C;
    pub const METADATA_INDEX: u8 = 0x0D;
}

/// Largest decompressed chunk we accept (a corrupt size field must not exhaust memory).
const MAX_CHUNK_BYTES: u64 = 1 << 31;

/// A schema record.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SchemaInfo {
    pub id: u16,
    pub name: String,
    pub encoding: String,
    pub data: Vec<u8>,
}

/// A channel record with its schema resolved.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChannelInfo {
    pub id: u16,
    pub topic: String,
    pub message_encoding: String,
    pub metadata: BTreeMap<String, String>,
    pub schema: Option<Arc<SchemaInfo>>,
}

impl ChannelInfo {
    pub fn schema_name(&self) -> &str {
        self.schema.as_deref().map_or("", |s| s.name.as_str())
    }
}

/// A metadata record (`name` plus string pairs).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MetadataRecord {
    pub name: String,
    pub entries: BTreeMap<String, String>,
}

/// Where a chunk is and what it holds.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChunkInfo {
    /// Offset of the chunk record (its opcode byte).
    pub offset: u64,
    /// Length of the whole record, opcode and length prefix included.
    pub length: u64,
    pub start: Nanos,
    pub end: Nanos,
    pub compression: String,
    /// Channel ids with messages in the chunk, when the index says so.
    pub channels: Option<BTreeSet<u16>>,
}

/// Message counts and time span.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Statistics {
    pub message_count: u64,
    pub start: Nanos,
    pub end: Nanos,
    pub channel_message_counts: BTreeMap<u16, u64>,
}

/// What opening a log learned without reading its messages.
#[derive(Debug, Clone, Default)]
pub struct LogSummary {
    pub profile: String,
    pub library: String,
    pub schemas: BTreeMap<u16, Arc<SchemaInfo>>,
    pub channels: BTreeMap<u16, Arc<ChannelInfo>>,
    pub chunks: Vec<ChunkInfo>,
    pub statistics: Option<Statistics>,
    pub metadata: Vec<MetadataRecord>,
    /// True if the index came from the file's summary section (false: built by a linear pass).
    pub from_summary_section: bool,
    /// True if some messages are stored outside chunks.
    pub unchunked_messages: bool,
    pub file_len: u64,
}

impl LogSummary {
    /// The channel of a topic (the first, if a topic has several channels).
    pub fn channel(&self, topic: &str) -> Option<&Arc<ChannelInfo>> {
        self.channels.values().find(|c| c.topic == topic)
    }

    /// Topics in channel-id order, without repeats.
    pub fn topics(&self) -> Vec<&str> {
        let mut seen = BTreeSet::new();
        self.channels
            .values()
            .filter(|c| seen.insert(c.topic.as_str()))
            .map(|c| c.topic.as_str())
            .collect()
    }
}

/// An open session log. Cheap to share; each [`SessionLog::messages`] call opens its own
/// file handle.
#[derive(Debug, Clone)]
pub struct SessionLog {
    path: PathBuf,
    summary: LogSummary,
}

/// Message bytes, borrowed from a decompressed chunk kept alive by reference counting.
#[derive(Clone)]
pub struct Payload {
    buf: Arc<Vec<u8>>,
    start: usize,
    end: usize,
}

impl Deref for Payload {
    type Target = [u8];
    fn deref(&self) -> &[u8] {
        &self.buf[self.start..self.end]
    }
}

impl std::fmt::Debug for Payload {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Payload({} bytes)", self.end - self.start)
    }
}

/// One message.
#[derive(Debug, Clone)]
pub struct Message {
    pub channel: Arc<ChannelInfo>,
    pub sequence: u32,
    pub log_time: Nanos,
    pub publish_time: Nanos,
    pub data: Payload,
}

impl Message {
    pub fn topic(&self) -> &str {
        &self.channel.topic
    }
}

// ---------------------------------------------------------------------------------------------
// Record parsing

/// A bounds-checked little-endian cursor over one record body.
struct Cursor<'a> {
    buf: &'a [u8],
    pos: usize,
}

impl<'a> Cursor<'a> {
    fn new(buf: &'a [u8]) -> Self {
        Cursor { buf, pos: 0 }
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        if n > self.buf.len() - self.pos {
            return Err(format!(
                "field at body byte {} needs {n} bytes, {} left",
                self.pos,
                self.buf.len() - self.pos
            ));
        }
        let s = &self.buf[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    fn u16(&mut self) -> Result<u16, String> {
        Ok(u16::from_le_bytes(
            self.take(2)?.try_into().expect("2 bytes"),
        ))
    }
    fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes(
            self.take(4)?.try_into().expect("4 bytes"),
        ))
    }
    fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from_le_bytes(
            self.take(8)?.try_into().expect("8 bytes"),
        ))
    }
    fn prefixed(&mut self) -> Result<&'a [u8], String> {
        let n = self.u32()? as usize;
        self.take(n)
    }
    fn string(&mut self) -> Result<String, String> {
        let b = self.prefixed()?;
        String::from_utf8(b.to_vec()).map_err(|_| "string is not UTF-8".to_string())
    }
    fn string_map(&mut self) -> Result<BTreeMap<String, String>, String> {
        let mut inner = Cursor::new(self.prefixed()?);
        let mut out = BTreeMap::new();
        while inner.pos < inner.buf.len() {
            let k = inner.string()?;
            let v = inner.string()?;
            out.insert(k, v);
        }
        Ok(out)
    }
    fn u16_u64_map(&mut self) -> Result<BTreeMap<u16, u64>, String> {
        let mut inner = Cursor::new(self.prefixed()?);
        let mut out = BTreeMap::new();
        while inner.pos < inner.buf.len() {
            let k = inner.u16()?;
            let v = inner.u64()?;
            out.insert(k, v);
        }
        Ok(out)
    }
    fn rest(&mut self) -> &'a [u8] {
        let s = &self.buf[self.pos..];
        self.pos = self.buf.len();
        s
    }
}

fn bad(record: &'static str, offset: u64) -> impl Fn(String) -> LogErrorKind {
    move |reason| LogErrorKind::BadRecord {
        record,
        offset,
        reason,
    }
}

fn parse_schema(body: &[u8]) -> Result<SchemaInfo, String> {
    let mut c = Cursor::new(body);
    Ok(SchemaInfo {
        id: c.u16()?,
        name: c.string()?,
        encoding: c.string()?,
        data: c.prefixed()?.to_vec(),
    })
}

struct RawChannel {
    id: u16,
    schema_id: u16,
    topic: String,
    message_encoding: String,
    metadata: BTreeMap<String, String>,
}

fn parse_channel(body: &[u8]) -> Result<RawChannel, String> {
    let mut c = Cursor::new(body);
    Ok(RawChannel {
        id: c.u16()?,
        schema_id: c.u16()?,
        topic: c.string()?,
        message_encoding: c.string()?,
        metadata: c.string_map()?,
    })
}

struct MessageHeader {
    channel: u16,
    sequence: u32,
    log_time: u64,
    publish_time: u64,
}

const MESSAGE_HEADER_LEN: usize = 22;

fn parse_message_header(body: &[u8]) -> Result<MessageHeader, String> {
    let mut c = Cursor::new(body);
    Ok(MessageHeader {
        channel: c.u16()?,
        sequence: c.u32()?,
        log_time: c.u64()?,
        publish_time: c.u64()?,
    })
}

struct ChunkHeader<'a> {
    start: u64,
    end: u64,
    uncompressed_size: u64,
    crc: u32,
    compression: String,
    records: &'a [u8],
}

fn parse_chunk(body: &[u8]) -> Result<ChunkHeader<'_>, String> {
    let mut c = Cursor::new(body);
    let start = c.u64()?;
    let end = c.u64()?;
    let uncompressed_size = c.u64()?;
    let crc = c.u32()?;
    let compression = c.string()?;
    let records_len = c.u64()?;
    let records = c.rest();
    if records_len != records.len() as u64 {
        return Err(format!(
            "records length field says {records_len} bytes, the record holds {}",
            records.len()
        ));
    }
    Ok(ChunkHeader {
        start,
        end,
        uncompressed_size,
        crc,
        compression,
        records,
    })
}

fn parse_chunk_index(body: &[u8]) -> Result<ChunkInfo, String> {
    let mut c = Cursor::new(body);
    let start = c.u64()?;
    let end = c.u64()?;
    let offset = c.u64()?;
    let length = c.u64()?;
    let index_offsets = c.u16_u64_map()?;
    let _message_index_length = c.u64()?;
    let compression = c.string()?;
    Ok(ChunkInfo {
        offset,
        length,
        start: Nanos(start),
        end: Nanos(end),
        compression,
        channels: (!index_offsets.is_empty()).then(|| index_offsets.keys().copied().collect()),
    })
}

fn parse_statistics(body: &[u8]) -> Result<Statistics, String> {
    let mut c = Cursor::new(body);
    let message_count = c.u64()?;
    let _schema_count = c.u16()?;
    let _channel_count = c.u32()?;
    let _attachment_count = c.u32()?;
    let _metadata_count = c.u32()?;
    let _chunk_count = c.u32()?;
    let start = c.u64()?;
    let end = c.u64()?;
    Ok(Statistics {
        message_count,
        start: Nanos(start),
        end: Nanos(end),
        channel_message_counts: c.u16_u64_map()?,
    })
}

fn parse_metadata(body: &[u8]) -> Result<MetadataRecord, String> {
    let mut c = Cursor::new(body);
    Ok(MetadataRecord {
        name: c.string()?,
        entries: c.string_map()?,
    })
}

/// Iterate `(opcode, body, offset_in_buf)` over a buffer of concatenated records.
fn records(buf: &[u8]) -> impl Iterator<Item = Result<(u8, &[u8], usize), String>> {
    let mut pos = 0usize;
    std::iter::from_fn(move || {
        if pos >= buf.len() {
            return None;
        }
        if buf.len() - pos < 9 {
            pos = buf.len();
            return Some(Err(format!(
                "record header at chunk byte {pos} is cut short"
            )));
        }
        let opcode = buf[pos];
        let len = u64::from_le_bytes(buf[pos + 1..pos + 9].try_into().expect("8 bytes"));
        let body_start = pos + 9;
        if len > (buf.len() - body_start) as u64 {
            let at = pos;
            pos = buf.len();
            return Some(Err(format!(
                "record at chunk byte {at} claims {len} bytes, {} left",
                buf.len() - body_start
            )));
        }
        let end = body_start + len as usize;
        let item = (opcode, &buf[body_start..end], pos);
        pos = end;
        Some(Ok(item))
    })
}

// ---------------------------------------------------------------------------------------------
// Opening

impl SessionLog {
    /// Open a log and read its index (summary section, or one linear pass without one).
    pub fn open(path: impl AsRef<Path>) -> Result<SessionLog, LogError> {
        let path = path.as_ref().to_path_buf();
        let err = |k: LogErrorKind| LogError::new(&path, k);
        let mut file = File::open(&path).map_err(|e| err(e.into()))?;
        let file_len = file.metadata().map_err(|e| err(e.into()))?.len();
        let mut magic = [0u8; 8];
        if file_len < 8 || file.read_exact(&mut magic).is_err() || &magic != MAGIC {
            return Err(err(LogErrorKind::NotMcap));
        }
        let summary = match read_summary_section(&mut file, file_len).map_err(err)? {
            Some(s) if summary_is_complete(&s) => s,
            _ => linear_index(&mut file, file_len).map_err(err)?,
        };
        Ok(SessionLog { path, summary })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    pub fn summary(&self) -> &LogSummary {
        &self.summary
    }

    /// Every message, in log-time order.
    pub fn messages(&self) -> Result<MessageStream, LogError> {
        self.stream(None)
    }

    /// Messages of the named topics, in log-time order. A topic absent from the log is an
    /// error (a typo must not give an empty result).
    pub fn messages_on(&self, topics: &[&str]) -> Result<MessageStream, LogError> {
        for t in topics {
            if self.summary.channel(t).is_none() {
                return Err(LogError::new(
                    &self.path,
                    LogErrorKind::MissingTopic((*t).to_string()),
                )
                .on_topic(t));
            }
        }
        self.stream(Some(topics.iter().map(|t| (*t).to_string()).collect()))
    }

    fn stream(&self, topics: Option<BTreeSet<String>>) -> Result<MessageStream, LogError> {
        let mut file = File::open(&self.path).map_err(|e| LogError::new(&self.path, e))?;
        file.seek(SeekFrom::Start(8))
            .map_err(|e| LogError::new(&self.path, e))?;
        let s = &self.summary;
        let mode = if s.unchunked_messages {
            Mode::Linear {
                reader: BufReader::with_capacity(1 << 16, file),
                pos: 8,
                current: None,
            }
        } else {
            let mut pending: Vec<ChunkInfo> = s
                .chunks
                .iter()
                .filter(|c| match (&topics, &c.channels) {
                    (Some(want), Some(chs)) => chs.iter().any(|id| {
                        s.channels
                            .get(id)
                            .is_some_and(|ch| want.contains(&ch.topic))
                    }),
                    _ => true,
                })
                .cloned()
                .collect();
            pending.sort_by_key(|c| (c.start, c.offset));
            pending.reverse(); // pop from the back
            Mode::Indexed {
                file,
                pending,
                slots: Vec::new(),
                heap: BinaryHeap::new(),
            }
        };
        Ok(MessageStream {
            path: self.path.clone(),
            schemas: s.schemas.clone(),
            channels: s.channels.clone(),
            topics,
            file_len: s.file_len,
            mode,
            last_time: None,
            done: false,
        })
    }
}

/// A summary is usable if it indexes the chunks, or says the messages are outside chunks (read
/// in file order), or says there are none. Without statistics and chunk indexes it tells too
/// little, and the index is rebuilt by a linear pass.
fn summary_is_complete(s: &LogSummary) -> bool {
    s.unchunked_messages
        || !s.chunks.is_empty()
        || s.statistics
            .as_ref()
            .is_some_and(|st| st.message_count == 0)
}

fn read_at(
    file: &mut File,
    offset: u64,
    len: u64,
    file_len: u64,
    what: &'static str,
) -> Result<Vec<u8>, LogErrorKind> {
    if offset.checked_add(len).is_none_or(|end| end > file_len) {
        return Err(LogErrorKind::Truncated {
            what,
            offset,
            needed: len,
            file_len,
            last: None,
        });
    }
    file.seek(SeekFrom::Start(offset))?;
    let mut buf = vec![0u8; len as usize];
    file.read_exact(&mut buf)?;
    Ok(buf)
}

/// Read the summary section through the footer. `None` if the file has no (valid) footer or
/// no summary section.
fn read_summary_section(
    file: &mut File,
    file_len: u64,
) -> Result<Option<LogSummary>, LogErrorKind> {
    const FOOTER_RECORD_LEN: u64 = 1 + 8 + 20;
    if file_len < 8 + FOOTER_RECORD_LEN + 8 {
        return Ok(None);
    }
    let footer_offset = file_len - 8 - FOOTER_RECORD_LEN;
    let tail = read_at(
        file,
        footer_offset,
        FOOTER_RECORD_LEN + 8,
        file_len,
        "footer",
    )?;
    if &tail[FOOTER_RECORD_LEN as usize..] != MAGIC || tail[0] != op::FOOTER {
        return Ok(None);
    }
    let mut c = Cursor::new(&tail[9..]);
    let (summary_start, _summary_offset_start, summary_crc) = match (c.u64(), c.u64(), c.u32()) {
        (Ok(a), Ok(b), Ok(crc)) => (a, b, crc),
        _ => return Ok(None),
    };
    if summary_start == 0 || summary_start >= footer_offset || summary_start < 8 {
        return Ok(None);
    }
    let section = read_at(
        file,
        summary_start,
        footer_offset - summary_start,
        file_len,
        "summary section",
    )?;
    if summary_crc != 0 {
        let mut h = crc32fast::Hasher::new();
        h.update(&section);
        h.update(&tail[..FOOTER_RECORD_LEN as usize - 4]);
        let computed = h.finalize();
        if computed != summary_crc {
            return Err(LogErrorKind::SummaryCrc {
                stored: summary_crc,
                computed,
            });
        }
    }
    let mut summary = LogSummary {
        from_summary_section: true,
        file_len,
        ..LogSummary::default()
    };
    let mut raw_channels = Vec::new();
    let mut metadata_offsets = Vec::new();
    for rec in records(&section) {
        let (opcode, body, at) = rec.map_err(bad("summary", summary_start))?;
        let at = summary_start + at as u64;
        match opcode {
            op::SCHEMA => {
                let s = parse_schema(body).map_err(bad("schema", at))?;
                summary.schemas.insert(s.id, Arc::new(s));
            }
            op::CHANNEL => raw_channels.push(parse_channel(body).map_err(bad("channel", at))?),
            op::CHUNK_INDEX => summary
                .chunks
                .push(parse_chunk_index(body).map_err(bad("chunk index", at))?),
            op::STATISTICS => {
                summary.statistics = Some(parse_statistics(body).map_err(bad("statistics", at))?)
            }
            op::METADATA_INDEX => {
                let mut c = Cursor::new(body);
                let (off, len) = (c.u64(), c.u64());
                if let (Ok(off), Ok(len)) = (off, len) {
                    metadata_offsets.push((off, len));
                }
            }
            _ => {}
        }
    }
    for rc in raw_channels {
        add_channel(&mut summary.channels, &summary.schemas, rc);
    }
    for (off, len) in metadata_offsets {
        let rec = read_at(file, off, len, file_len, "metadata record")?;
        if rec.len() >= 9 && rec[0] == op::METADATA {
            summary
                .metadata
                .push(parse_metadata(&rec[9..]).map_err(bad("metadata", off))?);
        }
    }
    // Header record right after the magic.
    let head = read_at(file, 8, 9, file_len, "header record")?;
    if head[0] == op::HEADER {
        let len = u64::from_le_bytes(head[1..9].try_into().expect("8 bytes"));
        let body = read_at(file, 17, len, file_len, "header record")?;
        let mut c = Cursor::new(&body);
        summary.profile = c.string().unwrap_or_default();
        summary.library = c.string().unwrap_or_default();
    }
    if let Some(st) = &summary.statistics
        && st.message_count > 0
        && summary.chunks.is_empty()
    {
        summary.unchunked_messages = true;
    }
    Ok(Some(summary))
}

fn add_channel(
    channels: &mut BTreeMap<u16, Arc<ChannelInfo>>,
    schemas: &BTreeMap<u16, Arc<SchemaInfo>>,
    rc: RawChannel,
) {
    channels.entry(rc.id).or_insert_with(|| {
        Arc::new(ChannelInfo {
            id: rc.id,
            topic: rc.topic,
            message_encoding: rc.message_encoding,
            metadata: rc.metadata,
            schema: schemas.get(&rc.schema_id).cloned(),
        })
    });
}

/// Decompress a chunk record body (as read from `offset`) and verify its CRC.
fn open_chunk(
    body: &[u8],
    offset: u64,
    channels: &BTreeMap<u16, Arc<ChannelInfo>>,
    ids: Option<&BTreeSet<u16>>,
) -> Result<(Nanos, Nanos, String, Vec<u8>), LogErrorKind> {
    let h = parse_chunk(body).map_err(bad("chunk", offset))?;
    let topics = || match ids {
        Some(ids) => ids
            .iter()
            .filter_map(|id| channels.get(id).map(|c| c.topic.clone()))
            .collect::<Vec<_>>()
            .join(", "),
        None => "unknown topics".to_string(),
    };
    if h.uncompressed_size > MAX_CHUNK_BYTES {
        return Err(LogErrorKind::BadRecord {
            record: "chunk",
            offset,
            reason: format!(
                "uncompressed size {} exceeds the {} byte limit",
                h.uncompressed_size, MAX_CHUNK_BYTES
            ),
        });
    }
    let want = h.uncompressed_size;
    let fail = |reason: String| LogErrorKind::Decompress {
        offset,
        start: Nanos(h.start),
        end: Nanos(h.end),
        topics: topics(),
        compression: h.compression.clone(),
        reason,
    };
    let data = match h.compression.as_str() {
        "" => h.records.to_vec(),
        // Sizes up to 256 MiB are trusted enough to allocate up front and decompress in one
        // call; larger claims stream, so a corrupt size cannot reserve gigabytes.
        "zstd" if want <= 1 << 28 => {
            let mut out = Vec::with_capacity(want as usize);
            zstd::bulk::Decompressor::new()
                .and_then(|mut d| d.decompress_to_buffer(h.records, &mut out))
                .map_err(|e| fail(e.to_string()))?;
            out
        }
        "zstd" => {
            let mut out = Vec::new();
            zstd::stream::read::Decoder::new(h.records)
                .and_then(|d| d.take(want + 1).read_to_end(&mut out))
                .map_err(|e| fail(e.to_string()))?;
            out
        }
        "lz4" => {
            let mut out = Vec::new();
            lz4::Decoder::new(h.records)
                .and_then(|d| d.take(want + 1).read_to_end(&mut out))
                .map_err(|e| fail(e.to_string()))?;
            out
        }
        other => {
            return Err(LogErrorKind::UnsupportedCompression {
                offset,
                compression: other.to_string(),
            });
        }
    };
    if data.len() as u64 != want {
        return Err(fail(format!(
            "gave {} bytes, the header says {want}",
            data.len()
        )));
    }
    if h.crc != 0 {
        let computed = crc32fast::hash(&data);
        if computed != h.crc {
            return Err(LogErrorKind::ChunkCrc {
                offset,
                start: Nanos(h.start),
                end: Nanos(h.end),
                topics: topics(),
                stored: h.crc,
                computed,
            });
        }
    }
    Ok((Nanos(h.start), Nanos(h.end), h.compression, data))
}

/// Build the index by reading the file front to back (no usable summary section).
fn linear_index(file: &mut File, file_len: u64) -> Result<LogSummary, LogErrorKind> {
    let mut summary = LogSummary {
        file_len,
        ..LogSummary::default()
    };
    let mut stats = Statistics::default();
    let mut first = true;
    let mut last: Option<(u16, Nanos)> = None;
    let mut reader = BufReader::with_capacity(1 << 16, &mut *file);
    reader.seek(SeekFrom::Start(8))?;
    let mut pos = 8u64;
    let mut previous_top_level: Option<Nanos> = None;
    let mut count = |ch: u16, t: Nanos, last: &mut Option<(u16, Nanos)>| {
        stats.message_count += 1;
        *stats.channel_message_counts.entry(ch).or_insert(0) += 1;
        if first || t < stats.start {
            stats.start = t;
        }
        if first || t > stats.end {
            stats.end = t;
        }
        first = false;
        if last.is_none_or(|(_, lt)| t >= lt) {
            *last = Some((ch, t));
        }
    };
    loop {
        let last_named = |channels: &BTreeMap<u16, Arc<ChannelInfo>>| {
            last.and_then(|(ch, t)| channels.get(&ch).map(|c| (c.topic.clone(), t)))
        };
        if pos + 9 > file_len {
            return Err(LogErrorKind::Truncated {
                what: if pos == file_len {
                    "footer record"
                } else {
                    "record header"
                },
                offset: pos,
                needed: 9,
                file_len,
                last: last_named(&summary.channels),
            });
        }
        let mut head = [0u8; 9];
        reader.read_exact(&mut head)?;
        let opcode = head[0];
        let len = u64::from_le_bytes(head[1..9].try_into().expect("8 bytes"));
        if len > file_len - pos - 9 {
            return Err(LogErrorKind::Truncated {
                what: record_name(opcode),
                offset: pos,
                needed: len.saturating_add(9),
                file_len,
                last: last_named(&summary.channels),
            });
        }
        let needs_body = matches!(
            opcode,
            op::HEADER | op::SCHEMA | op::CHANNEL | op::MESSAGE | op::CHUNK | op::METADATA
        );
        if !needs_body {
            if opcode == op::FOOTER {
                // a complete file ends with the footer and the closing magic
                let end = pos + 9 + len;
                let mut tail = Vec::new();
                reader.seek_relative(len as i64)?;
                reader.take(8).read_to_end(&mut tail)?;
                if tail.as_slice() != MAGIC {
                    return Err(LogErrorKind::Truncated {
                        what: "closing magic",
                        offset: end,
                        needed: 8,
                        file_len,
                        last: last_named(&summary.channels),
                    });
                }
                break;
            }
            reader.seek_relative(len as i64)?;
            pos += 9 + len;
            continue;
        }
        let mut body = vec![0u8; len as usize];
        reader.read_exact(&mut body)?;
        match opcode {
            op::HEADER => {
                let mut c = Cursor::new(&body);
                summary.profile = c.string().map_err(bad("header", pos))?;
                summary.library = c.string().map_err(bad("header", pos))?;
            }
            op::SCHEMA => {
                let s = parse_schema(&body).map_err(bad("schema", pos))?;
                summary.schemas.entry(s.id).or_insert_with(|| Arc::new(s));
            }
            op::CHANNEL => {
                let rc = parse_channel(&body).map_err(bad("channel", pos))?;
                add_channel(&mut summary.channels, &summary.schemas, rc);
            }
            op::METADATA => summary
                .metadata
                .push(parse_metadata(&body).map_err(bad("metadata", pos))?),
            op::MESSAGE => {
                let h = parse_message_header(&body).map_err(bad("message", pos))?;
                summary.unchunked_messages = true;
                let t = Nanos(h.log_time);
                if previous_top_level.is_some_and(|p| t < p) {
                    // linear reading would fail later; learn it now
                    return Err(LogErrorKind::NotTimeOrdered {
                        previous: previous_top_level.unwrap_or_default(),
                        this: t,
                    });
                }
                previous_top_level = Some(t);
                count(h.channel, t, &mut last);
            }
            op::CHUNK => {
                let (start, end, compression, data) =
                    open_chunk(&body, pos, &summary.channels, None)?;
                let mut ids = BTreeSet::new();
                for rec in records(&data) {
                    let (op_in, b, _) = rec.map_err(bad("chunk", pos))?;
                    match op_in {
                        op::SCHEMA => {
                            let s = parse_schema(b).map_err(bad("schema in chunk", pos))?;
                            summary.schemas.entry(s.id).or_insert_with(|| Arc::new(s));
                        }
                        op::CHANNEL => {
                            let rc = parse_channel(b).map_err(bad("channel in chunk", pos))?;
                            add_channel(&mut summary.channels, &summary.schemas, rc);
                        }
                        op::MESSAGE => {
                            let h =
                                parse_message_header(b).map_err(bad("message in chunk", pos))?;
                            ids.insert(h.channel);
                            count(h.channel, Nanos(h.log_time), &mut last);
                        }
                        _ => {}
                    }
                }
                summary.chunks.push(ChunkInfo {
                    offset: pos,
                    length: 9 + len,
                    start,
                    end,
                    compression,
                    channels: Some(ids),
                });
            }
            _ => unreachable!("needs_body covers these opcodes"),
        }
        pos += 9 + len;
    }
    summary.statistics = Some(stats);
    Ok(summary)
}

fn record_name(opcode: u8) -> &'static str {
    match opcode {
        op::HEADER => "header record",
        op::FOOTER => "footer record",
        op::SCHEMA => "schema record",
        op::CHANNEL => "channel record",
        op::MESSAGE => "message record",
        op::CHUNK => "chunk record",
        0x07 => "message index record",
        op::CHUNK_INDEX => "chunk index record",
        0x09 => "attachment record",
        0x0A => "attachment index record",
        op::STATISTICS => "statistics record",
        op::METADATA => "metadata record",
        op::METADATA_INDEX => "metadata index record",
        0x0E => "summary offset record",
        0x0F => "data end record",
        _ => "record of unknown type",
    }
}

// ---------------------------------------------------------------------------------------------
// Reading messages

struct Slot {
    buf: Arc<Vec<u8>>,
    /// `(log_time, offset of the message record in buf)`, sorted.
    entries: Vec<(u64, u32)>,
    next: usize,
    chunk_offset: u64,
}

enum Mode {
    Indexed {
        file: File,
        /// Chunks not loaded yet, latest start time first (popped from the back).
        pending: Vec<ChunkInfo>,
        slots: Vec<Option<Slot>>,
        /// `(log_time, chunk offset, record offset, slot)` of each loaded chunk's next message.
        heap: BinaryHeap<Reverse<(u64, u64, u32, usize)>>,
    },
    Linear {
        reader: BufReader<File>,
        pos: u64,
        current: Option<Slot>,
    },
}

/// Messages in log-time order. Yields `Err` at most once, then ends.
pub struct MessageStream {
    path: PathBuf,
    schemas: BTreeMap<u16, Arc<SchemaInfo>>,
    channels: BTreeMap<u16, Arc<ChannelInfo>>,
    topics: Option<BTreeSet<String>>,
    file_len: u64,
    mode: Mode,
    last_time: Option<(String, Nanos)>,
    done: bool,
}

impl MessageStream {
    fn wants(&self, ch: u16) -> bool {
        match &self.topics {
            None => true,
            Some(t) => self.channels.get(&ch).is_some_and(|c| t.contains(&c.topic)),
        }
    }

    /// Decompress a chunk body, register its schemas/channels, and index its wanted messages.
    fn load(&mut self, body: &[u8], chunk: &ChunkInfo) -> Result<Slot, LogErrorKind> {
        let chunk_offset = chunk.offset;
        let (start, end, _, data) =
            open_chunk(body, chunk_offset, &self.channels, chunk.channels.as_ref())?;
        if chunk.length > 0 && (start, end) != (chunk.start, chunk.end) {
            return Err(LogErrorKind::BadRecord {
                record: "chunk",
                offset: chunk_offset,
                reason: format!(
                    "header time range {start}..{end} s differs from the index's {}..{} s",
                    chunk.start, chunk.end
                ),
            });
        }
        let mut entries = Vec::new();
        for rec in records(&data) {
            let (opcode, b, at) = rec.map_err(bad("chunk", chunk_offset))?;
            match opcode {
                op::SCHEMA => {
                    let s = parse_schema(b).map_err(bad("schema in chunk", chunk_offset))?;
                    self.schemas.entry(s.id).or_insert_with(|| Arc::new(s));
                }
                op::CHANNEL => {
                    let rc = parse_channel(b).map_err(bad("channel in chunk", chunk_offset))?;
                    add_channel(&mut self.channels, &self.schemas, rc);
                }
                op::MESSAGE => {
                    let h =
                        parse_message_header(b).map_err(bad("message in chunk", chunk_offset))?;
                    if self.wants(h.channel) {
                        let at = u32::try_from(at).map_err(|_| LogErrorKind::BadRecord {
                            record: "chunk",
                            offset: chunk_offset,
                            reason: "chunk larger than 4 GiB".into(),
                        })?;
                        entries.push((h.log_time, at));
                    }
                }
                _ => {}
            }
        }
        entries.sort_unstable();
        Ok(Slot {
            buf: Arc::new(data),
            entries,
            next: 0,
            chunk_offset,
        })
    }

    /// Build the message at `at` in `buf`.
    fn message_at(
        &self,
        buf: &Arc<Vec<u8>>,
        at: usize,
        where_: u64,
    ) -> Result<Message, LogErrorKind> {
        let len = u64::from_le_bytes(
            buf[at + 1..at + 9]
                .try_into()
                .expect("checked by records()"),
        ) as usize;
        let body = &buf[at + 9..at + 9 + len];
        let h = parse_message_header(body).map_err(bad("message", where_))?;
        let channel =
            self.channels
                .get(&h.channel)
                .cloned()
                .ok_or(LogErrorKind::UnknownChannel {
                    offset: where_,
                    channel: h.channel,
                })?;
        Ok(Message {
            channel,
            sequence: h.sequence,
            log_time: Nanos(h.log_time),
            publish_time: Nanos(h.publish_time),
            data: Payload {
                buf: Arc::clone(buf),
                start: at + 9 + MESSAGE_HEADER_LEN,
                end: at + 9 + len,
            },
        })
    }

    fn next_indexed(&mut self) -> Result<Option<Message>, LogErrorKind> {
        loop {
            let Mode::Indexed {
                file,
                pending,
                slots,
                heap,
            } = &mut self.mode
            else {
                unreachable!("called in indexed mode")
            };
            // Load every chunk that starts no later than the earliest message we hold.
            let next_time = heap.peek().map(|Reverse((t, ..))| *t);
            let must_load = pending
                .last()
                .is_some_and(|c| next_time.is_none_or(|t| c.start.0 <= t));
            if must_load {
                let chunk = pending.pop().expect("checked non-empty");
                let rec = read_at(
                    file,
                    chunk.offset,
                    chunk.length,
                    self.file_len,
                    "chunk record",
                )?;
                if rec.len() < 9 || rec[0] != op::CHUNK {
                    return Err(LogErrorKind::BadRecord {
                        record: "chunk",
                        offset: chunk.offset,
                        reason: "the chunk index points at a record that is not a chunk".into(),
                    });
                }
                let stored_len = u64::from_le_bytes(rec[1..9].try_into().expect("8 bytes"));
                if stored_len != chunk.length - 9 {
                    return Err(LogErrorKind::BadRecord {
                        record: "chunk",
                        offset: chunk.offset,
                        reason: format!(
                            "record length field says {stored_len} bytes, the chunk index says {}",
                            chunk.length - 9
                        ),
                    });
                }
                let slot = self.load(&rec[9..], &chunk)?;
                let Mode::Indexed { slots, heap, .. } = &mut self.mode else {
                    unreachable!()
                };
                if let Some(&(t, at)) = slot.entries.first() {
                    let i = match slots.iter().position(Option::is_none) {
                        Some(i) => i,
                        None => {
                            slots.push(None);
                            slots.len() - 1
                        }
                    };
                    heap.push(Reverse((t, slot.chunk_offset, at, i)));
                    slots[i] = Some(slot);
                }
                continue;
            }
            let Some(Reverse((_, chunk_offset, at, i))) = heap.pop() else {
                return Ok(None);
            };
            let slot = slots[i].as_mut().expect("heap entries point at live slots");
            slot.next += 1;
            let buf = Arc::clone(&slot.buf);
            if let Some(&(t, next_at)) = slot.entries.get(slot.next) {
                heap.push(Reverse((t, chunk_offset, next_at, i)));
            } else {
                slots[i] = None; // last message of the chunk: free it once the caller drops it
            }
            return self.message_at(&buf, at as usize, chunk_offset).map(Some);
        }
    }

    fn next_linear(&mut self) -> Result<Option<Message>, LogErrorKind> {
        loop {
            let Mode::Linear {
                reader,
                pos,
                current,
            } = &mut self.mode
            else {
                unreachable!("called in linear mode")
            };
            if let Some(slot) = current {
                if let Some(&(_, at)) = slot.entries.get(slot.next) {
                    slot.next += 1;
                    let (buf, off) = (Arc::clone(&slot.buf), slot.chunk_offset);
                    return self.message_at(&buf, at as usize, off).map(Some);
                }
                *current = None;
            }
            if *pos + 9 > self.file_len {
                return Ok(None);
            }
            let record_pos = *pos;
            let mut head = [0u8; 9];
            reader.read_exact(&mut head)?;
            let opcode = head[0];
            let len = u64::from_le_bytes(head[1..9].try_into().expect("8 bytes"));
            if len > self.file_len - record_pos - 9 {
                return Err(LogErrorKind::Truncated {
                    what: record_name(opcode),
                    offset: record_pos,
                    needed: len + 9,
                    file_len: self.file_len,
                    last: self.last_time.clone(),
                });
            }
            *pos += 9 + len;
            match opcode {
                op::FOOTER => return Ok(None),
                op::MESSAGE | op::CHUNK | op::SCHEMA | op::CHANNEL => {
                    let mut body = vec![0u8; len as usize + 9];
                    body[..9].copy_from_slice(&head);
                    reader.read_exact(&mut body[9..])?;
                    match opcode {
                        op::SCHEMA => {
                            let s = parse_schema(&body[9..]).map_err(bad("schema", record_pos))?;
                            self.schemas.entry(s.id).or_insert_with(|| Arc::new(s));
                        }
                        op::CHANNEL => {
                            let rc =
                                parse_channel(&body[9..]).map_err(bad("channel", record_pos))?;
                            add_channel(&mut self.channels, &self.schemas, rc);
                        }
                        op::MESSAGE => {
                            let h = parse_message_header(&body[9..])
                                .map_err(bad("message", record_pos))?;
                            if self.wants(h.channel) {
                                let buf = Arc::new(body);
                                return self.message_at(&buf, 0, record_pos).map(Some);
                            }
                        }
                        _ => {
                            let unindexed = ChunkInfo {
                                offset: record_pos,
                                length: 0, // not from an index: nothing to compare with
                                start: Nanos(0),
                                end: Nanos(0),
                                compression: String::new(),
                                channels: None,
                            };
                            let slot = self.load(&body[9..], &unindexed)?;
                            let Mode::Linear { current, .. } = &mut self.mode else {
                                unreachable!()
                            };
                            *current = Some(slot);
                        }
                    }
                }
                _ => reader.seek_relative(len as i64)?,
            }
        }
    }
}

impl std::fmt::Debug for MessageStream {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MessageStream")
            .field("path", &self.path)
            .finish_non_exhaustive()
    }
}

impl Iterator for MessageStream {
    type Item = Result<Message, LogError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        let result = match self.mode {
            Mode::Indexed { .. } => self.next_indexed(),
            Mode::Linear { .. } => self.next_linear(),
        };
        match result {
            Ok(Some(m)) => {
                if matches!(self.mode, Mode::Linear { .. })
                    && let Some((_, prev)) = &self.last_time
                    && m.log_time < *prev
                {
                    self.done = true;
                    return Some(Err(LogError::new(
                        &self.path,
                        LogErrorKind::NotTimeOrdered {
                            previous: *prev,
                            this: m.log_time,
                        },
                    )
                    .on_topic(m.topic())
                    .at(m.log_time)));
                }
                self.last_time = Some((m.channel.topic.clone(), m.log_time));
                Some(Ok(m))
            }
            Ok(None) => {
                self.done = true;
                None
            }
            Err(kind) => {
                // Chunk errors name the chunk's topics and time span, truncation the last
                // complete message; both say more than the previous message would.
                self.done = true;
                Some(Err(LogError::new(&self.path, kind)))
            }
        }
    }
}

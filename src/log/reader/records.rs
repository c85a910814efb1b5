//! Pure MCAP record parsing: bytes in, records out. No files and no I/O — every function here
//! works on a `&[u8]`, checks each length before using it, and answers a reason string (the
//! callers wrap it in a [`LogErrorKind`] naming the record and its byte offset). Chunk bodies
//! are decompressed and their CRCs verified in [`super::chunk`].

use std::collections::{BTreeMap, BTreeSet};
use std::sync::Arc;

#[cfg(test)]
use super::chunk::open_chunk;

use super::super::error::LogErrorKind;
use crate::time::Nanos;

/// The eight bytes that open and close every MCAP file.
pub(super) const MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";

/// Bytes before a record's body: the opcode and the `u64` body length.
pub(super) const RECORD_HEAD_LEN: usize = 9;

/// Record opcodes.
pub(super) mod op {
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

/// A bounds-checked little-endian cursor over one record body.
pub(super) struct Cursor<'a> {
    buf: &'a [u8],
    pos: usize,
}

impl<'a> Cursor<'a> {
    #[inline]
    pub(super) fn new(buf: &'a [u8]) -> Self {
        Cursor { buf, pos: 0 }
    }

    #[inline]
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

    #[inline]
    fn array<const N: usize>(&mut self) -> Result<[u8; N], String> {
        let mut out = [0u8; N];
        out.copy_from_slice(self.take(N)?);
        Ok(out)
    }

    #[inline]
    pub(super) fn u16(&mut self) -> Result<u16, String> {
        self.array().map(u16::from_le_bytes)
    }
    #[inline]
    pub(super) fn u32(&mut self) -> Result<u32, String> {
        self.array().map(u32::from_le_bytes)
    }
    #[inline]
    pub(super) fn u64(&mut self) -> Result<u64, String> {
        self.array().map(u64::from_le_bytes)
    }
    fn prefixed(&mut self) -> Result<&'a [u8], String> {
        let n = self.u32()? as usize;
        self.take(n)
    }
    pub(super) fn string(&mut self) -> Result<String, String> {
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

/// Turns a parse failure's reason into a [`LogErrorKind::BadRecord`] for `record` at `offset`.
pub(super) fn bad(record: &'static str, offset: u64) -> impl Fn(String) -> LogErrorKind {
    move |reason| LogErrorKind::BadRecord {
        record,
        offset,
        reason,
    }
}

/// The opcode and body length of the 9-byte head that starts every record.
#[inline]
pub(super) fn record_head(head: &[u8; RECORD_HEAD_LEN]) -> (u8, u64) {
    let mut len = [0u8; 8];
    len.copy_from_slice(&head[1..]);
    (head[0], u64::from_le_bytes(len))
}

pub(super) fn parse_schema(body: &[u8]) -> Result<SchemaInfo, String> {
    let mut c = Cursor::new(body);
    Ok(SchemaInfo {
        id: c.u16()?,
        name: c.string()?,
        encoding: c.string()?,
        data: c.prefixed()?.to_vec(),
    })
}

/// A channel record before its schema id is resolved.
#[derive(Debug, PartialEq, Eq)]
pub(super) struct RawChannel {
    pub(super) id: u16,
    pub(super) schema_id: u16,
    pub(super) topic: String,
    pub(super) message_encoding: String,
    pub(super) metadata: BTreeMap<String, String>,
}

pub(super) fn parse_channel(body: &[u8]) -> Result<RawChannel, String> {
    let mut c = Cursor::new(body);
    Ok(RawChannel {
        id: c.u16()?,
        schema_id: c.u16()?,
        topic: c.string()?,
        message_encoding: c.string()?,
        metadata: c.string_map()?,
    })
}

/// Register a channel under its id (the first definition wins), resolving its schema.
pub(super) fn add_channel(
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

/// The fixed fields of a message record; the payload follows them.
#[derive(Debug, PartialEq, Eq)]
pub(super) struct MessageHeader {
    pub(super) channel: u16,
    pub(super) sequence: u32,
    pub(super) log_time: u64,
    pub(super) publish_time: u64,
}

/// Bytes of a message body before its payload.
pub(super) const MESSAGE_HEADER_LEN: usize = 22;

#[inline]
pub(super) fn parse_message_header(body: &[u8]) -> Result<MessageHeader, String> {
    let mut c = Cursor::new(body);
    Ok(MessageHeader {
        channel: c.u16()?,
        sequence: c.u32()?,
        log_time: c.u64()?,
        publish_time: c.u64()?,
    })
}

/// A chunk record's fields, its (compressed) records borrowed from the body.
#[derive(Debug, PartialEq, Eq)]
pub(super) struct ChunkHeader<'a> {
    pub(super) start: u64,
    pub(super) end: u64,
    pub(super) uncompressed_size: u64,
    pub(super) crc: u32,
    pub(super) compression: String,
    pub(super) records: &'a [u8],
}

pub(super) fn parse_chunk(body: &[u8]) -> Result<ChunkHeader<'_>, String> {
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

pub(super) fn parse_chunk_index(body: &[u8]) -> Result<ChunkInfo, String> {
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

pub(super) fn parse_statistics(body: &[u8]) -> Result<Statistics, String> {
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

pub(super) fn parse_metadata(body: &[u8]) -> Result<MetadataRecord, String> {
    let mut c = Cursor::new(body);
    Ok(MetadataRecord {
        name: c.string()?,
        entries: c.string_map()?,
    })
}

/// Iterate `(opcode, body, offset_in_buf)` over a buffer of concatenated records.
pub(super) fn records(buf: &[u8]) -> impl Iterator<Item = Result<(u8, &[u8], usize), String>> {
    let mut pos = 0usize;
    std::iter::from_fn(move || {
        if pos >= buf.len() {
            return None;
        }
        let Some(head) = buf[pos..].first_chunk::<RECORD_HEAD_LEN>() else {
            pos = buf.len();
            return Some(Err(format!(
                "record header at chunk byte {pos} is cut short"
            )));
        };
        let (opcode, len) = record_head(head);
        let body_start = pos + RECORD_HEAD_LEN;
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

/// What a record of this opcode is called in errors.
pub(super) fn record_name(opcode: u8) -> &'static str {
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

#[cfg(test)]
mod tests;

//! A log's index: what opening it learns without reading its messages. It comes from the
//! summary section when the file has a usable one (schemas, channels, statistics, chunk
//! indexes, metadata), otherwise from one linear pass that decompresses each chunk once to
//! learn its channels, time range and message count (files from a recorder that crashed
//! before writing the summary).
//!
//! The decisions are pure functions of bytes ([`parse_footer`], [`summary_from_section`],
//! [`LinearIndex`]); [`read_summary_section`] and [`linear_index`] only feed them from the
//! file.

use super::source::Source;
use std::collections::{BTreeMap, BTreeSet};
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::sync::Arc;

use super::super::error::LogErrorKind;
use super::chunk::{Keep, open_chunk_keeping};
use super::io::read_at;
use super::records::{
    ChannelInfo, ChunkInfo, Cursor, MAGIC, MetadataRecord, RECORD_HEAD_LEN, SchemaInfo, Statistics,
    add_channel, bad, op, parse_channel, parse_chunk_index, parse_message_header, parse_metadata,
    parse_schema, parse_statistics, record_head, record_name, records,
};
use crate::time::Nanos;

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
    /// Where the file's own index disagreed with its data (and the data was believed).
    pub warnings: Vec<String>,
    /// Read with `--recover`: the byte ranges `[start, end)` left out (a cut tail, chunks that
    /// do not open); an empty range where the file ends right after a complete record.
    pub lost: Vec<(u64, u64)>,
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

/// A summary is usable if it indexes the chunks or says the messages are outside chunks (read
/// in file order). Without chunk indexes and with statistics of no messages it may be true
/// (an empty log) or a lie hiding the data; a linear pass over the (then small) file tells.
pub(super) fn summary_is_complete(s: &LogSummary) -> bool {
    s.unchunked_messages || !s.chunks.is_empty()
}

// ---------------------------------------------------------------------------------------------
// Summary section

/// The footer record: opcode, length, summary start, summary offset start, summary CRC.
pub(super) const FOOTER_RECORD_LEN: u64 = 1 + 8 + 20;

/// Where the summary section is, as the footer says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Footer {
    pub(super) summary_start: u64,
    pub(super) summary_crc: u32,
}

/// Parse the file's last `FOOTER_RECORD_LEN + 8` bytes (footer record + closing magic) found
/// at `footer_offset`. `None` if they are not a footer or it points at no summary section.
pub(super) fn parse_footer(tail: &[u8], footer_offset: u64) -> Option<Footer> {
    let footer_len = FOOTER_RECORD_LEN as usize;
    if tail.len() != footer_len + 8 || &tail[footer_len..] != MAGIC || tail[0] != op::FOOTER {
        return None;
    }
    let mut c = Cursor::new(&tail[RECORD_HEAD_LEN..]);
    let (summary_start, _summary_offset_start, summary_crc) = match (c.u64(), c.u64(), c.u32()) {
        (Ok(a), Ok(b), Ok(crc)) => (a, b, crc),
        _ => return None,
    };
    if summary_start == 0 || summary_start >= footer_offset || summary_start < 8 {
        return None;
    }
    Some(Footer {
        summary_start,
        summary_crc,
    })
}

/// Check the summary CRC (over the section and the footer up to the CRC); 0 = not computed.
pub(super) fn check_summary_crc(
    section: &[u8],
    tail: &[u8],
    stored: u32,
) -> Result<(), LogErrorKind> {
    if stored == 0 {
        return Ok(());
    }
    let mut h = crc32fast::Hasher::new();
    h.update(section);
    h.update(&tail[..FOOTER_RECORD_LEN as usize - 4]);
    let computed = h.finalize();
    if computed != stored {
        return Err(LogErrorKind::SummaryCrc { stored, computed });
    }
    Ok(())
}

/// The index a summary section (starting at file byte `summary_start`) holds, and the
/// `(offset, length)` of the metadata records its metadata indexes point at.
pub(super) fn summary_from_section(
    section: &[u8],
    summary_start: u64,
    file_len: u64,
) -> Result<(LogSummary, Vec<(u64, u64)>), LogErrorKind> {
    let mut summary = LogSummary {
        from_summary_section: true,
        file_len,
        ..LogSummary::default()
    };
    let mut raw_channels = Vec::new();
    let mut metadata_offsets = Vec::new();
    for rec in records(section) {
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
    Ok((summary, metadata_offsets))
}

/// Read the summary section through the footer. `None` if the file has no (valid) footer or
/// no summary section.
pub(super) fn read_summary_section(
    file: &mut Source,
    file_len: u64,
) -> Result<Option<LogSummary>, LogErrorKind> {
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
    let Some(footer) = parse_footer(&tail, footer_offset) else {
        return Ok(None);
    };
    let summary_start = footer.summary_start;
    let section = read_at(
        file,
        summary_start,
        footer_offset - summary_start,
        file_len,
        "summary section",
    )?;
    check_summary_crc(&section, &tail, footer.summary_crc)?;
    let (mut summary, metadata_offsets) = summary_from_section(&section, summary_start, file_len)?;
    for (off, len) in metadata_offsets {
        let rec = read_at(file, off, len, file_len, "metadata record")?;
        if rec.len() >= RECORD_HEAD_LEN && rec[0] == op::METADATA {
            summary
                .metadata
                .push(parse_metadata(&rec[RECORD_HEAD_LEN..]).map_err(bad("metadata", off))?);
        }
    }
    // Header record right after the magic.
    let head = read_at(file, 8, RECORD_HEAD_LEN as u64, file_len, "header record")?;
    if let Some(head) = head.first_chunk::<RECORD_HEAD_LEN>()
        && let (op::HEADER, len) = record_head(head)
    {
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

// ---------------------------------------------------------------------------------------------
// Linear pass

/// The index built record by record from the front of a file without a usable summary: feed
/// it each top-level record whose body [`LinearIndex::needs_body`], then
/// [`LinearIndex::finish`].
pub(super) struct LinearIndex {
    summary: LogSummary,
    stats: Statistics,
    /// No message counted yet.
    first: bool,
    /// Channel and log time of the latest message so far (for truncation errors).
    last: Option<(u16, Nanos)>,
    /// Log time of the last message outside chunks (those must come in time order).
    previous_top_level: Option<Nanos>,
}

impl LinearIndex {
    pub(super) fn new(file_len: u64) -> LinearIndex {
        LinearIndex {
            summary: LogSummary {
                file_len,
                ..LogSummary::default()
            },
            stats: Statistics::default(),
            first: true,
            last: None,
            previous_top_level: None,
        }
    }

    /// Whether records of this opcode are indexed (the others are skipped unread).
    pub(super) fn needs_body(opcode: u8) -> bool {
        matches!(
            opcode,
            op::HEADER | op::SCHEMA | op::CHANNEL | op::MESSAGE | op::CHUNK | op::METADATA
        )
    }

    /// Topic and log time of the latest message indexed so far.
    pub(super) fn last_named(&self) -> Option<(String, Nanos)> {
        self.last
            .and_then(|(ch, t)| self.summary.channels.get(&ch).map(|c| (c.topic.clone(), t)))
    }

    fn count(&mut self, ch: u16, t: Nanos) {
        let stats = &mut self.stats;
        stats.message_count += 1;
        *stats.channel_message_counts.entry(ch).or_insert(0) += 1;
        if self.first || t < stats.start {
            stats.start = t;
        }
        if self.first || t > stats.end {
            stats.end = t;
        }
        self.first = false;
        if self.last.is_none_or(|(_, lt)| t >= lt) {
            self.last = Some((ch, t));
        }
    }

    /// Index one top-level record (`body` of a record at file byte `pos`, `len` = body length).
    pub(super) fn record(
        &mut self,
        opcode: u8,
        body: &[u8],
        pos: u64,
        len: u64,
    ) -> Result<(), LogErrorKind> {
        let summary = &mut self.summary;
        match opcode {
            op::HEADER => {
                let mut c = Cursor::new(body);
                summary.profile = c.string().map_err(bad("header", pos))?;
                summary.library = c.string().map_err(bad("header", pos))?;
            }
            op::SCHEMA => {
                let s = parse_schema(body).map_err(bad("schema", pos))?;
                summary.schemas.entry(s.id).or_insert_with(|| Arc::new(s));
            }
            op::CHANNEL => {
                let rc = parse_channel(body).map_err(bad("channel", pos))?;
                add_channel(&mut summary.channels, &summary.schemas, rc);
            }
            op::METADATA => summary
                .metadata
                .push(parse_metadata(body).map_err(bad("metadata", pos))?),
            op::MESSAGE => {
                let h = parse_message_header(body).map_err(bad("message", pos))?;
                summary.unchunked_messages = true;
                let t = Nanos(h.log_time);
                if let Some(previous) = self.previous_top_level
                    && t < previous
                {
                    // linear reading would fail later; learn it now
                    return Err(LogErrorKind::NotTimeOrdered { previous, this: t });
                }
                self.previous_top_level = Some(t);
                self.count(h.channel, t);
            }
            op::CHUNK => self.chunk(body, pos, len)?,
            _ => {}
        }
        Ok(())
    }

    /// Index a chunk: decompress it once, register its schemas and channels, count messages.
    fn chunk(&mut self, body: &[u8], pos: u64, len: u64) -> Result<(), LogErrorKind> {
        // only the messages' headers are kept: the pass needs channels and times
        let chunk = open_chunk_keeping(body, pos, &self.summary.channels, None, &mut |_| {
            Keep::Header
        })?;
        let mut ids = BTreeSet::new();
        let mut span: Option<(Nanos, Nanos)> = None;
        for rec in records(&chunk.data) {
            let (op_in, b, _) = rec.map_err(bad("chunk", pos))?;
            let summary = &mut self.summary;
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
                    let h = parse_message_header(b).map_err(bad("message in chunk", pos))?;
                    ids.insert(h.channel);
                    let t = Nanos(h.log_time);
                    span = Some(span.map_or((t, t), |(a, b)| (a.min(t), b.max(t))));
                    self.count(h.channel, t);
                }
                _ => {}
            }
        }
        // the merge orders chunks by their messages' real times, not the header's claim
        let (start, end) = span.unwrap_or((chunk.start, chunk.end));
        if start < chunk.start || end > chunk.end {
            self.summary.warnings.push(format!(
                "chunk at byte {pos} declares {}..{} s, its messages lie in {start}..{end} s",
                chunk.start, chunk.end
            ));
        }
        self.summary.chunks.push(ChunkInfo {
            offset: pos,
            length: RECORD_HEAD_LEN as u64 + len,
            start,
            end,
            compression: chunk.compression,
            channels: Some(ids),
        });
        Ok(())
    }

    /// The index, with the statistics counted.
    pub(super) fn finish(self) -> LogSummary {
        LogSummary {
            statistics: Some(self.stats),
            ..self.summary
        }
    }
}

/// Build the index by reading the file front to back (no usable summary section).
pub(super) fn linear_index(file: &mut Source, file_len: u64) -> Result<LogSummary, LogErrorKind> {
    linear_pass(file, file_len, false)
}

/// [`linear_index`] for `--recover`: a chunk that does not open (CRC, decompression, a bad
/// record inside) is skipped, and a cut or corrupt record framing ends the index there; each
/// loss is said in [`LogSummary::warnings`] (bytes, time span where known, last good message).
/// The stream then reads only what was indexed.
pub(super) fn recovering_index(
    file: &mut Source,
    file_len: u64,
) -> Result<LogSummary, LogErrorKind> {
    linear_pass(file, file_len, true)
}

fn linear_pass(
    file: &mut Source,
    file_len: u64,
    recover: bool,
) -> Result<LogSummary, LogErrorKind> {
    let mut index = LinearIndex::new(file_len);
    let mut reader = BufReader::with_capacity(1 << 16, &mut *file);
    reader.seek(SeekFrom::Start(8))?;
    let mut pos = 8u64;
    let head_len = RECORD_HEAD_LEN as u64;
    loop {
        let cut = if pos + head_len > file_len {
            Some(LogErrorKind::Truncated {
                what: if pos == file_len {
                    "footer record"
                } else {
                    "record header"
                },
                offset: pos,
                needed: head_len,
                file_len,
                last: index.last_named(),
            })
        } else {
            None
        };
        let mut head = [0u8; RECORD_HEAD_LEN];
        let (opcode, len) = match cut {
            Some(e) => return index.damaged(e, pos, recover),
            None => {
                reader.read_exact(&mut head)?;
                record_head(&head)
            }
        };
        if len > file_len - pos - head_len {
            let e = LogErrorKind::Truncated {
                what: record_name(opcode),
                offset: pos,
                needed: len.saturating_add(head_len),
                file_len,
                last: index.last_named(),
            };
            return index.damaged(e, pos, recover);
        }
        if opcode == op::FOOTER {
            // a complete file ends with the footer and the closing magic
            let end = pos + head_len + len;
            let mut tail = Vec::new();
            reader.seek_relative(len as i64)?;
            (&mut reader).take(8).read_to_end(&mut tail)?;
            if tail.as_slice() != MAGIC {
                let e = LogErrorKind::Truncated {
                    what: "closing magic",
                    offset: end,
                    needed: 8,
                    file_len,
                    last: index.last_named(),
                };
                return index.damaged(e, end, recover);
            }
            break;
        }
        if LinearIndex::needs_body(opcode) {
            let mut body = vec![0u8; len as usize];
            reader.read_exact(&mut body)?;
            match index.record(opcode, &body, pos, len) {
                Err(e) if recover && opcode == op::CHUNK => index.skip_chunk(e, &body, pos, len),
                other => other?,
            }
        } else {
            reader.seek_relative(len as i64)?;
        }
        pos += head_len + len;
    }
    Ok(index.finish())
}

impl LinearIndex {
    /// The file is damaged at byte `at`: an error, or (recovering) the index so far with
    /// the loss said and the file treated as ending there.
    fn damaged(
        mut self,
        e: LogErrorKind,
        at: u64,
        recover: bool,
    ) -> Result<LogSummary, LogErrorKind> {
        if !recover {
            return Err(e);
        }
        // the error names the last complete message
        let file_len = self.summary.file_len;
        let lost = if at < file_len {
            format!("bytes {at}..{file_len} ({} bytes) are lost", file_len - at)
        } else {
            // cut on a record boundary: no partial record, only what was never written
            format!(
                "the file ends at byte {at}, after a complete record: no partial record is lost, \
                 but nothing after it (more records, the summary section) was written"
            )
        };
        self.summary
            .warnings
            .push(format!("recovered: {e}; {lost}"));
        self.summary.lost.push((at, file_len));
        self.summary.file_len = at;
        Ok(self.finish())
    }

    /// Recovering: a chunk that does not open is left out, and its loss said.
    fn skip_chunk(&mut self, e: LogErrorKind, body: &[u8], pos: u64, len: u64) {
        let span = match super::records::parse_chunk(body) {
            Ok(h) => format!(", declared {}..{} s", Nanos(h.start), Nanos(h.end)),
            Err(_) => String::new(),
        };
        let total = len + RECORD_HEAD_LEN as u64;
        self.summary.warnings.push(format!(
            "recovered: the chunk at byte {pos} ({total} bytes{span}) is skipped: {e}"
        ));
        self.summary.lost.push((pos, pos + total));
    }
}

//! Messages in log-time order with bounded memory: a k-way merge of chunks by log time. A
//! chunk is read and decompressed only when the merge reaches its start time, and freed when
//! its last message is yielded, so memory holds the chunks that overlap in time — not the
//! file. Equal log times keep file order (chunk offset, then record offset), so the order is
//! deterministic. Files whose messages sit outside chunks are read in file order and must
//! already be time-ordered (checked).
//!
//! [`ChunkMerge`] is the merge itself (which chunk to load next, which message comes next) and
//! [`Catalog`] turns chunk bytes into messages; neither does I/O. [`MessageStream`] feeds them
//! from the file.

use super::source::Source;
use std::cmp::Reverse;
use std::collections::{BTreeMap, BTreeSet, BinaryHeap};
use std::io::{BufReader, Read};
use std::ops::Deref;
use std::path::PathBuf;
use std::sync::Arc;

use super::super::error::{LogError, LogErrorKind};
use super::chunk::{ChunkBuf, Keep, open_chunk_keeping};
use super::index::LogSummary;
use super::io::read_at;
use super::records::{
    ChannelInfo, ChunkInfo, MESSAGE_HEADER_LEN, RECORD_HEAD_LEN, SchemaInfo, add_channel, bad, op,
    parse_channel, parse_message_header, parse_schema, record_head, record_name, records,
};
use crate::time::Nanos;

/// Message bytes, borrowed from a decompressed chunk kept alive by reference counting.
#[derive(Clone)]
pub struct Payload {
    buf: Arc<ChunkBuf>,
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

/// A decompressed chunk and the messages still to yield from it.
struct Slot {
    buf: Arc<ChunkBuf>,
    /// `(log_time, offset of the message record in buf)`, sorted.
    entries: Vec<(u64, u32)>,
    next: usize,
    chunk_offset: u64,
}

/// The schemas and channels known so far (chunks may define more) and the topics wanted.
struct Catalog {
    schemas: BTreeMap<u16, Arc<SchemaInfo>>,
    channels: BTreeMap<u16, Arc<ChannelInfo>>,
    topics: Option<BTreeSet<String>>,
}

impl Catalog {
    fn wants(&self, ch: u16) -> bool {
        match &self.topics {
            None => true,
            Some(t) => self.channels.get(&ch).is_some_and(|c| t.contains(&c.topic)),
        }
    }

    /// Decompress a chunk body, register its schemas/channels, and index its wanted messages.
    fn load(&mut self, body: &[u8], chunk: &ChunkInfo) -> Result<Slot, LogErrorKind> {
        let chunk_offset = chunk.offset;
        // a channel defined inside this chunk is not known yet: keep its messages, the loop
        // below filters them
        let mut keep = |ch: u16| {
            if self.topics.is_none() || !self.channels.contains_key(&ch) || self.wants(ch) {
                Keep::Whole
            } else {
                Keep::Skip
            }
        };
        // The declared time ranges (index and header) are not trusted: the merge checks the
        // messages' own times as it goes (`Indexed::next`).
        let opened = open_chunk_keeping(
            body,
            chunk_offset,
            &self.channels,
            chunk.channels.as_ref(),
            &mut keep,
        )?;
        let data = opened.data;
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
            buf: Arc::new(ChunkBuf(data)),
            entries,
            next: 0,
            chunk_offset,
        })
    }

    /// Build the message whose record starts at `at` in `buf` (`where_`: the file offset
    /// errors name).
    fn message_at(
        &self,
        buf: &Arc<ChunkBuf>,
        at: usize,
        where_: u64,
    ) -> Result<Message, LogErrorKind> {
        // `records()` checked the record's bounds when `at` was taken; check again, cheaply,
        // rather than trust it with a panic.
        let cut = || bad("message", where_)("record is cut short".to_string());
        let head = buf
            .get(at..)
            .and_then(|b| b.first_chunk::<RECORD_HEAD_LEN>())
            .ok_or_else(cut)?;
        let (_, len) = record_head(head);
        let body_start = at + RECORD_HEAD_LEN;
        let body_end = usize::try_from(len)
            .ok()
            .and_then(|len| body_start.checked_add(len))
            .ok_or_else(cut)?;
        let body = buf.get(body_start..body_end).ok_or_else(cut)?;
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
                start: body_start + MESSAGE_HEADER_LEN,
                end: body_end,
            },
        })
    }
}

/// Most bytes of wanted messages held at once from chunks that overlap in time: beyond it a
/// log is refused with an error rather than exhausting memory. 1 GiB is some forty 4K RGB
/// images in flight; real logs hold a chunk or two (a few MiB) at a time.
const MAX_HELD_BYTES: usize = 1 << 30;

/// The k-way merge of indexed chunks by log time.
struct ChunkMerge {
    /// Bytes of the loaded chunks' kept records.
    held: usize,
    /// Chunks not loaded yet, latest start time first (popped from the back).
    pending: Vec<ChunkInfo>,
    slots: Vec<Option<Slot>>,
    /// `(log_time, chunk offset, record offset, slot)` of each loaded chunk's next message.
    heap: BinaryHeap<Reverse<(u64, u64, u32, usize)>>,
}

impl ChunkMerge {
    fn new(mut pending: Vec<ChunkInfo>) -> ChunkMerge {
        pending.sort_by_key(|c| (c.start, c.offset));
        pending.reverse(); // pop from the back
        ChunkMerge {
            held: 0,
            pending,
            slots: Vec::new(),
            heap: BinaryHeap::new(),
        }
    }

    /// The chunk to load before the next message can be known: one that starts no later than
    /// the earliest message held (or any, when none is held).
    fn next_to_load(&mut self) -> Option<ChunkInfo> {
        let next_time = self.heap.peek().map(|Reverse((t, ..))| *t);
        let must_load = self
            .pending
            .last()
            .is_some_and(|c| next_time.is_none_or(|t| c.start.0 <= t));
        if must_load { self.pending.pop() } else { None }
    }

    /// Add a loaded chunk to the merge (a chunk without wanted messages is dropped).
    fn insert(&mut self, slot: Slot) {
        if let Some(&(t, at)) = slot.entries.first() {
            let i = match self.slots.iter().position(Option::is_none) {
                Some(i) => i,
                None => {
                    self.slots.push(None);
                    self.slots.len() - 1
                }
            };
            self.heap.push(Reverse((t, slot.chunk_offset, at, i)));
            self.held += slot.buf.len();
            self.slots[i] = Some(slot);
        }
    }

    /// The next message's chunk buffer, record offset and chunk offset; a chunk's slot is
    /// freed with its last message (its buffer lives on while the caller holds a payload).
    fn pop(&mut self) -> Option<(Arc<ChunkBuf>, u32, u64)> {
        let Reverse((_, chunk_offset, at, i)) = self.heap.pop()?;
        // heap entries point at live slots
        let slot = self.slots.get_mut(i)?.as_mut()?;
        slot.next += 1;
        let buf = Arc::clone(&slot.buf);
        if let Some(&(t, next_at)) = slot.entries.get(slot.next) {
            self.heap.push(Reverse((t, chunk_offset, next_at, i)));
        } else {
            self.held -= slot.buf.len();
            self.slots[i] = None; // last message of the chunk: free it once the caller drops it
        }
        Some((buf, at, chunk_offset))
    }
}

/// Chunks read at their offsets from the chunk index.
struct Indexed {
    file: Source,
    merge: ChunkMerge,
    /// Log time of the latest message handed out.
    yielded: Option<u64>,
}

/// Records read front to back (messages outside chunks).
struct Linear {
    reader: BufReader<Source>,
    pos: u64,
    current: Option<Slot>,
}

enum Mode {
    Indexed(Indexed),
    Linear(Linear),
}

/// Messages in log-time order. Yields `Err` at most once, then ends.
pub struct MessageStream {
    path: PathBuf,
    catalog: Catalog,
    file_len: u64,
    mode: Mode,
    /// The channel and time of the last message handed out when reading in file order (its
    /// topic names it in errors; the channel is kept rather than its topic so that no message
    /// allocates).
    last_time: Option<(Arc<ChannelInfo>, Nanos)>,
    done: bool,
}

impl MessageStream {
    /// Stream the messages of `summary`'s log (open as `file`, positioned after the magic)
    /// on `topics` (`None`: all).
    pub(super) fn new(
        path: PathBuf,
        summary: &LogSummary,
        topics: Option<BTreeSet<String>>,
        file: Source,
    ) -> MessageStream {
        let s = summary;
        let mode = if s.unchunked_messages {
            Mode::Linear(Linear {
                reader: BufReader::with_capacity(1 << 16, file),
                pos: 8,
                current: None,
            })
        } else {
            let pending: Vec<ChunkInfo> = s
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
            Mode::Indexed(Indexed {
                file,
                merge: ChunkMerge::new(pending),
                yielded: None,
            })
        };
        MessageStream {
            path,
            catalog: Catalog {
                schemas: s.schemas.clone(),
                channels: s.channels.clone(),
                topics,
            },
            file_len: s.file_len,
            mode,
            last_time: None,
            done: false,
        }
    }
}

impl Indexed {
    fn next(
        &mut self,
        catalog: &mut Catalog,
        file_len: u64,
    ) -> Result<Option<Message>, LogErrorKind> {
        while let Some(chunk) = self.merge.next_to_load() {
            let rec = read_at(
                &mut self.file,
                chunk.offset,
                chunk.length,
                file_len,
                "chunk record",
            )?;
            let slot = catalog.load(chunk_body(&rec, &chunk)?, &chunk)?;
            // The merge loads a chunk by its declared start; a message before it is still
            // merged in order unless a later one was already handed out.
            if let (Some(&(first, _)), Some(previous)) = (slot.entries.first(), self.yielded)
                && first < previous
            {
                return Err(LogErrorKind::ChunkStartsEarlier {
                    offset: chunk.offset,
                    start: chunk.start,
                    this: Nanos(first),
                    previous: Nanos(previous),
                });
            }
            self.merge.insert(slot);
            if self.merge.held > MAX_HELD_BYTES {
                return Err(LogErrorKind::BadRecord {
                    record: "chunk",
                    offset: chunk.offset,
                    reason: format!(
                        "chunks overlapping in time up to {} s hold {} bytes of messages at once, more than the {MAX_HELD_BYTES} byte budget",
                        chunk.end, self.merge.held
                    ),
                });
            }
        }
        match self.merge.pop() {
            Some((buf, at, chunk_offset)) => {
                let m = catalog.message_at(&buf, at as usize, chunk_offset)?;
                self.yielded = Some(m.log_time.0);
                Ok(Some(m))
            }
            None => Ok(None),
        }
    }
}

/// The body of the chunk record `rec` that the index entry `chunk` points at.
fn chunk_body<'a>(rec: &'a [u8], chunk: &ChunkInfo) -> Result<&'a [u8], LogErrorKind> {
    let head = match rec.first_chunk::<RECORD_HEAD_LEN>() {
        Some(head) if head[0] == op::CHUNK => head,
        _ => {
            return Err(LogErrorKind::BadRecord {
                record: "chunk",
                offset: chunk.offset,
                reason: "the chunk index points at a record that is not a chunk".into(),
            });
        }
    };
    let (_, stored_len) = record_head(head);
    if stored_len != chunk.length - RECORD_HEAD_LEN as u64 {
        return Err(LogErrorKind::BadRecord {
            record: "chunk",
            offset: chunk.offset,
            reason: format!(
                "record length field says {stored_len} bytes, the chunk index says {}",
                chunk.length - RECORD_HEAD_LEN as u64
            ),
        });
    }
    Ok(&rec[RECORD_HEAD_LEN..])
}

impl Linear {
    fn next(
        &mut self,
        catalog: &mut Catalog,
        file_len: u64,
        last_time: &Option<(Arc<ChannelInfo>, Nanos)>,
    ) -> Result<Option<Message>, LogErrorKind> {
        let head_len = RECORD_HEAD_LEN as u64;
        loop {
            if let Some(slot) = &mut self.current {
                if let Some(&(_, at)) = slot.entries.get(slot.next) {
                    slot.next += 1;
                    let (buf, off) = (Arc::clone(&slot.buf), slot.chunk_offset);
                    return catalog.message_at(&buf, at as usize, off).map(Some);
                }
                self.current = None;
            }
            if self.pos + head_len > file_len {
                return Ok(None);
            }
            let record_pos = self.pos;
            let mut head = [0u8; RECORD_HEAD_LEN];
            self.reader.read_exact(&mut head)?;
            let (opcode, len) = record_head(&head);
            if len > file_len - record_pos - head_len {
                return Err(LogErrorKind::Truncated {
                    what: record_name(opcode),
                    offset: record_pos,
                    needed: len.saturating_add(head_len),
                    file_len,
                    last: last_time.as_ref().map(|(ch, t)| (ch.topic.clone(), *t)),
                });
            }
            self.pos += head_len + len;
            match opcode {
                op::FOOTER => return Ok(None),
                op::MESSAGE | op::CHUNK | op::SCHEMA | op::CHANNEL => {
                    let mut record = vec![0u8; len as usize + RECORD_HEAD_LEN];
                    record[..RECORD_HEAD_LEN].copy_from_slice(&head);
                    self.reader.read_exact(&mut record[RECORD_HEAD_LEN..])?;
                    if let Some(m) = self.record(catalog, opcode, record, record_pos)? {
                        return Ok(Some(m));
                    }
                }
                _ => self.reader.seek_relative(len as i64)?,
            }
        }
    }

    /// Take in one top-level record read whole (head included) at `record_pos`: a wanted
    /// message is returned, a chunk becomes the current slot, definitions are registered.
    fn record(
        &mut self,
        catalog: &mut Catalog,
        opcode: u8,
        record: Vec<u8>,
        record_pos: u64,
    ) -> Result<Option<Message>, LogErrorKind> {
        let body = &record[RECORD_HEAD_LEN..];
        match opcode {
            op::SCHEMA => {
                let s = parse_schema(body).map_err(bad("schema", record_pos))?;
                catalog.schemas.entry(s.id).or_insert_with(|| Arc::new(s));
            }
            op::CHANNEL => {
                let rc = parse_channel(body).map_err(bad("channel", record_pos))?;
                add_channel(&mut catalog.channels, &catalog.schemas, rc);
            }
            op::MESSAGE => {
                let h = parse_message_header(body).map_err(bad("message", record_pos))?;
                if catalog.wants(h.channel) {
                    let buf = Arc::new(ChunkBuf(record));
                    return catalog.message_at(&buf, 0, record_pos).map(Some);
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
                self.current = Some(catalog.load(body, &unindexed)?);
            }
        }
        Ok(None)
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
        let result = match &mut self.mode {
            Mode::Indexed(m) => m.next(&mut self.catalog, self.file_len),
            Mode::Linear(m) => m.next(&mut self.catalog, self.file_len, &self.last_time),
        };
        match result {
            Ok(Some(m)) => {
                if matches!(self.mode, Mode::Linear(_))
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
                if matches!(self.mode, Mode::Linear(_)) {
                    self.last_time = Some((Arc::clone(&m.channel), m.log_time));
                }
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

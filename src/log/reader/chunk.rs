//! Opening a chunk record: its records are decompressed as a stream and walked record by
//! record, and only what the reader asked to keep is held — schemas, channels and the wanted
//! messages (whole, or only their fixed header for the linear index pass). A chunk that
//! declares 2 GiB (a zstd bomb, or a big chunk of which one small topic is wanted) never
//! takes 2 GiB: memory is what is kept, not what the chunk holds. The CRC is computed over
//! every byte as it streams past, so nothing kept is handed out before it is verified.

use std::cell::RefCell;
use std::collections::{BTreeMap, BTreeSet};
use std::io::{self, BufReader, Read};
use std::sync::Arc;

use super::super::error::LogErrorKind;
use super::records::{
    ChannelInfo, MESSAGE_HEADER_LEN, RECORD_HEAD_LEN, bad, op, parse_chunk, parse_message_header,
    record_head,
};
use crate::time::Nanos;

/// Largest decompressed chunk we accept (a corrupt size field must not run for ever).
const MAX_CHUNK_BYTES: u64 = 1 << 31;

/// Largest schema or channel record inside a chunk (real ones are a few KB of text).
const MAX_DEFINITION_BYTES: u64 = 16 << 20;

/// What to keep of one message record.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Keep {
    Whole,
    /// Only the channel, sequence and times (the record's length then says 22 bytes).
    Header,
    Skip,
}

/// A chunk's kept records, decompressed and CRC-checked, in the chunk's record format.
pub(super) struct OpenChunk {
    pub(super) start: Nanos,
    pub(super) end: Nanos,
    pub(super) compression: String,
    pub(super) data: Vec<u8>,
}

/// Decompress a chunk record body (as read from `offset`), keep every record, and verify its
/// CRC. `ids` (the chunk's channels, when the index knows them) name the topics in errors.
#[cfg(test)]
pub(super) fn open_chunk(
    body: &[u8],
    offset: u64,
    channels: &BTreeMap<u16, Arc<ChannelInfo>>,
    ids: Option<&BTreeSet<u16>>,
) -> Result<OpenChunk, LogErrorKind> {
    open_chunk_keeping(body, offset, channels, ids, &mut |_| Keep::Whole)
}

/// A reader that counts and checksums the bytes read through it (no checksum when the chunk
/// stores none: rosbags writes 0 = not computed).
struct Tally<R> {
    inner: R,
    crc: Option<crc32fast::Hasher>,
    count: u64,
}

impl<R: Read> Read for Tally<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        if let Some(crc) = &mut self.crc {
            crc.update(&buf[..n]);
        }
        self.count += n as u64;
        Ok(n)
    }
}

/// Records read by [`walk`]: how many bytes have passed, and skipping without copying where
/// the bytes are already in memory.
trait Records: Read {
    fn count(&self) -> u64;
    fn skip(&mut self, len: u64) -> io::Result<()>;
}

impl<R: Read> Records for Tally<R> {
    fn count(&self) -> u64 {
        self.count
    }
    fn skip(&mut self, len: u64) -> io::Result<()> {
        skip(self, len)
    }
}

/// A whole decompressed chunk in memory.
struct Bytes<'a> {
    buf: &'a [u8],
    at: usize,
}

impl Read for Bytes<'_> {
    fn read(&mut self, out: &mut [u8]) -> io::Result<usize> {
        let n = (&self.buf[self.at..]).read(out)?;
        self.at += n;
        Ok(n)
    }
}

impl Records for Bytes<'_> {
    fn count(&self) -> u64 {
        self.at as u64
    }
    fn skip(&mut self, len: u64) -> io::Result<()> {
        let left = self.buf.len() - self.at;
        match usize::try_from(len) {
            Ok(n) if n <= left => {
                self.at += n;
                Ok(())
            }
            _ => Err(io::ErrorKind::UnexpectedEof.into()),
        }
    }
}

/// zstd chunks of at most this many uncompressed bytes (real ones are a few MiB) are
/// decompressed in one call, which is faster than the stream and skips unwanted records
/// without copying them; a larger declared size takes the streaming path, so a corrupt size
/// field never allocates more than this.
const BULK_MAX_BYTES: u64 = 64 << 20;

/// The whole zstd frame `src`, if it decompresses to exactly `want` bytes (else `None`: the
/// streaming path then reads it and says what is wrong).
fn zstd_whole(src: &[u8], want: u64) -> Option<Vec<u8>> {
    let want = usize::try_from(want).ok()?;
    let mut out = pooled_buffer(want);
    let n = ZSTD.with(|d| {
        let mut d = d.try_borrow_mut().ok()?;
        if d.is_none() {
            *d = zstd::bulk::Decompressor::new().ok();
        }
        d.as_mut()?.decompress_to_buffer(src, &mut out).ok()
    })?;
    (n == want).then_some(out)
}

/// Decompressed chunk bytes shared by the messages borrowed from them. When the last
/// reference goes, the buffer returns to the dropping thread's pool (see [`pooled_buffer`]),
/// so a read does not take fresh pages from the system, and fault them in, for every chunk.
pub(super) struct ChunkBuf(pub(super) Vec<u8>);

impl std::ops::Deref for ChunkBuf {
    type Target = [u8];
    fn deref(&self) -> &[u8] {
        &self.0
    }
}

impl Drop for ChunkBuf {
    fn drop(&mut self) {
        let buf = std::mem::take(&mut self.0);
        if (POOL_MIN_BYTES..=POOL_MAX_BYTES).contains(&buf.capacity()) {
            // a thread being torn down has no pool left: the buffer is simply freed
            let _ = POOL.try_with(|p| {
                if let Ok(mut p) = p.try_borrow_mut()
                    && p.len() < POOL_MAX_BUFFERS
                {
                    p.push(buf);
                }
            });
        }
    }
}

/// Buffers a thread keeps for its next chunks, and the sizes it keeps: memory held beyond
/// the chunks in use stays at most 2 × 8 MiB (real chunks are 1 to 4 MiB; single message
/// records outside chunks are not worth keeping).
const POOL_MAX_BUFFERS: usize = 2;
const POOL_MIN_BYTES: usize = 64 << 10;
const POOL_MAX_BYTES: usize = 8 << 20;

/// An empty buffer with room for `capacity` bytes, from this thread's pool when it has one.
fn pooled_buffer(capacity: usize) -> Vec<u8> {
    let mut buf = POOL
        .try_with(|p| p.try_borrow_mut().ok().and_then(|mut p| p.pop()))
        .ok()
        .flatten()
        .unwrap_or_default();
    buf.clear();
    buf.reserve(capacity);
    buf
}

thread_local! {
    /// Freed chunk buffers, reused by [`pooled_buffer`].
    static POOL: RefCell<Vec<Vec<u8>>> = const { RefCell::new(Vec::new()) };
    /// One zstd decompression context per thread, reused from chunk to chunk.
    static ZSTD: RefCell<Option<zstd::bulk::Decompressor<'static>>> = const { RefCell::new(None) };
}

/// Whether [`walk`] would keep every record of `all` as it is, without an error: only
/// definitions within their size limit and messages kept whole, each record within the data.
fn all_kept_whole(all: &[u8], keep: &mut dyn FnMut(u16) -> Keep) -> bool {
    let mut at = 0;
    while at < all.len() {
        let Some(head) = all[at..].first_chunk::<RECORD_HEAD_LEN>() else {
            return false;
        };
        let (opcode, len) = record_head(head);
        let body = at + RECORD_HEAD_LEN;
        let Some(end) = usize::try_from(len)
            .ok()
            .and_then(|len| body.checked_add(len))
            .filter(|&end| end <= all.len())
        else {
            return false;
        };
        let kept = match opcode {
            op::SCHEMA | op::CHANNEL => len <= MAX_DEFINITION_BYTES,
            op::MESSAGE if len >= MESSAGE_HEADER_LEN as u64 => {
                parse_message_header(&all[body..end]).is_ok_and(|h| keep(h.channel) == Keep::Whole)
            }
            _ => false,
        };
        if !kept {
            return false;
        }
        at = end;
    }
    true
}

/// [`open_chunk`], keeping of each message what `keep(channel id)` says.
pub(super) fn open_chunk_keeping(
    body: &[u8],
    offset: u64,
    channels: &BTreeMap<u16, Arc<ChannelInfo>>,
    ids: Option<&BTreeSet<u16>>,
    keep: &mut dyn FnMut(u16) -> Keep,
) -> Result<OpenChunk, LogErrorKind> {
    let h = parse_chunk(body).map_err(bad("chunk", offset))?;
    let topics = || match ids {
        Some(ids) => ids
            .iter()
            .filter_map(|id| channels.get(id).map(|c| c.topic.clone()))
            .collect::<Vec<_>>()
            .join(", "),
        None => "unknown topics".to_string(),
    };
    let want = h.uncompressed_size;
    if want > MAX_CHUNK_BYTES {
        return Err(LogErrorKind::BadRecord {
            record: "chunk",
            offset,
            reason: format!("uncompressed size {want} exceeds the {MAX_CHUNK_BYTES} byte limit"),
        });
    }
    let fail = |reason: String| LogErrorKind::Decompress {
        offset,
        start: Nanos(h.start),
        end: Nanos(h.end),
        topics: topics(),
        compression: h.compression.clone(),
        reason,
    };
    if h.compression == "zstd"
        && want <= BULK_MAX_BYTES
        && let Some(all) = zstd_whole(h.records, want)
    {
        // the same walk, then the same CRC check, as the stream below; a record cut short
        // by the end of the data is left to the stream, which names it. When every record is
        // kept as it is, the walk's output would be the data itself: no copy is made.
        let whole = all_kept_whole(&all, keep);
        let walked = if whole {
            Ok(Vec::new())
        } else {
            walk(&mut Bytes { buf: &all, at: 0 }, want, keep)
        };
        match walked {
            Ok(data) => {
                if h.crc != 0 {
                    let computed = crc32fast::hash(&all);
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
                return Ok(OpenChunk {
                    start: Nanos(h.start),
                    end: Nanos(h.end),
                    compression: h.compression,
                    data: if whole { all } else { data },
                });
            }
            Err(Walk::Bad(reason)) => return Err(bad("chunk", offset)(reason)),
            Err(Walk::Io(_)) => {}
        }
    }
    let inner: Box<dyn Read + '_> = match h.compression.as_str() {
        "" => Box::new(h.records),
        "zstd" => Box::new(BufReader::with_capacity(
            1 << 16,
            zstd::stream::read::Decoder::with_buffer(h.records).map_err(|e| fail(e.to_string()))?,
        )),
        "lz4" => Box::new(BufReader::with_capacity(
            1 << 16,
            lz4::Decoder::new(h.records).map_err(|e| fail(e.to_string()))?,
        )),
        other => {
            return Err(LogErrorKind::UnsupportedCompression {
                offset,
                compression: other.to_string(),
            });
        }
    };
    let mut r = Tally {
        inner,
        crc: (h.crc != 0).then(crc32fast::Hasher::new),
        count: 0,
    };
    let data = walk(&mut r, want, keep).map_err(|e| match e {
        Walk::Io(e) if e.kind() == io::ErrorKind::UnexpectedEof => {
            fail(format!("gave {} bytes, the header says {want}", r.count))
        }
        Walk::Io(e) => fail(e.to_string()),
        Walk::Bad(reason) => bad("chunk", offset)(reason),
    })?;
    // the declared size must be the whole stream
    let mut extra = [0u8; 1];
    if r.read(&mut extra).map_err(|e| fail(e.to_string()))? > 0 {
        return Err(fail(format!(
            "gave more bytes than the {want} the header says"
        )));
    }
    if let Some(crc) = r.crc {
        let computed = crc.finalize();
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
    Ok(OpenChunk {
        start: Nanos(h.start),
        end: Nanos(h.end),
        compression: h.compression,
        data,
    })
}

enum Walk {
    Io(io::Error),
    Bad(String),
}

impl From<io::Error> for Walk {
    fn from(e: io::Error) -> Walk {
        Walk::Io(e)
    }
}

/// Read `want` bytes of records from `r`, keeping definitions and the messages `keep` wants.
fn walk<R: Records>(
    r: &mut R,
    want: u64,
    keep: &mut dyn FnMut(u16) -> Keep,
) -> Result<Vec<u8>, Walk> {
    let mut out = Vec::new();
    while r.count() < want {
        let at = r.count();
        let mut head = [0u8; RECORD_HEAD_LEN];
        r.read_exact(&mut head)?;
        let (opcode, len) = record_head(&head);
        // the record head itself may run past the chunk's declared size (found by fuzzing)
        let Some(left) = want.checked_sub(r.count()) else {
            return Err(Walk::Bad(format!(
                "record head at chunk byte {at} runs past the chunk's {want} uncompressed bytes"
            )));
        };
        if len > left {
            return Err(Walk::Bad(format!(
                "record at chunk byte {at} claims {len} bytes, {left} left"
            )));
        }
        match opcode {
            op::SCHEMA | op::CHANNEL => {
                if len > MAX_DEFINITION_BYTES {
                    return Err(Walk::Bad(format!(
                        "definition record at chunk byte {at} claims {len} bytes (at most \
                         {MAX_DEFINITION_BYTES})"
                    )));
                }
                out.extend_from_slice(&head);
                read_into(r, len, &mut out)?;
            }
            op::MESSAGE if len >= MESSAGE_HEADER_LEN as u64 => {
                let mut fixed = [0u8; MESSAGE_HEADER_LEN];
                r.read_exact(&mut fixed)?;
                let channel = parse_message_header(&fixed).map_err(Walk::Bad)?.channel;
                let rest = len - MESSAGE_HEADER_LEN as u64;
                match keep(channel) {
                    Keep::Whole => {
                        out.extend_from_slice(&head);
                        out.extend_from_slice(&fixed);
                        read_into(r, rest, &mut out)?;
                    }
                    Keep::Header => {
                        out.push(op::MESSAGE);
                        out.extend_from_slice(&(MESSAGE_HEADER_LEN as u64).to_le_bytes());
                        out.extend_from_slice(&fixed);
                        r.skip(rest)?;
                    }
                    Keep::Skip => r.skip(rest)?,
                }
            }
            op::MESSAGE => {
                return Err(Walk::Bad(format!(
                    "message record at chunk byte {at} has {len} bytes, fewer than its \
                     {MESSAGE_HEADER_LEN}-byte header"
                )));
            }
            _ => r.skip(len)?,
        }
    }
    Ok(out)
}

/// Append exactly `len` bytes of `r` to `out` (growing as they arrive, not up front).
fn read_into<R: Read>(r: &mut R, len: u64, out: &mut Vec<u8>) -> io::Result<()> {
    let got = r.take(len).read_to_end(out)?;
    if (got as u64) < len {
        return Err(io::ErrorKind::UnexpectedEof.into());
    }
    Ok(())
}

fn skip<R: Read>(r: &mut R, len: u64) -> io::Result<()> {
    let got = io::copy(&mut r.take(len), &mut io::sink())?;
    if got < len {
        return Err(io::ErrorKind::UnexpectedEof.into());
    }
    Ok(())
}

#[cfg(test)]
mod tests;

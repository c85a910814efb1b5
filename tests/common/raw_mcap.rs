//! MCAP files written record by record, for logs no well-behaved writer would produce
//! (chunks whose times lie, statistics that lie, no CRCs, zstd bombs, cuts). The layout is
//! the MCAP spec's: magic `\x89MCAP0\r\n`, then records of opcode (u8) + body length (u64 LE)
//! + body, and the magic again at the end.

pub const MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";

pub fn record(op: u8, body: &[u8]) -> Vec<u8> {
    let mut r = vec![op];
    r.extend_from_slice(&(body.len() as u64).to_le_bytes());
    r.extend_from_slice(body);
    r
}

pub fn string(s: &str) -> Vec<u8> {
    let mut b = (s.len() as u32).to_le_bytes().to_vec();
    b.extend_from_slice(s.as_bytes());
    b
}

pub fn header() -> Vec<u8> {
    record(0x01, &[string("ros2"), string("raw_mcap test")].concat())
}

pub fn schema(id: u16, name: &str, encoding: &str, data: &[u8]) -> Vec<u8> {
    let mut b = id.to_le_bytes().to_vec();
    b.extend(string(name));
    b.extend(string(encoding));
    b.extend((data.len() as u32).to_le_bytes());
    b.extend_from_slice(data);
    record(0x03, &b)
}

pub fn channel(id: u16, schema_id: u16, topic: &str, encoding: &str) -> Vec<u8> {
    let mut b = id.to_le_bytes().to_vec();
    b.extend(schema_id.to_le_bytes());
    b.extend(string(topic));
    b.extend(string(encoding));
    b.extend(0u32.to_le_bytes()); // empty metadata map
    record(0x04, &b)
}

pub fn message(channel: u16, sequence: u32, log_time: u64, payload: &[u8]) -> Vec<u8> {
    let mut b = channel.to_le_bytes().to_vec();
    b.extend(sequence.to_le_bytes());
    b.extend(log_time.to_le_bytes());
    b.extend(log_time.to_le_bytes());
    b.extend_from_slice(payload);
    record(0x05, &b)
}

/// A chunk record. `compressed` holds the records as stored; `uncompressed_size` and `crc`
/// are written as given (a CRC of 0 means "not computed").
pub fn chunk_raw(
    start: u64,
    end: u64,
    uncompressed_size: u64,
    crc: u32,
    compression: &str,
    compressed: &[u8],
) -> Vec<u8> {
    let mut b = start.to_le_bytes().to_vec();
    b.extend(end.to_le_bytes());
    b.extend(uncompressed_size.to_le_bytes());
    b.extend(crc.to_le_bytes());
    b.extend(string(compression));
    b.extend((compressed.len() as u64).to_le_bytes());
    b.extend_from_slice(compressed);
    record(0x06, &b)
}

/// An uncompressed chunk of `records` with their CRC (or 0) and the declared time range.
pub fn chunk(start: u64, end: u64, records: &[u8], with_crc: bool) -> Vec<u8> {
    let crc = if with_crc {
        crc32fast::hash(records)
    } else {
        0
    };
    chunk_raw(start, end, records.len() as u64, crc, "", records)
}

/// A chunk index entry for a chunk record at `offset` of `length` bytes (whole record).
pub fn chunk_index(start: u64, end: u64, offset: u64, length: u64, channels: &[u16]) -> Vec<u8> {
    let mut b = start.to_le_bytes().to_vec();
    b.extend(end.to_le_bytes());
    b.extend(offset.to_le_bytes());
    b.extend(length.to_le_bytes());
    b.extend(((channels.len() * 10) as u32).to_le_bytes());
    for c in channels {
        b.extend(c.to_le_bytes());
        b.extend(0u64.to_le_bytes()); // message index offset (unused by the reader)
    }
    b.extend(0u64.to_le_bytes()); // message index length
    b.extend(string(""));
    b.extend(0u64.to_le_bytes()); // compressed size
    b.extend(0u64.to_le_bytes()); // uncompressed size
    record(0x08, &b)
}

pub fn statistics(message_count: u64, chunk_count: u32, start: u64, end: u64) -> Vec<u8> {
    let mut b = message_count.to_le_bytes().to_vec();
    b.extend(0u16.to_le_bytes());
    b.extend(0u32.to_le_bytes());
    b.extend(0u32.to_le_bytes());
    b.extend(0u32.to_le_bytes());
    b.extend(chunk_count.to_le_bytes());
    b.extend(start.to_le_bytes());
    b.extend(end.to_le_bytes());
    b.extend(0u32.to_le_bytes()); // empty channel count map
    record(0x0B, &b)
}

pub fn data_end() -> Vec<u8> {
    record(0x0F, &0u32.to_le_bytes())
}

/// The footer (summary CRC 0 = not computed) and the closing magic.
pub fn footer(summary_start: u64) -> Vec<u8> {
    let mut b = summary_start.to_le_bytes().to_vec();
    b.extend(0u64.to_le_bytes());
    b.extend(0u32.to_le_bytes());
    let mut r = record(0x02, &b);
    r.extend_from_slice(MAGIC);
    r
}

/// A whole file: magic, header, `data` records, data end, then `summary` records (if any),
/// with the footer pointing at them.
pub fn file(data: &[&[u8]], summary: &[&[u8]]) -> Vec<u8> {
    let mut f = MAGIC.to_vec();
    f.extend(header());
    for r in data {
        f.extend_from_slice(r);
    }
    f.extend(data_end());
    let summary_start = if summary.is_empty() {
        0
    } else {
        f.len() as u64
    };
    for r in summary {
        f.extend_from_slice(r);
    }
    f.extend(footer(summary_start));
    f
}

/// A CDR payload (little endian) of `body`.
pub fn cdr(body: &[u8]) -> Vec<u8> {
    let mut p = vec![0, 1, 0, 0];
    p.extend_from_slice(body);
    p
}

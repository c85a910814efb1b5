//! Known answers for zstd chunks, which open in one call (`zstd_whole`) below
//! `BULK_MAX_BYTES`: the same records, the same filtering and the same errors as the stream.

use super::*;
use crate::log::reader::records::op;

fn record(opcode: u8, body: &[u8]) -> Vec<u8> {
    let mut out = vec![opcode];
    out.extend_from_slice(&(body.len() as u64).to_le_bytes());
    out.extend_from_slice(body);
    out
}

fn message(channel: u16, log_time: u64, payload: &[u8]) -> Vec<u8> {
    let mut b = channel.to_le_bytes().to_vec();
    b.extend_from_slice(&1u32.to_le_bytes());
    b.extend_from_slice(&log_time.to_le_bytes());
    b.extend_from_slice(&log_time.to_le_bytes());
    b.extend_from_slice(payload);
    record(op::MESSAGE, &b)
}

/// A chunk record body holding `records` compressed as `compression`, declaring `size`.
fn chunk(records: &[u8], compression: &str, size: u64, crc: u32) -> Vec<u8> {
    let packed = match compression {
        "zstd" => zstd::bulk::compress(records, 3).expect("compresses"),
        _ => records.to_vec(),
    };
    let mut b = 10u64.to_le_bytes().to_vec();
    b.extend_from_slice(&20u64.to_le_bytes());
    b.extend_from_slice(&size.to_le_bytes());
    b.extend_from_slice(&crc.to_le_bytes());
    b.extend_from_slice(&(compression.len() as u32).to_le_bytes());
    b.extend_from_slice(compression.as_bytes());
    b.extend_from_slice(&(packed.len() as u64).to_le_bytes());
    b.extend_from_slice(&packed);
    b
}

fn open(body: &[u8], keep: Keep) -> Result<Vec<u8>, String> {
    open_chunk_keeping(body, 100, &BTreeMap::new(), None, &mut |ch| {
        if ch == 1 { Keep::Whole } else { keep }
    })
    .map(|c| c.data)
    .map_err(|e| e.to_string())
}

#[test]
fn zstd_chunks_keep_and_skip_exactly_what_the_stream_does() {
    let (a, b, c) = (
        message(1, 11, b"one"),
        message(2, 12, b"two!"),
        message(1, 13, b""),
    );
    let records = [a.clone(), b.clone(), c.clone()].concat();
    let n = records.len() as u64;
    let crc = crc32fast::hash(&records);
    for compression in ["zstd", ""] {
        let body = chunk(&records, compression, n, crc);
        assert_eq!(
            open(&body, Keep::Whole),
            Ok(records.clone()),
            "{compression}"
        );
        assert_eq!(open(&body, Keep::Skip), Ok([a.clone(), c.clone()].concat()));
        // the header form: opcode, length 22, the fixed fields, no payload
        let mut header = b[..9 + 22].to_vec();
        header[1..9].copy_from_slice(&22u64.to_le_bytes());
        assert_eq!(
            open(&body, Keep::Header),
            Ok([a.clone(), header, c.clone()].concat())
        );
    }
}

#[test]
fn zstd_chunk_errors_are_the_streams() {
    let records = [message(1, 11, b"one"), message(1, 12, b"two")].concat();
    let n = records.len() as u64;
    let crc = crc32fast::hash(&records);
    // a wrong CRC
    let e = open(&chunk(&records, "zstd", n, crc ^ 1), Keep::Whole).expect_err("crc");
    assert!(e.contains("CRC"), "{e}");
    // declared one byte more than the data: the stream runs dry
    let e = open(&chunk(&records, "zstd", n + 1, 0), Keep::Whole).expect_err("short");
    assert!(
        e.ends_with(&format!("gave {n} bytes, the header says {}", n + 1)),
        "{e}"
    );
    // declared one byte fewer: the last record runs past the declared size
    let e = open(&chunk(&records, "zstd", n - 1, 0), Keep::Whole).expect_err("long");
    // the uncompressed stream of the same bytes fails the same way
    let streamed = open(&chunk(&records, "", n - 1, 0), Keep::Whole).expect_err("long");
    assert!(e.contains("claims"), "{e}");
    assert_eq!(e, streamed);
}

//! Hostile logs take little memory (issue 19): a zstd bomb of three time-overlapping chunks
//! that each declare 2 GiB, a fixed array of 10^12 empty messages in a tiny file and an 8 MiB
//! message of one-byte structs all end (in messages or a clear error) with a peak heap under
//! 64 MiB beyond the largest message. Measured with a counting global allocator (exact and
//! deterministic, unlike RSS), in one test so that no other test shares the counter.
//!
//! Set `PEOPLETRACK_KEEP_HOSTILE=DIR` to keep the crafted files (to measure `cat` with
//! `/usr/bin/time -v`).

use crate::common;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering::Relaxed;

use crate::support::counting_alloc::{CURRENT, PEAK};

use common::raw_mcap as raw;
use peopletrack::log::{Decoders, SessionLog};

const MIB: usize = 1 << 20;

/// Peak heap above the current level while reading and decoding every message of `path`;
/// the number of messages or the error text.
fn peak_reading(path: &Path) -> (usize, Result<usize, String>) {
    let base = CURRENT.load(Relaxed);
    PEAK.store(base, Relaxed);
    let result = (|| {
        let log = SessionLog::open(path).map_err(|e| e.to_string())?;
        let mut dec = Decoders::new();
        let mut n = 0;
        for m in log.messages().map_err(|e| e.to_string())? {
            let m = m.map_err(|e| e.to_string())?;
            dec.value(&log, &m).map_err(|e| e.to_string())?;
            n += 1;
        }
        Ok(n)
    })();
    (PEAK.load(Relaxed) - base, result)
}

fn keep(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).expect("write");
    if let Ok(keep) = std::env::var("PEOPLETRACK_KEEP_HOSTILE") {
        std::fs::write(Path::new(&keep).join(name), bytes).expect("keep");
    }
    p
}

/// A zstd chunk declaring 2 GiB: one `/x` JSON message at 5 ns, then a record of an unknown
/// opcode padding the rest with zeros (which compress to almost nothing).
fn bomb_chunk() -> Vec<u8> {
    let total: u64 = 1 << 31;
    let message = raw::message(1, 1, 5, b"{}");
    let pad = total - message.len() as u64 - 9;
    let mut enc = zstd::stream::write::Encoder::new(Vec::new(), 1).expect("encoder");
    enc.write_all(&message).expect("compress");
    enc.write_all(&[0x7f]).expect("compress");
    enc.write_all(&pad.to_le_bytes()).expect("compress");
    let zeros = vec![0u8; MIB];
    let mut left = pad;
    while left > 0 {
        let n = left.min(MIB as u64) as usize;
        enc.write_all(&zeros[..n]).expect("compress");
        left -= n as u64;
    }
    let compressed = enc.finish().expect("compress");
    raw::chunk_raw(0, 10, total, 0, "zstd", &compressed)
}

#[test]
fn hostile_logs_stay_within_64_mib_beyond_the_largest_message() {
    let _alone = crate::support::counting_alloc::alone();
    let dir = tempfile::tempdir().expect("tempdir");

    // three time-overlapping chunks of 2 GiB each in a small file: it used to peak at 6.2 GB
    let channel = raw::channel(1, 0, "/x", "json");
    let chunk = bomb_chunk();
    let bytes = raw::file(&[&channel, &chunk, &chunk, &chunk], &[]);
    assert!(bytes.len() < 1 << 20, "the bomb is small: {}", bytes.len());
    let p = keep(dir.path(), "bomb.mcap", &bytes);
    let (peak, result) = peak_reading(&p);
    assert_eq!(result, Ok(3));
    assert!(peak < 64 * MIB, "bomb: peak heap {} MiB", peak / MIB);
    eprintln!(
        "bomb.mcap ({} bytes): peak heap {:.1} MiB",
        bytes.len(),
        peak as f64 / MIB as f64
    );

    // a fixed array of 10^12 empty messages (each a dummy byte, or nothing at all): it used
    // to allocate 3.25 GB and abort
    for (name, text) in [
        (
            "empty_structs.mcap",
            "p/E[1000000000000] e\n===\nMSG: p/E\n",
        ),
        (
            "zero_structs.mcap",
            "p/Z[1000000000000] z\n===\nMSG: p/Z\nuint8[0] nothing\n",
        ),
    ] {
        let schema = raw::schema(1, "p/msg/T0", "ros2msg", text.as_bytes());
        let channel = raw::channel(1, 1, "/x", "cdr");
        let message = raw::message(1, 1, 5, &raw::cdr(&[1, 2, 3, 4]));
        let chunk = raw::chunk(
            5,
            5,
            &[schema.clone(), channel.clone(), message].concat(),
            true,
        );
        let bytes = raw::file(&[&schema, &channel, &chunk], &[]);
        let p = keep(dir.path(), name, &bytes);
        let (peak, result) = peak_reading(&p);
        assert!(result.is_err(), "{name}");
        assert!(peak < MIB, "{name}: peak heap {peak} bytes");
        eprintln!("{name} ({} bytes): peak heap {peak} bytes", bytes.len());
    }

    // an 8 MiB message of one-byte structs: it used to peak at 806 MB
    let schema = raw::schema(
        1,
        "p/msg/T0",
        "ros2msg",
        b"p/B[] items\n===\nMSG: p/B\nuint8 v\n",
    );
    let channel = raw::channel(1, 1, "/x", "cdr");
    let mut body = (8u32 << 20).to_le_bytes().to_vec();
    body.resize(4 + 8 * MIB, 1);
    let message = raw::message(1, 1, 5, &raw::cdr(&body));
    let chunk = raw::chunk(5, 5, &[channel.clone(), message].concat(), true);
    let bytes = raw::file(&[&schema, &channel, &chunk], &[]);
    let p = keep(dir.path(), "one_byte_structs.mcap", &bytes);
    let (peak, result) = peak_reading(&p);
    assert!(
        result
            .expect_err("too large a tree")
            .contains("bytes of structure")
    );
    assert!(
        peak < 8 * MIB + 64 * MIB,
        "one-byte structs: peak heap {} MiB",
        peak / MIB
    );
    eprintln!(
        "one_byte_structs.mcap: peak heap {:.1} MiB",
        peak as f64 / MIB as f64
    );
}

//! The MCAP reader on arbitrary bytes: open (summary section or linear index), the recovering
//! open of `--recover`, the CRC coverage of `inspect`, and every message in log-time order,
//! each decoded as its channel says (CDR, protobuf, JSON). Errors are fine; a panic, abort,
//! stack overflow or an allocation past libFuzzer's RSS limit is a crash.
//!
//! The reader opens files by path (it re-opens the file for each stream), so each input is
//! written to one file per fuzzing process in /dev/shm (tmpfs) first.
#![no_main]

use std::path::PathBuf;
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use peopletrack::log::{Decoders, SessionLog};

fn scratch() -> &'static PathBuf {
    static PATH: OnceLock<PathBuf> = OnceLock::new();
    PATH.get_or_init(|| {
        let dir = PathBuf::from("/dev/shm");
        let dir = if dir.is_dir() {
            dir
        } else {
            std::env::temp_dir()
        };
        dir.join(format!("peopletrack-fuzz-{}.mcap", std::process::id()))
    })
}

fn read_all(log: &SessionLog) {
    let _ = log.crc_coverage();
    let _ = log.summary().topics();
    let mut decoders = Decoders::new();
    if let Ok(stream) = log.messages() {
        for m in stream {
            match m {
                Ok(m) => {
                    let _ = decoders.value(log, &m);
                }
                Err(_) => break,
            }
        }
    }
    // one topic alone: the merge with a topic filter
    let first = log.summary().topics().first().map(|t| t.to_string());
    if let Some(t) = first {
        if let Ok(stream) = log.messages_on(&[t.as_str()]) {
            for m in stream {
                if m.is_err() {
                    break;
                }
            }
        }
    }
}

fuzz_target!(|data: &[u8]| {
    let path = scratch();
    if std::fs::write(path, data).is_err() {
        return;
    }
    if let Ok(log) = SessionLog::open(path) {
        read_all(&log);
    }
    if let Ok(log) = SessionLog::open_recovering(path) {
        read_all(&log);
    }
});

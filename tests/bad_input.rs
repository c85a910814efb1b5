//! Bad input gives one clear error naming the file (and the topic and time where they are
//! known) — never a panic, never silently wrong data.

use crate::common;

use std::path::{Path, PathBuf};

use peopletrack::Nanos;
use peopletrack::log::msgs::LaserScan;
use peopletrack::log::{Decoders, LogError, SessionLog, SessionWriter, WriterOptions};

/// Open, read every message and decode it; the first error, if any.
fn read_everything(path: &Path) -> Result<usize, LogError> {
    let log = SessionLog::open(path)?;
    let mut dec = Decoders::new();
    let mut n = 0;
    for m in log.messages()? {
        dec.value(&log, &m?)?;
        n += 1;
    }
    Ok(n)
}

fn write_prefix(dir: &Path, data: &[u8], len: usize) -> PathBuf {
    let p = dir.join(format!("cut_{len}.mcap"));
    std::fs::write(&p, &data[..len]).expect("write prefix");
    p
}

#[test]
fn real_log_truncated_at_sixty_offsets_always_errors_with_context() {
    let Some(src) = common::laser_log("general_tracking_moving_1") else {
        return;
    };
    let data = std::fs::read(&src).expect("read");
    let dir = tempfile::tempdir().expect("tempdir");
    let n = data.len();
    let mut cuts: Vec<usize> = (1..=52).map(|i| i * n / 53).collect();
    cuts.extend([0, 4, 8, 12, 40, n - 1, n - 8, n - 37, n - 100, n / 2 + 1]);
    let first_chunk_end = 200_000; // the first chunk ends well before this
    for &cut in &cuts {
        let p = write_prefix(dir.path(), &data, cut);
        let e = read_everything(&p).expect_err("a truncated log must not read as complete");
        let msg = e.to_string();
        assert!(
            msg.contains(&format!("cut_{cut}.mcap")),
            "error names the file: {msg}"
        );
        if cut >= 8 && cut < n - 37 {
            assert!(msg.contains("truncated"), "{msg}");
        }
        if cut > first_chunk_end && cut < n - 200_000 {
            // past the first chunk the error says which message was the last good one
            assert!(msg.contains("the last complete message is /"), "{msg}");
            assert!(msg.contains(" s"), "{msg}");
        }
    }
    assert!(cuts.len() >= 50);
}

fn own_log(dir: &Path, options: &WriterOptions) -> PathBuf {
    let p = dir.join("own.mcap");
    let mut w = SessionWriter::create(&p, options).expect("create");
    let ch = w.add_ros2::<LaserScan>("/scan").expect("channel");
    for i in 0..200u64 {
        let scan = LaserScan {
            ranges: (0..100).map(|k| (i * 100 + k) as f32 * 0.01).collect(),
            range_max: 30.0,
            ..Default::default()
        };
        w.write(ch, Nanos(1_000_000_000 + i * 100_000_000), &scan)
            .expect("write");
    }
    w.finish().expect("finish")
}

#[test]
fn any_flipped_byte_in_a_chunk_of_our_logs_is_detected() {
    let dir = tempfile::tempdir().expect("tempdir");
    for compression in [
        peopletrack::log::Compression::Zstd,
        peopletrack::log::Compression::None,
    ] {
        let src = own_log(
            dir.path(),
            &WriterOptions {
                compression,
                chunk_size: 16 * 1024,
                ..Default::default()
            },
        );
        let log = SessionLog::open(&src).expect("intact log opens");
        let chunks = log.summary().chunks.clone();
        assert!(chunks.len() >= 3);
        let data = std::fs::read(&src).expect("read");
        let mut tried = 0;
        for c in &chunks {
            let (start, len) = (c.offset as usize, c.length as usize);
            for k in 0..15 {
                let at = start + k * (len - 1) / 14;
                let mut bad = data.clone();
                bad[at] ^= 0x5a;
                let p = dir.path().join("flipped.mcap");
                std::fs::write(&p, &bad).expect("write");
                let e =
                    read_everything(&p).expect_err(&format!("flip at byte {at} must be detected"));
                let msg = e.to_string();
                assert!(msg.contains("flipped.mcap"), "{msg}");
                tried += 1;
            }
        }
        assert!(tried >= 45);
    }
}

#[test]
fn flipped_bytes_in_a_real_zstd_log_never_panic() {
    // rosbags stores no CRCs (0), so a flip inside compressed data may go unnoticed by the
    // container; it must still never panic, and an error must name the file.
    let Some(src) = common::laser_log("demo_stationary_simple_environment") else {
        return;
    };
    let data = std::fs::read(&src).expect("read");
    let log = SessionLog::open(&src).expect("opens");
    let dir = tempfile::tempdir().expect("tempdir");
    let mut errors = 0;
    for c in &log.summary().chunks {
        for k in 1..20 {
            let at = c.offset as usize + k * c.length as usize / 20;
            let mut bad = data.clone();
            bad[at] ^= 0xff;
            let p = dir.path().join("real_flipped.mcap");
            std::fs::write(&p, &bad).expect("write");
            if let Err(e) = read_everything(&p) {
                assert!(e.to_string().contains("real_flipped.mcap"), "{e}");
                errors += 1;
            }
        }
    }
    assert!(errors > 0, "at least some flips must be detected");
}

#[test]
fn schema_that_does_not_parse_names_file_topic_time_and_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let p = dir.path().join("badschema.mcap");
    let mut w = SessionWriter::create(&p, &WriterOptions::default()).expect("create");
    let ch = w
        .add_raw(
            "/weird",
            Some(("my_pkg/msg/Weird", "ros2msg", b"int32 a\nflot32 b\n")),
            "cdr",
        )
        .expect("channel");
    w.write_bytes(ch, Nanos(42_000_000_001), &[0, 1, 0, 0, 1, 0, 0, 0])
        .expect("write");
    w.finish().expect("finish");
    let msg = read_everything(&p).expect_err("bad schema").to_string();
    for needle in [
        "badschema.mcap",
        "/weird",
        "42.000000001",
        "my_pkg/msg/Weird",
        "line 2",
        "flot32",
    ] {
        assert!(msg.contains(needle), "`{needle}` missing from: {msg}");
    }
}

#[test]
fn unknown_encoding_is_named() {
    let dir = tempfile::tempdir().expect("tempdir");
    let p = dir.path().join("cbor.mcap");
    let mut w = SessionWriter::create(&p, &WriterOptions::default()).expect("create");
    let ch = w
        .add_raw("/x", Some(("x", "cborschema", b"{}")), "cbor")
        .expect("channel");
    w.write_bytes(ch, Nanos(1), &[1, 2, 3]).expect("write");
    w.finish().expect("finish");
    let msg = read_everything(&p)
        .expect_err("unknown encoding")
        .to_string();
    assert!(
        msg.contains("cbor.mcap") && msg.contains("/x") && msg.contains("`cbor`"),
        "{msg}"
    );
}

#[test]
fn short_cdr_payload_names_the_field() {
    let dir = tempfile::tempdir().expect("tempdir");
    let p = dir.path().join("short.mcap");
    let reg = peopletrack::log::definitions::registry("sensor_msgs/msg/LaserScan").expect("known");
    let full = peopletrack::log::cdr::encode(
        &reg,
        &peopletrack::log::msgs::RosMessage::to_value(&LaserScan {
            ranges: vec![1.0; 10],
            ..Default::default()
        }),
        peopletrack::log::cdr::Endian::Little,
    )
    .expect("encodes");
    let text =
        peopletrack::log::definitions::full_definition("sensor_msgs/msg/LaserScan").expect("known");
    let mut w = SessionWriter::create(&p, &WriterOptions::default()).expect("create");
    let ch = w
        .add_raw(
            "/scan",
            Some(("sensor_msgs/msg/LaserScan", "ros2msg", text.as_bytes())),
            "cdr",
        )
        .expect("channel");
    w.write_bytes(ch, Nanos(7), &full[..full.len() - 12])
        .expect("write");
    w.finish().expect("finish");
    let msg = read_everything(&p).expect_err("short payload").to_string();
    assert!(
        msg.contains("/scan") && msg.contains("ranges") && msg.contains("0.000000007"),
        "{msg}"
    );
}

#[test]
fn not_an_mcap_file_and_missing_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let p = dir.path().join("notes.mcap");
    std::fs::write(&p, b"hello, this is not a log").expect("write");
    let msg = read_everything(&p).expect_err("not mcap").to_string();
    assert!(
        msg.contains("notes.mcap") && msg.contains("not an MCAP file"),
        "{msg}"
    );
    std::fs::write(&p, b"").expect("write");
    assert!(read_everything(&p).is_err());
    let msg = read_everything(&dir.path().join("absent.mcap"))
        .expect_err("missing")
        .to_string();
    assert!(msg.contains("absent.mcap"), "{msg}");
}

#[test]
fn missing_topic_is_an_error_not_an_empty_result() {
    let dir = tempfile::tempdir().expect("tempdir");
    let p = own_log(dir.path(), &WriterOptions::default());
    let log = SessionLog::open(&p).expect("opens");
    let e = log.messages_on(&["/scna"]).expect_err("typo");
    assert!(e.to_string().contains("/scna"), "{e}");
}

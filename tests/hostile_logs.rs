//! Logs from strangers (issue 19): hostile schemas and payloads give a clear error naming the
//! file, topic and schema — never a stack overflow, a wrapped length or gigabytes of memory —
//! and indexes that lie never hide or reorder messages. Every log here is crafted by the test.

use crate::common;

use std::path::{Path, PathBuf};

use assert_cmd::Command;
use common::raw_mcap as raw;
use peopletrack::Nanos;
use peopletrack::log::{Decoders, LogError, SessionLog, SessionWriter, WriterOptions};

/// Open, read every message and decode it; the messages' `(topic, log time)`, or the first
/// error.
fn read_everything(path: &Path) -> Result<Vec<(String, u64)>, LogError> {
    let log = SessionLog::open(path)?;
    let mut dec = Decoders::new();
    let mut seen = Vec::new();
    for m in log.messages()? {
        let m = m?;
        dec.value(&log, &m)?;
        seen.push((m.topic().to_string(), m.log_time.0));
    }
    Ok(seen)
}

fn peopletrack() -> Command {
    Command::cargo_bin("peopletrack").expect("binary built")
}

/// A log with one message on `/x` of ROS 2 type `p/msg/T0` with schema `text`.
fn one_message_log(dir: &Path, name: &str, text: &str, payload: &[u8]) -> PathBuf {
    let p = dir.join(name);
    let mut w = SessionWriter::create(&p, &WriterOptions::default()).expect("create");
    let ch = w
        .add_raw("/x", Some(("p/msg/T0", "ros2msg", text.as_bytes())), "cdr")
        .expect("channel");
    w.write_bytes(ch, Nanos(5_000_000_000), payload)
        .expect("write");
    w.finish().expect("finish")
}

/// `p/T0` holds a `p/T1`, ..., `p/T{depth-1}` holds an `int8`: `depth` nested types.
fn nested_schema(depth: usize) -> String {
    let mut text = String::new();
    for i in 0..depth {
        if i > 0 {
            text.push_str(&format!("===\nMSG: p/T{i}\n"));
        }
        if i + 1 < depth {
            text.push_str(&format!("p/T{} inner\n", i + 1));
        } else {
            text.push_str("int8 leaf\n");
        }
    }
    text
}

/// Run `cat` and `inspect` on `log`: both must fail with exit status 1 (an error, not an
/// abort) and say every `needle` on stderr.
fn cli_fails_clearly(log: &Path, needles: &[&str]) {
    for args in [vec!["cat", "--topic", "/x"], vec!["inspect"]] {
        let out = peopletrack().args(&args).arg(log).output().expect("runs");
        let stderr = String::from_utf8_lossy(&out.stderr);
        let stdout = String::from_utf8_lossy(&out.stdout);
        if args[0] == "inspect" {
            // inspect reports an undecodable channel in its table rather than failing
            let text = format!("{stdout}{stderr}");
            for n in needles {
                assert!(text.contains(n), "inspect: `{n}` missing from: {text}");
            }
            continue;
        }
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        for n in needles {
            assert!(stderr.contains(n), "{args:?}: `{n}` missing from: {stderr}");
        }
    }
}

#[test]
fn schema_nested_ten_thousand_deep_is_an_error_in_cat_and_inspect_not_a_stack_overflow() {
    let dir = tempfile::tempdir().expect("tempdir");
    let p = one_message_log(
        dir.path(),
        "deep.mcap",
        &nested_schema(10_000),
        &raw::cdr(&[7]),
    );
    let msg = read_everything(&p).expect_err("too deep").to_string();
    for needle in ["deep.mcap", "/x", "p/msg/T0", "nest more than 64"] {
        assert!(msg.contains(needle), "`{needle}` missing from: {msg}");
    }
    cli_fails_clearly(&p, &["deep.mcap", "nest more than 64"]);
}

#[test]
fn schema_nested_two_thousand_deep_fails_inside_a_worker_thread_without_aborting() {
    let dir = tempfile::tempdir().expect("tempdir");
    let p = one_message_log(
        dir.path(),
        "deep.mcap",
        &nested_schema(2_000),
        &raw::cdr(&[7]),
    );
    // a pipeline worker: a spawned thread with the default stack
    let result = std::thread::spawn(move || read_everything(&p).map_err(|e| e.to_string()))
        .join()
        .expect("the worker returns instead of aborting");
    assert!(result.expect_err("too deep").contains("nest more than 64"));
}

#[test]
fn nesting_at_the_limit_decodes_prints_and_drops_in_a_worker_thread() {
    let dir = tempfile::tempdir().expect("tempdir");
    let ok = one_message_log(dir.path(), "ok.mcap", &nested_schema(64), &raw::cdr(&[7]));
    let over = one_message_log(dir.path(), "over.mcap", &nested_schema(65), &raw::cdr(&[7]));
    let printed = std::thread::spawn(move || {
        let log = SessionLog::open(&ok).expect("opens");
        let m = log
            .messages()
            .expect("stream")
            .next()
            .expect("one")
            .expect("reads");
        let v = Decoders::new().value(&log, &m).expect("64 levels decode");
        v.to_json(None).to_string()
    })
    .join()
    .expect("no stack overflow at the limit");
    assert_eq!(
        printed,
        format!(
            "{}{{\"leaf\":7}}{}",
            "{\"inner\":".repeat(63),
            "}".repeat(63)
        )
    );
    let msg = read_everything(&over).expect_err("65 levels").to_string();
    assert!(
        msg.contains("p/msg/T0") && msg.contains("nest more than 64"),
        "{msg}"
    );
}

#[test]
fn fixed_array_whose_byte_length_overflows_is_an_error_not_one_wrapped_element() {
    let dir = tempfile::tempdir().expect("tempdir");
    // 2305843009213693953 * 8 = 2^64 + 8: it used to wrap to 8 bytes and print {"x":[42.0]}
    let p = one_message_log(
        dir.path(),
        "wrap.mcap",
        "float64[2305843009213693953] x\n",
        &raw::cdr(&42.0f64.to_le_bytes()),
    );
    let msg = read_everything(&p).expect_err("overflow").to_string();
    for needle in ["wrap.mcap", "/x", "p/msg/T0", "2305843009213693953", "`x`"] {
        assert!(msg.contains(needle), "`{needle}` missing from: {msg}");
    }
    let out = peopletrack()
        .args(["cat", "--topic", "/x"])
        .arg(&p)
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(1));
    assert!(out.stdout.is_empty(), "nothing printed");
    let out = peopletrack().arg("inspect").arg(&p).output().expect("runs");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(!text.contains(" ok"), "inspect must not call it ok: {text}");
}

#[test]
fn long_fixed_arrays_and_sequences_are_bounded_by_the_bytes_left() {
    let dir = tempfile::tempdir().expect("tempdir");
    let check = |name: &str, text: &str, body: &[u8], needle: &str| {
        let p = one_message_log(dir.path(), name, text, &raw::cdr(body));
        let msg = read_everything(&p).expect_err(name).to_string();
        assert!(msg.contains(needle) && msg.contains(name), "{name}: {msg}");
    };
    // 10^12 empty messages: each takes its one dummy byte, and 4 bytes are left
    check(
        "empty.mcap",
        "p/E[1000000000000] e\n===\nMSG: p/E\n",
        &[1, 2, 3, 4],
        "1000000000000 at byte 4 cannot fit in the 4 bytes left",
    );
    // 10^12 messages of zero-length arrays take no bytes at all: capped outright
    check(
        "zero.mcap",
        "p/Z[1000000000000] z\n===\nMSG: p/Z\nuint8[0] nothing\n",
        &[],
        "1000000000000 elements of a type that takes no bytes on the wire",
    );
    // a sequence of 2^31 float64s in a 12-byte payload
    check(
        "seq.mcap",
        "float64[] v\n",
        &[0, 0, 0, 0x80, 1, 2, 3, 4, 5, 6, 7, 8],
        "2147483648 at byte 8 cannot fit in the 8 bytes left",
    );
    // 8 Mi one-byte messages: 8 MiB of payload would take ~800 MB as a tree
    let mut body = (8u32 << 20).to_le_bytes().to_vec();
    body.resize(4 + (8 << 20), 1);
    check(
        "bytes.mcap",
        "p/B[] items\n===\nMSG: p/B\nuint8 v\n",
        &body,
        "bytes of structure",
    );
    // ... while a zero-length array of zero-size messages and 65,536 of them are fine
    let p = one_message_log(
        dir.path(),
        "fine.mcap",
        "p/Z[65536] z\nuint8 tail\n===\nMSG: p/Z\nuint8[0] nothing\n",
        &raw::cdr(&[9]),
    );
    assert_eq!(read_everything(&p).expect("fine").len(), 1);
}

/// A `FileDescriptorSet` of `message t.Node { t.Node child = 1; int32 v = 2; }` (proto3).
fn recursive_descriptor_set() -> Vec<u8> {
    use prost_reflect::prost::Message as _;
    use prost_reflect::prost_types::{
        DescriptorProto, FieldDescriptorProto, FileDescriptorProto, FileDescriptorSet,
        field_descriptor_proto::{Label, Type},
    };
    let field = |name: &str, number: i32, ty: Type, type_name: Option<&str>| FieldDescriptorProto {
        name: Some(name.into()),
        number: Some(number),
        label: Some(Label::Optional as i32),
        r#type: Some(ty as i32),
        type_name: type_name.map(Into::into),
        ..Default::default()
    };
    FileDescriptorSet {
        file: vec![FileDescriptorProto {
            name: Some("node.proto".into()),
            package: Some("t".into()),
            syntax: Some("proto3".into()),
            message_type: vec![DescriptorProto {
                name: Some("Node".into()),
                field: vec![
                    field("child", 1, Type::Message, Some(".t.Node")),
                    field("v", 2, Type::Int32, None),
                ],
                ..Default::default()
            }],
            ..Default::default()
        }],
    }
    .encode_to_vec()
}

#[test]
fn recursive_protobuf_type_reads_unset_children_as_empty_instead_of_recursing_forever() {
    use peopletrack::log::protobuf;
    let desc = protobuf::descriptor("t.Node", &recursive_descriptor_set()).expect("descriptor");
    // nothing set: the unset child used to expand its own default child, without end
    let v = protobuf::decode(&desc, &[]).expect("decodes");
    assert_eq!(v.to_json(None).to_string(), r#"{"child":{},"v":0}"#);
    // child { child { v: 3 } }: set levels are kept, the unset one below is empty
    let payload = [0x0a, 0x04, 0x0a, 0x02, 0x10, 0x03];
    let v = protobuf::decode(&desc, &payload).expect("decodes");
    assert_eq!(
        v.to_json(None).to_string(),
        r#"{"child":{"child":{"child":{},"v":3},"v":0},"v":0}"#
    );
    // 90 set levels: within prost's limit of 100, over ours of 64
    let mut deep = vec![0x10, 0x01];
    for _ in 0..90 {
        let mut outer = vec![0x0a, deep.len() as u8];
        if deep.len() >= 0x80 {
            // two-byte varint length
            outer = vec![
                0x0a,
                (deep.len() as u8 & 0x7f) | 0x80,
                (deep.len() >> 7) as u8,
            ];
        }
        outer.extend(deep);
        deep = outer;
    }
    let e = protobuf::decode(&desc, &deep).expect_err("too deep");
    assert!(e.contains("nests more than 64 deep"), "{e}");
}

/// `/x` (JSON, channel 1) messages at `times`, as top-level records.
fn json_messages(times: &[u64]) -> Vec<u8> {
    times
        .iter()
        .enumerate()
        .flat_map(|(i, t)| raw::message(1, i as u32, *t, b"{}"))
        .collect()
}

fn log_times(seen: &[(String, u64)]) -> Vec<u64> {
    seen.iter().map(|(_, t)| *t).collect()
}

#[test]
fn message_before_its_chunks_declared_start_is_never_delivered_out_of_order() {
    let dir = tempfile::tempdir().expect("tempdir");
    let channel = raw::channel(1, 0, "/x", "json");
    // chunk A says 0..30 and holds 0, 30; chunk B says 40..100 but holds 20, 100
    let a = raw::chunk(0, 30, &json_messages(&[0, 30]), true);
    let b = raw::chunk(40, 100, &json_messages(&[20, 100]), true);
    let a_at = 8 + raw::header().len() as u64 + channel.len() as u64;
    let b_at = a_at + a.len() as u64;
    let indexed = raw::file(
        &[&channel, &a, &b],
        &[
            &channel,
            &raw::chunk_index(0, 30, a_at, a.len() as u64, &[1]),
            &raw::chunk_index(40, 100, b_at, b.len() as u64, &[1]),
            &raw::statistics(4, 2, 0, 100),
        ],
    );
    let p = dir.path().join("lying_index.mcap");
    std::fs::write(&p, &indexed).expect("write");
    // it used to print 0, 30, 20, 100 with exit 0
    let msg = read_everything(&p)
        .expect_err("order cannot be kept")
        .to_string();
    for needle in [
        "lying_index.mcap",
        &format!("chunk at byte {b_at}"),
        "0.000000040 s",
        "0.000000020 s",
        "lies",
        "cat --recover",
    ] {
        assert!(msg.contains(needle), "`{needle}` missing from: {msg}");
    }
    // the fallback the error names: index from the data (`run` does this by itself)
    for log in [
        SessionLog::open_scanning(&p).expect("scans"),
        SessionLog::open_recovering(&p).expect("recovers"),
    ] {
        let times: Vec<u64> = log
            .messages()
            .expect("stream")
            .map(|m| m.expect("message").log_time.0)
            .collect();
        assert_eq!(times, [0, 20, 30, 100]);
        assert!(
            log.summary()
                .warnings
                .iter()
                .any(|w| w.contains(&format!("chunk at byte {b_at} declares"))),
            "{:?}",
            log.summary().warnings
        );
    }
    // without the summary the linear pass learns each chunk's real range: right order
    let p = dir.path().join("lying_header.mcap");
    std::fs::write(&p, raw::file(&[&channel, &a, &b], &[])).expect("write");
    assert_eq!(
        log_times(&read_everything(&p).expect("reads")),
        [0, 20, 30, 100]
    );
    let log = SessionLog::open(&p).expect("opens");
    assert_eq!(
        log.summary().warnings,
        [format!(
            "chunk at byte {b_at} declares 0.000000040..0.000000100 s, its messages lie in \
             0.000000020..0.000000100 s"
        )]
    );
}

#[test]
fn statistics_of_zero_messages_without_a_chunk_index_fall_back_to_a_linear_scan() {
    let dir = tempfile::tempdir().expect("tempdir");
    let channel = raw::channel(1, 0, "/x", "json");
    let chunk = raw::chunk(10, 50, &json_messages(&[10, 20, 30, 40, 50]), true);
    let p = dir.path().join("zero_stats.mcap");
    std::fs::write(
        &p,
        raw::file(
            &[&channel, &chunk],
            &[&channel, &raw::statistics(0, 0, 0, 0)],
        ),
    )
    .expect("write");
    // it used to say `messages: 0` and print nothing
    assert_eq!(
        log_times(&read_everything(&p).expect("reads")),
        [10, 20, 30, 40, 50]
    );
    let log = SessionLog::open(&p).expect("opens");
    assert_eq!(
        log.summary().warnings,
        [
            "the summary section says 0 messages and has no chunk index; a linear scan of the \
          data found 5, and the index was rebuilt from the data"
        ]
    );
    let out = peopletrack().arg("inspect").arg(&p).output().expect("runs");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("messages:  5\n"), "{text}");
    assert!(
        text.contains("warning:   the summary section says 0 messages"),
        "{text}"
    );
    let out = peopletrack()
        .args(["cat", "--topic", "/x"])
        .arg(&p)
        .output()
        .expect("runs");
    assert_eq!(String::from_utf8_lossy(&out.stdout).lines().count(), 5);
    assert!(String::from_utf8_lossy(&out.stderr).contains("linear scan"));
    // a log that really is empty stays empty, without a warning
    let p = dir.path().join("empty.mcap");
    std::fs::write(
        &p,
        raw::file(&[&channel], &[&channel, &raw::statistics(0, 0, 0, 0)]),
    )
    .expect("write");
    assert!(read_everything(&p).expect("reads").is_empty());
    assert!(
        SessionLog::open(&p)
            .expect("opens")
            .summary()
            .warnings
            .is_empty()
    );
}

#[test]
fn inspect_says_when_a_log_carries_no_crcs() {
    let dir = tempfile::tempdir().expect("tempdir");
    let channel = raw::channel(1, 0, "/x", "json");
    let inspect = |name: &str, chunks: &[&[u8]]| {
        let p = dir.path().join(name);
        let mut data: Vec<&[u8]> = vec![&channel];
        data.extend_from_slice(chunks);
        std::fs::write(&p, raw::file(&data, &[])).expect("write");
        let crc = SessionLog::open(&p)
            .expect("opens")
            .crc_coverage()
            .expect("crc");
        let out = peopletrack().arg("inspect").arg(&p).output().expect("runs");
        (crc, String::from_utf8_lossy(&out.stdout).into_owned())
    };
    // rosbags writes chunk CRC 0 ("not computed")
    let no_crc = raw::chunk(1, 2, &json_messages(&[1, 2]), false);
    let crc = raw::chunk(3, 4, &json_messages(&[3, 4]), true);
    let (c, text) = inspect("rosbags.mcap", &[&no_crc, &no_crc]);
    assert_eq!((c.chunks, c.with_crc, c.incomplete()), (2, 0, true));
    assert!(
        text.contains(
            "crc:       none of the 2 chunks carries a CRC (0 = not computed): corruption \
             cannot be detected"
        ),
        "{text}"
    );
    let (c, text) = inspect("mixed.mcap", &[&crc, &no_crc]);
    assert_eq!((c.with_crc, c.incomplete()), (1, true));
    assert!(text.contains("1 of 2 chunks carry no CRC"), "{text}");
    let (c, text) = inspect("checked.mcap", &[&crc]);
    assert!(!c.incomplete());
    assert!(
        text.contains("crc:       all 1 chunks carry a CRC"),
        "{text}"
    );
    let (c, text) = inspect("loose.mcap", &[&json_messages(&[5])]);
    assert!(c.incomplete());
    assert!(
        text.contains("messages outside chunks carry no CRC"),
        "{text}"
    );
}

/// A log of 40 `/x` JSON messages (1..=40 s) in small uncompressed chunks with CRCs.
fn chunked_log(dir: &Path) -> (PathBuf, Vec<peopletrack::log::reader::ChunkInfo>) {
    let p = dir.join("full.mcap");
    let options = WriterOptions {
        compression: peopletrack::log::Compression::None,
        chunk_size: 200,
        ..WriterOptions::default()
    };
    let mut w = SessionWriter::create(&p, &options).expect("create");
    let ch = w.add_json("/x", "X", "{}").expect("channel");
    for i in 1..=40u64 {
        w.write_json(ch, Nanos(i * 1_000_000_000), &serde_json::json!({ "i": i }))
            .expect("write");
    }
    let p = w.finish().expect("finish");
    let chunks = SessionLog::open(&p)
        .expect("opens")
        .summary()
        .chunks
        .clone();
    assert!(chunks.len() >= 4, "several chunks: {}", chunks.len());
    (p, chunks)
}

#[test]
fn recover_reads_every_complete_chunk_before_a_cut_and_says_what_was_lost() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (full, chunks) = chunked_log(dir.path());
    let data = std::fs::read(&full).expect("read");
    let all: Vec<u64> = (1..=40).map(|i| i * 1_000_000_000).collect();
    let second = &chunks[1];
    let second_end = (second.offset + second.length) as usize;
    let third = chunks[2].offset as usize;
    // cut exactly at the end of the second chunk, inside the message index after it, and in
    // the middle of the third chunk: (cut, where the damaged record starts)
    for (cut, damage) in [
        (second_end, second_end),
        (second_end + 40, second_end),
        (third + 20, third),
    ] {
        let p = dir.path().join(format!("cut_{cut}.mcap"));
        std::fs::write(&p, &data[..cut]).expect("write");
        let out = peopletrack()
            .args(["cat", "--topic", "/x"])
            .arg(&p)
            .output()
            .expect("runs");
        assert_eq!(out.status.code(), Some(1), "without --recover: an error");
        assert!(String::from_utf8_lossy(&out.stderr).contains("truncated"));
        let out = peopletrack()
            .args(["cat", "--recover", "--topic", "/x"])
            .arg(&p)
            .output()
            .expect("runs");
        assert!(out.status.success());
        let stdout = String::from_utf8_lossy(&out.stdout);
        let times: Vec<u64> = stdout
            .lines()
            .map(|l| {
                let v: serde_json::Value = serde_json::from_str(l).expect("json line");
                v["log_time_ns"].as_u64().expect("time")
            })
            .collect();
        let last_complete = *times.last().expect("some messages");
        // the messages of the first two chunks, in order, and nothing invented
        assert_eq!(times, all[..times.len()]);
        assert_eq!(Nanos(last_complete), second.end);
        let stderr = String::from_utf8_lossy(&out.stderr);
        // a cut on a record boundary loses no partial record: it says so, not "0 bytes"
        let lost = if damage == cut {
            format!(
                "the file ends at byte {cut}, after a complete record: no partial record is lost"
            )
        } else {
            format!("bytes {damage}..{cut} ({} bytes) are lost", cut - damage)
        };
        assert!(
            stderr.contains("warning:") && stderr.contains(&lost) && !stderr.contains("(0 bytes)"),
            "{stderr}"
        );
        assert!(
            stderr.contains(&format!(
                "the last complete message is /x at {}",
                second.end
            )),
            "{stderr}"
        );
    }
}

#[test]
fn recover_skips_a_corrupt_chunk_and_reads_the_good_ones_after_it() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (full, chunks) = chunked_log(dir.path());
    let mut data = std::fs::read(&full).expect("read");
    let bad = &chunks[1];
    let flip = (bad.offset + bad.length - 3) as usize; // inside its records
    data[flip] ^= 0x55;
    let p = dir.path().join("flipped.mcap");
    std::fs::write(&p, &data).expect("write");
    assert!(
        read_everything(&p).is_err(),
        "without --recover: the CRC error"
    );
    let log = SessionLog::open_recovering(&p).expect("opens");
    let n = log.messages().expect("stream").count();
    let good = SessionLog::open(&full).expect("opens");
    let in_bad = good
        .messages()
        .expect("stream")
        .filter(|m| {
            m.as_ref()
                .is_ok_and(|m| m.log_time >= bad.start && m.log_time <= bad.end)
        })
        .count();
    assert_eq!(n, 40 - in_bad);
    assert_eq!(
        log.summary().warnings.len(),
        1,
        "{:?}",
        log.summary().warnings
    );
    let w = &log.summary().warnings[0];
    assert!(
        w.contains(&format!(
            "the chunk at byte {} ({} bytes",
            bad.offset, bad.length
        )) && w.contains(&format!("declared {}..{} s", bad.start, bad.end))
            && w.contains("CRC"),
        "{w}"
    );
}

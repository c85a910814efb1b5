//! Inputs that crashed a `cargo fuzz` target (`fuzz/`, `make fuzz`), rebuilt here as crafted
//! bytes: each must now give a clear error.

use crate::common;

use common::raw_mcap as raw;
use peopletrack::Nanos;
use peopletrack::log::{Decoders, SessionLog, SessionWriter, WriterOptions, protobuf};
use prost_reflect::prost::Message as _;
use prost_reflect::prost_types::{DescriptorProto, FileDescriptorProto, FileDescriptorSet};

/// A descriptor set of one file declaring message `fuzz.M`, with the given `syntax`.
fn descriptor_set(syntax: Option<&str>) -> Vec<u8> {
    FileDescriptorSet {
        file: vec![FileDescriptorProto {
            name: Some("m.proto".into()),
            package: Some("fuzz".into()),
            syntax: syntax.map(str::to_string),
            message_type: vec![DescriptorProto {
                name: Some("M".into()),
                ..Default::default()
            }],
            ..Default::default()
        }],
    }
    .encode_to_vec()
}

/// protobuf_decode / mcap_reader: `prost-reflect` 0.16.5 panicked (index out of bounds) on a
/// file whose `syntax` is neither proto2 nor proto3.
#[test]
fn a_descriptor_set_of_unknown_syntax_is_an_error_not_a_panic() {
    for ok in [None, Some("proto2"), Some("proto3")] {
        let set = descriptor_set(ok);
        let desc = protobuf::descriptor("fuzz.M", &set).expect("a valid set");
        assert_eq!(desc.full_name(), "fuzz.M");
    }
    let err = protobuf::descriptor("fuzz.M", &descriptor_set(Some("proto4")))
        .expect_err("unknown syntax");
    assert_eq!(
        err,
        "schema `fuzz.M` is not a valid FileDescriptorSet: file `m.proto` has unknown syntax \"proto4\""
    );

    // the same schema in a log: decoding its message names the topic and time
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("syntax.mcap");
    let mut w = SessionWriter::create(&path, &WriterOptions::default()).expect("create");
    let set = descriptor_set(Some("proto4"));
    let ch = w
        .add_raw("/m", Some(("fuzz.M", "protobuf", &set)), "protobuf")
        .expect("channel");
    w.write_bytes(ch, Nanos(7), &[]).expect("write");
    w.finish().expect("finish");
    let log = SessionLog::open(&path).expect("opens");
    let msg = log
        .messages()
        .expect("stream")
        .next()
        .expect("one message")
        .expect("reads");
    let err = Decoders::new()
        .value(&log, &msg)
        .expect_err("bad schema")
        .to_string();
    assert!(
        err.contains("unknown syntax \"proto4\"") && err.contains("/m"),
        "{err}"
    );
}

/// mcap_reader (`--recover`'s linear pass, overflow check): a chunk whose declared
/// uncompressed size ends inside a record head subtracted past zero.
#[test]
fn a_chunk_size_ending_inside_a_record_head_is_an_error_not_an_overflow() {
    let records = [
        raw::channel(1, 0, "/x", "json"),
        raw::message(1, 0, 5, b"{}"),
    ]
    .concat();
    // the size ends 4 bytes into the message record's 9-byte head
    let size = raw::channel(1, 0, "/x", "json").len() as u64 + 4;
    let chunk = raw::chunk_raw(5, 5, size, 0, "", &records);
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("head.mcap");
    std::fs::write(&path, raw::file(&[&chunk], &[])).expect("write");
    for recovering in [false, true] {
        let err = if recovering {
            SessionLog::open_recovering(&path).map(|_| ())
        } else {
            SessionLog::open(&path).map(|_| ())
        };
        if let Err(e) = err {
            let e = e.to_string();
            assert!(e.contains("runs past the chunk's"), "{e}");
        }
    }
    // --recover reads on and says the chunk was lost
    let log = SessionLog::open_recovering(&path).expect("recovers");
    let warnings = log.summary().warnings.join("\n");
    assert!(warnings.contains("runs past the chunk's"), "{warnings}");
}

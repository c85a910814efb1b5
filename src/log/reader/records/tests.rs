//! Known answers for the pure record parser: hand-made bytes in, exact records or exact
//! errors out.

use super::*;

/// `u32` length prefix + bytes.
fn prefixed(b: &[u8]) -> Vec<u8> {
    let mut out = (b.len() as u32).to_le_bytes().to_vec();
    out.extend_from_slice(b);
    out
}

/// Opcode + `u64` length + body.
fn record(opcode: u8, body: &[u8]) -> Vec<u8> {
    let mut out = vec![opcode];
    out.extend_from_slice(&(body.len() as u64).to_le_bytes());
    out.extend_from_slice(body);
    out
}

fn schema_body() -> Vec<u8> {
    let mut b = 7u16.to_le_bytes().to_vec();
    b.extend(prefixed(b"std_msgs/msg/String"));
    b.extend(prefixed(b"ros2msg"));
    b.extend(prefixed(b"string data"));
    b
}

fn message_body(channel: u16, sequence: u32, log_time: u64, payload: &[u8]) -> Vec<u8> {
    let mut b = channel.to_le_bytes().to_vec();
    b.extend_from_slice(&sequence.to_le_bytes());
    b.extend_from_slice(&log_time.to_le_bytes());
    b.extend_from_slice(&(log_time + 1).to_le_bytes());
    b.extend_from_slice(payload);
    b
}

fn chunk_body(records: &[u8], crc: u32) -> Vec<u8> {
    let mut b = 10u64.to_le_bytes().to_vec();
    b.extend_from_slice(&20u64.to_le_bytes());
    b.extend_from_slice(&(records.len() as u64).to_le_bytes());
    b.extend_from_slice(&crc.to_le_bytes());
    b.extend(prefixed(b""));
    b.extend_from_slice(&(records.len() as u64).to_le_bytes());
    b.extend_from_slice(records);
    b
}

#[test]
fn schema_known_answer() {
    assert_eq!(
        parse_schema(&schema_body()),
        Ok(SchemaInfo {
            id: 7,
            name: "std_msgs/msg/String".into(),
            encoding: "ros2msg".into(),
            data: b"string data".to_vec(),
        })
    );
}

#[test]
fn channel_known_answer_with_metadata() {
    let mut map = prefixed(b"offered_qos_profiles");
    map.extend(prefixed(b"- depth: 10"));
    let mut b = 3u16.to_le_bytes().to_vec();
    b.extend_from_slice(&7u16.to_le_bytes());
    b.extend(prefixed(b"/scan"));
    b.extend(prefixed(b"cdr"));
    b.extend(prefixed(&map));
    assert_eq!(
        parse_channel(&b),
        Ok(RawChannel {
            id: 3,
            schema_id: 7,
            topic: "/scan".into(),
            message_encoding: "cdr".into(),
            metadata: [("offered_qos_profiles".into(), "- depth: 10".into())].into(),
        })
    );
}

#[test]
fn add_channel_resolves_the_schema_and_keeps_the_first_definition() {
    let schema = Arc::new(parse_schema(&schema_body()).expect("schema"));
    let schemas = BTreeMap::from([(7, Arc::clone(&schema))]);
    let raw = |topic: &str| RawChannel {
        id: 3,
        schema_id: 7,
        topic: topic.into(),
        message_encoding: "cdr".into(),
        metadata: BTreeMap::new(),
    };
    let mut channels = BTreeMap::new();
    add_channel(&mut channels, &schemas, raw("/first"));
    add_channel(&mut channels, &schemas, raw("/second"));
    assert_eq!(channels.len(), 1);
    assert_eq!(channels[&3].topic, "/first");
    assert_eq!(channels[&3].schema_name(), "std_msgs/msg/String");
}

#[test]
fn message_header_known_answer() {
    let b = message_body(3, 42, 1_000, b"xyz");
    assert_eq!(b.len(), MESSAGE_HEADER_LEN + 3);
    assert_eq!(
        parse_message_header(&b),
        Ok(MessageHeader {
            channel: 3,
            sequence: 42,
            log_time: 1_000,
            publish_time: 1_001,
        })
    );
}

#[test]
fn truncated_fields_give_the_exact_error() {
    let b = message_body(3, 42, 1_000, b"");
    assert_eq!(
        parse_message_header(&b[..10]).map(|_| ()),
        Err("field at body byte 6 needs 8 bytes, 4 left".to_string())
    );
    // a string whose length prefix claims more than the body holds
    let mut s = 7u16.to_le_bytes().to_vec();
    s.extend_from_slice(&100u32.to_le_bytes());
    s.extend_from_slice(b"abc");
    assert_eq!(
        parse_schema(&s),
        Err("field at body byte 6 needs 100 bytes, 3 left".to_string())
    );
    let mut s = 7u16.to_le_bytes().to_vec();
    s.extend(prefixed(&[0xff, 0xfe]));
    assert_eq!(parse_schema(&s), Err("string is not UTF-8".to_string()));
}

#[test]
fn bad_names_the_record_and_offset() {
    let e = parse_schema(&[1]).map_err(bad("schema", 123)).map(|_| ());
    assert_eq!(
        e.map_err(|e| e.to_string()),
        Err("corrupt schema record at byte 123: field at body byte 0 needs 2 bytes, 1 left".into())
    );
}

#[test]
fn records_iterates_opcode_body_and_offset() {
    let mut buf = record(op::SCHEMA, &schema_body());
    let second_at = buf.len();
    buf.extend(record(op::MESSAGE, &message_body(3, 1, 5, b"p")));
    buf.extend(record(0x7F, b""));
    let got: Vec<_> = records(&buf).collect::<Result<_, _>>().expect("records");
    assert_eq!(got.len(), 3);
    assert_eq!(
        (got[0].0, got[0].1, got[0].2),
        (op::SCHEMA, schema_body().as_slice(), 0)
    );
    assert_eq!(got[1].0, op::MESSAGE);
    assert_eq!(got[1].2, second_at);
    assert_eq!(got[1].1, message_body(3, 1, 5, b"p").as_slice());
    assert_eq!((got[2].0, got[2].1.len()), (0x7F, 0));
    assert_eq!(records(&[]).count(), 0);
}

#[test]
fn truncated_records_give_the_exact_error_once() {
    let mut buf = record(op::MESSAGE, &message_body(3, 1, 5, b"p"));
    let whole = buf.len();
    // a record head cut short (the offset reported is where the buffer ends)
    buf.extend_from_slice(&[op::MESSAGE, 1, 0]);
    let got: Vec<_> = records(&buf).collect();
    assert_eq!(got.len(), 2);
    assert!(got[0].is_ok());
    assert_eq!(
        got[1],
        Err(format!(
            "record header at chunk byte {} is cut short",
            whole + 3
        ))
    );
    // a body shorter than its length field
    let mut cut = record(op::SCHEMA, &schema_body());
    cut.truncate(cut.len() - 4);
    let got: Vec<_> = records(&cut).collect();
    assert_eq!(
        got,
        vec![Err(format!(
            "record at chunk byte 0 claims {} bytes, {} left",
            schema_body().len(),
            schema_body().len() - 4
        ))]
    );
    // an absurd length is an error, not an allocation or an overflow
    let mut huge = vec![op::CHUNK];
    huge.extend_from_slice(&u64::MAX.to_le_bytes());
    assert_eq!(
        records(&huge).collect::<Vec<_>>(),
        vec![Err(format!(
            "record at chunk byte 0 claims {} bytes, 0 left",
            u64::MAX
        ))]
    );
}

#[test]
fn record_head_and_names() {
    let r = record(op::CHUNK, &[0; 300]);
    let head = r.first_chunk::<RECORD_HEAD_LEN>().expect("head");
    assert_eq!(record_head(head), (op::CHUNK, 300));
    assert_eq!(record_name(op::CHUNK), "chunk record");
    assert_eq!(record_name(0x0F), "data end record");
    assert_eq!(record_name(0x80), "record of unknown type");
}

#[test]
fn chunk_index_statistics_and_metadata_known_answers() {
    let mut b = 10u64.to_le_bytes().to_vec(); // start
    b.extend_from_slice(&20u64.to_le_bytes()); // end
    b.extend_from_slice(&4096u64.to_le_bytes()); // chunk offset
    b.extend_from_slice(&512u64.to_le_bytes()); // chunk length
    let mut offsets = 3u16.to_le_bytes().to_vec();
    offsets.extend_from_slice(&9000u64.to_le_bytes());
    b.extend(prefixed(&offsets));
    b.extend_from_slice(&64u64.to_le_bytes()); // message index length
    b.extend(prefixed(b"zstd"));
    b.extend_from_slice(&400u64.to_le_bytes()); // compressed size (ignored)
    b.extend_from_slice(&800u64.to_le_bytes()); // uncompressed size (ignored)
    assert_eq!(
        parse_chunk_index(&b),
        Ok(ChunkInfo {
            offset: 4096,
            length: 512,
            start: Nanos(10),
            end: Nanos(20),
            compression: "zstd".into(),
            channels: Some([3].into()),
        })
    );

    let mut s = 5u64.to_le_bytes().to_vec(); // messages
    s.extend_from_slice(&1u16.to_le_bytes());
    s.extend_from_slice(&[0; 16]); // channel, attachment, metadata, chunk counts
    s.extend_from_slice(&10u64.to_le_bytes());
    s.extend_from_slice(&20u64.to_le_bytes());
    let mut counts = 3u16.to_le_bytes().to_vec();
    counts.extend_from_slice(&5u64.to_le_bytes());
    s.extend(prefixed(&counts));
    assert_eq!(
        parse_statistics(&s),
        Ok(Statistics {
            message_count: 5,
            start: Nanos(10),
            end: Nanos(20),
            channel_message_counts: [(3, 5)].into(),
        })
    );

    let mut m = prefixed(b"session");
    let mut pairs = prefixed(b"robot");
    pairs.extend(prefixed(b"tiago"));
    m.extend(prefixed(&pairs));
    assert_eq!(
        parse_metadata(&m),
        Ok(MetadataRecord {
            name: "session".into(),
            entries: [("robot".into(), "tiago".into())].into(),
        })
    );
}

#[test]
fn chunk_known_answer_and_length_mismatch() {
    let inner = record(op::MESSAGE, &message_body(3, 1, 15, b"p"));
    let body = chunk_body(&inner, 0);
    let h = parse_chunk(&body).expect("chunk");
    assert_eq!((h.start, h.end, h.crc), (10, 20, 0));
    assert_eq!(h.uncompressed_size, inner.len() as u64);
    assert_eq!((h.compression.as_str(), h.records), ("", inner.as_slice()));

    let mut long = body.clone();
    long.push(0);
    assert_eq!(
        parse_chunk(&long).map(|_| ()),
        Err(format!(
            "records length field says {} bytes, the record holds {}",
            inner.len(),
            inner.len() + 1
        ))
    );
}

#[test]
fn open_chunk_checks_the_crc_and_the_size() {
    let inner = record(op::MESSAGE, &message_body(3, 1, 15, b"p"));
    let channels = BTreeMap::new();
    let good = chunk_body(&inner, crc32fast::hash(&inner));
    let opened = open_chunk(&good, 100, &channels, None).expect("open");
    assert_eq!((opened.start, opened.end), (Nanos(10), Nanos(20)));
    assert_eq!(opened.data, inner);

    let wrong = crc32fast::hash(&inner) ^ 1;
    let bad_crc = chunk_body(&inner, wrong);
    match open_chunk(&bad_crc, 100, &channels, None) {
        Err(LogErrorKind::ChunkCrc {
            offset,
            topics,
            stored,
            ..
        }) => assert_eq!(
            (offset, topics.as_str(), stored),
            (100, "unknown topics", wrong)
        ),
        other => panic!("expected a CRC error, got {:?}", other.map(|c| c.data)),
    }

    // uncompressed size field disagreeing with the (uncompressed) records
    let mut short = chunk_body(&inner, 0);
    short[16..24].copy_from_slice(&(inner.len() as u64 + 1).to_le_bytes());
    match open_chunk(&short, 100, &channels, None) {
        Err(e @ LogErrorKind::Decompress { .. }) => assert!(
            e.to_string().ends_with(&format!(
                "gave {} bytes, the header says {}",
                inner.len(),
                inner.len() + 1
            )),
            "{e}"
        ),
        other => panic!("expected a size error, got {:?}", other.map(|c| c.data)),
    }

    let mut huge = chunk_body(&inner, 0);
    huge[16..24].copy_from_slice(&(1u64 << 40).to_le_bytes());
    assert!(matches!(
        open_chunk(&huge, 100, &channels, None),
        Err(LogErrorKind::BadRecord {
            record: "chunk",
            offset: 100,
            ..
        })
    ));
}

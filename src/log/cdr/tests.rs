use super::*;

fn reg(text: &str) -> Registry {
    Registry::parse("t/T", text).expect("schema parses")
}

/// Bytes of a std_msgs/Header {stamp {sec 1, nanosec 2}, frame_id "ab"} followed by
/// float64 x = 1.0 as rmw_fastrtps writes them (little endian).
const HEADER_THEN_F64: &[u8] = &[
    0, 1, 0, 0, // CDR_LE
    1, 0, 0, 0, // sec
    2, 0, 0, 0, // nanosec
    3, 0, 0, 0, b'a', b'b', 0, // "ab\0"
    0, // pad to 8 (offset 15 -> 16)
    0, 0, 0, 0, 0, 0, 0xf0, 0x3f, // 1.0
];

const HEADER_SCHEMA: &str = "std_msgs/Header header\nfloat64 x\n===\nMSG: std_msgs/Header\n\
    builtin_interfaces/Time stamp\nstring frame_id\n===\nMSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec";

#[test]
fn decodes_known_bytes_with_alignment() {
    let r = reg(HEADER_SCHEMA);
    let v = decode(&r, HEADER_THEN_F64).expect("decodes");
    assert_eq!(v.get("x"), Ok(&Value::F64(1.0)));
    let h = v.get("header").expect("header");
    assert_eq!(h.get("frame_id").and_then(Value::as_str), Ok("ab"));
    assert_eq!(
        h.get("stamp").and_then(|s| s.get("nanosec")),
        Ok(&Value::U32(2))
    );
    // and encoding gives the same bytes back
    assert_eq!(
        encode(&r, &v, Endian::Little).expect("encodes"),
        HEADER_THEN_F64
    );
}

#[test]
fn xcdr2_caps_alignment_at_four() {
    let r = reg("uint32 a\nfloat64 b");
    let data = [0, 7, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xf0, 0x3f];
    let v = decode(&r, &data).expect("decodes");
    assert_eq!(v.get("b"), Ok(&Value::F64(1.0)));
}

#[test]
fn big_endian_round_trip() {
    let r = reg("int16 a\nfloat32[] b\nstring s\nwstring w\nuint64[2] c");
    let v = Value::Struct(vec![
        ("a".into(), Value::I16(-2)),
        ("b".into(), Value::F32s(vec![1.0, f32::NAN])),
        ("s".into(), Value::String("hé".into())),
        ("w".into(), Value::String("ü€".into())),
        ("c".into(), Value::U64s(vec![7, u64::MAX])),
    ]);
    let bytes = encode(&r, &v, Endian::Big).expect("encodes");
    assert_eq!(&bytes[..2], &[0, 0]);
    let back = decode(&r, &bytes).expect("decodes");
    assert_eq!(back.get("a"), Ok(&Value::I16(-2)));
    assert_eq!(back.get("s").and_then(Value::as_str), Ok("hé"));
    assert_eq!(back.get("w").and_then(Value::as_str), Ok("ü€"));
    assert_eq!(back.get("c"), Ok(&Value::U64s(vec![7, u64::MAX])));
    let Ok(Value::F32s(b)) = back.get("b") else {
        panic!("packed floats")
    };
    assert!(b[0] == 1.0 && b[1].is_nan());
}

#[test]
fn empty_message_is_one_byte() {
    let r = reg("");
    let bytes = encode(&r, &Value::Struct(vec![]), Endian::Little).expect("encodes");
    assert_eq!(bytes, [0, 1, 0, 0, 0]);
    assert_eq!(decode(&r, &bytes), Ok(Value::Struct(vec![])));
}

#[test]
fn short_payload_names_the_field_and_offset() {
    let r = reg(HEADER_SCHEMA);
    let e = decode(&r, &HEADER_THEN_F64[..20]).expect_err("short");
    assert_eq!(e.path, "x");
    assert_eq!(
        e.kind,
        CdrErrorKind::UnexpectedEnd {
            offset: 20,
            need: 8,
            have: 0
        }
    );
}

#[test]
fn absurd_sequence_length_is_an_error_not_an_allocation() {
    let r = reg("float64[] v");
    let e = decode(&r, &[0, 1, 0, 0, 0xff, 0xff, 0xff, 0x7f]).expect_err("corrupt");
    assert!(matches!(e.kind, CdrErrorKind::LengthTooLarge { .. }), "{e}");
    assert_eq!(e.path, "v");
}

#[test]
fn unknown_representation_is_named() {
    let r = reg("int8 a");
    let e = decode(&r, &[0, 3, 0, 0, 1]).expect_err("PL_CDR");
    assert_eq!(e.kind, CdrErrorKind::UnsupportedEncapsulation(3));
}

#[test]
fn missing_fields_take_schema_defaults() {
    let r = reg("int32 a 5\nstring s \"x\"\nfloat64[2] v");
    let bytes = encode(&r, &Value::Struct(vec![]), Endian::Little).expect("encodes");
    let v = decode(&r, &bytes).expect("decodes");
    assert_eq!(v.get("a"), Ok(&Value::I32(5)));
    assert_eq!(v.get("s").and_then(Value::as_str), Ok("x"));
    assert_eq!(v.get("v"), Ok(&Value::F64s(vec![0.0, 0.0])));
}

#[test]
fn encoder_checks_ranges_bounds_and_unknown_fields() {
    let r = reg("uint8 a\nint8[<=2] b\nfloat64[2] c");
    let enc = |v: Vec<(&str, Value)>| {
        encode(
            &r,
            &Value::Struct(v.into_iter().map(|(k, v)| (Arc::from(k), v)).collect()),
            Endian::Little,
        )
    };
    assert!(matches!(
        enc(vec![("a", Value::I32(300))]).map_err(|e| e.kind),
        Err(CdrErrorKind::OutOfRange { .. })
    ));
    assert!(matches!(
        enc(vec![("b", Value::I8s(vec![1, 2, 3]))]).map_err(|e| e.kind),
        Err(CdrErrorKind::BoundExceeded { .. })
    ));
    assert!(matches!(
        enc(vec![("c", Value::F64s(vec![1.0]))]).map_err(|e| e.kind),
        Err(CdrErrorKind::FixedLength { .. })
    ));
    assert!(matches!(
        enc(vec![("zz", Value::I32(1))]).map_err(|e| e.kind),
        Err(CdrErrorKind::UnknownField(_))
    ));
}

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

/// `write_json` text of a payload (a fresh float cache, or the one given).
fn json_text(r: &Registry, data: &[u8], max: Option<usize>, floats: &mut FloatText) -> String {
    let mut out = Vec::new();
    write_json(r, data, max, floats, &mut out).expect("writes");
    String::from_utf8(out).expect("utf-8")
}

#[test]
fn json_of_known_bytes() {
    let r = reg(HEADER_SCHEMA);
    assert_eq!(
        json_text(&r, HEADER_THEN_F64, None, &mut FloatText::default()),
        r#"{"header":{"stamp":{"sec":1,"nanosec":2},"frame_id":"ab"},"x":1.0}"#
    );
    assert_eq!(
        json_text(&reg(""), &[0, 1, 0, 0, 0], None, &mut FloatText::default()),
        "{}"
    );
}

const EVERY_TYPE: &str = "bool b\nbyte y\nchar ch\nint8 i8v\nuint8 u8v\nint16 a\nuint16 u16v\n\
    int32 i32v\nuint32 u32v\nint64 i64v\nuint64 u64v\nfloat32 f\nfloat64 d\nstring s\nwstring w\n\
    bool[] bs\nuint8[] by\nint8[3] i8s\nint16[] i16s\nuint16[] u16s\nint32[] i32s\nuint32[] u32s\n\
    int64[] i64s\nuint64[2] u64s\nfloat32[] fs\nfloat64[<=4] ds\nstring[] ss\nt/Inner[] inner\n\
    ===\nMSG: t/Inner\nfloat64 x\nstring[] names";

fn every_type() -> Value {
    let inner = |x: f64, names: &[&str]| {
        Value::Struct(vec![
            ("x".into(), Value::F64(x)),
            (
                "names".into(),
                Value::Array(names.iter().map(|n| Value::String((*n).into())).collect()),
            ),
        ])
    };
    Value::Struct(vec![
        ("b".into(), Value::Bool(true)),
        ("y".into(), Value::U8(255)),
        ("ch".into(), Value::U8(65)),
        ("i8v".into(), Value::I8(-128)),
        ("u8v".into(), Value::U8(7)),
        ("a".into(), Value::I16(-2)),
        ("u16v".into(), Value::U16(65535)),
        ("i32v".into(), Value::I32(i32::MIN)),
        ("u32v".into(), Value::U32(u32::MAX)),
        ("i64v".into(), Value::I64(i64::MIN)),
        ("u64v".into(), Value::U64(u64::MAX)),
        ("f".into(), Value::F32(0.1)),
        ("d".into(), Value::F64(-1e-300)),
        ("s".into(), Value::String("q\"\\\n\u{1}é".into())),
        ("w".into(), Value::String("ü€".into())),
        ("bs".into(), Value::Bools(vec![true, false, true])),
        ("by".into(), Value::Bytes(vec![0, 1, 255])),
        ("i8s".into(), Value::I8s(vec![-1, 0, 1])),
        ("i16s".into(), Value::I16s(vec![-300, 300])),
        ("u16s".into(), Value::U16s(vec![1, 2, 3])),
        ("i32s".into(), Value::I32s(vec![-5])),
        ("u32s".into(), Value::U32s(vec![])),
        ("i64s".into(), Value::I64s(vec![1 << 40, -(1 << 40)])),
        ("u64s".into(), Value::U64s(vec![0, u64::MAX])),
        (
            "fs".into(),
            Value::F32s(vec![
                0.1,
                f32::NAN,
                f32::INFINITY,
                f32::NEG_INFINITY,
                0.1,
                3.0,
            ]),
        ),
        ("ds".into(), Value::F64s(vec![1.5, 1e21, -0.0])),
        (
            "ss".into(),
            Value::Array(vec![Value::String("a".into()), Value::String("".into())]),
        ),
        (
            "inner".into(),
            Value::Array(vec![
                inner(1.0, &["x", "y"]),
                inner(f64::NAN, &[]),
                inner(2.5, &["z"]),
            ]),
        ),
    ])
}

#[test]
fn json_is_the_value_tree_text_for_every_type_both_byte_orders_and_cuts() {
    let r = reg(EVERY_TYPE);
    let v = every_type();
    let mut floats = FloatText::default();
    for endian in [Endian::Little, Endian::Big] {
        let bytes = encode(&r, &v, endian).expect("encodes");
        let tree = decode(&r, &bytes).expect("decodes");
        for max in [None, Some(0), Some(1), Some(2), Some(100)] {
            let want = serde_json::to_string(&tree.json(max)).expect("json");
            // twice with one cache: the second pass reads every float text from it
            for _ in 0..2 {
                assert_eq!(json_text(&r, &bytes, max, &mut floats), want, "{max:?}");
            }
        }
    }
    // a hand-checked piece: cut arrays say how many elements were left out
    let bytes = encode(&r, &v, Endian::Little).expect("encodes");
    let text = json_text(&r, &bytes, Some(1), &mut FloatText::default());
    assert!(
        text.contains(r#""fs":[0.10000000149011612,"... 5 more"]"#),
        "{text}"
    );
    assert!(text.contains(r#""u32s":[]"#), "{text}");
    assert!(
        text.contains(r#""inner":[{"x":1.0,"names":["x","... 1 more"]},"... 2 more"]"#),
        "{text}"
    );
    let full = json_text(&r, &bytes, None, &mut FloatText::default());
    assert!(
        full.contains(r#""fs":[0.10000000149011612,"NaN","Infinity","-Infinity","#),
        "{full}"
    );
}

#[test]
fn json_refuses_what_the_decoder_refuses() {
    let r = reg(HEADER_SCHEMA);
    let mut out = Vec::new();
    let short = &HEADER_THEN_F64[..HEADER_THEN_F64.len() - 3];
    let err =
        write_json(&r, short, None, &mut FloatText::default(), &mut out).expect_err("cut payload");
    assert_eq!(Err(err), decode(&r, short));
    // a huge count of elements that take no bytes on the wire
    let r = reg("t/E[] many\n===\nMSG: t/E\n");
    let bomb = [0, 1, 0, 0, 0xff, 0xff, 0xff, 0x0f];
    let err = write_json(&r, &bomb, None, &mut FloatText::default(), &mut out)
        .expect_err("too many empty elements");
    assert_eq!(Err(err), decode(&r, &bomb));
}

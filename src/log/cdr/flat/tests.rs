use std::sync::Arc;

use super::super::super::ros2msg::Registry;
use super::super::{Endian, decode, encode};
use super::*;

fn reg(text: &str) -> Registry {
    Registry::parse("t/T", text).expect("schema parses")
}

const PERSON: &str = "geometry_msgs/Pose pose\nuint32 id\n===\nMSG: geometry_msgs/Pose\n\
    geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n===\n\
    MSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z\n===\n\
    MSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w";

/// A `leg_tracker/msg/Person` written by hand: x = 1.5, y = -2.0, w = 1.0, id = 7.
fn person_bytes() -> Vec<u8> {
    let mut b = vec![0, 1, 0, 0];
    for v in [1.5f64, -2.0, 0.0, 0.0, 0.0, 0.0, 1.0] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.extend_from_slice(&7u32.to_le_bytes());
    b
}

fn flat_value(plan: &Plan, flat: &mut Flat, data: &[u8]) -> Result<Value> {
    flat.decode(plan, data).map(|r| r.to_value())
}

#[test]
fn person_decodes_known_bytes_into_slots() {
    let r = reg(PERSON);
    let plan = Plan::compile(&r).expect("compiles");
    let mut flat = Flat::default();
    let bytes = person_bytes();
    let m = flat.decode(&plan, &bytes).expect("decodes");
    assert_eq!(m.get("pose.position.x"), Ok(Value::F64(1.5)));
    assert_eq!(m.get("pose.position.y"), Ok(Value::F64(-2.0)));
    assert_eq!(m.get("pose.orientation.w"), Ok(Value::F64(1.0)));
    assert_eq!(m.get("id"), Ok(Value::U32(7)));
    // 3 + 4 inline slots for the pose, one for the id
    assert_eq!(m.slots.len(), 8);
    assert_eq!(plan.field("id").map(|f| f.slot), Ok(7));
    assert_eq!(Ok(m.to_value()), decode(&r, &bytes));
}

#[test]
fn paths_that_do_not_name_a_field_are_errors() {
    let r = reg("geometry_msgs/Point[] ps\nint8 a\n===\nMSG: geometry_msgs/Point\nfloat64 x");
    let plan = Plan::compile(&r).expect("compiles");
    assert_eq!(plan.field("b").map_err(|e| e.path), Err("b".to_string()));
    assert!(plan.field("ps.x").is_err(), "through an array");
    assert!(plan.field("a.x").is_err(), "through a scalar");
    assert!(plan.field("ps").is_ok());
}

const EVERYTHING: &str = "int16 a\nfloat32[] b\nstring s\nwstring w\nuint64[2] c\nbool[] flags\n\
    int8[] small\nstring[] names\nwstring[<=3] wide\nt/Item[] items\nt/Item[2] pair\nt/Empty e\n\
    t/Empty[] es\nfloat64 last\n===\nMSG: t/Item\nstring label\nuint8[] blob\nt/Empty nothing\n\
    int32[3] xyz\nfloat64 v\n===\nMSG: t/Empty\n";

fn item(label: &str, blob: &[u8], v: f64) -> Value {
    Value::Struct(vec![
        ("label".into(), Value::String(label.into())),
        ("blob".into(), Value::Bytes(blob.to_vec())),
        ("nothing".into(), Value::Struct(vec![])),
        ("xyz".into(), Value::I32s(vec![1, -2, 3])),
        ("v".into(), Value::F64(v)),
    ])
}

fn everything() -> Value {
    let s = |x: &str| Value::String(x.into());
    Value::Struct(vec![
        ("a".into(), Value::I16(-2)),
        ("b".into(), Value::F32s(vec![1.0, -0.5, 3.25])),
        ("s".into(), s("hé")),
        ("w".into(), s("ü€")),
        ("c".into(), Value::U64s(vec![7, u64::MAX])),
        ("flags".into(), Value::Bools(vec![true, false, true])),
        ("small".into(), Value::I8s(vec![-1, 2])),
        ("names".into(), Value::Array(vec![s("a"), s(""), s("ccc")])),
        ("wide".into(), Value::Array(vec![s("x€")])),
        (
            "items".into(),
            Value::Array(vec![item("one", &[1, 2, 3], 0.5), item("", &[], -1.0)]),
        ),
        (
            "pair".into(),
            Value::Array(vec![item("p", &[9], 2.0), item("q", &[], 3.0)]),
        ),
        ("e".into(), Value::Struct(vec![])),
        (
            "es".into(),
            Value::Array(vec![Value::Struct(vec![]), Value::Struct(vec![])]),
        ),
        ("last".into(), Value::F64(1e300)),
    ])
}

#[test]
fn every_kind_of_field_gives_back_the_tree_in_both_byte_orders() {
    let r = reg(EVERYTHING);
    let plan = Plan::compile(&r).expect("compiles");
    let mut flat = Flat::default();
    for endian in [Endian::Little, Endian::Big] {
        let bytes = encode(&r, &everything(), endian).expect("encodes");
        let tree = decode(&r, &bytes).expect("tree");
        assert_eq!(tree, everything(), "{endian:?}");
        assert_eq!(flat_value(&plan, &mut flat, &bytes), Ok(tree), "{endian:?}");
        let m = flat.decode(&plan, &bytes).expect("decodes");
        assert_eq!(m.get("last"), Ok(Value::F64(1e300)));
        assert_eq!(m.get("w"), Ok(Value::String("ü€".into())));
    }
}

#[test]
fn invalid_utf8_is_made_lossy_as_the_tree_decoder_does() {
    let r = reg("string s\nstring[] more");
    let bytes = [
        0, 1, 0, 0, 4, 0, 0, 0, b'a', 0xff, b'b', 0, // "a\xffb"
        1, 0, 0, 0, 3, 0, 0, 0, 0xc3, b'x', 0, // ["\xc3x"]
    ];
    let tree = decode(&r, &bytes).expect("tree");
    assert_eq!(tree.get("s").and_then(Value::as_str), Ok("a\u{fffd}b"));
    let plan = Plan::compile(&r).expect("compiles");
    let mut flat = Flat::default();
    assert_eq!(flat_value(&plan, &mut flat, &bytes), Ok(tree));
}

/// Every truncation and many single-byte corruptions of a payload: the flat walk accepts
/// exactly what the tree decoder accepts, with the same error kind and the same values (one
/// `Flat` reused throughout, so stale slots would show).
#[test]
fn corrupted_payloads_fail_or_decode_exactly_as_trees_do() {
    let cases: [(&str, Vec<u8>); 3] = [
        (EVERYTHING, {
            let r = reg(EVERYTHING);
            encode(&r, &everything(), Endian::Little).expect("encodes")
        }),
        (PERSON, person_bytes()),
        // elements that take no bytes: a count of 70,000 must be refused by both
        ("t/Z[] zs\nint8 tail\n===\nMSG: t/Z\nuint8[0] none", {
            vec![0, 1, 0, 0, 0x70, 0x11, 0x01, 0x00, 5]
        }),
    ];
    let (mut agreed, mut failed) = (0, 0);
    for (schema, good) in cases {
        let r = reg(schema);
        let plan = Plan::compile(&r).expect("compiles");
        let mut flat = Flat::default();
        let mut check = |data: &[u8]| {
            let tree = decode(&r, data);
            let got = flat_value(&plan, &mut flat, data);
            match (&tree, &got) {
                (Ok(t), Ok(g)) => assert_eq!(format!("{t:?}"), format!("{g:?}"), "{data:?}"),
                (Err(t), Err(g)) => {
                    assert_eq!(t.kind, g.kind, "{data:?}");
                    failed += 1;
                }
                _ => panic!("{schema}: tree {tree:?} vs flat {got:?} on {data:?}"),
            }
            agreed += 1;
        };
        for cut in 0..=good.len() {
            check(&good[..cut]);
        }
        for at in 0..good.len() {
            for b in [0x00, 0x01, 0x7f, 0x80, 0xff] {
                let mut bad = good.clone();
                bad[at] = b;
                check(&bad);
            }
        }
    }
    assert!(
        agreed > 1000 && failed > 100,
        "{agreed} checked, {failed} failed"
    );
}

/// 65,536 elements of a type of 60,000 zero-length arrays: the tree decoder runs out of its
/// structure budget within the first elements; the flat walk must refuse before it allocates
/// 31 GB of slots.
#[test]
fn wide_elements_that_take_no_bytes_are_refused_before_allocating() {
    let mut text = String::from("t/W[] ws\n===\nMSG: t/W\n");
    for i in 0..60_000 {
        text.push_str(&format!("int8[0] f{i}\n"));
    }
    let r = reg(&text);
    let plan = Plan::compile(&r).expect("compiles");
    let data = [0, 1, 0, 0, 0, 0, 1, 0]; // 65,536 elements
    let tree = decode(&r, &data).expect_err("too large");
    assert!(
        matches!(tree.kind, CdrErrorKind::TreeTooLarge { .. }),
        "{tree}"
    );
    let flat = Flat::default()
        .decode(&plan, &data)
        .map(|_| ())
        .expect_err("too large");
    assert_eq!(flat.kind, tree.kind);
}

#[test]
fn a_message_wider_than_the_limit_is_not_compiled() {
    // 2^17 inline slots: 32 fields of a 64-field type of 64 float64 each
    let mut text = String::new();
    for i in 0..32 {
        text.push_str(&format!("t/B b{i}\n"));
    }
    text.push_str("===\nMSG: t/B\n");
    for i in 0..64 {
        text.push_str(&format!("t/C c{i}\n"));
    }
    text.push_str("===\nMSG: t/C\n");
    for i in 0..64 {
        text.push_str(&format!("float64 f{i}\n"));
    }
    let r = reg(&text);
    assert!(Plan::compile(&r).is_none());
    let names: Vec<Arc<str>> = r.defs[r.root]
        .fields
        .iter()
        .map(|f| f.name.clone())
        .collect();
    assert_eq!(names.len(), 32);
}

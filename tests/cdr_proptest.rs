//! Property test: for generated ROS 2 schemas (primitives, strings, wstrings, fixed / bounded /
//! unbounded arrays, nested types) and generated values, CDR encode → decode is the identity,
//! in both byte orders. The schema goes through its text form, so the parser is exercised too.

use std::sync::Arc;

use peopletrack::log::Value;
use peopletrack::log::cdr::{self, Endian};
use peopletrack::log::ros2msg::Registry;
use proptest::prelude::*;

#[derive(Debug, Clone)]
enum Ty {
    Prim(&'static str),
    Str,
    WStr,
    Nested(Vec<Field>),
}

#[derive(Debug, Clone)]
enum Arr {
    Single,
    Fixed(usize),
    Bounded(usize),
    Unbounded,
}

#[derive(Debug, Clone)]
struct Field {
    ty: Ty,
    arr: Arr,
}

const PRIMS: &[&str] = &[
    "bool", "byte", "char", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64",
    "uint64", "float32", "float64",
];

fn arb_arr() -> impl Strategy<Value = Arr> {
    prop_oneof![
        3 => Just(Arr::Single),
        1 => (0usize..4).prop_map(Arr::Fixed),
        1 => (0usize..4).prop_map(Arr::Bounded),
        1 => Just(Arr::Unbounded),
    ]
}

fn arb_fields(depth: u32) -> BoxedStrategy<Vec<Field>> {
    let leaf = prop_oneof![
        6 => proptest::sample::select(PRIMS).prop_map(Ty::Prim),
        1 => Just(Ty::Str),
        1 => Just(Ty::WStr),
    ];
    let ty: BoxedStrategy<Ty> = if depth == 0 {
        leaf.boxed()
    } else {
        prop_oneof![4 => leaf, 1 => arb_fields(depth - 1).prop_map(Ty::Nested)].boxed()
    };
    proptest::collection::vec(
        (ty, arb_arr()).prop_map(|(ty, arr)| Field { ty, arr }),
        0..5,
    )
    .boxed()
}

/// Schema text: the root type, then one `MSG:` block per nested type (named N0, N1, ...).
fn schema_text(fields: &[Field]) -> String {
    let mut blocks: Vec<String> = Vec::new();
    fn render(fields: &[Field], blocks: &mut Vec<String>) -> String {
        let mut out = String::new();
        for (i, f) in fields.iter().enumerate() {
            let base = match &f.ty {
                Ty::Prim(p) => (*p).to_string(),
                Ty::Str => "string".into(),
                Ty::WStr => "wstring".into(),
                Ty::Nested(inner) => {
                    let idx = blocks.len();
                    blocks.push(String::new());
                    let body = render(inner, blocks);
                    blocks[idx] = format!("MSG: gen/N{idx}\n{body}");
                    format!("gen/N{idx}")
                }
            };
            let suffix = match f.arr {
                Arr::Single => String::new(),
                Arr::Fixed(n) => format!("[{n}]"),
                Arr::Bounded(n) => format!("[<={n}]"),
                Arr::Unbounded => "[]".into(),
            };
            out.push_str(&format!("{base}{suffix} f{i}\n"));
        }
        out
    }
    let root = render(fields, &mut blocks);
    let mut text = root;
    for b in blocks {
        text.push_str(
            "================================================================================\n",
        );
        text.push_str(&b);
    }
    text
}

fn arb_scalar(p: &'static str) -> BoxedStrategy<Value> {
    match p {
        "bool" => any::<bool>().prop_map(Value::Bool).boxed(),
        "byte" | "char" | "uint8" => any::<u8>().prop_map(Value::U8).boxed(),
        "int8" => any::<i8>().prop_map(Value::I8).boxed(),
        "int16" => any::<i16>().prop_map(Value::I16).boxed(),
        "uint16" => any::<u16>().prop_map(Value::U16).boxed(),
        "int32" => any::<i32>().prop_map(Value::I32).boxed(),
        "uint32" => any::<u32>().prop_map(Value::U32).boxed(),
        "int64" => any::<i64>().prop_map(Value::I64).boxed(),
        "uint64" => any::<u64>().prop_map(Value::U64).boxed(),
        "float32" => proptest::num::f32::NORMAL.prop_map(Value::F32).boxed(),
        _ => proptest::num::f64::NORMAL.prop_map(Value::F64).boxed(),
    }
}

/// Pack a list of scalars the way the decoder does.
fn pack(p: &str, items: Vec<Value>) -> Value {
    macro_rules! get {
        ($v:ident) => {
            items
                .into_iter()
                .map(|x| {
                    if let Value::$v(y) = x {
                        y
                    } else {
                        unreachable!()
                    }
                })
                .collect()
        };
    }
    match p {
        "bool" => Value::Bools(get!(Bool)),
        "byte" | "char" | "uint8" => Value::Bytes(get!(U8)),
        "int8" => Value::I8s(get!(I8)),
        "int16" => Value::I16s(get!(I16)),
        "uint16" => Value::U16s(get!(U16)),
        "int32" => Value::I32s(get!(I32)),
        "uint32" => Value::U32s(get!(U32)),
        "int64" => Value::I64s(get!(I64)),
        "uint64" => Value::U64s(get!(U64)),
        "float32" => Value::F32s(get!(F32)),
        _ => Value::F64s(get!(F64)),
    }
}

fn arb_single(ty: &Ty) -> BoxedStrategy<Value> {
    match ty {
        Ty::Prim(p) => arb_scalar(p),
        Ty::Str => "[a-zA-Z0-9 _/é]{0,12}".prop_map(Value::String).boxed(),
        Ty::WStr => "[a-z€ü]{0,6}".prop_map(Value::String).boxed(),
        Ty::Nested(fields) => arb_struct(fields),
    }
}

fn arb_struct(fields: &[Field]) -> BoxedStrategy<Value> {
    let strategies: Vec<BoxedStrategy<(Arc<str>, Value)>> = fields
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let name: Arc<str> = Arc::from(format!("f{i}").as_str());
            let len = match f.arr {
                Arr::Single => None,
                Arr::Fixed(n) => Some(n..n + 1),
                Arr::Bounded(n) => Some(0..n + 1),
                Arr::Unbounded => Some(0..6),
            };
            let ty = f.ty.clone();
            match len {
                None => arb_single(&ty).prop_map(move |v| (name.clone(), v)).boxed(),
                Some(range) => proptest::collection::vec(arb_single(&ty), range)
                    .prop_map(move |items| {
                        let v = match &ty {
                            Ty::Prim(p) => pack(p, items),
                            _ => Value::Array(items),
                        };
                        (name.clone(), v)
                    })
                    .boxed(),
            }
        })
        .collect();
    strategies.prop_map(Value::Struct).boxed()
}

fn arb_case() -> impl Strategy<Value = (String, Value)> {
    arb_fields(2).prop_flat_map(|fields| {
        let text = schema_text(&fields);
        arb_struct(&fields).prop_map(move |v| (text.clone(), v))
    })
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 400,
        failure_persistence: None,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x9e3779b97f4a7c15),
        ..ProptestConfig::default()
    })]

    #[test]
    fn encode_then_decode_is_identity((text, value) in arb_case(), big in any::<bool>()) {
        let reg = Registry::parse("gen/msg/Root", &text).map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        let endian = if big { Endian::Big } else { Endian::Little };
        let bytes = cdr::encode(&reg, &value, endian).map_err(|e| TestCaseError::fail(e.to_string()))?;
        let back = cdr::decode(&reg, &bytes).map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert_eq!(back, value);
    }

    #[test]
    fn truncated_payloads_error_instead_of_panicking((text, value) in arb_case(), cut in 0.0f64..1.0) {
        let reg = Registry::parse("gen/msg/Root", &text).map_err(|e| TestCaseError::fail(e.to_string()))?;
        let bytes = cdr::encode(&reg, &value, Endian::Little).map_err(|e| TestCaseError::fail(e.to_string()))?;
        let n = ((bytes.len() - 4) as f64 * cut) as usize + 4;
        if n < bytes.len() {
            // may decode if only trailing padding was cut; must never panic
            let _ = cdr::decode(&reg, &bytes[..n]);
        }
    }
}

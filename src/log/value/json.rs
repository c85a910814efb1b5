//! [`Value`] rendered as JSON through serde's serializer, without building a `serde_json`
//! tree first: `serde_json::to_writer(out, &value.json(max))` streams the text with the same
//! formatting (`serde_json`'s shortest round-trip floats, its string escaping, `null`) that
//! [`Value::to_json`] gives when the tree is printed, so `cat` output is byte-identical and
//! formatting no longer dominates it. The known-answer tests check the two against each other.

use serde::ser::{Serialize, SerializeMap, SerializeSeq, Serializer};

use super::Value;

/// A borrowed value that serializes as its JSON rendering ([`Value::json`]).
#[derive(Debug, Clone, Copy)]
pub struct Json<'a> {
    value: &'a Value,
    max_array: Option<usize>,
}

impl Value {
    /// JSON rendering as a [`Serialize`] view: the same text as [`Value::to_json`], streamed.
    pub fn json(&self, max_array: Option<usize>) -> Json<'_> {
        Json {
            value: self,
            max_array,
        }
    }
}

fn float<S: Serializer>(v: f64, s: S) -> Result<S::Ok, S::Error> {
    if v.is_finite() {
        s.serialize_f64(v)
    } else if v.is_nan() {
        s.serialize_str("NaN")
    } else if v > 0.0 {
        s.serialize_str("Infinity")
    } else {
        s.serialize_str("-Infinity")
    }
}

fn list<S: Serializer, T>(
    items: &[T],
    max: Option<usize>,
    s: S,
    f: impl Fn(&T, &mut S::SerializeSeq) -> Result<(), S::Error>,
) -> Result<S::Ok, S::Error> {
    let n = max.map_or(items.len(), |m| m.min(items.len()));
    let more = items.len() - n;
    let mut seq = s.serialize_seq(Some(n + usize::from(more > 0)))?;
    for x in &items[..n] {
        f(x, &mut seq)?;
    }
    if more > 0 {
        seq.serialize_element(&format!("... {more} more"))?;
    }
    seq.end()
}

/// A finite-or-not float element.
struct F(f64);

impl Serialize for F {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        float(self.0, s)
    }
}

impl Serialize for Json<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let max = self.max_array;
        match self.value {
            Value::Bool(b) => s.serialize_bool(*b),
            Value::I8(v) => s.serialize_i8(*v),
            Value::U8(v) => s.serialize_u8(*v),
            Value::I16(v) => s.serialize_i16(*v),
            Value::U16(v) => s.serialize_u16(*v),
            Value::I32(v) => s.serialize_i32(*v),
            Value::U32(v) => s.serialize_u32(*v),
            Value::I64(v) => s.serialize_i64(*v),
            Value::U64(v) => s.serialize_u64(*v),
            // f32 -> f64 is exact; the shortest f64 that round-trips that value
            Value::F32(v) => float(f64::from(*v), s),
            Value::F64(v) => float(*v, s),
            Value::String(v) => s.serialize_str(v),
            Value::Struct(fields) => {
                let mut m = s.serialize_map(Some(fields.len()))?;
                for (k, v) in fields {
                    m.serialize_entry(&**k, &v.json(max))?;
                }
                m.end()
            }
            Value::Array(v) => list(v, max, s, |x, q| q.serialize_element(&x.json(max))),
            Value::Bools(v) => list(v, max, s, |x, q| q.serialize_element(x)),
            Value::Bytes(v) => list(v, max, s, |x, q| q.serialize_element(x)),
            Value::I8s(v) => list(v, max, s, |x, q| q.serialize_element(x)),
            Value::I16s(v) => list(v, max, s, |x, q| q.serialize_element(x)),
            Value::U16s(v) => list(v, max, s, |x, q| q.serialize_element(x)),
            Value::I32s(v) => list(v, max, s, |x, q| q.serialize_element(x)),
            Value::U32s(v) => list(v, max, s, |x, q| q.serialize_element(x)),
            Value::I64s(v) => list(v, max, s, |x, q| q.serialize_element(x)),
            Value::U64s(v) => list(v, max, s, |x, q| q.serialize_element(x)),
            Value::F32s(v) => list(v, max, s, |x, q| q.serialize_element(&F(f64::from(*x)))),
            Value::F64s(v) => list(v, max, s, |x, q| q.serialize_element(&F(*x))),
            Value::Null => s.serialize_unit(),
        }
    }
}

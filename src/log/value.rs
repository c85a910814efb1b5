//! The generic value tree every decoder produces (ROS 2 CDR, Foxglove protobuf, JSON).
//!
//! Arrays of numbers are stored packed (`Vec<f32>`, `Vec<u8>`, ...) rather than as one
//! [`Value`] per element, so a laser scan or an image decodes into a handful of allocations and
//! typed messages take their buffers over without copying. Structures keep their fields in wire
//! order with names shared from the schema.
//!
//! JSON rendering follows the protobuf JSON mapping for non-finite floats (`"NaN"`,
//! `"Infinity"`, `"-Infinity"`), so `cat` output stays valid JSON and keeps no-returns visible.

use std::sync::Arc;

mod json;

pub use json::Json;

/// A decoded message or part of one.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    Bool(bool),
    I8(i8),
    U8(u8),
    I16(i16),
    U16(u16),
    I32(i32),
    U32(u32),
    I64(i64),
    U64(u64),
    F32(f32),
    F64(f64),
    String(String),
    /// A nested message: fields in declaration order.
    Struct(Vec<(Arc<str>, Value)>),
    /// An array of strings or messages (or mixed JSON values).
    Array(Vec<Value>),
    /// Packed `bool[]`.
    Bools(Vec<bool>),
    /// Packed `uint8[]`, `byte[]`, `char[]` and protobuf `bytes`.
    Bytes(Vec<u8>),
    I8s(Vec<i8>),
    I16s(Vec<i16>),
    U16s(Vec<u16>),
    I32s(Vec<i32>),
    U32s(Vec<u32>),
    I64s(Vec<i64>),
    U64s(Vec<u64>),
    F32s(Vec<f32>),
    F64s(Vec<f64>),
    /// JSON `null` (only from JSON messages).
    Null,
}

/// Why a value could not be read as the type a typed message expects. `path` is the dotted
/// field path from the message root, built up as the error propagates.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("field `{path}`: {reason}")]
pub struct FieldError {
    pub path: String,
    pub reason: String,
}

impl FieldError {
    pub fn new(reason: impl Into<String>) -> Self {
        FieldError {
            path: String::new(),
            reason: reason.into(),
        }
    }

    /// Prefix the path with the enclosing field's name.
    pub fn within(mut self, field: &str) -> Self {
        self.path = if self.path.is_empty() {
            field.to_string()
        } else if self.path.starts_with('[') {
            format!("{field}{}", self.path)
        } else {
            format!("{field}.{}", self.path)
        };
        self
    }
}

impl Value {
    /// A short name of the variant, for error messages.
    pub fn kind(&self) -> &'static str {
        match self {
            Value::Bool(_) => "bool",
            Value::I8(_) => "int8",
            Value::U8(_) => "uint8",
            Value::I16(_) => "int16",
            Value::U16(_) => "uint16",
            Value::I32(_) => "int32",
            Value::U32(_) => "uint32",
            Value::I64(_) => "int64",
            Value::U64(_) => "uint64",
            Value::F32(_) => "float32",
            Value::F64(_) => "float64",
            Value::String(_) => "string",
            Value::Struct(_) => "struct",
            Value::Array(_) => "array",
            Value::Bools(_) => "bool[]",
            Value::Bytes(_) => "uint8[]",
            Value::I8s(_) => "int8[]",
            Value::I16s(_) => "int16[]",
            Value::U16s(_) => "uint16[]",
            Value::I32s(_) => "int32[]",
            Value::U32s(_) => "uint32[]",
            Value::I64s(_) => "int64[]",
            Value::U64s(_) => "uint64[]",
            Value::F32s(_) => "float32[]",
            Value::F64s(_) => "float64[]",
            Value::Null => "null",
        }
    }

    fn mismatch(&self, want: &str) -> FieldError {
        FieldError::new(format!("expected {want}, found {}", self.kind()))
    }

    /// The field `name` of a structure.
    pub fn get(&self, name: &str) -> Result<&Value, FieldError> {
        match self {
            Value::Struct(fields) => fields
                .iter()
                .find(|(n, _)| &**n == name)
                .map(|(_, v)| v)
                .ok_or_else(|| FieldError::new("missing").within(name)),
            other => Err(other.mismatch("struct").within(name)),
        }
    }

    /// Take the field `name` out of a structure (leaving `Null`), so buffers move, not copy.
    pub fn take(&mut self, name: &str) -> Result<Value, FieldError> {
        match self {
            Value::Struct(fields) => fields
                .iter_mut()
                .find(|(n, _)| &**n == name)
                .map(|(_, v)| std::mem::replace(v, Value::Null))
                .ok_or_else(|| FieldError::new("missing").within(name)),
            other => Err(other.mismatch("struct").within(name)),
        }
    }

    /// Any numeric scalar as `f64` (integers convert exactly up to 2^53).
    pub fn as_f64(&self) -> Result<f64, FieldError> {
        Ok(match *self {
            Value::I8(v) => v.into(),
            Value::U8(v) => v.into(),
            Value::I16(v) => v.into(),
            Value::U16(v) => v.into(),
            Value::I32(v) => v.into(),
            Value::U32(v) => v.into(),
            Value::I64(v) => v as f64,
            Value::U64(v) => v as f64,
            Value::F32(v) => v.into(),
            Value::F64(v) => v,
            ref other => return Err(other.mismatch("a number")),
        })
    }

    /// Any integer scalar as `i128`; floats only when they hold an exact integer (JSON).
    pub fn as_i128(&self) -> Result<i128, FieldError> {
        Ok(match *self {
            Value::Bool(b) => b.into(),
            Value::I8(v) => v.into(),
            Value::U8(v) => v.into(),
            Value::I16(v) => v.into(),
            Value::U16(v) => v.into(),
            Value::I32(v) => v.into(),
            Value::U32(v) => v.into(),
            Value::I64(v) => v.into(),
            Value::U64(v) => v.into(),
            Value::F64(v) if v.fract() == 0.0 && v.abs() < 9.0e15 => v as i128,
            ref other => return Err(other.mismatch("an integer")),
        })
    }

    pub fn as_u32(&self) -> Result<u32, FieldError> {
        let v = self.as_i128()?;
        u32::try_from(v).map_err(|_| FieldError::new(format!("{v} does not fit in uint32")))
    }

    pub fn as_i32(&self) -> Result<i32, FieldError> {
        let v = self.as_i128()?;
        i32::try_from(v).map_err(|_| FieldError::new(format!("{v} does not fit in int32")))
    }

    pub fn as_u8(&self) -> Result<u8, FieldError> {
        let v = self.as_i128()?;
        u8::try_from(v).map_err(|_| FieldError::new(format!("{v} does not fit in uint8")))
    }

    pub fn as_bool(&self) -> Result<bool, FieldError> {
        match *self {
            Value::Bool(b) => Ok(b),
            ref other => Err(other.mismatch("bool")),
        }
    }

    pub fn as_str(&self) -> Result<&str, FieldError> {
        match self {
            Value::String(s) => Ok(s),
            other => Err(other.mismatch("string")),
        }
    }

    pub fn into_string(self) -> Result<String, FieldError> {
        match self {
            Value::String(s) => Ok(s),
            other => Err(other.mismatch("string")),
        }
    }

    /// A packed byte array (also accepts an array of small integers, as JSON gives).
    pub fn into_bytes(self) -> Result<Vec<u8>, FieldError> {
        match self {
            Value::Bytes(b) => Ok(b),
            Value::Array(items) => items.iter().map(Value::as_u8).collect(),
            other => Err(other.mismatch("uint8[]")),
        }
    }

    /// Any numeric array as `Vec<f32>` (packed float32 moves without copying).
    pub fn into_f32s(self) -> Result<Vec<f32>, FieldError> {
        match self {
            Value::F32s(v) => Ok(v),
            Value::F64s(v) => Ok(v.into_iter().map(|x| x as f32).collect()),
            other => Ok(other.into_f64s()?.into_iter().map(|x| x as f32).collect()),
        }
    }

    /// Any numeric array as `Vec<f64>`.
    pub fn into_f64s(self) -> Result<Vec<f64>, FieldError> {
        Ok(match self {
            Value::F64s(v) => v,
            Value::F32s(v) => v.into_iter().map(f64::from).collect(),
            Value::Bytes(v) => v.into_iter().map(f64::from).collect(),
            Value::I8s(v) => v.into_iter().map(f64::from).collect(),
            Value::I16s(v) => v.into_iter().map(f64::from).collect(),
            Value::U16s(v) => v.into_iter().map(f64::from).collect(),
            Value::I32s(v) => v.into_iter().map(f64::from).collect(),
            Value::U32s(v) => v.into_iter().map(f64::from).collect(),
            Value::I64s(v) => v.into_iter().map(|x| x as f64).collect(),
            Value::U64s(v) => v.into_iter().map(|x| x as f64).collect(),
            Value::Array(items) => items
                .iter()
                .enumerate()
                .map(|(i, x)| x.as_f64().map_err(|e| e.within(&format!("[{i}]"))))
                .collect::<Result<_, _>>()?,
            other => return Err(other.mismatch("a numeric array")),
        })
    }

    /// A fixed-size numeric array, e.g. a 3x3 covariance.
    pub fn into_f64_array<const N: usize>(self) -> Result<[f64; N], FieldError> {
        let v = self.into_f64s()?;
        let n = v.len();
        v.try_into()
            .map_err(|_| FieldError::new(format!("expected {N} elements, found {n}")))
    }

    /// The elements of an array of strings or structures.
    pub fn into_array(self) -> Result<Vec<Value>, FieldError> {
        match self {
            Value::Array(items) => Ok(items),
            other => Err(other.mismatch("an array of messages")),
        }
    }

    /// Number of elements if this is an array of any kind.
    pub fn array_len(&self) -> Option<usize> {
        Some(match self {
            Value::Array(v) => v.len(),
            Value::Bools(v) => v.len(),
            Value::Bytes(v) => v.len(),
            Value::I8s(v) => v.len(),
            Value::I16s(v) => v.len(),
            Value::U16s(v) => v.len(),
            Value::I32s(v) => v.len(),
            Value::U32s(v) => v.len(),
            Value::I64s(v) => v.len(),
            Value::U64s(v) => v.len(),
            Value::F32s(v) => v.len(),
            Value::F64s(v) => v.len(),
            _ => return None,
        })
    }

    /// Render as JSON. `max_array` truncates long arrays (for human reading) and appends a
    /// string saying how many elements were left out; `None` writes every element.
    pub fn to_json(&self, max_array: Option<usize>) -> serde_json::Value {
        use serde_json::Value as J;
        fn float(v: f64) -> J {
            if v.is_finite() {
                serde_json::Number::from_f64(v).map_or(J::Null, J::Number)
            } else if v.is_nan() {
                J::String("NaN".into())
            } else if v > 0.0 {
                J::String("Infinity".into())
            } else {
                J::String("-Infinity".into())
            }
        }
        fn list<T>(items: &[T], max: Option<usize>, f: impl Fn(&T) -> J) -> J {
            let n = max.map_or(items.len(), |m| m.min(items.len()));
            let mut out: Vec<J> = items[..n].iter().map(f).collect();
            if n < items.len() {
                out.push(J::String(format!("... {} more", items.len() - n)));
            }
            J::Array(out)
        }
        match self {
            Value::Bool(b) => J::Bool(*b),
            Value::I8(v) => J::from(*v),
            Value::U8(v) => J::from(*v),
            Value::I16(v) => J::from(*v),
            Value::U16(v) => J::from(*v),
            Value::I32(v) => J::from(*v),
            Value::U32(v) => J::from(*v),
            Value::I64(v) => J::from(*v),
            Value::U64(v) => J::from(*v),
            // f32 -> f64 is exact; print the shortest f64 that round-trips that value.
            Value::F32(v) => float(f64::from(*v)),
            Value::F64(v) => float(*v),
            Value::String(s) => J::String(s.clone()),
            Value::Struct(fields) => J::Object(
                fields
                    .iter()
                    .map(|(k, v)| (k.to_string(), v.to_json(max_array)))
                    .collect(),
            ),
            Value::Array(v) => list(v, max_array, |x| x.to_json(max_array)),
            Value::Bools(v) => list(v, max_array, |x| J::Bool(*x)),
            Value::Bytes(v) => list(v, max_array, |x| J::from(*x)),
            Value::I8s(v) => list(v, max_array, |x| J::from(*x)),
            Value::I16s(v) => list(v, max_array, |x| J::from(*x)),
            Value::U16s(v) => list(v, max_array, |x| J::from(*x)),
            Value::I32s(v) => list(v, max_array, |x| J::from(*x)),
            Value::U32s(v) => list(v, max_array, |x| J::from(*x)),
            Value::I64s(v) => list(v, max_array, |x| J::from(*x)),
            Value::U64s(v) => list(v, max_array, |x| J::from(*x)),
            Value::F32s(v) => list(v, max_array, |x| float(f64::from(*x))),
            Value::F64s(v) => list(v, max_array, |x| float(*x)),
            Value::Null => J::Null,
        }
    }

    /// Build a value from JSON (for JSON-encoded channels). Integers stay integers, other
    /// numbers become `F64`, objects keep their key order.
    pub fn from_json(j: &serde_json::Value) -> Value {
        use serde_json::Value as J;
        match j {
            J::Null => Value::Null,
            J::Bool(b) => Value::Bool(*b),
            J::Number(n) => {
                if let Some(i) = n.as_i64() {
                    Value::I64(i)
                } else if let Some(u) = n.as_u64() {
                    Value::U64(u)
                } else {
                    Value::F64(n.as_f64().unwrap_or(f64::NAN))
                }
            }
            J::String(s) => Value::String(s.clone()),
            J::Array(items) => Value::Array(items.iter().map(Value::from_json).collect()),
            J::Object(map) => Value::Struct(
                map.iter()
                    .map(|(k, v)| (Arc::from(k.as_str()), Value::from_json(v)))
                    .collect(),
            ),
        }
    }
}

/// Build a structure from `(name, value)` pairs.
pub fn record(fields: impl IntoIterator<Item = (&'static str, Value)>) -> Value {
    Value::Struct(fields.into_iter().map(|(k, v)| (Arc::from(k), v)).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_keeps_non_finite_floats_visible() {
        let v = Value::F32s(vec![1.5, f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.0]);
        assert_eq!(
            v.to_json(None).to_string(),
            r#"[1.5,"NaN","Infinity","-Infinity",0.0]"#
        );
    }

    /// The streamed rendering is byte-identical to printing the `serde_json` tree.
    fn same_text(v: &Value, max: Option<usize>) {
        let tree = v.to_json(max).to_string();
        let streamed = serde_json::to_string(&v.json(max)).expect("serializes");
        assert_eq!(streamed, tree);
    }

    #[test]
    fn streamed_json_equals_the_tree_rendering() {
        let v = record([
            ("b", Value::Bool(true)),
            ("i", Value::I8(-8)),
            ("u", Value::U64(u64::MAX)),
            ("l", Value::I64(i64::MIN)),
            ("f", Value::F32(0.1)),
            ("d", Value::F64(1e-310)),
            ("e", Value::F64(-0.0)),
            ("big", Value::F64(1.5e300)),
            ("n", Value::F64(f64::NAN)),
            ("s", Value::String("quote \" tab \t é \u{1} ☃".into())),
            ("z", Value::Null),
            ("empty", Value::Struct(vec![])),
            (
                "a",
                Value::Array(vec![
                    record([("x", Value::U16(7))]),
                    Value::String("y".into()),
                ]),
            ),
            ("bs", Value::Bools(vec![true, false])),
            ("by", Value::Bytes(vec![0, 255, 7])),
            ("i8s", Value::I8s(vec![-1, 2])),
            ("i16s", Value::I16s(vec![-300])),
            ("u16s", Value::U16s(vec![65535])),
            ("i32s", Value::I32s(vec![i32::MIN])),
            ("u32s", Value::U32s(vec![u32::MAX, 0])),
            ("i64s", Value::I64s(vec![])),
            ("u64s", Value::U64s(vec![1, 2, 3])),
            (
                "f32s",
                Value::F32s(vec![1.5, f32::NAN, f32::NEG_INFINITY, 3.4e38, 1e-45]),
            ),
            (
                "f64s",
                Value::F64s(vec![0.1 + 0.2, f64::INFINITY, 123456789.0, 1e21]),
            ),
        ]);
        for max in [None, Some(0), Some(1), Some(2), Some(100)] {
            same_text(&v, max);
        }
        same_text(&Value::F64s(vec![]), Some(0));
    }

    #[test]
    fn json_truncation_says_how_much_was_left_out() {
        let v = Value::Bytes(vec![1, 2, 3, 4]);
        assert_eq!(v.to_json(Some(2)).to_string(), r#"[1,2,"... 2 more"]"#);
    }

    #[test]
    fn errors_carry_the_field_path() {
        let v = record([("header", record([("stamp", Value::I32(1))]))]);
        let e = v
            .get("header")
            .and_then(|h| h.get("frame_id"))
            .expect_err("missing");
        assert_eq!(e.to_string(), "field `frame_id`: missing");
        let e = FieldError::new("bad").within("[3]").within("poses");
        assert_eq!(e.path, "poses[3]");
    }

    #[test]
    fn json_round_trip_keeps_integers_and_order() {
        let j: serde_json::Value =
            serde_json::from_str(r#"{"b":1,"a":[2.5,-3],"c":"x"}"#).expect("valid json");
        let v = Value::from_json(&j);
        assert_eq!(v.get("b").and_then(Value::as_i128), Ok(1));
        assert_eq!(v.to_json(None), j);
    }
}

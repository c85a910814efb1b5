//! Reading a flat-decoded message: one field by its [`FieldRef`], or the whole message as the
//! value tree the tree decoder would have built.

use super::super::super::ros2msg::{ArrayKind, Prim};
use super::super::super::value::{FieldError, Value};
use super::super::packed_value;
use super::{FieldRef, FlatRef, IN_TEXT, Leaf, Plan, unpack};

/// A scalar slot as its value.
fn scalar(p: Prim, bits: u64) -> Value {
    match p {
        Prim::Bool => Value::Bool(bits != 0),
        Prim::Byte | Prim::Char | Prim::U8 => Value::U8(bits as u8),
        Prim::I8 => Value::I8(bits as i8),
        Prim::I16 => Value::I16(bits as i16),
        Prim::U16 => Value::U16(bits as u16),
        Prim::I32 => Value::I32(bits as i32),
        Prim::U32 => Value::U32(bits as u32),
        Prim::I64 => Value::I64(bits as i64),
        Prim::U64 => Value::U64(bits),
        Prim::F32 => Value::F32(f32::from_bits(bits as u32)),
        Prim::F64 => Value::F64(f64::from_bits(bits)),
    }
}

impl<'s, 'm> FlatRef<'s, 'm> {
    /// The plan the message was decoded by (to locate fields: [`Plan::field`]).
    pub fn plan(&self) -> &'s Plan {
        self.plan
    }

    /// The field at `path` (see [`Plan::field`]) as a value; scalars allocate nothing.
    pub fn get(&self, path: &str) -> Result<Value, FieldError> {
        self.plan.field(path).map(|f| self.value(&f))
    }

    /// A located field's value (arrays and messages as the tree decoder builds them).
    pub fn value(&self, f: &FieldRef) -> Value {
        self.leaf(f.leaf, f.array, f.slot)
    }

    /// The whole message as a value tree, equal to what [`super::super::decode`] gives.
    pub fn to_value(&self) -> Value {
        self.message(self.plan.root, 0)
    }

    /// The string in slot `slot`: borrowed from the payload or from the text buffer.
    fn str_at(&self, slot: u64) -> &str {
        let (start, len) = unpack(slot);
        if slot & IN_TEXT != 0 {
            &self.text[start..start + len]
        } else {
            // checked to be UTF-8 when decoded
            std::str::from_utf8(&self.body[start..start + len]).unwrap_or_default()
        }
    }

    fn message(&self, d: usize, base: usize) -> Value {
        let fields = &self.plan.layouts[d].fields;
        Value::Struct(
            fields
                .iter()
                .map(|f| {
                    (
                        std::sync::Arc::clone(&f.name),
                        self.leaf(f.leaf, f.array, base + f.offset),
                    )
                })
                .collect(),
        )
    }

    fn leaf(&self, leaf: Leaf, array: ArrayKind, at: usize) -> Value {
        let slot = self.slots[at];
        if array == ArrayKind::Single {
            return match leaf {
                Leaf::Prim(p) => scalar(p, slot),
                Leaf::Str { .. } => Value::String(self.str_at(slot).to_string()),
                Leaf::Msg(d) => self.message(d, at),
                Leaf::Packed(_) | Leaf::Strings { .. } | Leaf::Msgs(_) => Value::Null,
            };
        }
        let (first, n) = unpack(slot);
        match leaf {
            Leaf::Packed(p) => packed_value(p, &self.body[first..first + n * p.size()], self.big),
            Leaf::Strings { .. } => Value::Array(
                (0..n)
                    .map(|i| Value::String(self.str_at(self.slots[first + i]).to_string()))
                    .collect(),
            ),
            Leaf::Msgs(d) => {
                let w = self.plan.layouts[d].width;
                Value::Array((0..n).map(|i| self.message(d, first + i * w)).collect())
            }
            Leaf::Prim(_) | Leaf::Str { .. } | Leaf::Msg(_) => Value::Null,
        }
    }
}

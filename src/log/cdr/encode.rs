//! CDR encoding of a [`Value`] as a registry's type (the writer's half of [`super`]): the wire
//! rules of the module docs, missing fields filled with their schema default or zero.

use std::sync::Arc;

use super::super::ros2msg::{ArrayKind, BaseType, Literal, MsgDef, Prim, Registry};
use super::super::value::Value;
use super::{CdrError, CdrErrorKind, Endian, Result};

/// Encode `value` as the registry's root type.
pub fn encode(registry: &Registry, value: &Value, endian: Endian) -> Result<Vec<u8>> {
    let mut w = Writer {
        buf: Vec::with_capacity(256),
        big: endian == Endian::Big,
    };
    w.buf
        .extend_from_slice(&[0, if w.big { 0 } else { 1 }, 0, 0]);
    w.write_struct(registry, registry.root, value)?;
    Ok(w.buf)
}

struct Writer {
    buf: Vec<u8>,
    big: bool,
}

macro_rules! write_scalar {
    ($name:ident, $t:ty) => {
        fn $name(&mut self, v: $t) {
            self.align(std::mem::size_of::<$t>());
            if self.big {
                self.buf.extend_from_slice(&v.to_be_bytes());
            } else {
                self.buf.extend_from_slice(&v.to_le_bytes());
            }
        }
    };
}

fn wrong(expected: impl Into<String>, found: &Value) -> CdrError {
    CdrError::new(CdrErrorKind::WrongType {
        expected: expected.into(),
        found: found.kind(),
    })
}

fn int_in(value: &Value, lo: i128, hi: i128, ty: &'static str) -> Result<i128> {
    let v = match value {
        Value::F32(_) | Value::F64(_) => return Err(wrong(ty, value)),
        other => other.as_i128().map_err(|_| wrong(ty, other))?,
    };
    if v < lo || v > hi {
        return Err(CdrError::new(CdrErrorKind::OutOfRange {
            value: v.to_string(),
            ty,
        }));
    }
    Ok(v)
}

impl Writer {
    fn align(&mut self, size: usize) {
        let pos = self.buf.len() - 4;
        let rem = pos % size;
        if rem != 0 {
            self.buf.resize(self.buf.len() + size - rem, 0);
        }
    }

    write_scalar!(u16, u16);
    write_scalar!(i16, i16);
    write_scalar!(u32, u32);
    write_scalar!(i32, i32);
    write_scalar!(u64, u64);
    write_scalar!(i64, i64);
    write_scalar!(f32, f32);
    write_scalar!(f64, f64);

    fn len_prefix(&mut self, n: usize) -> Result<()> {
        let n = u32::try_from(n).map_err(|_| {
            CdrError::new(CdrErrorKind::OutOfRange {
                value: n.to_string(),
                ty: "uint32 sequence length",
            })
        })?;
        self.u32(n);
        Ok(())
    }

    fn write_struct(&mut self, reg: &Registry, idx: usize, value: &Value) -> Result<()> {
        let def: &MsgDef = &reg.defs[idx];
        let Value::Struct(given) = value else {
            return Err(wrong(format!("message {}", def.name), value));
        };
        if let Some((name, _)) = given
            .iter()
            .find(|(n, _)| !def.fields.iter().any(|f| f.name == *n))
        {
            return Err(CdrError::new(CdrErrorKind::UnknownField(name.to_string())));
        }
        if def.fields.is_empty() {
            self.buf.push(0);
            return Ok(());
        }
        for f in &def.fields {
            let result = match given.iter().find(|(n, _)| *n == f.name) {
                Some((_, v)) => self.write_field(reg, &f.ty, f.array, v),
                None => {
                    let v = default_value(reg, &f.ty, f.array, f.default.as_ref());
                    self.write_field(reg, &f.ty, f.array, &v)
                }
            };
            result.map_err(|e| e.within(&f.name))?;
        }
        Ok(())
    }

    fn write_field(
        &mut self,
        reg: &Registry,
        ty: &BaseType,
        array: ArrayKind,
        v: &Value,
    ) -> Result<()> {
        match array {
            ArrayKind::Single => self.write_single(reg, ty, v),
            ArrayKind::Fixed(n) => {
                let len = v.array_len().ok_or_else(|| wrong("an array", v))?;
                if len != n {
                    return Err(CdrError::new(CdrErrorKind::FixedLength {
                        expected: n,
                        found: len,
                    }));
                }
                self.write_elements(reg, ty, v)
            }
            ArrayKind::Bounded(bound) => {
                let len = v.array_len().ok_or_else(|| wrong("an array", v))?;
                if len > bound {
                    return Err(CdrError::new(CdrErrorKind::BoundExceeded {
                        bound,
                        found: len,
                    }));
                }
                self.len_prefix(len)?;
                self.write_elements(reg, ty, v)
            }
            ArrayKind::Unbounded => {
                let len = v.array_len().ok_or_else(|| wrong("an array", v))?;
                self.len_prefix(len)?;
                self.write_elements(reg, ty, v)
            }
        }
    }

    /// A packed array of `N`-byte numbers, aligned to `N` when not empty.
    fn put_packed<T: Copy, const N: usize>(
        &mut self,
        xs: &[T],
        be: fn(T) -> [u8; N],
        le: fn(T) -> [u8; N],
    ) {
        if !xs.is_empty() {
            self.align(N);
        }
        self.buf.reserve(xs.len() * N);
        let bytes = if self.big { be } else { le };
        for &x in xs {
            self.buf.extend_from_slice(&bytes(x));
        }
    }

    fn write_elements(&mut self, reg: &Registry, ty: &BaseType, v: &Value) -> Result<()> {
        // Fast paths: packed arrays whose variant matches the wire type exactly.
        match (ty, v) {
            (BaseType::Prim(Prim::U8 | Prim::Byte | Prim::Char), Value::Bytes(b)) => {
                self.buf.extend_from_slice(b);
                return Ok(());
            }
            (BaseType::Prim(Prim::F32), Value::F32s(xs)) => {
                self.put_packed(xs, f32::to_be_bytes, f32::to_le_bytes);
                return Ok(());
            }
            (BaseType::Prim(Prim::F64), Value::F64s(xs)) => {
                self.put_packed(xs, f64::to_be_bytes, f64::to_le_bytes);
                return Ok(());
            }
            _ => {}
        }
        let items = elements(v);
        for (i, item) in items.iter().enumerate() {
            self.write_single(reg, ty, item)
                .map_err(|e| e.within(&format!("[{i}]")))?;
        }
        Ok(())
    }

    fn write_single(&mut self, reg: &Registry, ty: &BaseType, v: &Value) -> Result<()> {
        match ty {
            BaseType::Prim(p) => self.write_prim(*p, v),
            BaseType::String { bound } => {
                let s = v.as_str().map_err(|_| wrong("string", v))?;
                if let Some(b) = bound
                    && s.len() > *b
                {
                    return Err(CdrError::new(CdrErrorKind::BoundExceeded {
                        bound: *b,
                        found: s.len(),
                    }));
                }
                self.len_prefix(s.len() + 1)?;
                self.buf.extend_from_slice(s.as_bytes());
                self.buf.push(0);
                Ok(())
            }
            BaseType::WString { bound } => {
                let s = v.as_str().map_err(|_| wrong("wstring", v))?;
                let n = s.chars().count();
                if let Some(b) = bound
                    && n > *b
                {
                    return Err(CdrError::new(CdrErrorKind::BoundExceeded {
                        bound: *b,
                        found: n,
                    }));
                }
                self.len_prefix(n)?;
                for c in s.chars() {
                    self.u32(c as u32);
                }
                Ok(())
            }
            BaseType::Msg(i) => self.write_struct(reg, *i, v),
        }
    }

    fn write_prim(&mut self, p: Prim, v: &Value) -> Result<()> {
        match p {
            Prim::Bool => {
                let b = match v {
                    Value::Bool(b) => *b,
                    other => int_in(other, 0, 1, "bool")? == 1,
                };
                self.buf.push(u8::from(b));
            }
            Prim::Byte | Prim::Char | Prim::U8 => self.buf.push(int_in(v, 0, 255, "uint8")? as u8),
            Prim::I8 => self.buf.push(int_in(v, -128, 127, "int8")? as i8 as u8),
            Prim::I16 => self.i16(int_in(v, i16::MIN.into(), i16::MAX.into(), "int16")? as i16),
            Prim::U16 => self.u16(int_in(v, 0, u16::MAX.into(), "uint16")? as u16),
            Prim::I32 => self.i32(int_in(v, i32::MIN.into(), i32::MAX.into(), "int32")? as i32),
            Prim::U32 => self.u32(int_in(v, 0, u32::MAX.into(), "uint32")? as u32),
            Prim::I64 => self.i64(int_in(v, i64::MIN.into(), i64::MAX.into(), "int64")? as i64),
            Prim::U64 => self.u64(int_in(v, 0, u64::MAX.into(), "uint64")? as u64),
            Prim::F32 => self.f32(v.as_f64().map_err(|_| wrong("float32", v))? as f32),
            Prim::F64 => self.f64(v.as_f64().map_err(|_| wrong("float64", v))?),
        }
        Ok(())
    }
}

/// The elements of any array value as individual values (packed arrays are expanded).
fn elements(v: &Value) -> Vec<Value> {
    match v {
        Value::Array(items) => items.clone(),
        Value::Bools(x) => x.iter().map(|b| Value::Bool(*b)).collect(),
        Value::Bytes(x) => x.iter().map(|b| Value::U8(*b)).collect(),
        Value::I8s(x) => x.iter().map(|b| Value::I8(*b)).collect(),
        Value::I16s(x) => x.iter().map(|b| Value::I16(*b)).collect(),
        Value::U16s(x) => x.iter().map(|b| Value::U16(*b)).collect(),
        Value::I32s(x) => x.iter().map(|b| Value::I32(*b)).collect(),
        Value::U32s(x) => x.iter().map(|b| Value::U32(*b)).collect(),
        Value::I64s(x) => x.iter().map(|b| Value::I64(*b)).collect(),
        Value::U64s(x) => x.iter().map(|b| Value::U64(*b)).collect(),
        Value::F32s(x) => x.iter().map(|b| Value::F32(*b)).collect(),
        Value::F64s(x) => x.iter().map(|b| Value::F64(*b)).collect(),
        _ => Vec::new(),
    }
}

/// The value a missing field takes: its schema default, or zero / empty.
pub fn default_value(
    reg: &Registry,
    ty: &BaseType,
    array: ArrayKind,
    default: Option<&Literal>,
) -> Value {
    if let Some(lit) = default {
        return literal_value(ty, lit);
    }
    match array {
        ArrayKind::Single => zero(reg, ty),
        ArrayKind::Fixed(n) => match ty {
            BaseType::Prim(_) => packed_zeros(ty, n),
            _ => Value::Array((0..n).map(|_| zero(reg, ty)).collect()),
        },
        ArrayKind::Bounded(_) | ArrayKind::Unbounded => match ty {
            BaseType::Prim(_) => packed_zeros(ty, 0),
            _ => Value::Array(Vec::new()),
        },
    }
}

fn packed_zeros(ty: &BaseType, n: usize) -> Value {
    match ty {
        BaseType::Prim(Prim::Bool) => Value::Bools(vec![false; n]),
        BaseType::Prim(Prim::Byte | Prim::Char | Prim::U8) => Value::Bytes(vec![0; n]),
        BaseType::Prim(Prim::I8) => Value::I8s(vec![0; n]),
        BaseType::Prim(Prim::I16) => Value::I16s(vec![0; n]),
        BaseType::Prim(Prim::U16) => Value::U16s(vec![0; n]),
        BaseType::Prim(Prim::I32) => Value::I32s(vec![0; n]),
        BaseType::Prim(Prim::U32) => Value::U32s(vec![0; n]),
        BaseType::Prim(Prim::I64) => Value::I64s(vec![0; n]),
        BaseType::Prim(Prim::U64) => Value::U64s(vec![0; n]),
        BaseType::Prim(Prim::F32) => Value::F32s(vec![0.0; n]),
        BaseType::Prim(Prim::F64) => Value::F64s(vec![0.0; n]),
        _ => Value::Array(Vec::new()),
    }
}

fn zero(reg: &Registry, ty: &BaseType) -> Value {
    match ty {
        BaseType::Prim(p) => prim_from_i128(*p, 0),
        BaseType::String { .. } | BaseType::WString { .. } => Value::String(String::new()),
        BaseType::Msg(i) => Value::Struct(
            reg.defs[*i]
                .fields
                .iter()
                .map(|f| {
                    (
                        Arc::clone(&f.name),
                        default_value(reg, &f.ty, f.array, f.default.as_ref()),
                    )
                })
                .collect(),
        ),
    }
}

fn prim_from_i128(p: Prim, v: i128) -> Value {
    match p {
        Prim::Bool => Value::Bool(v != 0),
        Prim::Byte | Prim::Char | Prim::U8 => Value::U8(v as u8),
        Prim::I8 => Value::I8(v as i8),
        Prim::I16 => Value::I16(v as i16),
        Prim::U16 => Value::U16(v as u16),
        Prim::I32 => Value::I32(v as i32),
        Prim::U32 => Value::U32(v as u32),
        Prim::I64 => Value::I64(v as i64),
        Prim::U64 => Value::U64(v as u64),
        Prim::F32 => Value::F32(v as f32),
        Prim::F64 => Value::F64(v as f64),
    }
}

/// A parsed literal as a value of the field's type (ranges were checked by the parser).
pub fn literal_value(ty: &BaseType, lit: &Literal) -> Value {
    match (ty, lit) {
        (_, Literal::Array(items)) => {
            let values: Vec<Value> = items.iter().map(|l| literal_value(ty, l)).collect();
            if let BaseType::Prim(_) = ty {
                pack(ty, &values)
            } else {
                Value::Array(values)
            }
        }
        (BaseType::Prim(Prim::F32), Literal::Float(f)) => Value::F32(*f as f32),
        (BaseType::Prim(Prim::F64), Literal::Float(f)) => Value::F64(*f),
        (BaseType::Prim(Prim::F32), Literal::Int(i)) => Value::F32(*i as f32),
        (BaseType::Prim(Prim::F64), Literal::Int(i)) => Value::F64(*i as f64),
        (BaseType::Prim(p), Literal::Int(i)) => prim_from_i128(*p, *i),
        (BaseType::Prim(p), Literal::Bool(b)) => prim_from_i128(*p, i128::from(*b)),
        (_, Literal::Str(s)) => Value::String(s.clone()),
        (_, Literal::Float(f)) => Value::F64(*f),
        (_, Literal::Int(i)) => Value::I64(*i as i64),
        (_, Literal::Bool(b)) => Value::Bool(*b),
    }
}

fn pack(ty: &BaseType, values: &[Value]) -> Value {
    let mut out = packed_zeros(ty, values.len());
    macro_rules! fill {
        ($v:ident, $pat:ident) => {
            for (slot, x) in $v.iter_mut().zip(values) {
                if let Value::$pat(y) = x {
                    *slot = *y;
                }
            }
        };
    }
    match &mut out {
        Value::Bools(v) => fill!(v, Bool),
        Value::Bytes(v) => fill!(v, U8),
        Value::I8s(v) => fill!(v, I8),
        Value::I16s(v) => fill!(v, I16),
        Value::U16s(v) => fill!(v, U16),
        Value::I32s(v) => fill!(v, I32),
        Value::U32s(v) => fill!(v, U32),
        Value::I64s(v) => fill!(v, I64),
        Value::U64s(v) => fill!(v, U64),
        Value::F32s(v) => fill!(v, F32),
        Value::F64s(v) => fill!(v, F64),
        _ => {}
    }
    out
}

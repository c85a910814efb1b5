//! ROS 2 CDR (OMG Common Data Representation) decoding and encoding driven by a parsed
//! [`Registry`] — any message type, including custom ones, with no generated code.
//!
//! Wire rules implemented (as `rmw_fastrtps`/`rmw_cyclonedds` write them):
//! - a 4-byte encapsulation header: representation id (big-endian u16) + 2 option bytes.
//!   Supported ids: `CDR_BE` 0x0000, `CDR_LE` 0x0001 (XCDR1: 8-byte types align to 8) and
//!   `CDR2_BE` 0x0006, `CDR2_LE` 0x0007 (plain XCDR2 of final types: alignment capped at 4).
//!   Parameter-list and delimited encodings (mutable/appendable types) are rejected by name.
//! - every primitive is aligned to its size, relative to the byte after the header;
//! - `string`: u32 length including the NUL terminator, the bytes, the NUL;
//! - `wstring`: u32 count of characters, each a 4-byte code unit (Fast-CDR's `wchar_t`);
//! - `T[N]`: N elements, no prefix; `T[]` and `T[<=N]`: u32 count, then the elements;
//! - an empty message carries one dummy `uint8` (ROS 2 adds
//!   `structure_needs_at_least_one_member` when it converts `.msg` to IDL).
//!
//! Written by hand: the only Rust CDR crate (`cdr`) needs compile-time serde types.

use std::sync::Arc;

use super::ros2msg::{ArrayKind, BaseType, Literal, MsgDef, Prim, Registry};
use super::value::Value;

/// Byte order of a CDR payload.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Endian {
    Little,
    Big,
}

/// What went wrong, without the field path.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CdrErrorKind {
    #[error("payload of {0} bytes is too short for the 4-byte encapsulation header")]
    NoHeader(usize),
    #[error(
        "unsupported CDR representation 0x{0:04x} (supported: CDR_LE/BE 0x0001/0x0000, plain CDR2_LE/BE 0x0007/0x0006)"
    )]
    UnsupportedEncapsulation(u16),
    #[error("payload ended at byte {offset}: need {need} more bytes, {have} left")]
    UnexpectedEnd {
        offset: usize,
        need: usize,
        have: usize,
    },
    #[error("sequence length {len} at byte {offset} cannot fit in the {remaining} bytes left")]
    LengthTooLarge {
        offset: usize,
        len: u64,
        remaining: usize,
    },
    #[error("expected {expected}, found {found}")]
    WrongType {
        expected: String,
        found: &'static str,
    },
    #[error("fixed-size array needs {expected} elements, found {found}")]
    FixedLength { expected: usize, found: usize },
    #[error("{found} elements exceed the bound {bound}")]
    BoundExceeded { bound: usize, found: usize },
    #[error("value {value} does not fit in {ty}")]
    OutOfRange { value: String, ty: &'static str },
    #[error("field `{0}` is not in the message definition")]
    UnknownField(String),
}

/// A CDR decode or encode failure and the field path where it happened (e.g. `ranges[12]`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{kind}{}", if path.is_empty() { String::new() } else { format!(" (field `{path}`)") })]
pub struct CdrError {
    pub path: String,
    pub kind: CdrErrorKind,
}

impl CdrError {
    fn new(kind: CdrErrorKind) -> Self {
        CdrError {
            path: String::new(),
            kind,
        }
    }

    fn within(mut self, field: &str) -> Self {
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

type Result<T> = std::result::Result<T, CdrError>;

/// Parse the encapsulation header: byte order and maximum alignment.
fn encapsulation(data: &[u8]) -> Result<(Endian, usize)> {
    if data.len() < 4 {
        return Err(CdrError::new(CdrErrorKind::NoHeader(data.len())));
    }
    let id = u16::from_be_bytes([data[0], data[1]]);
    match id {
        0x0000 => Ok((Endian::Big, 8)),
        0x0001 => Ok((Endian::Little, 8)),
        0x0006 => Ok((Endian::Big, 4)),
        0x0007 => Ok((Endian::Little, 4)),
        other => Err(CdrError::new(CdrErrorKind::UnsupportedEncapsulation(other))),
    }
}

/// Decode one CDR message of the registry's root type.
pub fn decode(registry: &Registry, data: &[u8]) -> Result<Value> {
    let (endian, max_align) = encapsulation(data)?;
    let mut reader = Reader {
        buf: &data[4..],
        pos: 0,
        big: endian == Endian::Big,
        max_align,
    };
    reader.read_struct(registry, registry.root)
}

struct Reader<'a> {
    buf: &'a [u8],
    pos: usize,
    big: bool,
    max_align: usize,
}

macro_rules! read_scalar {
    ($name:ident, $t:ty) => {
        fn $name(&mut self) -> Result<$t> {
            const N: usize = std::mem::size_of::<$t>();
            self.align(N);
            let b: [u8; N] = self.take(N)?.try_into().expect("take returns N bytes");
            Ok(if self.big {
                <$t>::from_be_bytes(b)
            } else {
                <$t>::from_le_bytes(b)
            })
        }
    };
}

macro_rules! read_packed {
    ($self:ident, $n:ident, $t:ty, $variant:ident) => {{
        const N: usize = std::mem::size_of::<$t>();
        if $n > 0 {
            $self.align(N);
        }
        let bytes = $self.take($n * N)?;
        let v: Vec<$t> = if $self.big {
            bytes
                .chunks_exact(N)
                .map(|c| <$t>::from_be_bytes(c.try_into().expect("chunk of N")))
                .collect()
        } else {
            bytes
                .chunks_exact(N)
                .map(|c| <$t>::from_le_bytes(c.try_into().expect("chunk of N")))
                .collect()
        };
        Value::$variant(v)
    }};
}

impl<'a> Reader<'a> {
    fn align(&mut self, size: usize) {
        let a = size.min(self.max_align);
        let rem = self.pos % a;
        if rem != 0 {
            self.pos += a - rem;
        }
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        let have = self.buf.len().saturating_sub(self.pos);
        if n > have {
            return Err(CdrError::new(CdrErrorKind::UnexpectedEnd {
                offset: self.pos + 4,
                need: n,
                have,
            }));
        }
        let out = &self.buf[self.pos..self.pos + n];
        self.pos += n;
        Ok(out)
    }

    read_scalar!(u16, u16);
    read_scalar!(i16, i16);
    read_scalar!(u32, u32);
    read_scalar!(i32, i32);
    read_scalar!(u64, u64);
    read_scalar!(i64, i64);
    read_scalar!(f32, f32);
    read_scalar!(f64, f64);

    fn u8(&mut self) -> Result<u8> {
        Ok(self.take(1)?[0])
    }

    /// A sequence length, checked against the bytes left so corrupt data cannot make us
    /// allocate gigabytes.
    fn seq_len(&mut self, min_elem_size: usize) -> Result<usize> {
        let len = self.u32()?;
        let remaining = self.buf.len().saturating_sub(self.pos);
        let need = u64::from(len) * min_elem_size as u64;
        if need > remaining as u64 {
            return Err(CdrError::new(CdrErrorKind::LengthTooLarge {
                offset: self.pos,
                len: len.into(),
                remaining,
            }));
        }
        Ok(len as usize)
    }

    fn string(&mut self) -> Result<String> {
        let len = self.seq_len(1)?;
        let bytes = self.take(len)?;
        // length counts the NUL terminator; tolerate writers that omit it
        let bytes = bytes.strip_suffix(&[0]).unwrap_or(bytes);
        Ok(String::from_utf8_lossy(bytes).into_owned())
    }

    fn wstring(&mut self) -> Result<String> {
        let len = self.seq_len(4)?;
        let mut s = String::with_capacity(len);
        for _ in 0..len {
            let unit = self.u32()?;
            s.push(char::from_u32(unit).unwrap_or(char::REPLACEMENT_CHARACTER));
        }
        Ok(s)
    }

    fn read_struct(&mut self, reg: &Registry, idx: usize) -> Result<Value> {
        let def = &reg.defs[idx];
        if def.fields.is_empty() {
            self.u8()?;
            return Ok(Value::Struct(Vec::new()));
        }
        let mut fields = Vec::with_capacity(def.fields.len());
        for f in &def.fields {
            let v = match f.array {
                ArrayKind::Single => self.read_single(reg, &f.ty),
                ArrayKind::Fixed(n) => self.read_array(reg, &f.ty, n),
                ArrayKind::Bounded(_) | ArrayKind::Unbounded => {
                    let min = min_wire_size(reg, &f.ty);
                    self.seq_len(min)
                        .and_then(|n| self.read_array(reg, &f.ty, n))
                }
            }
            .map_err(|e| e.within(&f.name))?;
            fields.push((Arc::clone(&f.name), v));
        }
        Ok(Value::Struct(fields))
    }

    fn read_single(&mut self, reg: &Registry, ty: &BaseType) -> Result<Value> {
        Ok(match ty {
            BaseType::Prim(p) => match p {
                Prim::Bool => Value::Bool(self.u8()? != 0),
                Prim::Byte | Prim::Char | Prim::U8 => Value::U8(self.u8()?),
                Prim::I8 => Value::I8(self.u8()? as i8),
                Prim::I16 => Value::I16(self.i16()?),
                Prim::U16 => Value::U16(self.u16()?),
                Prim::I32 => Value::I32(self.i32()?),
                Prim::U32 => Value::U32(self.u32()?),
                Prim::I64 => Value::I64(self.i64()?),
                Prim::U64 => Value::U64(self.u64()?),
                Prim::F32 => Value::F32(self.f32()?),
                Prim::F64 => Value::F64(self.f64()?),
            },
            BaseType::String { .. } => Value::String(self.string()?),
            BaseType::WString { .. } => Value::String(self.wstring()?),
            BaseType::Msg(i) => self.read_struct(reg, *i)?,
        })
    }

    fn read_array(&mut self, reg: &Registry, ty: &BaseType, n: usize) -> Result<Value> {
        Ok(match ty {
            BaseType::Prim(p) => match p {
                Prim::Bool => Value::Bools(self.take(n)?.iter().map(|b| *b != 0).collect()),
                Prim::Byte | Prim::Char | Prim::U8 => Value::Bytes(self.take(n)?.to_vec()),
                Prim::I8 => Value::I8s(self.take(n)?.iter().map(|b| *b as i8).collect()),
                Prim::I16 => read_packed!(self, n, i16, I16s),
                Prim::U16 => read_packed!(self, n, u16, U16s),
                Prim::I32 => read_packed!(self, n, i32, I32s),
                Prim::U32 => read_packed!(self, n, u32, U32s),
                Prim::I64 => read_packed!(self, n, i64, I64s),
                Prim::U64 => read_packed!(self, n, u64, U64s),
                Prim::F32 => read_packed!(self, n, f32, F32s),
                Prim::F64 => read_packed!(self, n, f64, F64s),
            },
            _ => {
                let mut items = Vec::with_capacity(n.min(self.buf.len()));
                for i in 0..n {
                    items.push(
                        self.read_single(reg, ty)
                            .map_err(|e| e.within(&format!("[{i}]")))?,
                    );
                }
                Value::Array(items)
            }
        })
    }
}

/// The fewest bytes one element can take on the wire (used to bound sequence lengths).
fn min_wire_size(reg: &Registry, ty: &BaseType) -> usize {
    match ty {
        BaseType::Prim(p) => p.size(),
        BaseType::String { .. } | BaseType::WString { .. } => 4,
        BaseType::Msg(i) => {
            let def = &reg.defs[*i];
            if def.fields.is_empty() {
                return 1;
            }
            def.fields
                .iter()
                .map(|f| match f.array {
                    ArrayKind::Single => min_wire_size(reg, &f.ty),
                    ArrayKind::Fixed(n) => n * min_wire_size(reg, &f.ty),
                    _ => 4,
                })
                .sum::<usize>()
                .max(1)
        }
    }
}

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

    fn write_elements(&mut self, reg: &Registry, ty: &BaseType, v: &Value) -> Result<()> {
        // Fast paths: packed arrays whose variant matches the wire type exactly.
        match (ty, v) {
            (BaseType::Prim(Prim::U8 | Prim::Byte | Prim::Char), Value::Bytes(b)) => {
                self.buf.extend_from_slice(b);
                return Ok(());
            }
            (BaseType::Prim(Prim::F32), Value::F32s(xs)) => {
                if !xs.is_empty() {
                    self.align(4);
                }
                self.buf.reserve(xs.len() * 4);
                for x in xs {
                    if self.big {
                        self.buf.extend_from_slice(&x.to_be_bytes());
                    } else {
                        self.buf.extend_from_slice(&x.to_le_bytes());
                    }
                }
                return Ok(());
            }
            (BaseType::Prim(Prim::F64), Value::F64s(xs)) => {
                if !xs.is_empty() {
                    self.align(8);
                }
                self.buf.reserve(xs.len() * 8);
                for x in xs {
                    if self.big {
                        self.buf.extend_from_slice(&x.to_be_bytes());
                    } else {
                        self.buf.extend_from_slice(&x.to_le_bytes());
                    }
                }
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

#[cfg(test)]
mod tests;

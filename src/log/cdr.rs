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
//! Decoding is bounded for hostile input: nesting by the schema's checked depth (and a depth
//! counter here as well), every array and sequence length by the bytes left before anything is
//! allocated (checked arithmetic, the least wire size per element from
//! [`Registry::min_size`]), elements that take no bytes at all by [`MAX_ZERO_SIZE_ELEMENTS`],
//! and the decoded tree's structure by [`tree_budget`].
//!
//! Written by hand: the only Rust CDR crate (`cdr`) needs compile-time serde types.

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use super::ros2msg::{ArrayKind, BaseType, MAX_NESTING, Prim, Registry, min_wire_size};
use super::value::Value;

/// Most elements accepted in one array of a type that takes no bytes on the wire (a struct of
/// zero-length arrays): its length cannot be bounded by the payload, so it is capped outright.
pub const MAX_ZERO_SIZE_ELEMENTS: usize = 1 << 16;

/// Bytes the decoded tree's structure (struct fields and array slots, not the packed numbers,
/// bytes and strings, which the payload bounds) may take for a payload of `payload_len`
/// bytes: by default ([`default_tree_budget`]) 16 MiB plus 8 per payload byte, or the limit
/// set for the process ([`set_structure_limit`], the CLI's `--max-structure-mib`).
pub fn tree_budget(payload_len: usize) -> usize {
    budget_for(payload_len, structure_limit())
}

/// The default structure budget: 16 MiB plus 8 bytes per payload byte. A dense
/// `geometry_msgs/Point[]` takes about 7.3 bytes of structure per wire byte, so real messages
/// fit; an array of one-byte structs (about 80) is refused instead of taking a hundred times
/// its size in memory — unless the user raises the limit.
pub fn default_tree_budget(payload_len: usize) -> usize {
    (16usize << 20).saturating_add(payload_len.saturating_mul(8))
}

/// The structure budget of a payload under `limit` (bytes), or the default without one.
pub fn budget_for(payload_len: usize, limit: Option<usize>) -> usize {
    limit.unwrap_or_else(|| default_tree_budget(payload_len))
}

/// The process-wide structure limit in bytes; 0 = the default rule.
static STRUCTURE_LIMIT: AtomicUsize = AtomicUsize::new(0);

/// Set (or, with `None`, clear) the structure limit of every decode in this process: set once
/// by the CLI from `--max-structure-mib`, before anything is decoded (like the thread count).
pub fn set_structure_limit(bytes: Option<usize>) {
    STRUCTURE_LIMIT.store(bytes.map_or(0, |b| b.max(1)), Ordering::Relaxed);
}

/// The structure limit set for this process, if any.
pub fn structure_limit() -> Option<usize> {
    match STRUCTURE_LIMIT.load(Ordering::Relaxed) {
        0 => None,
        n => Some(n),
    }
}

/// What a refused message's error says to raise the budget.
pub const RAISE_HINT: &str = "--max-structure-mib raises this limit";

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
    #[error("array length {len} at byte {offset} cannot fit in the {remaining} bytes left")]
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
    #[error("message types nest more than {MAX_NESTING} deep")]
    TooDeep,
    #[error(
        "{len} elements of a type that takes no bytes on the wire (at most {MAX_ZERO_SIZE_ELEMENTS} accepted)"
    )]
    TooManyEmpty { len: u64 },
    #[error(
        "decoded message would take more than {budget} bytes of structure (payload {payload} bytes; {RAISE_HINT})"
    )]
    TreeTooLarge { budget: usize, payload: usize },
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

mod budget;
mod cursor;
mod encode;
pub mod flat;
mod json;

use budget::Budget;
pub use cursor::Cursor;
pub use encode::{default_value, encode, literal_value};
pub use json::{FloatText, write_json};

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
    let mut reader = Reader {
        cur: Cursor::new(data)?,
        depth: 0,
        budget: Budget::new(data.len()),
    };
    reader.read_struct(registry, registry.root)
}

struct Reader<'a> {
    cur: Cursor<'a>,
    /// Message types entered and not yet left.
    depth: usize,
    /// Bytes of tree structure still allowed ([`tree_budget`]).
    budget: Budget,
}

macro_rules! packed {
    ($bytes:ident, $big:ident, $t:ty, $variant:ident) => {{
        const N: usize = std::mem::size_of::<$t>();
        Value::$variant(
            $bytes
                .as_chunks::<N>()
                .0
                .iter()
                .map(|&c| {
                    if $big {
                        <$t>::from_be_bytes(c)
                    } else {
                        <$t>::from_le_bytes(c)
                    }
                })
                .collect(),
        )
    }};
}

/// The bytes of `n` packed elements of `p` at the cursor (aligned first, except single bytes).
fn packed_bytes<'a>(cur: &mut Cursor<'a>, p: Prim, n: usize) -> Result<&'a [u8]> {
    match p {
        Prim::Bool | Prim::Byte | Prim::Char | Prim::U8 | Prim::I8 => cur.take(n),
        _ => cur.packed(n, p.size()),
    }
}

/// Packed elements of `p` (their bytes, in the payload's byte order) as a packed value.
fn packed_value(p: Prim, bytes: &[u8], big: bool) -> Value {
    match p {
        Prim::Bool => Value::Bools(bytes.iter().map(|b| *b != 0).collect()),
        Prim::Byte | Prim::Char | Prim::U8 => Value::Bytes(bytes.to_vec()),
        Prim::I8 => Value::I8s(bytes.iter().map(|b| *b as i8).collect()),
        Prim::I16 => packed!(bytes, big, i16, I16s),
        Prim::U16 => packed!(bytes, big, u16, U16s),
        Prim::I32 => packed!(bytes, big, i32, I32s),
        Prim::U32 => packed!(bytes, big, u32, U32s),
        Prim::I64 => packed!(bytes, big, i64, I64s),
        Prim::U64 => packed!(bytes, big, u64, U64s),
        Prim::F32 => packed!(bytes, big, f32, F32s),
        Prim::F64 => packed!(bytes, big, f64, F64s),
    }
}

impl<'a> Reader<'a> {
    fn check_len(&mut self, n: usize, min_elem_size: usize, slot: usize) -> Result<usize> {
        self.budget.check_len(&self.cur, n, min_elem_size, slot)
    }

    fn seq_len(&mut self, min_elem_size: usize, slot: usize) -> Result<usize> {
        self.budget.seq_len(&mut self.cur, min_elem_size, slot)
    }

    fn string(&mut self) -> Result<String> {
        let len = self.seq_len(1, 0)?;
        let bytes = self.cur.take(len)?;
        // length counts the NUL terminator; tolerate writers that omit it
        let bytes = bytes.strip_suffix(&[0]).unwrap_or(bytes);
        Ok(String::from_utf8_lossy(bytes).into_owned())
    }

    fn wstring(&mut self) -> Result<String> {
        let len = self.seq_len(4, 0)?;
        let mut s = String::with_capacity(len);
        for _ in 0..len {
            let unit = self.cur.u32()?;
            s.push(char::from_u32(unit).unwrap_or(char::REPLACEMENT_CHARACTER));
        }
        Ok(s)
    }

    fn read_struct(&mut self, reg: &Registry, idx: usize) -> Result<Value> {
        if self.depth >= MAX_NESTING {
            return Err(CdrError::new(CdrErrorKind::TooDeep));
        }
        self.depth += 1;
        let v = self.read_fields(reg, idx);
        self.depth -= 1;
        v
    }

    fn read_fields(&mut self, reg: &Registry, idx: usize) -> Result<Value> {
        let def = reg
            .defs
            .get(idx)
            .ok_or(CdrError::new(CdrErrorKind::TooDeep))?;
        if def.fields.is_empty() {
            self.cur.u8()?;
            return Ok(Value::Struct(Vec::new()));
        }
        self.budget
            .charge(def.fields.len() * std::mem::size_of::<(Arc<str>, Value)>())?;
        let mut fields = Vec::with_capacity(def.fields.len());
        for f in &def.fields {
            let min = min_wire_size(&reg.min_size, &f.ty);
            let slot = match f.ty {
                BaseType::Prim(_) => 0, // packed: the payload bounds it
                _ => std::mem::size_of::<Value>(),
            };
            let v = match f.array {
                ArrayKind::Single => self.read_single(reg, &f.ty),
                ArrayKind::Fixed(n) => self
                    .check_len(n, min, slot)
                    .and_then(|n| self.read_array(reg, &f.ty, n)),
                ArrayKind::Bounded(_) | ArrayKind::Unbounded => self
                    .seq_len(min, slot)
                    .and_then(|n| self.read_array(reg, &f.ty, n)),
            }
            .map_err(|e| e.within(&f.name))?;
            fields.push((Arc::clone(&f.name), v));
        }
        Ok(Value::Struct(fields))
    }

    fn read_single(&mut self, reg: &Registry, ty: &BaseType) -> Result<Value> {
        Ok(match ty {
            BaseType::Prim(p) => match p {
                Prim::Bool => Value::Bool(self.cur.u8()? != 0),
                Prim::Byte | Prim::Char | Prim::U8 => Value::U8(self.cur.u8()?),
                Prim::I8 => Value::I8(self.cur.u8()? as i8),
                Prim::I16 => Value::I16(self.cur.i16()?),
                Prim::U16 => Value::U16(self.cur.u16()?),
                Prim::I32 => Value::I32(self.cur.i32()?),
                Prim::U32 => Value::U32(self.cur.u32()?),
                Prim::I64 => Value::I64(self.cur.i64()?),
                Prim::U64 => Value::U64(self.cur.u64()?),
                Prim::F32 => Value::F32(self.cur.f32()?),
                Prim::F64 => Value::F64(self.cur.f64()?),
            },
            BaseType::String { .. } => Value::String(self.string()?),
            BaseType::WString { .. } => Value::String(self.wstring()?),
            BaseType::Msg(i) => self.read_struct(reg, *i)?,
        })
    }

    fn read_array(&mut self, reg: &Registry, ty: &BaseType, n: usize) -> Result<Value> {
        Ok(match ty {
            BaseType::Prim(p) => {
                let big = self.cur.is_big_endian();
                packed_value(*p, packed_bytes(&mut self.cur, *p, n)?, big)
            }
            _ => {
                // `n` was checked against the bytes left and the tree budget
                let mut items = Vec::with_capacity(n);
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

#[cfg(test)]
mod tests;

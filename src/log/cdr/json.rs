//! A CDR payload written straight as JSON text, in one pass and without the [`Value`] tree:
//! what `peopletrack cat` prints. The walk is [`super::decode`]'s (same bounds, nesting limit,
//! tree budget and errors, so a payload the dynamic decoder refuses is refused here too) and
//! the text is that of [`Value::json`] streamed by `serde_json` (keys in definition order,
//! `serde_json`'s own number formatting through its [`CompactFormatter`], non-finite floats
//! as `"NaN"`, `"Infinity"`, `"-Infinity"`, arrays longer than `max_array` cut with a
//! `"... N more"` element). The known-answer tests check the two byte for byte.
//!
//! Written by hand for the same reason as the dynamic decoder: no crate decodes CDR from a
//! schema known only at run time.

use std::sync::Arc;

use serde_json::ser::{CompactFormatter, Formatter};

use super::{Budget, CdrError, CdrErrorKind, Cursor, Result};
use crate::log::ros2msg::{ArrayKind, BaseType, MAX_NESTING, Prim, Registry, min_wire_size};
use crate::log::value::Value;

/// Append the JSON rendering of the CDR payload `data` (message type `registry.root`) to
/// `out`. On error `out` may hold a partial rendering: the caller drops it. `floats` keeps
/// the text of recent float values from message to message.
pub fn write_json(
    registry: &Registry,
    data: &[u8],
    max_array: Option<usize>,
    floats: &mut FloatText,
    out: &mut Vec<u8>,
) -> Result<()> {
    let mut w = Writer {
        cur: Cursor::new(data)?,
        depth: 0,
        budget: Budget::new(data.len()),
        max: max_array,
        out: Out { buf: out, floats },
    };
    w.write_struct(registry, registry.root)
}

/// Slots of [`FloatText`] (a power of two).
const FLOAT_SLOTS: usize = 1 << 12;

/// The longest float text cached (`serde_json`'s f64 texts are at most 24 bytes).
const FLOAT_TEXT: usize = 24;

/// A direct-mapped cache of float texts, keyed by the value's bits: sensor data repeats its
/// values (a laser's ranges are quantized), and copying a cached text is several times
/// cheaper than finding the shortest round-trip digits again. The texts are `serde_json`'s
/// own, so the output is unchanged.
#[derive(Default)]
pub struct FloatText {
    /// `(bits, text length, text)`; length 0: empty slot. Allocated on first use.
    slots: Vec<(u64, u8, [u8; FLOAT_TEXT])>,
}

impl std::fmt::Debug for FloatText {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "FloatText({} slots)", self.slots.len())
    }
}

impl FloatText {
    /// Append the text of the finite `v`.
    fn write(&mut self, out: &mut Vec<u8>, v: f64) {
        if self.slots.is_empty() {
            self.slots = vec![(0, 0, [0; FLOAT_TEXT]); FLOAT_SLOTS];
        }
        let bits = v.to_bits();
        let i = (bits.wrapping_mul(0x9e37_79b9_7f4a_7c15) >> (64 - 12)) as usize;
        let slot = &mut self.slots[i & (FLOAT_SLOTS - 1)];
        if slot.1 > 0 && slot.0 == bits {
            out.extend_from_slice(&slot.2[..usize::from(slot.1)]);
            return;
        }
        let at = out.len();
        ok(CompactFormatter.write_f64(out, v));
        let text = &out[at..];
        if let Ok(len) = u8::try_from(text.len())
            && text.len() <= FLOAT_TEXT
        {
            slot.0 = bits;
            slot.1 = len;
            slot.2[..text.len()].copy_from_slice(text);
        }
    }
}

/// The output buffer and the float cache.
struct Out<'o> {
    buf: &'o mut Vec<u8>,
    floats: &'o mut FloatText,
}

struct Writer<'a, 'o> {
    cur: Cursor<'a>,
    depth: usize,
    budget: Budget,
    max: Option<usize>,
    out: Out<'o>,
}

/// Writing to a `Vec` cannot fail.
fn ok(r: std::io::Result<()>) {
    debug_assert!(r.is_ok());
}

/// A string as `serde_json` escapes it.
fn string(out: &mut Vec<u8>, s: &str) {
    // serializing a &str into a Vec cannot fail
    let _ = serde_json::to_writer(&mut *out, s);
}

/// A float as [`Value::json`] writes it (finite: `serde_json`'s shortest round trip).
fn float(o: &mut Out<'_>, v: f64) {
    let out = &mut *o.buf;
    if v.is_finite() {
        o.floats.write(out, v);
    } else if v.is_nan() {
        out.extend_from_slice(b"\"NaN\"");
    } else if v > 0.0 {
        out.extend_from_slice(b"\"Infinity\"");
    } else {
        out.extend_from_slice(b"\"-Infinity\"");
    }
}

/// How many of `n` elements are shown, and the `"... N more"` marker after them.
fn shown(n: usize, max: Option<usize>) -> usize {
    max.map_or(n, |m| m.min(n))
}

fn more(out: &mut Vec<u8>, n: usize, show: usize) {
    if n > show {
        if show > 0 {
            out.push(b',');
        }
        string(out, &format!("... {} more", n - show));
    }
}

/// `[a,b,...]` of `n` packed elements of `N` bytes, each written by `f`.
fn packed<const N: usize>(
    out: &mut Out<'_>,
    bytes: &[u8],
    max: Option<usize>,
    mut f: impl FnMut(&mut Out<'_>, [u8; N]),
) {
    let items = bytes.as_chunks::<N>().0;
    let show = shown(items.len(), max);
    out.buf.push(b'[');
    for (i, c) in items[..show].iter().enumerate() {
        if i > 0 {
            out.buf.push(b',');
        }
        f(out, *c);
    }
    more(out.buf, items.len(), show);
    out.buf.push(b']');
}

macro_rules! num {
    ($big:expr, $t:ty, $write:ident) => {
        |o: &mut Out<'_>, c| {
            let v = if $big {
                <$t>::from_be_bytes(c)
            } else {
                <$t>::from_le_bytes(c)
            };
            ok(CompactFormatter.$write(o.buf, v));
        }
    };
}

impl Writer<'_, '_> {
    fn check_len(&mut self, n: usize, min_elem_size: usize, slot: usize) -> Result<usize> {
        self.budget.check_len(&self.cur, n, min_elem_size, slot)
    }

    fn seq_len(&mut self, min_elem_size: usize, slot: usize) -> Result<usize> {
        self.budget.seq_len(&mut self.cur, min_elem_size, slot)
    }

    fn string(&mut self) -> Result<()> {
        let len = self.seq_len(1, 0)?;
        let bytes = self.cur.take(len)?;
        let bytes = bytes.strip_suffix(&[0]).unwrap_or(bytes);
        string(self.out.buf, &String::from_utf8_lossy(bytes));
        Ok(())
    }

    fn wstring(&mut self) -> Result<()> {
        let len = self.seq_len(4, 0)?;
        let mut s = String::with_capacity(len);
        for _ in 0..len {
            let unit = self.cur.u32()?;
            s.push(char::from_u32(unit).unwrap_or(char::REPLACEMENT_CHARACTER));
        }
        string(self.out.buf, &s);
        Ok(())
    }

    fn write_struct(&mut self, reg: &Registry, idx: usize) -> Result<()> {
        if self.depth >= MAX_NESTING {
            return Err(CdrError::new(CdrErrorKind::TooDeep));
        }
        self.depth += 1;
        let r = self.write_fields(reg, idx);
        self.depth -= 1;
        r
    }

    fn write_fields(&mut self, reg: &Registry, idx: usize) -> Result<()> {
        let def = reg
            .defs
            .get(idx)
            .ok_or(CdrError::new(CdrErrorKind::TooDeep))?;
        if def.fields.is_empty() {
            self.cur.u8()?;
            self.out.buf.extend_from_slice(b"{}");
            return Ok(());
        }
        self.budget
            .charge(def.fields.len() * std::mem::size_of::<(Arc<str>, Value)>())?;
        self.out.buf.push(b'{');
        for (i, f) in def.fields.iter().enumerate() {
            if i > 0 {
                self.out.buf.push(b',');
            }
            string(self.out.buf, &f.name);
            self.out.buf.push(b':');
            let min = min_wire_size(&reg.min_size, &f.ty);
            let slot = match f.ty {
                BaseType::Prim(_) => 0,
                _ => std::mem::size_of::<Value>(),
            };
            match f.array {
                ArrayKind::Single => self.write_single(reg, &f.ty),
                ArrayKind::Fixed(n) => self
                    .check_len(n, min, slot)
                    .and_then(|n| self.write_array(reg, &f.ty, n)),
                ArrayKind::Bounded(_) | ArrayKind::Unbounded => self
                    .seq_len(min, slot)
                    .and_then(|n| self.write_array(reg, &f.ty, n)),
            }
            .map_err(|e| e.within(&f.name))?;
        }
        self.out.buf.push(b'}');
        Ok(())
    }

    fn write_single(&mut self, reg: &Registry, ty: &BaseType) -> Result<()> {
        let o = &mut self.out;
        let c = &mut self.cur;
        match ty {
            BaseType::Prim(p) => match p {
                Prim::Bool => ok(CompactFormatter.write_bool(o.buf, c.u8()? != 0)),
                Prim::Byte | Prim::Char | Prim::U8 => ok(CompactFormatter.write_u8(o.buf, c.u8()?)),
                Prim::I8 => ok(CompactFormatter.write_i8(o.buf, c.u8()? as i8)),
                Prim::I16 => ok(CompactFormatter.write_i16(o.buf, c.i16()?)),
                Prim::U16 => ok(CompactFormatter.write_u16(o.buf, c.u16()?)),
                Prim::I32 => ok(CompactFormatter.write_i32(o.buf, c.i32()?)),
                Prim::U32 => ok(CompactFormatter.write_u32(o.buf, c.u32()?)),
                Prim::I64 => ok(CompactFormatter.write_i64(o.buf, c.i64()?)),
                Prim::U64 => ok(CompactFormatter.write_u64(o.buf, c.u64()?)),
                // f32 -> f64 is exact, as in `Value::json`
                Prim::F32 => float(o, f64::from(c.f32()?)),
                Prim::F64 => float(o, c.f64()?),
            },
            BaseType::String { .. } => self.string()?,
            BaseType::WString { .. } => self.wstring()?,
            BaseType::Msg(i) => self.write_struct(reg, *i)?,
        }
        Ok(())
    }

    fn write_array(&mut self, reg: &Registry, ty: &BaseType, n: usize) -> Result<()> {
        let max = self.max;
        let big = self.cur.is_big_endian();
        let BaseType::Prim(p) = ty else {
            // every element is read (and checked); only the first `show` are written
            let show = shown(n, max);
            self.out.buf.push(b'[');
            for i in 0..n {
                let mark = self.out.buf.len();
                if 0 < i && i < show {
                    self.out.buf.push(b',');
                }
                self.write_single(reg, ty)
                    .map_err(|e| e.within(&format!("[{i}]")))?;
                if i >= show {
                    self.out.buf.truncate(mark);
                }
            }
            more(self.out.buf, n, show);
            self.out.buf.push(b']');
            return Ok(());
        };
        let o = &mut self.out;
        match p {
            Prim::Bool => packed::<1>(o, self.cur.take(n)?, max, |o, c| {
                ok(CompactFormatter.write_bool(o.buf, c[0] != 0));
            }),
            Prim::Byte | Prim::Char | Prim::U8 => packed::<1>(o, self.cur.take(n)?, max, |o, c| {
                ok(CompactFormatter.write_u8(o.buf, c[0]));
            }),
            Prim::I8 => packed::<1>(o, self.cur.take(n)?, max, |o, c| {
                ok(CompactFormatter.write_i8(o.buf, c[0] as i8));
            }),
            Prim::I16 => packed::<2>(o, self.cur.packed(n, 2)?, max, num!(big, i16, write_i16)),
            Prim::U16 => packed::<2>(o, self.cur.packed(n, 2)?, max, num!(big, u16, write_u16)),
            Prim::I32 => packed::<4>(o, self.cur.packed(n, 4)?, max, num!(big, i32, write_i32)),
            Prim::U32 => packed::<4>(o, self.cur.packed(n, 4)?, max, num!(big, u32, write_u32)),
            Prim::I64 => packed::<8>(o, self.cur.packed(n, 8)?, max, num!(big, i64, write_i64)),
            Prim::U64 => packed::<8>(o, self.cur.packed(n, 8)?, max, num!(big, u64, write_u64)),
            Prim::F32 => packed::<4>(o, self.cur.packed(n, 4)?, max, |o, c| {
                let v = if big {
                    f32::from_be_bytes(c)
                } else {
                    f32::from_le_bytes(c)
                };
                float(o, f64::from(v));
            }),
            Prim::F64 => packed::<8>(o, self.cur.packed(n, 8)?, max, |o, c| {
                float(
                    o,
                    if big {
                        f64::from_be_bytes(c)
                    } else {
                        f64::from_le_bytes(c)
                    },
                );
            }),
        }
        Ok(())
    }
}

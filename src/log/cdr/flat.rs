//! Flat decoding of any ROS 2 CDR message into buffers reused from message to message: the
//! dynamic counterpart of the typed fast paths ([`crate::log::fast`]) for types they do not
//! cover (a project's own messages, such as `leg_tracker/msg/Person`).
//!
//! A channel's schema is compiled once into a [`Plan`]: every message type gets a fixed-width
//! layout of 64-bit slots, a slot per scalar, string or array field, with nested single
//! messages laid out inline. A payload then decodes into a [`Flat`] (the slots and a text
//! buffer, cleared, not freed, between messages): scalars keep their bits in their slot;
//! strings and packed numeric arrays keep the position of their bytes in the payload (the
//! view borrows the payload, nothing is copied); arrays of strings or messages append their
//! elements' slots after the fixed part. Once the buffers have grown, a message decodes
//! without allocating.
//!
//! The walk makes the same cursor moves and the same structure-budget, nesting and length
//! checks as the value-tree decoder ([`super::decode`]), so a payload (below [`MAX_PAYLOAD`])
//! decodes flat exactly when it decodes to a tree, and [`FlatRef::to_value`] gives the same tree (pinned on every
//! message of the real logs and on mutated payloads in the tests). Errors carry no field path:
//! callers re-run the tree decoder for the full message ([`crate::log::Decoders::decode`]).
//!
//! Written by hand: no crate decodes CDR against a runtime `ros2msg` schema without building
//! a tree per message.

use std::sync::Arc;

use super::super::ros2msg::{ArrayKind, BaseType, MAX_NESTING, Prim, Registry, min_wire_size};
use super::super::value::{FieldError, Value};
use super::{Budget, CdrError, CdrErrorKind, Cursor, Result};

/// The most slots one message type may take inline: beyond it a schema is not compiled and
/// its channel decodes to trees.
const MAX_WIDTH: usize = 1 << 16;

/// The largest payload decoded flat, exclusive: an invalid UTF-8 byte becomes three bytes of
/// U+FFFD, and text positions must stay below 2^31.
pub const MAX_PAYLOAD: usize = 1 << 29;

/// Set in a string slot whose text is in [`Flat::text`] (invalid UTF-8 made lossy, or a
/// `wstring`), clear when the string is valid UTF-8 borrowed from the payload.
const IN_TEXT: u64 = 1 << 63;

/// What one field's slot holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Leaf {
    Prim(Prim),
    /// `string` (`wide: false`) or `wstring`.
    Str {
        wide: bool,
    },
    /// A single nested message, inline from the field's slot on.
    Msg(usize),
    /// A packed numeric array: its bytes' offset and element count.
    Packed(Prim),
    /// An array of strings: first element slot and count.
    Strings {
        wide: bool,
    },
    /// An array of messages: first element slot and count (elements `width` slots apart).
    Msgs(usize),
}

#[derive(Debug, Clone)]
struct SlotField {
    name: Arc<str>,
    leaf: Leaf,
    array: ArrayKind,
    /// The fewest wire bytes one element takes (the tree decoder's length check).
    min: usize,
    /// First slot, relative to the enclosing message's.
    offset: usize,
}

#[derive(Debug, Clone, Default)]
struct Layout {
    fields: Vec<SlotField>,
    width: usize,
}

/// A schema compiled for flat decoding. Built once per channel.
#[derive(Debug, Clone)]
pub struct Plan {
    layouts: Vec<Layout>,
    root: usize,
}

/// A field located by [`Plan::field`]: its slot from the message root and what it holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FieldRef {
    slot: usize,
    leaf: Leaf,
    array: ArrayKind,
}

impl Plan {
    /// Compile `reg`'s root type; `None` when a type would take more than [`MAX_WIDTH`] slots
    /// inline (such channels decode to trees).
    pub fn compile(reg: &Registry) -> Option<Plan> {
        let mut layouts: Vec<Option<Layout>> = vec![None; reg.defs.len()];
        width_of(reg, reg.root, &mut layouts, 0)?;
        Some(Plan {
            layouts: layouts.into_iter().map(Option::unwrap_or_default).collect(),
            root: reg.root,
        })
    }

    /// Locate a field by its dotted path from the root (`pose.position.x`) through single
    /// nested messages; the last part may be of any kind.
    pub fn field(&self, path: &str) -> std::result::Result<FieldRef, FieldError> {
        let (mut def, mut slot) = (self.root, 0);
        let mut parts = path.split('.').peekable();
        while let Some(part) = parts.next() {
            let f = self.layouts[def]
                .fields
                .iter()
                .find(|f| &*f.name == part)
                .ok_or_else(|| FieldError::new("missing").within(path))?;
            slot += f.offset;
            if parts.peek().is_none() {
                return Ok(FieldRef {
                    slot,
                    leaf: f.leaf,
                    array: f.array,
                });
            }
            match (f.leaf, f.array) {
                (Leaf::Msg(d), ArrayKind::Single) => def = d,
                _ => return Err(FieldError::new("not a single message").within(path)),
            }
        }
        Err(FieldError::new("empty path"))
    }
}

/// Lay out definition `d` (and the types it nests) and return its width in slots.
fn width_of(
    reg: &Registry,
    d: usize,
    layouts: &mut Vec<Option<Layout>>,
    depth: usize,
) -> Option<usize> {
    if let Some(l) = &layouts[d] {
        return Some(l.width);
    }
    // the registry rejects cycles and nesting beyond MAX_NESTING; this guards the recursion
    if depth > MAX_NESTING {
        return None;
    }
    let def = reg.defs.get(d)?;
    let mut fields = Vec::with_capacity(def.fields.len());
    let mut width = 0usize;
    for f in &def.fields {
        let single = f.array == ArrayKind::Single;
        let (leaf, w) = match (&f.ty, single) {
            (BaseType::Prim(p), true) => (Leaf::Prim(*p), 1),
            (BaseType::Prim(p), false) => (Leaf::Packed(*p), 1),
            (BaseType::String { .. }, true) => (Leaf::Str { wide: false }, 1),
            (BaseType::WString { .. }, true) => (Leaf::Str { wide: true }, 1),
            (BaseType::String { .. }, false) => (Leaf::Strings { wide: false }, 1),
            (BaseType::WString { .. }, false) => (Leaf::Strings { wide: true }, 1),
            (BaseType::Msg(i), true) => (Leaf::Msg(*i), width_of(reg, *i, layouts, depth + 1)?),
            (BaseType::Msg(i), false) => {
                width_of(reg, *i, layouts, depth + 1)?;
                (Leaf::Msgs(*i), 1)
            }
        };
        fields.push(SlotField {
            name: Arc::clone(&f.name),
            leaf,
            array: f.array,
            min: min_wire_size(&reg.min_size, &f.ty),
            offset: width,
        });
        width = width.checked_add(w).filter(|&w| w <= MAX_WIDTH)?;
    }
    layouts[d] = Some(Layout { fields, width });
    Some(width)
}

/// The reused buffers of flat decoding.
#[derive(Debug, Default)]
pub struct Flat {
    slots: Vec<u64>,
    text: String,
}

/// A decoded message: the plan, the filled buffers and the payload they point into.
#[derive(Debug, Clone, Copy)]
pub struct FlatRef<'s, 'm> {
    plan: &'s Plan,
    slots: &'s [u64],
    text: &'s str,
    /// The payload after its 4-byte encapsulation header.
    body: &'m [u8],
    big: bool,
}

impl Flat {
    /// Decode `data` by `plan`. The error is the tree decoder's kind at the same byte, with no
    /// field path. Payloads of [`MAX_PAYLOAD`] bytes or more are refused with
    /// [`CdrErrorKind::TreeTooLarge`] (offsets and lossy text must fit in 31 bits); the caller
    /// decodes those to a tree.
    pub fn decode<'s, 'm>(&'s mut self, plan: &'s Plan, data: &'m [u8]) -> Result<FlatRef<'s, 'm>> {
        if data.len() >= MAX_PAYLOAD {
            return Err(CdrError::new(CdrErrorKind::TreeTooLarge {
                budget: MAX_PAYLOAD,
                payload: data.len(),
            }));
        }
        let cur = Cursor::new(data)?;
        let big = cur.is_big_endian();
        self.slots.clear();
        self.text.clear();
        self.slots.resize(plan.layouts[plan.root].width, 0);
        let mut w = Walk {
            plan,
            cur,
            out: self,
            depth: 0,
            budget: Budget::new(data.len()),
            body: &data[4..],
        };
        w.message(plan.root, 0)?;
        Ok(FlatRef {
            plan,
            slots: &self.slots,
            text: &self.text,
            body: &data[4..],
            big,
        })
    }
}

struct Walk<'p, 'o, 'a> {
    plan: &'p Plan,
    cur: Cursor<'a>,
    out: &'o mut Flat,
    depth: usize,
    budget: Budget,
    body: &'a [u8],
}

fn pack(first: usize, count: usize) -> u64 {
    first as u64 | (count as u64) << 32
}

fn unpack(slot: u64) -> (usize, usize) {
    (
        (slot & 0xffff_ffff) as usize,
        ((slot >> 32) & 0x7fff_ffff) as usize,
    )
}

impl Walk<'_, '_, '_> {
    fn check_len(&mut self, n: usize, min: usize, slot: usize) -> Result<usize> {
        self.budget.check_len(&self.cur, n, min, slot)
    }

    fn message(&mut self, d: usize, base: usize) -> Result<()> {
        if self.depth >= MAX_NESTING {
            return Err(CdrError::new(CdrErrorKind::TooDeep));
        }
        self.depth += 1;
        let r = self.fields(d, base);
        self.depth -= 1;
        r
    }

    fn fields(&mut self, d: usize, base: usize) -> Result<()> {
        let plan = self.plan;
        let layout = &plan.layouts[d];
        if layout.fields.is_empty() {
            self.cur.u8()?;
            return Ok(());
        }
        self.budget
            .charge(layout.fields.len() * std::mem::size_of::<(Arc<str>, Value)>())?;
        for f in &layout.fields {
            let at = base + f.offset;
            let n = match f.array {
                ArrayKind::Single => {
                    self.single(f.leaf, at)?;
                    continue;
                }
                ArrayKind::Fixed(n) => n,
                ArrayKind::Bounded(_) | ArrayKind::Unbounded => self.cur.u32()? as usize,
            };
            let slot = match f.leaf {
                Leaf::Packed(_) => 0,
                _ => std::mem::size_of::<Value>(),
            };
            let n = self.check_len(n, f.min, slot)?;
            self.out.slots[at] = self.array(f.leaf, n)?;
        }
        Ok(())
    }

    fn single(&mut self, leaf: Leaf, at: usize) -> Result<()> {
        let c = &mut self.cur;
        self.out.slots[at] = match leaf {
            Leaf::Prim(p) => match p {
                Prim::Bool => u64::from(c.u8()? != 0),
                Prim::Byte | Prim::Char | Prim::U8 => u64::from(c.u8()?),
                Prim::I8 => c.u8()? as i8 as i64 as u64,
                Prim::I16 => c.i16()? as i64 as u64,
                Prim::U16 => u64::from(c.u16()?),
                Prim::I32 => c.i32()? as i64 as u64,
                Prim::U32 => u64::from(c.u32()?),
                Prim::I64 => c.i64()? as u64,
                Prim::U64 => c.u64()?,
                Prim::F32 => u64::from(c.f32()?.to_bits()),
                Prim::F64 => c.f64()?.to_bits(),
            },
            Leaf::Str { wide } => self.string(wide)?,
            Leaf::Msg(d) => return self.message(d, at),
            Leaf::Packed(_) | Leaf::Strings { .. } | Leaf::Msgs(_) => {
                unreachable!("array leaves are read by Walk::array")
            }
        };
        Ok(())
    }

    fn offset_of(&self, bytes: &[u8]) -> usize {
        bytes.as_ptr() as usize - self.body.as_ptr() as usize
    }

    /// `n` elements (already checked) of an array field; the field's slot value.
    fn array(&mut self, leaf: Leaf, n: usize) -> Result<u64> {
        match leaf {
            Leaf::Packed(p) => {
                let bytes = super::packed_bytes(&mut self.cur, p, n)?;
                Ok(pack(self.offset_of(bytes), n))
            }
            Leaf::Strings { wide } => {
                let first = self.out.slots.len();
                self.out.slots.resize(first + n, 0);
                for i in 0..n {
                    self.out.slots[first + i] = self.string(wide)?;
                }
                Ok(pack(first, n))
            }
            Leaf::Msgs(d) => {
                let w = self.plan.layouts[d].width;
                // Every slot is a field the tree decoder charges as it reads each element: if
                // that cannot fit, it fails, so fail before the slots are allocated.
                let least = n
                    .checked_mul(w)
                    .and_then(|s| s.checked_mul(std::mem::size_of::<(Arc<str>, Value)>()));
                if least.is_none_or(|b| b > self.budget.left()) {
                    return Err(self.budget.exceeded());
                }
                let first = self.out.slots.len();
                self.out.slots.resize(first + n * w, 0);
                for i in 0..n {
                    self.message(d, first + i * w)?;
                }
                Ok(pack(first, n))
            }
            Leaf::Prim(_) | Leaf::Str { .. } | Leaf::Msg(_) => {
                unreachable!("single leaves are read by Walk::single")
            }
        }
    }

    /// A string's slot: its bytes in the payload when valid UTF-8, else (and for `wstring`)
    /// its text appended to [`Flat::text`], as the tree decoder converts it.
    fn string(&mut self, wide: bool) -> Result<u64> {
        if wide {
            let len = self.cur.u32()? as usize;
            self.check_len(len, 4, 0)?;
            let start = self.out.text.len();
            for _ in 0..len {
                let unit = self.cur.u32()?;
                let ch = char::from_u32(unit).unwrap_or(char::REPLACEMENT_CHARACTER);
                self.out.text.push(ch);
            }
            return Ok(pack(start, self.out.text.len() - start) | IN_TEXT);
        }
        let len = self.cur.u32()? as usize;
        self.check_len(len, 1, 0)?;
        let bytes = self.cur.take(len)?;
        let bytes = bytes.strip_suffix(&[0]).unwrap_or(bytes);
        if std::str::from_utf8(bytes).is_ok() {
            return Ok(pack(self.offset_of(bytes), bytes.len()));
        }
        let start = self.out.text.len();
        self.out.text.push_str(&String::from_utf8_lossy(bytes));
        Ok(pack(start, self.out.text.len() - start) | IN_TEXT)
    }
}

mod view;

#[cfg(test)]
mod tests;

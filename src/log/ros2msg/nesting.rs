//! What a parsed schema's types cost to decode, checked once when the schema is parsed so that
//! decoding stays bounded: each type's nesting depth (no type may contain itself, none may nest
//! deeper than [`MAX_NESTING`]) and the fewest bytes one instance takes on the wire (CDR
//! decoding bounds array and sequence lengths by it before allocating).
//!
//! The walk is an explicit-stack depth-first search, not recursion: a hostile schema nested
//! 10,000 types deep must give an error, not overflow the stack while being checked.

use super::{ArrayKind, BaseType, MsgDef, SchemaError};

/// The deepest nesting of message types accepted (a type without nested messages is depth 1).
///
/// ROS 2 interfaces nest a handful of levels (`visualization_msgs/MarkerArray` → `Marker` →
/// `Header` → `Time` is 4; the deepest common types stay under 10). The decoder, encoder,
/// value printer and `Drop` of a decoded tree all recurse once or a few frames per level, so
/// the limit is what bounds their stack use: 64 levels take well under the 2 MiB stack of a
/// worker thread even in a debug build, with ample room over any real type.
pub const MAX_NESTING: usize = 64;

/// Nesting depth and least wire size of every definition, in `defs` order.
pub(super) struct Measures {
    pub(super) min_size: Vec<usize>,
}

/// The least bytes one element of `ty` takes, given the least sizes of the message types
/// ([`super::Registry::min_size`]).
pub fn min_wire_size(min_size: &[usize], ty: &BaseType) -> usize {
    match ty {
        BaseType::Prim(p) => p.size(),
        // string and wstring: the u32 length prefix
        BaseType::String { .. } | BaseType::WString { .. } => 4,
        BaseType::Msg(i) => min_size.get(*i).copied().unwrap_or(0),
    }
}

/// The least wire size of a definition whose nested types' sizes are known. An empty message
/// still carries one dummy byte; a type whose fields are all zero-length arrays takes 0.
fn def_min_size(def: &MsgDef, min_size: &[usize]) -> Result<usize, String> {
    if def.fields.is_empty() {
        return Ok(1);
    }
    let mut total = 0usize;
    for f in &def.fields {
        let elem = min_wire_size(min_size, &f.ty);
        let size = match f.array {
            ArrayKind::Single => elem,
            ArrayKind::Fixed(n) => n.checked_mul(elem).ok_or_else(|| {
                format!(
                    "field `{}` is a fixed array of {n} elements of at least {elem} bytes each, \
                     more bytes than any message can hold",
                    f.name
                )
            })?,
            // the u32 element count
            ArrayKind::Bounded(_) | ArrayKind::Unbounded => 4,
        };
        total = total.checked_add(size).ok_or_else(|| {
            format!(
                "fields up to `{}` take more bytes than any message can hold",
                f.name
            )
        })?;
    }
    Ok(total)
}

/// Check that no type contains itself or nests deeper than [`MAX_NESTING`], and measure each
/// type's least wire size (post-order, so nested types are measured first).
pub(super) fn measure(defs: &[MsgDef]) -> Result<Measures, SchemaError> {
    const UNSEEN: u8 = 0;
    const OPEN: u8 = 1;
    const DONE: u8 = 2;
    let mut state = vec![UNSEEN; defs.len()];
    let mut depth = vec![0usize; defs.len()];
    let mut min_size = vec![0usize; defs.len()];
    let err = |i: usize, reason: String| SchemaError {
        type_name: defs[i].name.clone(),
        line: 0,
        reason,
    };
    for start in 0..defs.len() {
        if state[start] == DONE {
            continue;
        }
        // (type, index of the next field to look at)
        let mut stack = vec![(start, 0usize)];
        state[start] = OPEN;
        while let Some(top) = stack.last_mut() {
            let (i, next) = *top;
            let child = defs[i].fields[next..]
                .iter()
                .position(|f| matches!(f.ty, BaseType::Msg(_)))
                .map(|k| next + k);
            match child {
                Some(k) => {
                    top.1 = k + 1;
                    let BaseType::Msg(j) = defs[i].fields[k].ty else {
                        continue;
                    };
                    match state.get(j).copied() {
                        Some(DONE) => {}
                        // A sequence of itself could be empty, but ROS forbids recursive types.
                        Some(OPEN) => return Err(err(j, "type contains itself".into())),
                        Some(_) => {
                            state[j] = OPEN;
                            stack.push((j, 0));
                        }
                        None => return Err(err(i, format!("nested type index {j} is unknown"))),
                    }
                }
                None => {
                    stack.pop();
                    let d = 1 + defs[i]
                        .fields
                        .iter()
                        .filter_map(|f| match f.ty {
                            BaseType::Msg(j) => Some(depth[j]),
                            _ => None,
                        })
                        .max()
                        .unwrap_or(0);
                    if d > MAX_NESTING {
                        return Err(err(
                            i,
                            format!(
                                "message types nest more than {MAX_NESTING} deep here (the \
                                 limit that keeps decoding within the stack; real ROS types \
                                 nest under 10)"
                            ),
                        ));
                    }
                    depth[i] = d;
                    min_size[i] = def_min_size(&defs[i], &min_size).map_err(|r| err(i, r))?;
                    state[i] = DONE;
                }
            }
        }
    }
    Ok(Measures { min_size })
}

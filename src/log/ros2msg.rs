//! Parser for ROS 2 message definitions as MCAP stores them (schema encoding `ros2msg`).
//!
//! The schema text is the root type's `.msg` definition followed by one block per dependency,
//! each introduced by a line of `=` characters and a `MSG: pkg/Type` line — exactly what
//! `ros2 bag record -s mcap` and `rosbags` write. A definition line is one of
//!
//! ```text
//! float32[] ranges              # field: type, name
//! uint8[<=16] small_bytes       # bounded sequence
//! float64[9] k                  # fixed-size array
//! string<=8 short_name "abc"    # bounded string with a default value
//! int8 MODE_AUTO=1              # constant
//! ```
//!
//! Type names may be written `pkg/Type`, `pkg/msg/Type`, or bare `Type` for a type of the same
//! package (`Header` alone means `std_msgs/Header`, as ROS 1 definitions write it). Nested types
//! are resolved to indices into [`Registry::defs`] once, so decoding never looks names up.
//!
//! Not handled here: the `ros2idl` (OMG IDL) schema encoding, which no recorder we know of
//! writes for plain `.msg` types; it is reported as an unsupported encoding by the decoder.

use std::collections::HashMap;
use std::sync::Arc;

mod nesting;

pub use nesting::{MAX_NESTING, min_wire_size};

/// A numeric or boolean primitive of the ROS 2 interface language.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Prim {
    Bool,
    /// `byte` (an octet).
    Byte,
    /// `char` (an unsigned 8-bit value in ROS 2).
    Char,
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
}

impl Prim {
    /// Serialized size in bytes, which is also its CDR alignment.
    pub fn size(self) -> usize {
        match self {
            Prim::Bool | Prim::Byte | Prim::Char | Prim::I8 | Prim::U8 => 1,
            Prim::I16 | Prim::U16 => 2,
            Prim::I32 | Prim::U32 | Prim::F32 => 4,
            Prim::I64 | Prim::U64 | Prim::F64 => 8,
        }
    }

    fn from_name(name: &str) -> Option<Prim> {
        Some(match name {
            "bool" => Prim::Bool,
            "byte" => Prim::Byte,
            "char" => Prim::Char,
            "int8" => Prim::I8,
            "uint8" => Prim::U8,
            "int16" => Prim::I16,
            "uint16" => Prim::U16,
            "int32" => Prim::I32,
            "uint32" => Prim::U32,
            "int64" => Prim::I64,
            "uint64" => Prim::U64,
            "float32" => Prim::F32,
            "float64" => Prim::F64,
            _ => return None,
        })
    }

    pub fn name(self) -> &'static str {
        match self {
            Prim::Bool => "bool",
            Prim::Byte => "byte",
            Prim::Char => "char",
            Prim::I8 => "int8",
            Prim::U8 => "uint8",
            Prim::I16 => "int16",
            Prim::U16 => "uint16",
            Prim::I32 => "int32",
            Prim::U32 => "uint32",
            Prim::I64 => "int64",
            Prim::U64 => "uint64",
            Prim::F32 => "float32",
            Prim::F64 => "float64",
        }
    }
}

/// The element type of a field.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum BaseType {
    Prim(Prim),
    /// `string` or `string<=N`.
    String {
        bound: Option<usize>,
    },
    /// `wstring` or `wstring<=N`.
    WString {
        bound: Option<usize>,
    },
    /// A nested message: index into [`Registry::defs`].
    Msg(usize),
}

/// Whether and how a field is an array.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ArrayKind {
    Single,
    /// `T[N]`: exactly N elements, no length prefix on the wire.
    Fixed(usize),
    /// `T[<=N]`: a sequence of at most N elements.
    Bounded(usize),
    /// `T[]`: a sequence of any length.
    Unbounded,
}

/// A literal from a default value or a constant, before it is given its field's type.
#[derive(Debug, Clone, PartialEq)]
pub enum Literal {
    Bool(bool),
    Int(i128),
    Float(f64),
    Str(String),
    Array(Vec<Literal>),
}

#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    pub name: Arc<str>,
    pub ty: BaseType,
    pub array: ArrayKind,
    pub default: Option<Literal>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Constant {
    pub name: String,
    pub ty: BaseType,
    pub value: Literal,
}

/// One message type: `pkg/msg/Type` and its fields in wire order.
#[derive(Debug, Clone, PartialEq)]
pub struct MsgDef {
    /// Normalised full name, `pkg/msg/Type`.
    pub name: String,
    pub fields: Vec<Field>,
    pub constants: Vec<Constant>,
}

/// All message types of one schema, nested references resolved.
#[derive(Debug, Clone, PartialEq)]
pub struct Registry {
    pub defs: Vec<MsgDef>,
    /// Index of the schema's own (root) type.
    pub root: usize,
    /// The fewest bytes one instance of each type takes on the wire (0 for a type of
    /// zero-length arrays only). A schema whose size overflows `usize` does not parse.
    pub min_size: Vec<usize>,
}

/// A definition that does not parse: which type block, which line (1-based within the whole
/// schema text; 0 when the fault is not on one line), and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("schema {type_name}{}: {reason}", if *line == 0 { String::new() } else { format!(", line {line}") })]
pub struct SchemaError {
    pub type_name: String,
    pub line: usize,
    pub reason: String,
}

/// Normalise `pkg/Type` or `pkg/msg/Type` to `pkg/msg/Type`; `None` for other shapes.
pub fn normalize_type_name(name: &str) -> Option<String> {
    let parts: Vec<&str> = name.split('/').collect();
    match parts.as_slice() {
        [pkg, ty] if !pkg.is_empty() && !ty.is_empty() => Some(format!("{pkg}/msg/{ty}")),
        [pkg, kind, ty] if !pkg.is_empty() && !kind.is_empty() && !ty.is_empty() => {
            Some(format!("{pkg}/{kind}/{ty}"))
        }
        _ => None,
    }
}

/// True for `bool`, the numeric types, `string`, `wstring` and their bounded forms.
pub fn is_primitive_or_string(elem: &str) -> bool {
    Prim::from_name(elem).is_some()
        || elem == "string"
        || elem == "wstring"
        || elem.starts_with("string<=")
        || elem.starts_with("wstring<=")
}

fn package_of(full_name: &str) -> &str {
    full_name.split('/').next().unwrap_or("")
}

/// A field's type as written, before nested names are resolved.
struct RawField {
    line: usize,
    name: String,
    base: RawBase,
    array: ArrayKind,
    default: Option<Literal>,
}

enum RawBase {
    Known(BaseType),
    Named(String),
}

struct RawDef {
    name: String,
    fields: Vec<RawField>,
    constants: Vec<Constant>,
}

impl Registry {
    /// Parse the schema text of type `schema_name` (e.g. `sensor_msgs/msg/LaserScan`).
    pub fn parse(schema_name: &str, text: &str) -> Result<Registry, SchemaError> {
        let root_name = normalize_type_name(schema_name).ok_or_else(|| SchemaError {
            type_name: schema_name.to_string(),
            line: 0,
            reason: "schema name is not of the form pkg/Type or pkg/msg/Type".into(),
        })?;
        let raw = split_blocks(&root_name, text)?;
        let mut index: HashMap<String, usize> = HashMap::new();
        for (i, def) in raw.iter().enumerate() {
            if index.insert(def.name.clone(), i).is_some() {
                // rosbag2 never repeats a block; a repeat would be ambiguous only if it differed,
                // and silently preferring one would hide that.
                return Err(SchemaError {
                    type_name: def.name.clone(),
                    line: 0,
                    reason: "type defined twice in the schema".into(),
                });
            }
        }
        let mut defs = Vec::with_capacity(raw.len());
        for def in &raw {
            let pkg = package_of(&def.name).to_string();
            let mut fields = Vec::with_capacity(def.fields.len());
            for f in &def.fields {
                let ty = match &f.base {
                    RawBase::Known(t) => t.clone(),
                    RawBase::Named(n) => BaseType::Msg(resolve(&index, &pkg, n).ok_or_else(|| {
                        SchemaError {
                            type_name: def.name.clone(),
                            line: f.line,
                            reason: format!(
                                "field `{}` has type `{n}`, which is neither a primitive nor defined in the schema",
                                f.name
                            ),
                        }
                    })?),
                };
                fields.push(Field {
                    name: Arc::from(f.name.as_str()),
                    ty,
                    array: f.array,
                    default: f.default.clone(),
                });
            }
            defs.push(MsgDef {
                name: def.name.clone(),
                fields,
                constants: def.constants.clone(),
            });
        }
        let measures = nesting::measure(&defs)?;
        Ok(Registry {
            defs,
            root: 0,
            min_size: measures.min_size,
        })
    }

    pub fn root_def(&self) -> &MsgDef {
        &self.defs[self.root]
    }
}

fn resolve(index: &HashMap<String, usize>, pkg: &str, name: &str) -> Option<usize> {
    if let Some(full) = normalize_type_name(name) {
        return index.get(&full).copied();
    }
    if name.contains('/') {
        return None;
    }
    if let Some(&i) = index.get(&format!("{pkg}/msg/{name}")) {
        return Some(i);
    }
    if name == "Header" {
        return index.get("std_msgs/msg/Header").copied();
    }
    None
}

/// Split the text into type blocks and parse each block's lines.
fn split_blocks(root_name: &str, text: &str) -> Result<Vec<RawDef>, SchemaError> {
    let mut defs = vec![RawDef {
        name: root_name.to_string(),
        fields: Vec::new(),
        constants: Vec::new(),
    }];
    let mut expect_msg_line = false;
    for (i, line) in text.lines().enumerate() {
        let line_no = i + 1;
        let trimmed = line.trim();
        if trimmed.len() >= 3 && trimmed.chars().all(|c| c == '=') {
            expect_msg_line = true;
            continue;
        }
        if expect_msg_line {
            if trimmed.is_empty() {
                continue;
            }
            let current = defs.last().map(|d| d.name.clone()).unwrap_or_default();
            let Some(rest) = trimmed.strip_prefix("MSG:") else {
                return Err(SchemaError {
                    type_name: current,
                    line: line_no,
                    reason: format!(
                        "expected `MSG: pkg/Type` after a separator line, found `{trimmed}`"
                    ),
                });
            };
            let name = normalize_type_name(rest.trim()).ok_or_else(|| SchemaError {
                type_name: current,
                line: line_no,
                reason: format!("`{}` is not a type name of the form pkg/Type", rest.trim()),
            })?;
            defs.push(RawDef {
                name,
                fields: Vec::new(),
                constants: Vec::new(),
            });
            expect_msg_line = false;
            continue;
        }
        let def = defs.last_mut().expect("defs starts non-empty");
        parse_line(def, line, line_no)?;
    }
    if expect_msg_line {
        let current = defs.last().map(|d| d.name.clone()).unwrap_or_default();
        return Err(SchemaError {
            type_name: current,
            line: text.lines().count(),
            reason: "separator line at the end of the schema without a `MSG:` block".into(),
        });
    }
    Ok(defs)
}

/// Remove a `#` comment that is not inside a quoted string.
fn strip_comment(line: &str) -> &str {
    let mut quote: Option<char> = None;
    let mut escaped = false;
    for (i, c) in line.char_indices() {
        if escaped {
            escaped = false;
            continue;
        }
        match (quote, c) {
            (Some(_), '\\') => escaped = true,
            (Some(q), c) if c == q => quote = None,
            (None, '"' | '\'') => quote = Some(c),
            (None, '#') => return &line[..i],
            _ => {}
        }
    }
    line
}

fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic())
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

fn parse_line(def: &mut RawDef, line: &str, line_no: usize) -> Result<(), SchemaError> {
    let err = |reason: String| SchemaError {
        type_name: def.name.clone(),
        line: line_no,
        reason,
    };
    let code = strip_comment(line).trim();
    if code.is_empty() {
        return Ok(());
    }
    // type token ends at the first whitespace
    let (type_token, rest) = code
        .split_once(char::is_whitespace)
        .ok_or_else(|| err(format!("`{code}` has a type but no name")))?;
    let rest = rest.trim_start();
    let (base, array) = parse_type_token(type_token).map_err(err)?;

    // constant: NAME=value (spaces around '=' allowed)
    let name_end = rest
        .find(|c: char| c.is_whitespace() || c == '=')
        .unwrap_or(rest.len());
    let name = &rest[..name_end];
    let after_name = rest[name_end..].trim_start();
    if !is_identifier(name) {
        return Err(err(format!(
            "`{name}` is not a valid field or constant name"
        )));
    }
    if let Some(value_text) = after_name.strip_prefix('=') {
        let ty = match base {
            RawBase::Known(t) => t,
            RawBase::Named(n) => {
                return Err(err(format!(
                    "constant `{name}` has non-primitive type `{n}`"
                )));
            }
        };
        if array != ArrayKind::Single {
            return Err(err(format!("constant `{name}` cannot be an array")));
        }
        let value = parse_literal(&ty, ArrayKind::Single, value_text.trim()).map_err(err)?;
        def.constants.push(Constant {
            name: name.to_string(),
            ty,
            value,
        });
        return Ok(());
    }
    let default = if after_name.is_empty() {
        None
    } else {
        let ty = match &base {
            RawBase::Known(t) => t,
            RawBase::Named(n) => {
                return Err(err(format!(
                    "field `{name}` of message type `{n}` cannot have a default value"
                )));
            }
        };
        Some(parse_literal(ty, array, after_name).map_err(err)?)
    };
    def.fields.push(RawField {
        line: line_no,
        name: name.to_string(),
        base,
        array,
        default,
    });
    Ok(())
}

fn parse_type_token(token: &str) -> Result<(RawBase, ArrayKind), String> {
    let (elem, array) = match token.find('[') {
        None => (token, ArrayKind::Single),
        Some(open) => {
            let inner = token[open + 1..]
                .strip_suffix(']')
                .ok_or_else(|| format!("array type `{token}` is missing its closing `]`"))?;
            let array = if inner.is_empty() {
                ArrayKind::Unbounded
            } else if let Some(n) = inner.strip_prefix("<=") {
                ArrayKind::Bounded(parse_size(n, token)?)
            } else {
                ArrayKind::Fixed(parse_size(inner, token)?)
            };
            (&token[..open], array)
        }
    };
    let base = if let Some(p) = Prim::from_name(elem) {
        RawBase::Known(BaseType::Prim(p))
    } else if let Some(bound) = elem.strip_prefix("string") {
        RawBase::Known(BaseType::String {
            bound: parse_string_bound(bound, token)?,
        })
    } else if let Some(bound) = elem.strip_prefix("wstring") {
        RawBase::Known(BaseType::WString {
            bound: parse_string_bound(bound, token)?,
        })
    } else if elem
        .split('/')
        .all(|part| !part.is_empty() && part.chars().all(|c| c.is_ascii_alphanumeric() || c == '_'))
    {
        RawBase::Named(elem.to_string())
    } else {
        return Err(format!("`{elem}` is not a type name"));
    };
    Ok((base, array))
}

fn parse_string_bound(bound: &str, token: &str) -> Result<Option<usize>, String> {
    if bound.is_empty() {
        return Ok(None);
    }
    match bound.strip_prefix("<=") {
        Some(n) => Ok(Some(parse_size(n, token)?)),
        None => Err(format!("`{token}` is not a type name")),
    }
}

fn parse_size(s: &str, token: &str) -> Result<usize, String> {
    s.trim()
        .parse::<usize>()
        .map_err(|_| format!("array or string bound in `{token}` is not a non-negative integer"))
}

/// Parse a default value or constant value for a field of type `ty` (and array kind `array`).
fn parse_literal(ty: &BaseType, array: ArrayKind, text: &str) -> Result<Literal, String> {
    if array != ArrayKind::Single {
        let inner = text
            .strip_prefix('[')
            .and_then(|t| t.strip_suffix(']'))
            .ok_or_else(|| format!("array default `{text}` must be written [a, b, ...]"))?;
        let items = split_array_items(inner)?;
        let values = items
            .iter()
            .map(|item| parse_literal(ty, ArrayKind::Single, item))
            .collect::<Result<Vec<_>, _>>()?;
        match array {
            ArrayKind::Fixed(n) if values.len() != n => {
                return Err(format!(
                    "default has {} elements, the array has {n}",
                    values.len()
                ));
            }
            ArrayKind::Bounded(n) if values.len() > n => {
                return Err(format!(
                    "default has {} elements, the bound is {n}",
                    values.len()
                ));
            }
            _ => {}
        }
        return Ok(Literal::Array(values));
    }
    match ty {
        BaseType::Prim(Prim::Bool) => match text {
            "true" | "True" | "1" => Ok(Literal::Bool(true)),
            "false" | "False" | "0" => Ok(Literal::Bool(false)),
            _ => Err(format!("`{text}` is not a bool")),
        },
        BaseType::Prim(Prim::F32 | Prim::F64) => text
            .parse::<f64>()
            .map(Literal::Float)
            .map_err(|_| format!("`{text}` is not a number")),
        BaseType::Prim(p) => {
            let v = parse_int(text).ok_or_else(|| format!("`{text}` is not an integer"))?;
            let (lo, hi): (i128, i128) = match p {
                Prim::I8 => (i8::MIN.into(), i8::MAX.into()),
                Prim::I16 => (i16::MIN.into(), i16::MAX.into()),
                Prim::I32 => (i32::MIN.into(), i32::MAX.into()),
                Prim::I64 => (i64::MIN.into(), i64::MAX.into()),
                Prim::U16 => (0, u16::MAX.into()),
                Prim::U32 => (0, u32::MAX.into()),
                Prim::U64 => (0, u64::MAX.into()),
                _ => (0, u8::MAX.into()),
            };
            if v < lo || v > hi {
                return Err(format!("{v} does not fit in {}", p.name()));
            }
            Ok(Literal::Int(v))
        }
        BaseType::String { bound } | BaseType::WString { bound } => {
            let s = unquote(text)?;
            if let Some(b) = bound
                && s.chars().count() > *b
            {
                return Err(format!("default string is longer than its bound {b}"));
            }
            Ok(Literal::Str(s))
        }
        BaseType::Msg(_) => Err("message-typed fields have no default".into()),
    }
}

fn parse_int(text: &str) -> Option<i128> {
    let (neg, digits) = match text.strip_prefix('-') {
        Some(d) => (true, d),
        None => (false, text.strip_prefix('+').unwrap_or(text)),
    };
    let v = if let Some(hex) = digits
        .strip_prefix("0x")
        .or_else(|| digits.strip_prefix("0X"))
    {
        i128::from_str_radix(hex, 16).ok()?
    } else {
        digits.parse::<i128>().ok()?
    };
    Some(if neg { -v } else { v })
}

/// A string default: quoted with ' or " (with backslash escapes), or bare text.
fn unquote(text: &str) -> Result<String, String> {
    let mut chars = text.chars();
    let Some(q) = chars.next().filter(|c| *c == '"' || *c == '\'') else {
        return Ok(text.to_string());
    };
    let mut out = String::new();
    let mut escaped = false;
    for (i, c) in text.char_indices().skip(1) {
        if escaped {
            out.push(match c {
                'n' => '\n',
                't' => '\t',
                'r' => '\r',
                '0' => '\0',
                other => other,
            });
            escaped = false;
        } else if c == '\\' {
            escaped = true;
        } else if c == q {
            if !text[i + 1..].trim().is_empty() {
                return Err(format!(
                    "unexpected text after the closing quote in `{text}`"
                ));
            }
            return Ok(out);
        } else {
            out.push(c);
        }
    }
    Err(format!("unterminated string `{text}`"))
}

/// Split `a, "b, c", d` at commas outside quotes.
fn split_array_items(inner: &str) -> Result<Vec<String>, String> {
    let mut items = Vec::new();
    let mut current = String::new();
    let mut quote: Option<char> = None;
    let mut escaped = false;
    for c in inner.chars() {
        if escaped {
            current.push(c);
            escaped = false;
            continue;
        }
        match (quote, c) {
            (Some(_), '\\') => {
                current.push(c);
                escaped = true;
            }
            (Some(q), c) if c == q => {
                current.push(c);
                quote = None;
            }
            (None, '"' | '\'') => {
                current.push(c);
                quote = Some(c);
            }
            (None, ',') => items.push(std::mem::take(&mut current)),
            _ => current.push(c),
        }
    }
    if quote.is_some() {
        return Err(format!("unterminated string in `[{inner}]`"));
    }
    if !current.trim().is_empty() || !items.is_empty() {
        items.push(current);
    }
    let items: Vec<String> = items.into_iter().map(|s| s.trim().to_string()).collect();
    if items.iter().any(|s| s.is_empty()) {
        return Err(format!("empty element in `[{inner}]`"));
    }
    Ok(items)
}

#[cfg(test)]
mod tests;

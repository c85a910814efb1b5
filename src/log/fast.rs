//! Typed CDR fast paths for the high-rate standard types (`tf2_msgs/msg/TFMessage`,
//! `nav_msgs/msg/Odometry`, `sensor_msgs/msg/{Imu, LaserScan, Image, CompressedImage,
//! CameraInfo}`): read the wire bytes straight into the typed message, skipping the dynamic
//! [`Value`](super::value::Value) tree of [`super::cdr`].
//!
//! A channel takes the fast path only when its schema has exactly the wire layout of our
//! canonical definition ([`definitions::same_layout`]: field names, types, string bounds and
//! arrays, recursively); any other definition of the same name goes through the dynamic
//! decoder, so a log that adds or reorders fields still reads. The wire rules are those of
//! [`super::cdr`] (encapsulation header, alignment relative to the byte after it, capped at 4
//! for plain CDR2, NUL-terminated strings read lossily as UTF-8, packed arrays aligned only when
//! non-empty), and the known-answer tests check every fast path against the dynamic decoder.
//!
//! - `read_into` decodes into an existing message and reuses its buffers (strings, vectors,
//!   the transforms of a `TFMessage`), so a reading loop allocates nothing per message once
//!   the buffers have grown;
//! - [`ImageRef`] and [`CompressedImageRef`] borrow the pixel bytes (and, when they are valid
//!   UTF-8, the strings) from the payload, which is itself borrowed from the decompressed chunk:
//!   no copy at all.
//!
//! Written by hand for the same reason as [`super::cdr`]: the Rust CDR crates need serde types
//! generated at compile time and would not share the dynamic decoder's bounds and errors.

use std::any::{Any, TypeId};
use std::sync::OnceLock;

use super::cdr::{CdrError, Cursor};
use super::definitions;
use super::msgs::{CameraInfo, CompressedImage, Image, Imu, LaserScan, Odometry, TfMessage};
use super::ros2msg::Registry;

mod read;
#[cfg(test)]
mod tests;

pub use read::{CompressedImageRef, HeaderRef, ImageRef};

type Result<T> = std::result::Result<T, CdrError>;

/// The standard types with a typed fast path.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FastKind {
    Tf,
    Odometry,
    Imu,
    LaserScan,
    Image,
    CompressedImage,
    CameraInfo,
}

/// Every kind, in declaration order.
pub const ALL_KINDS: [FastKind; 7] = [
    FastKind::Tf,
    FastKind::Odometry,
    FastKind::Imu,
    FastKind::LaserScan,
    FastKind::Image,
    FastKind::CompressedImage,
    FastKind::CameraInfo,
];

impl FastKind {
    /// The ROS 2 type name, `pkg/msg/Type`.
    pub fn type_name(self) -> &'static str {
        match self {
            FastKind::Tf => "tf2_msgs/msg/TFMessage",
            FastKind::Odometry => "nav_msgs/msg/Odometry",
            FastKind::Imu => "sensor_msgs/msg/Imu",
            FastKind::LaserScan => "sensor_msgs/msg/LaserScan",
            FastKind::Image => "sensor_msgs/msg/Image",
            FastKind::CompressedImage => "sensor_msgs/msg/CompressedImage",
            FastKind::CameraInfo => "sensor_msgs/msg/CameraInfo",
        }
    }

    /// The fast path that reads a channel of this parsed schema, if its root type is one of
    /// the standard types with exactly the canonical wire layout.
    pub fn for_registry(reg: &Registry) -> Option<FastKind> {
        static CANONICAL: OnceLock<Vec<(FastKind, Registry)>> = OnceLock::new();
        let canonical = CANONICAL.get_or_init(|| {
            ALL_KINDS
                .iter()
                .filter_map(|k| definitions::registry(k.type_name()).map(|r| (*k, r)))
                .collect()
        });
        let root = reg.defs.get(reg.root)?;
        let (kind, ours) = canonical.iter().find(|(k, _)| k.type_name() == root.name)?;
        definitions::same_layout(reg, reg.root, ours, ours.root).then_some(*kind)
    }
}

/// A message type with a typed CDR fast path.
pub trait FastCdr: Sized {
    const KIND: FastKind;
    /// Decode `data` into `self`, reusing its buffers. On error `self` holds a partial
    /// message and must not be used.
    fn read_into(&mut self, c: &mut Cursor<'_>) -> Result<()>;
}

/// Decode a whole CDR payload (encapsulation header included) as `T`.
pub fn decode<T: FastCdr + Default>(data: &[u8]) -> Result<T> {
    let mut out = T::default();
    decode_into(data, &mut out)?;
    Ok(out)
}

/// Decode a payload of a channel of fast kind `kind` as `T`, when `T` is that kind's typed
/// message (`None` otherwise). For generic callers that hold a `T: RosMessage`; the concrete
/// type is recovered by downcasting, so the message types need not know this module.
pub fn decode_as<T: 'static>(kind: FastKind, data: &[u8]) -> Option<Result<T>> {
    fn boxed<U: FastCdr + Default + 'static>(data: &[u8]) -> Result<Box<dyn Any>> {
        decode::<U>(data).map(|u| Box::new(u) as Box<dyn Any>)
    }
    let wanted = TypeId::of::<T>();
    let r = match kind {
        FastKind::Tf if wanted == TypeId::of::<TfMessage>() => boxed::<TfMessage>(data),
        FastKind::Odometry if wanted == TypeId::of::<Odometry>() => boxed::<Odometry>(data),
        FastKind::Imu if wanted == TypeId::of::<Imu>() => boxed::<Imu>(data),
        FastKind::LaserScan if wanted == TypeId::of::<LaserScan>() => boxed::<LaserScan>(data),
        FastKind::Image if wanted == TypeId::of::<Image>() => boxed::<Image>(data),
        FastKind::CompressedImage if wanted == TypeId::of::<CompressedImage>() => {
            boxed::<CompressedImage>(data)
        }
        FastKind::CameraInfo if wanted == TypeId::of::<CameraInfo>() => boxed::<CameraInfo>(data),
        _ => return None,
    };
    // the arms above checked the type id, so the downcast cannot fail; were it to, the
    // generic decoder would read the message instead
    match r {
        Ok(b) => b.downcast::<T>().ok().map(|b| Ok(*b)),
        Err(e) => Some(Err(e)),
    }
}

/// Decode a whole CDR payload into `out`, reusing its buffers.
pub fn decode_into<T: FastCdr>(data: &[u8], out: &mut T) -> Result<()> {
    out.read_into(&mut Cursor::new(data)?)
}

/// An error inside field `name` (path as [`super::cdr`] writes it, e.g. `transforms[3].header`).
fn prefixed(mut e: CdrError, name: &str) -> CdrError {
    e.path = if e.path.is_empty() {
        name.to_string()
    } else if e.path.starts_with('[') {
        format!("{name}{}", e.path)
    } else {
        format!("{name}.{}", e.path)
    };
    e
}

fn within<T>(r: Result<T>, name: &str) -> Result<T> {
    r.map_err(|e| prefixed(e, name))
}

/// Owned messages from the borrowed image views (one copy of the pixels).
impl ImageRef<'_> {
    pub fn to_owned(&self) -> Image {
        Image {
            header: self.header.to_owned(),
            height: self.height,
            width: self.width,
            encoding: self.encoding.to_string(),
            is_bigendian: self.is_bigendian,
            step: self.step,
            data: self.data.to_vec(),
        }
    }
}

impl CompressedImageRef<'_> {
    pub fn to_owned(&self) -> CompressedImage {
        CompressedImage {
            header: self.header.to_owned(),
            format: self.format.to_string(),
            data: self.data.to_vec(),
        }
    }
}

/// A message decoded by the fast path where its channel has one ([`FastKind`]), else the
/// dynamic tree. The typed variants borrow the decoder's reused buffers; the image views
/// borrow the payload.
#[derive(Debug)]
pub enum Decoded<'s, 'm> {
    Tf(&'s TfMessage),
    Odometry(&'s Odometry),
    Imu(&'s Imu),
    LaserScan(&'s LaserScan),
    CameraInfo(&'s CameraInfo),
    Image(ImageRef<'m>),
    CompressedImage(CompressedImageRef<'m>),
    /// Any other CDR type, decoded flat ([`super::cdr::flat`]).
    Flat(super::cdr::flat::FlatRef<'s, 'm>),
    Value(super::value::Value),
}

/// Reused buffers for [`Decoded`]: one message of each buffered kind, and of TF one per
/// transform count. A log's TF publishers each send their own fixed set of frames (one
/// odometry transform; nineteen static mounts; four wheels), interleaved: a buffer per count
/// keeps each set's frame-id strings, which the next message of that set then only compares
/// ([`Cursor::string_into`]) instead of freeing, allocating and copying them.
#[derive(Debug, Default)]
pub struct Scratch {
    tf: Vec<TfMessage>,
    odometry: Odometry,
    imu: Imu,
    scan: LaserScan,
    camera_info: CameraInfo,
}

/// TF buffers a [`Scratch`] keeps (distinct transform counts; beyond, the first is reused).
const TF_BUFFERS: usize = 8;

impl Scratch {
    /// Decode a payload of a channel whose fast kind is `kind`.
    pub fn decode<'s, 'm>(&'s mut self, kind: FastKind, data: &'m [u8]) -> Result<Decoded<'s, 'm>> {
        Ok(match kind {
            FastKind::Tf => {
                // the transform count leads the payload; a short one is left to the decoder
                // to report
                let n = Cursor::new(data).and_then(|mut c| c.u32()).unwrap_or(0);
                let k = match self
                    .tf
                    .iter()
                    .position(|t| t.transforms.len() == n as usize)
                {
                    Some(k) => k,
                    None if self.tf.len() < TF_BUFFERS => {
                        self.tf.push(TfMessage::default());
                        self.tf.len() - 1
                    }
                    None => 0,
                };
                decode_into(data, &mut self.tf[k])?;
                Decoded::Tf(&self.tf[k])
            }
            FastKind::Odometry => {
                decode_into(data, &mut self.odometry)?;
                Decoded::Odometry(&self.odometry)
            }
            FastKind::Imu => {
                decode_into(data, &mut self.imu)?;
                Decoded::Imu(&self.imu)
            }
            FastKind::LaserScan => {
                decode_into(data, &mut self.scan)?;
                Decoded::LaserScan(&self.scan)
            }
            FastKind::CameraInfo => {
                decode_into(data, &mut self.camera_info)?;
                Decoded::CameraInfo(&self.camera_info)
            }
            FastKind::Image => Decoded::Image(ImageRef::decode(data)?),
            FastKind::CompressedImage => {
                Decoded::CompressedImage(CompressedImageRef::decode(data)?)
            }
        })
    }
}

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
use std::borrow::Cow;
use std::sync::OnceLock;

use super::cdr::{CdrError, CdrErrorKind};
use super::definitions;
use super::msgs::{CameraInfo, CompressedImage, Image, Imu, LaserScan, Odometry, TfMessage, Time};
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

const KINDS: [(FastKind, &str); 7] = [
    (FastKind::Tf, "tf2_msgs/msg/TFMessage"),
    (FastKind::Odometry, "nav_msgs/msg/Odometry"),
    (FastKind::Imu, "sensor_msgs/msg/Imu"),
    (FastKind::LaserScan, "sensor_msgs/msg/LaserScan"),
    (FastKind::Image, "sensor_msgs/msg/Image"),
    (FastKind::CompressedImage, "sensor_msgs/msg/CompressedImage"),
    (FastKind::CameraInfo, "sensor_msgs/msg/CameraInfo"),
];

impl FastKind {
    /// The ROS 2 type name, `pkg/msg/Type`.
    pub fn type_name(self) -> &'static str {
        KINDS
            .iter()
            .find(|(k, _)| *k == self)
            .map(|(_, n)| *n)
            .expect("every kind is listed")
    }

    /// The fast path that reads a channel of this parsed schema, if its root type is one of
    /// the standard types with exactly the canonical wire layout.
    pub fn for_registry(reg: &Registry) -> Option<FastKind> {
        static CANONICAL: OnceLock<Vec<(FastKind, Registry)>> = OnceLock::new();
        let canonical = CANONICAL.get_or_init(|| {
            KINDS
                .iter()
                .filter_map(|(k, n)| definitions::registry(n).map(|r| (*k, r)))
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
    Some(r.map(|b| *b.downcast::<T>().expect("the type id was checked")))
}

/// Decode a whole CDR payload into `out`, reusing its buffers.
pub fn decode_into<T: FastCdr>(data: &[u8], out: &mut T) -> Result<()> {
    out.read_into(&mut Cursor::new(data)?)
}

/// A position in a CDR payload (after its 4-byte encapsulation header).
pub struct Cursor<'a> {
    buf: &'a [u8],
    pos: usize,
    big: bool,
    max_align: usize,
}

macro_rules! scalar {
    ($name:ident, $t:ty) => {
        #[inline]
        pub fn $name(&mut self) -> Result<$t> {
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

impl<'a> Cursor<'a> {
    /// Parse the encapsulation header (the same four representations as [`super::cdr`]).
    pub fn new(data: &'a [u8]) -> Result<Self> {
        if data.len() < 4 {
            return Err(err(CdrErrorKind::NoHeader(data.len())));
        }
        let (big, max_align) = match u16::from_be_bytes([data[0], data[1]]) {
            0x0000 => (true, 8),
            0x0001 => (false, 8),
            0x0006 => (true, 4),
            0x0007 => (false, 4),
            other => return Err(err(CdrErrorKind::UnsupportedEncapsulation(other))),
        };
        Ok(Cursor {
            buf: &data[4..],
            pos: 0,
            big,
            max_align,
        })
    }

    #[inline]
    fn align(&mut self, size: usize) {
        let a = size.min(self.max_align);
        let rem = self.pos % a;
        if rem != 0 {
            self.pos += a - rem;
        }
    }

    #[inline]
    fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        let have = self.buf.len().saturating_sub(self.pos);
        if n > have {
            return Err(err(CdrErrorKind::UnexpectedEnd {
                offset: self.pos + 4,
                need: n,
                have,
            }));
        }
        let out = &self.buf[self.pos..self.pos + n];
        self.pos += n;
        Ok(out)
    }

    #[inline]
    pub fn u8(&mut self) -> Result<u8> {
        Ok(self.take(1)?[0])
    }

    scalar!(i32, i32);
    scalar!(u32, u32);
    scalar!(f32, f32);
    scalar!(f64, f64);

    /// A sequence length whose `min_elem` bytes per element must fit in the bytes left.
    #[inline]
    pub fn seq_len(&mut self, min_elem: usize) -> Result<usize> {
        let n = self.u32()? as usize;
        let remaining = self.buf.len().saturating_sub(self.pos);
        match n.checked_mul(min_elem) {
            Some(need) if need <= remaining => Ok(n),
            _ => Err(err(CdrErrorKind::LengthTooLarge {
                offset: self.pos + 4,
                len: n as u64,
                remaining,
            })),
        }
    }

    /// A string's bytes without the NUL terminator (tolerating writers that omit it).
    #[inline]
    fn str_bytes(&mut self) -> Result<&'a [u8]> {
        let n = self.seq_len(1)?;
        let b = self.take(n)?;
        Ok(b.strip_suffix(&[0]).unwrap_or(b))
    }

    /// A string, borrowed when it is valid UTF-8 (invalid bytes become U+FFFD).
    pub fn str(&mut self) -> Result<Cow<'a, str>> {
        Ok(String::from_utf8_lossy(self.str_bytes()?))
    }

    /// A string into `out`, reusing its buffer.
    pub fn string_into(&mut self, out: &mut String) -> Result<()> {
        let b = self.str_bytes()?;
        out.clear();
        match std::str::from_utf8(b) {
            Ok(s) => out.push_str(s),
            Err(_) => out.push_str(&String::from_utf8_lossy(b)),
        }
        Ok(())
    }

    /// `uint8[]`, borrowed.
    pub fn bytes(&mut self) -> Result<&'a [u8]> {
        let n = self.seq_len(1)?;
        self.take(n)
    }

    /// `float64[N]` (no length prefix).
    pub fn f64_array<const N: usize>(&mut self, out: &mut [f64; N]) -> Result<()> {
        let b = self.packed(N, 8)?;
        self.fill_f64(b, out);
        Ok(())
    }

    /// `float64[]` into `out`, reusing its buffer.
    pub fn f64_seq(&mut self, out: &mut Vec<f64>) -> Result<()> {
        let n = self.seq_len(8)?;
        let b = self.packed(n, 8)?;
        out.clear();
        out.resize(n, 0.0);
        self.fill_f64(b, out);
        Ok(())
    }

    /// `float32[]` into `out`, reusing its buffer.
    pub fn f32_seq(&mut self, out: &mut Vec<f32>) -> Result<()> {
        let n = self.seq_len(4)?;
        let b = self.packed(n, 4)?;
        out.clear();
        let big = self.big;
        out.extend(b.chunks_exact(4).map(|c| {
            let a: [u8; 4] = c.try_into().expect("chunk of 4");
            if big {
                f32::from_be_bytes(a)
            } else {
                f32::from_le_bytes(a)
            }
        }));
        Ok(())
    }

    /// The bytes of `n` packed elements of `size` bytes (aligned first when `n > 0`).
    fn packed(&mut self, n: usize, size: usize) -> Result<&'a [u8]> {
        if n > 0 {
            self.align(size);
        }
        let remaining = self.buf.len().saturating_sub(self.pos);
        match n.checked_mul(size) {
            Some(need) if need <= remaining => self.take(need),
            _ => Err(err(CdrErrorKind::LengthTooLarge {
                offset: self.pos + 4,
                len: n as u64,
                remaining,
            })),
        }
    }

    fn fill_f64(&self, b: &[u8], out: &mut [f64]) {
        for (o, c) in out.iter_mut().zip(b.chunks_exact(8)) {
            let a: [u8; 8] = c.try_into().expect("chunk of 8");
            *o = if self.big {
                f64::from_be_bytes(a)
            } else {
                f64::from_le_bytes(a)
            };
        }
    }

    /// `builtin_interfaces/msg/Time`.
    pub fn time(&mut self) -> Result<Time> {
        Ok(Time {
            sec: self.i32()?,
            nanosec: self.u32()?,
        })
    }

    /// Three `float64` (a `Point` or `Vector3`).
    pub fn xyz(&mut self) -> Result<[f64; 3]> {
        Ok([self.f64()?, self.f64()?, self.f64()?])
    }

    /// `geometry_msgs/msg/Quaternion` as `[x, y, z, w]`.
    pub fn xyzw(&mut self) -> Result<[f64; 4]> {
        Ok([self.f64()?, self.f64()?, self.f64()?, self.f64()?])
    }
}

fn err(kind: CdrErrorKind) -> CdrError {
    CdrError {
        path: String::new(),
        kind,
    }
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
    Value(super::value::Value),
}

/// Reused buffers for [`Decoded`]: one message of each buffered kind.
#[derive(Debug, Default)]
pub struct Scratch {
    tf: TfMessage,
    odometry: Odometry,
    imu: Imu,
    scan: LaserScan,
    camera_info: CameraInfo,
}

impl Scratch {
    /// Decode a payload of a channel whose fast kind is `kind`.
    pub fn decode<'s, 'm>(&'s mut self, kind: FastKind, data: &'m [u8]) -> Result<Decoded<'s, 'm>> {
        Ok(match kind {
            FastKind::Tf => {
                decode_into(data, &mut self.tf)?;
                Decoded::Tf(&self.tf)
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

//! A bounds-checked position in a CDR payload: the wire primitives (alignment, scalars in
//! either byte order, length prefixes checked against the bytes left, strings, packed
//! numeric runs) shared by the dynamic decoder ([`super::decode`]) and the typed fast paths
//! ([`crate::log::fast`]). Every read returns [`CdrError`] on a short or lying payload; none
//! panics.

use std::borrow::Cow;

use super::{CdrError, CdrErrorKind, Result};

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
            let b: [u8; N] = *self.take_array::<N>()?;
            Ok(if self.big {
                <$t>::from_be_bytes(b)
            } else {
                <$t>::from_le_bytes(b)
            })
        }
    };
}

impl<'a> Cursor<'a> {
    /// Parse the encapsulation header and stand at the first byte after it.
    pub fn new(data: &'a [u8]) -> Result<Self> {
        let (endian, max_align) = super::encapsulation(data)?;
        Ok(Cursor {
            buf: &data[4..],
            pos: 0,
            big: endian == super::Endian::Big,
            max_align,
        })
    }

    /// Bytes of the whole payload, encapsulation header included.
    pub fn payload_len(&self) -> usize {
        self.buf.len() + 4
    }

    #[inline]
    pub fn align(&mut self, size: usize) {
        let a = size.min(self.max_align);
        let rem = self.pos % a;
        if rem != 0 {
            self.pos += a - rem;
        }
    }

    #[inline]
    pub fn take(&mut self, n: usize) -> Result<&'a [u8]> {
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

    #[inline]
    pub fn u8(&mut self) -> Result<u8> {
        Ok(self.take(1)?[0])
    }

    scalar!(u16, u16);
    scalar!(i16, i16);
    scalar!(i32, i32);
    scalar!(u32, u32);
    scalar!(u64, u64);
    scalar!(i64, i64);
    scalar!(f32, f32);
    scalar!(f64, f64);

    #[inline]
    fn take_array<const N: usize>(&mut self) -> Result<&'a [u8; N]> {
        let have = self.buf.len().saturating_sub(self.pos);
        match self.buf.get(self.pos..).and_then(<[u8]>::first_chunk::<N>) {
            Some(a) => {
                self.pos += N;
                Ok(a)
            }
            None => Err(CdrError::new(CdrErrorKind::UnexpectedEnd {
                offset: self.pos + 4,
                need: N,
                have,
            })),
        }
    }

    /// A sequence length whose `min_elem` bytes per element must fit in the bytes left.
    #[inline]
    pub fn seq_len(&mut self, min_elem: usize) -> Result<usize> {
        let n = self.u32()? as usize;
        let remaining = self.buf.len().saturating_sub(self.pos);
        match n.checked_mul(min_elem) {
            Some(need) if need <= remaining => Ok(n),
            _ => Err(CdrError::new(CdrErrorKind::LengthTooLarge {
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

    /// A string into `out`, reusing its buffer (untouched when it already holds these bytes,
    /// as a frame id read message after message does).
    pub fn string_into(&mut self, out: &mut String) -> Result<()> {
        let b = self.str_bytes()?;
        if out.as_bytes() == b {
            return Ok(());
        }
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
        out.extend(b.as_chunks::<4>().0.iter().map(|&a| {
            if big {
                f32::from_be_bytes(a)
            } else {
                f32::from_le_bytes(a)
            }
        }));
        Ok(())
    }

    /// The bytes of `n` packed elements of `size` bytes (aligned first when `n > 0`).
    pub fn packed(&mut self, n: usize, size: usize) -> Result<&'a [u8]> {
        if n > 0 {
            self.align(size);
        }
        let need = self.check_fits(n, size)?;
        self.take(need)
    }

    /// The bytes `n` elements of `size` bytes take, if the payload has that many left.
    pub fn check_fits(&self, n: usize, size: usize) -> Result<usize> {
        let remaining = self.buf.len().saturating_sub(self.pos);
        match n.checked_mul(size) {
            Some(need) if need <= remaining => Ok(need),
            _ => Err(CdrError::new(CdrErrorKind::LengthTooLarge {
                offset: self.pos + 4,
                len: n as u64,
                remaining,
            })),
        }
    }

    /// Whether the payload is big-endian (`CDR_BE` / `CDR2_BE`).
    pub fn is_big_endian(&self) -> bool {
        self.big
    }

    fn fill_f64(&self, b: &[u8], out: &mut [f64]) {
        for (o, &a) in out.iter_mut().zip(b.as_chunks::<8>().0) {
            *o = if self.big {
                f64::from_be_bytes(a)
            } else {
                f64::from_le_bytes(a)
            };
        }
    }

    /// Three `float64` (a `Point` or `Vector3`).
    #[inline]
    pub fn xyz(&mut self) -> Result<[f64; 3]> {
        match self.f64s::<3>() {
            Some(v) => Ok(v),
            None => Ok([self.f64()?, self.f64()?, self.f64()?]),
        }
    }

    /// `geometry_msgs/msg/Quaternion` as `[x, y, z, w]`.
    #[inline]
    pub fn xyzw(&mut self) -> Result<[f64; 4]> {
        match self.f64s::<4>() {
            Some(v) => Ok(v),
            None => Ok([self.f64()?, self.f64()?, self.f64()?, self.f64()?]),
        }
    }

    /// `N` consecutive `float64` fields when the payload has them all (one alignment: after
    /// the first each is aligned already), else `None` with the cursor unmoved, for the
    /// field-by-field reads to name what is missing.
    #[inline]
    fn f64s<const N: usize>(&mut self) -> Option<[f64; N]> {
        let a = 8.min(self.max_align);
        let start = self.pos.next_multiple_of(a);
        let bytes = self.buf.get(start..)?.get(..8 * N)?;
        let mut out = [0.0; N];
        for (o, &b) in out.iter_mut().zip(bytes.as_chunks::<8>().0) {
            *o = if self.big {
                f64::from_be_bytes(b)
            } else {
                f64::from_le_bytes(b)
            };
        }
        self.pos = start + 8 * N;
        Some(out)
    }
}

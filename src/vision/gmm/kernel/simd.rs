//! The SIMD vocabulary the kernel is written in: eight-lane `f32` operations ([`Simd`]) and
//! their portable array implementation ([`Portable`]).

/// Pixels updated together: eight `f32` lanes fill one AVX register.
pub(in crate::vision::gmm) const LANES: usize = 8;

/// One lane vector of state.
pub(in crate::vision::gmm) type Lanes = [f32; LANES];

/// Bytes of a cache line: [`LaneBuf`] starts its vectors on one.
const LINE: usize = 64;
/// Floats of slack a [`LaneBuf`] allocates to move its start to a line boundary.
const SLACK: usize = LINE / 4 - 1;

/// Lane vectors whose first vector starts on a 64-byte boundary, so that no 32-byte vector
/// load straddles two cache lines (a `Vec<[f32; 8]>` is only 16-byte aligned in practice).
/// Stored as floats with a little slack; the vectors are a safe `as_chunks` view of them.
#[derive(Debug, Default)]
pub(in crate::vision::gmm) struct LaneBuf {
    raw: Vec<f32>,
    len: usize,
}

impl LaneBuf {
    /// `len` vectors of zeros.
    pub fn zeroed(len: usize) -> Self {
        Self {
            raw: vec![0.0; len * LANES + SLACK],
            len,
        }
    }
    fn start(&self) -> usize {
        // An `f32` pointer can always reach the boundary within 15 floats.
        self.raw.as_ptr().align_offset(LINE).min(SLACK)
    }
    pub fn as_slice(&self) -> &[Lanes] {
        if self.len == 0 {
            return &[];
        }
        let s = self.start();
        self.raw[s..s + self.len * LANES].as_chunks::<LANES>().0
    }
    pub fn as_mut_slice(&mut self) -> &mut [Lanes] {
        if self.len == 0 {
            return &mut [];
        }
        let s = self.start();
        self.raw[s..s + self.len * LANES].as_chunks_mut::<LANES>().0
    }
}

/// A derived `Clone` would copy the floats to an allocation whose boundary may fall
/// elsewhere; copy the vectors instead.
impl Clone for LaneBuf {
    fn clone(&self) -> Self {
        let mut out = Self::zeroed(self.len);
        out.as_mut_slice().copy_from_slice(self.as_slice());
        out
    }
}

/// Eight-lane `f32` operations. Comparisons are ordered and quiet (false on NaN), like
/// Rust's `<`; masks are all-ones or all-zeros per lane.
pub(super) trait Simd: Copy {
    type F: Copy;
    type M: Copy;
    fn splat(self, v: f32) -> Self::F;
    fn load(self, v: &Lanes) -> Self::F;
    fn store(self, v: &mut Lanes, x: Self::F);
    fn add(self, a: Self::F, b: Self::F) -> Self::F;
    fn sub(self, a: Self::F, b: Self::F) -> Self::F;
    fn mul(self, a: Self::F, b: Self::F) -> Self::F;
    fn div(self, a: Self::F, b: Self::F) -> Self::F;
    fn abs(self, a: Self::F) -> Self::F;
    fn lt(self, a: Self::F, b: Self::F) -> Self::M;
    fn le(self, a: Self::F, b: Self::F) -> Self::M;
    fn eq(self, a: Self::F, b: Self::F) -> Self::M;
    fn and(self, a: Self::M, b: Self::M) -> Self::M;
    fn or(self, a: Self::M, b: Self::M) -> Self::M;
    /// `a & !b`.
    fn and_not(self, a: Self::M, b: Self::M) -> Self::M;
    fn none(self) -> Self::M;
    fn all(self) -> Self::M;
    /// `if m { a } else { +0.0 }` per lane.
    fn keep(self, m: Self::M, a: Self::F) -> Self::F;
    /// One bit per lane (lane 0 in bit 0).
    fn bits(self, m: Self::M) -> u32;
    /// `if m { t } else { f }` per lane.
    fn select(self, m: Self::M, t: Self::F, f: Self::F) -> Self::F;
    /// Eight 8-bit pixels of `C` interleaved channels (`src.len() == LANES * C`) as one
    /// vector per channel.
    fn load_pixels<const C: usize>(self, src: &[u8]) -> [Self::F; C];
    /// Component counts (small integers, exact in `f32`).
    fn load_counts(self, c: &[u8; LANES]) -> Self::F;
    fn store_counts(self, c: &mut [u8; LANES], v: Self::F);
    /// Mask bytes: 0 where `background`, else `shadow_value` where `shadow`, else 255.
    fn mask_bytes(self, background: Self::M, shadow: Self::M, shadow_value: u8) -> [u8; LANES];
}

/// Plain arrays; LLVM vectorises what it can. Runs everywhere.
#[derive(Clone, Copy)]
pub(super) struct Portable;

#[inline(always)]
fn lanes<T: Copy + Default, const N: usize>(f: impl Fn(usize) -> T) -> [T; N] {
    let mut out = [T::default(); N];
    for (l, o) in out.iter_mut().enumerate() {
        *o = f(l);
    }
    out
}

#[inline(always)]
fn flag(c: bool) -> u32 {
    if c { u32::MAX } else { 0 }
}

impl Simd for Portable {
    type F = Lanes;
    type M = [u32; LANES];
    #[inline(always)]
    fn splat(self, v: f32) -> Lanes {
        [v; LANES]
    }
    #[inline(always)]
    fn load(self, v: &Lanes) -> Lanes {
        *v
    }
    #[inline(always)]
    fn store(self, v: &mut Lanes, x: Lanes) {
        *v = x;
    }
    #[inline(always)]
    fn add(self, a: Lanes, b: Lanes) -> Lanes {
        lanes(|l| a[l] + b[l])
    }
    #[inline(always)]
    fn sub(self, a: Lanes, b: Lanes) -> Lanes {
        lanes(|l| a[l] - b[l])
    }
    #[inline(always)]
    fn mul(self, a: Lanes, b: Lanes) -> Lanes {
        lanes(|l| a[l] * b[l])
    }
    #[inline(always)]
    fn div(self, a: Lanes, b: Lanes) -> Lanes {
        lanes(|l| a[l] / b[l])
    }
    #[inline(always)]
    fn abs(self, a: Lanes) -> Lanes {
        lanes(|l| a[l].abs())
    }
    #[inline(always)]
    fn lt(self, a: Lanes, b: Lanes) -> Self::M {
        lanes(|l| flag(a[l] < b[l]))
    }
    #[inline(always)]
    fn le(self, a: Lanes, b: Lanes) -> Self::M {
        lanes(|l| flag(a[l] <= b[l]))
    }
    #[inline(always)]
    fn eq(self, a: Lanes, b: Lanes) -> Self::M {
        lanes(|l| flag(a[l] == b[l]))
    }
    #[inline(always)]
    fn and(self, a: Self::M, b: Self::M) -> Self::M {
        lanes(|l| a[l] & b[l])
    }
    #[inline(always)]
    fn or(self, a: Self::M, b: Self::M) -> Self::M {
        lanes(|l| a[l] | b[l])
    }
    #[inline(always)]
    fn and_not(self, a: Self::M, b: Self::M) -> Self::M {
        lanes(|l| a[l] & !b[l])
    }
    #[inline(always)]
    fn none(self) -> Self::M {
        [0; LANES]
    }
    #[inline(always)]
    fn all(self) -> Self::M {
        [u32::MAX; LANES]
    }
    #[inline(always)]
    fn keep(self, m: Self::M, a: Lanes) -> Lanes {
        lanes(|l| f32::from_bits(a[l].to_bits() & m[l]))
    }
    #[inline(always)]
    fn bits(self, m: Self::M) -> u32 {
        m.iter()
            .enumerate()
            .fold(0, |acc, (l, &v)| acc | ((v & 1) << l))
    }
    #[inline(always)]
    fn select(self, m: Self::M, t: Lanes, f: Lanes) -> Lanes {
        lanes(|l| f32::from_bits((t[l].to_bits() & m[l]) | (f[l].to_bits() & !m[l])))
    }
    #[inline(always)]
    fn load_pixels<const C: usize>(self, src: &[u8]) -> [Lanes; C] {
        let src = &src[..LANES * C];
        std::array::from_fn(|c| lanes(|l| f32::from(src[l * C + c])))
    }
    #[inline(always)]
    fn load_counts(self, c: &[u8; LANES]) -> Lanes {
        lanes(|l| f32::from(c[l]))
    }
    #[inline(always)]
    fn store_counts(self, c: &mut [u8; LANES], v: Lanes) {
        *c = lanes(|l| v[l] as u8);
    }
    #[inline(always)]
    fn mask_bytes(self, background: Self::M, shadow: Self::M, shadow_value: u8) -> [u8; LANES] {
        lanes(|l| {
            if background[l] != 0 {
                0
            } else if shadow[l] != 0 {
                shadow_value
            } else {
                255
            }
        })
    }
}

//! [`Simd`] with AVX2 intrinsics, for CPUs that have them (detected at run time).

use std::arch::x86_64::*;

use super::simd::{LANES, Lanes, Simd};

/// AVX2 intrinsics. A value of this type exists only once AVX2 was detected at run
/// time (see [`Avx2::detect`]), which is what makes the `unsafe` calls below sound.
#[derive(Clone, Copy)]
pub(in crate::vision::gmm) struct Avx2(());

impl Avx2 {
    pub fn detect() -> Option<Avx2> {
        std::arch::is_x86_feature_detected!("avx2").then_some(Avx2(()))
    }
}

// SAFETY (every `unsafe` block in this impl): the intrinsics need AVX/AVX2, and an
// `Avx2` value is only made after `is_x86_feature_detected!("avx2")`; loads and stores
// go through references to `[f32; 8]`, whose size the 256-bit access matches.
impl Simd for Avx2 {
    type F = __m256;
    type M = __m256;
    #[inline(always)]
    fn splat(self, v: f32) -> __m256 {
        unsafe { _mm256_set1_ps(v) }
    }
    #[inline(always)]
    fn load(self, v: &Lanes) -> __m256 {
        unsafe { _mm256_loadu_ps(v.as_ptr()) }
    }
    #[inline(always)]
    fn store(self, v: &mut Lanes, x: __m256) {
        unsafe { _mm256_storeu_ps(v.as_mut_ptr(), x) }
    }
    #[inline(always)]
    fn add(self, a: __m256, b: __m256) -> __m256 {
        unsafe { _mm256_add_ps(a, b) }
    }
    #[inline(always)]
    fn sub(self, a: __m256, b: __m256) -> __m256 {
        unsafe { _mm256_sub_ps(a, b) }
    }
    #[inline(always)]
    fn mul(self, a: __m256, b: __m256) -> __m256 {
        unsafe { _mm256_mul_ps(a, b) }
    }
    #[inline(always)]
    fn div(self, a: __m256, b: __m256) -> __m256 {
        unsafe { _mm256_div_ps(a, b) }
    }
    #[inline(always)]
    fn abs(self, a: __m256) -> __m256 {
        unsafe { _mm256_andnot_ps(_mm256_set1_ps(-0.0), a) }
    }
    #[inline(always)]
    fn lt(self, a: __m256, b: __m256) -> __m256 {
        unsafe { _mm256_cmp_ps::<_CMP_LT_OQ>(a, b) }
    }
    #[inline(always)]
    fn le(self, a: __m256, b: __m256) -> __m256 {
        unsafe { _mm256_cmp_ps::<_CMP_LE_OQ>(a, b) }
    }
    #[inline(always)]
    fn eq(self, a: __m256, b: __m256) -> __m256 {
        unsafe { _mm256_cmp_ps::<_CMP_EQ_OQ>(a, b) }
    }
    #[inline(always)]
    fn and(self, a: __m256, b: __m256) -> __m256 {
        unsafe { _mm256_and_ps(a, b) }
    }
    #[inline(always)]
    fn or(self, a: __m256, b: __m256) -> __m256 {
        unsafe { _mm256_or_ps(a, b) }
    }
    #[inline(always)]
    fn and_not(self, a: __m256, b: __m256) -> __m256 {
        unsafe { _mm256_andnot_ps(b, a) }
    }
    #[inline(always)]
    fn none(self) -> __m256 {
        unsafe { _mm256_setzero_ps() }
    }
    #[inline(always)]
    fn all(self) -> __m256 {
        unsafe { _mm256_castsi256_ps(_mm256_set1_epi32(-1)) }
    }
    #[inline(always)]
    fn keep(self, m: __m256, a: __m256) -> __m256 {
        unsafe { _mm256_and_ps(m, a) }
    }
    #[inline(always)]
    fn bits(self, m: __m256) -> u32 {
        unsafe { _mm256_movemask_ps(m) as u32 }
    }
    #[inline(always)]
    fn select(self, m: __m256, t: __m256, f: __m256) -> __m256 {
        unsafe { _mm256_blendv_ps(f, t, m) }
    }
    #[inline(always)]
    fn load_pixels<const C: usize>(self, src: &[u8]) -> [__m256; C] {
        // No closures here: a closure is a function of its own, compiled without AVX2, so
        // the intrinsics inside it would not inline into the AVX2 row.
        let src = &src[..LANES * C];
        let mut out = [self.none(); C];
        if C == 3 {
            // 24 bytes: pshufb channel c's bytes (c, c+3, .., c+21) to the bottom of a
            // 16-byte register from the two halves, OR them, widen to i32 and convert.
            const LO: [[i8; 16]; 3] = shuffle_lo();
            const HI: [[i8; 16]; 3] = shuffle_hi();
            unsafe {
                let lo = _mm_loadu_si128(src.as_ptr().cast());
                let hi = _mm_loadl_epi64(src[16..].as_ptr().cast());
                for (c, o) in out.iter_mut().enumerate() {
                    let a = _mm_loadu_si128(LO[c].as_ptr().cast());
                    let b = _mm_loadu_si128(HI[c].as_ptr().cast());
                    let v = _mm_or_si128(_mm_shuffle_epi8(lo, a), _mm_shuffle_epi8(hi, b));
                    *o = _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(v));
                }
            }
        } else {
            for (c, o) in out.iter_mut().enumerate() {
                let mut b = [0u8; 16];
                for l in 0..LANES {
                    b[l] = src[l * C + c];
                }
                unsafe {
                    let v = _mm_loadu_si128(b.as_ptr().cast());
                    *o = _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(v));
                }
            }
        }
        out
    }
    #[inline(always)]
    fn load_counts(self, c: &[u8; LANES]) -> __m256 {
        unsafe {
            let v = _mm_loadl_epi64(c.as_ptr().cast());
            _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(v))
        }
    }
    #[inline(always)]
    fn store_counts(self, c: &mut [u8; LANES], v: __m256) {
        // Counts are 0..=16: i32 -> i16 -> u8 packing cannot saturate.
        unsafe {
            let i = _mm256_cvttps_epi32(v);
            let w = _mm_packs_epi32(_mm256_castsi256_si128(i), _mm256_extracti128_si256::<1>(i));
            let b = _mm_packus_epi16(w, w);
            _mm_storel_epi64(c.as_mut_ptr().cast(), b);
        }
    }
    #[inline(always)]
    fn mask_bytes(self, background: __m256, shadow: __m256, shadow_value: u8) -> [u8; LANES] {
        let mut out = [0u8; LANES];
        unsafe {
            let fg = _mm256_blendv_ps(
                _mm256_set1_ps(255.0),
                _mm256_set1_ps(f32::from(shadow_value)),
                shadow,
            );
            let v = _mm256_andnot_ps(background, fg);
            let i = _mm256_cvttps_epi32(v);
            let w = _mm_packs_epi32(_mm256_castsi256_si128(i), _mm256_extracti128_si256::<1>(i));
            _mm_storel_epi64(out.as_mut_ptr().cast(), _mm_packus_epi16(w, w));
        }
        out
    }
}

/// `pshufb` controls gathering channel c of eight RGB pixels from bytes 0..16 (`LO`) and
/// 16..24 (`HI`) of the row; -1 zeroes a byte.
const fn shuffle_lo() -> [[i8; 16]; 3] {
    shuffle(true)
}
const fn shuffle_hi() -> [[i8; 16]; 3] {
    shuffle(false)
}
const fn shuffle(low: bool) -> [[i8; 16]; 3] {
    let mut out = [[-1i8; 16]; 3];
    let mut c = 0;
    while c < 3 {
        let mut l = 0;
        while l < LANES {
            let i = l * 3 + c;
            if low && i < 16 {
                out[c][l] = i as i8;
            } else if !low && i >= 16 {
                out[c][l] = (i - 16) as i8;
            }
            l += 1;
        }
        c += 1;
    }
    out
}

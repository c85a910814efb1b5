//! The per-pixel update of the adaptive mixture, run on [`LANES`] neighbouring pixels in
//! lock-step so that every step is one SIMD instruction.
//!
//! Each pixel follows exactly the scalar recursion of the paper as OpenCV orders it (see the
//! parent module): the lanes differ only in which components exist, which one owns the sample
//! and where it moves in the weight order, and those differences become lane masks and
//! blends. No arithmetic is reordered or fused, so every lane computes bit for bit what the
//! scalar per-pixel loop computes (the unit tests compare the two on random sequences, on
//! every instruction set).
//!
//! The kernel is written once against [`Simd`]; [`Portable`] implements it with arrays
//! (any CPU), `Avx2` with `std::arch` AVX2 intrinsics, chosen at run time
//! ([`Isa::detect`]). Hand-written rather than the `wide` crate: `wide` picks its backend
//! at compile time from the enabled target features, so the default x86-64 build (no
//! `-C target-cpu`) would run 4-lane SSE code, while run-time detection gives one binary
//! that uses 8 lanes wherever AVX2 exists and stays correct elsewhere. Neither side uses
//! fused multiply-adds (Rust never contracts `a * b + c`, and the intrinsics are plain
//! `mul`/`add`), which is what keeps every lane equal to OpenCV's scalar code.
//!
//! Two things keep the AVX2 path fast. The row functions carry
//! `#[target_feature(enable = "avx2")]` and every [`Simd`] method is `#[inline(always)]`, so
//! the intrinsics inline into them; a closure (`std::array::from_fn(|c| ..)`, `map`) is a
//! function of its own compiled *without* AVX2, into which the intrinsics cannot inline, so
//! the kernel uses plain loops (one closure in `load_pixels` once made the whole update
//! several times slower). And the state is a [`LaneBuf`], whose vectors start on cache-line
//! boundaries.
//!
//! State layout ([`Layout`]): each image row is `groups = ceil(width / LANES)` groups of
//! pixels; within a row, component slot k of every group comes before slot k + 1
//! (slot-major), and a slot is `2 + C` lane vectors `[weight, variance, mean_0 .. mean_C-1]`,
//! each `[f32; LANES]`. Walking a row therefore reads one sequential stream per slot in use,
//! and slots no pixel uses are never touched. Lanes past the right edge of the image compute
//! on zeros and are never read back.

pub(super) use simd::{LANES, LaneBuf, Lanes};
use simd::{Portable, Simd};

#[cfg(target_arch = "x86_64")]
mod avx2;
mod simd;

/// Per-frame constants of the update, already in the precision OpenCV uses (`f32`).
#[derive(Debug, Clone, Copy)]
pub(super) struct Coeffs {
    /// Learning rate α.
    pub alpha: f32,
    /// `1 - α`.
    pub alpha1: f32,
    /// `-α c_T`: the Dirichlet-prior term of eq. 14.
    pub prune: f32,
    /// A component whose weight after eq. 14 is below this is dropped: `α c_T` (that is
    /// `-prune`, OpenCV's test) or 0 (the paper's "becomes negative").
    pub drop_below: f32,
    /// Foreground threshold on the squared Mahalanobis distance (`varThreshold`, c_thr).
    pub tb: f32,
    /// `1 - c_f` (`backgroundRatio`).
    pub background_ratio: f32,
    /// Ownership threshold on the squared Mahalanobis distance (`varThresholdGen`).
    pub tg: f32,
    pub var_init: f32,
    pub var_min: f32,
    pub var_max: f32,
    /// Shadow brightness ratio lower bound τ.
    pub tau: f32,
    pub detect_shadows: bool,
    pub shadow_value: u8,
    /// Maximum number of components M.
    pub n_mix: usize,
}

/// Where a row's state lives (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Layout {
    /// Pixel groups per row.
    pub groups: usize,
    /// Component slots per pixel (M).
    pub n_mix: usize,
    /// Lane vectors per slot, `2 + channels`.
    pub stride: usize,
}

impl Layout {
    pub fn new(width: usize, n_mix: usize, channels: usize) -> Self {
        Self {
            groups: width.div_ceil(LANES),
            n_mix,
            stride: 2 + channels,
        }
    }
    /// Lane vectors per row.
    pub fn row_len(&self) -> usize {
        self.groups * self.n_mix * self.stride
    }
    /// Index within its row of field `f` (0 weight, 1 variance, 2.. mean) of slot `k` of
    /// group `g`.
    #[inline(always)]
    pub fn index(&self, g: usize, k: usize, f: usize) -> usize {
        (k * self.groups + g) * self.stride + f
    }
}

// ---------------------------------------------------------------------------------------
// One group of LANES pixels.

/// A group's slots inside its row.
struct Group<'a> {
    row: &'a mut [Lanes],
    layout: Layout,
    g: usize,
}

impl Group<'_> {
    #[inline(always)]
    fn at(&self, k: usize, f: usize) -> usize {
        self.layout.index(self.g, k, f)
    }
    #[inline(always)]
    fn get<S: Simd>(&self, s: S, k: usize, f: usize) -> S::F {
        s.load(&self.row[self.at(k, f)])
    }
    #[inline(always)]
    fn set<S: Simd>(&mut self, s: S, k: usize, f: usize, v: S::F) {
        let i = self.at(k, f);
        s.store(&mut self.row[i], v)
    }
    /// Field `f` of slot `k` in lane `l`.
    #[inline(always)]
    fn lane(&mut self, k: usize, f: usize, l: usize) -> &mut f32 {
        let i = self.at(k, f);
        &mut self.row[i][l]
    }
    /// Swap slots `i` and `i - 1` in the lanes whose bits are set. Reordering is rare, so
    /// it is done lane by lane: a blended vector store of a value loaded from the same place
    /// becomes a masked store, which is slow on some CPUs.
    #[inline(always)]
    fn swap_down(&mut self, i: usize, mut bits: u32) {
        while bits != 0 {
            let l = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            for f in 0..self.layout.stride {
                let (hi, lo) = (self.at(i, f), self.at(i - 1, f));
                let t = self.row[hi][l];
                self.row[hi][l] = self.row[lo][l];
                self.row[lo][l] = t;
            }
        }
    }
}

/// `!(a < b)`, true for NaN too (OpenCV's loop test `if (alpha < w) break;`).
#[inline(always)]
fn not_less(a: f32, b: f32) -> bool {
    a.partial_cmp(&b) != Some(std::cmp::Ordering::Less)
}

/// `count > k` per lane, for counts held as exact small floats.
#[inline(always)]
fn above<S: Simd>(s: S, count: S::F, k: usize) -> S::M {
    s.lt(s.splat(k as f32), count)
}

/// Divide the first `most` weights by their sum `total` (0 where the sum vanishes). Slots
/// past a lane's count are dead (never read before a new component overwrites them whole), so
/// no lane mask is needed.
#[inline(always)]
fn renormalise<S: Simd>(s: S, grp: &mut Group<'_>, most: usize, total: S::F) {
    let nonzero = s.lt(s.splat(f32::EPSILON), s.abs(total));
    let inv = s.select(nonzero, s.div(s.splat(1.0), total), s.splat(0.0));
    for k in 0..most {
        let w = grp.get(s, k, 0);
        grp.set(s, k, 0, s.mul(w, inv));
    }
}

/// Update one group with the sample `x` (per channel); write the new component counts into
/// `modes` and return the mask bytes.
#[inline(always)]
fn update_group<S: Simd, const C: usize>(
    s: S,
    grp: &mut Group<'_>,
    modes: &mut [u8; LANES],
    x: &[S::F; C],
    co: &Coeffs,
) -> [u8; LANES] {
    let alpha = s.splat(co.alpha);
    let alpha1 = s.splat(co.alpha1);
    let prune = s.splat(co.prune);
    let drop_below = s.splat(co.drop_below);
    let tb = s.splat(co.tb);
    let tg = s.splat(co.tg);
    let big_tb = s.splat(co.background_ratio);
    let zero = s.splat(0.0);
    let one = s.splat(1.0);

    let mut most = usize::from(modes.iter().fold(0, |a, &m| a.max(m)));
    let mut nm = s.load_counts(modes);
    let mut fits = s.none();
    let mut background = s.none();
    let mut total = zero;

    // Eq. 4–6 and 14 for every existing component, in descending weight order; the first
    // component within `tg` owns the sample (OpenCV's order, not the closest one).
    for k in 0..most {
        let active = above(s, nm, k);
        if s.bits(active) == 0 {
            break;
        }
        let w_old = grp.get(s, k, 0);
        let mut w = s.add(s.mul(alpha1, w_old), prune);
        let open = s.and_not(active, fits);
        let mut owner = s.none();
        if s.bits(open) != 0 {
            let var = grp.get(s, k, 1);
            // Loops, not closures (see `Avx2::load_pixels`).
            let mut d = [zero; C];
            for (c, dc) in d.iter_mut().enumerate() {
                *dc = s.sub(grp.get(s, k, 2 + c), x[c]);
            }
            let mut dist2 = s.mul(d[0], d[0]);
            for dc in d.iter().skip(1) {
                dist2 = s.add(dist2, s.mul(*dc, *dc));
            }
            let in_background = s.and(s.lt(total, big_tb), s.lt(dist2, s.mul(tb, var)));
            background = s.or(background, s.and(open, in_background));
            owner = s.and(open, s.lt(dist2, s.mul(tg, var)));
            if s.bits(owner) != 0 {
                // Non-owner lanes must keep their mean and variance. Instead of blending the
                // results (which the compiler turns into masked stores, slow on some CPUs),
                // their step `r` is zeroed: `m - 0` and `v + 0 * (..)` are exactly `m` and `v`.
                let w_own = s.add(w, alpha);
                let r = s.keep(owner, s.div(alpha, w_own));
                for (c, dc) in d.iter().enumerate() {
                    let m = grp.get(s, k, 2 + c);
                    grp.set(s, k, 2 + c, s.sub(m, s.mul(r, *dc)));
                }
                let mut var_new = s.add(var, s.mul(r, s.sub(dist2, var)));
                // Clamp only the owners' (a variance never updated may lie outside the range
                // when fVarInit does).
                let var_min = s.splat(co.var_min);
                let var_max = s.splat(co.var_max);
                let low = s.and(owner, s.lt(var_new, var_min));
                var_new = s.select(low, var_min, var_new);
                let high = s.and(owner, s.lt(var_max, var_new));
                var_new = s.select(high, var_max, var_new);
                grp.set(s, k, 1, var_new);
                w = s.select(owner, w_own, w);
                fits = s.or(fits, owner);
            }
        }
        // Eq. 14's "drop the component when its weight goes negative": below α c_T as OpenCV
        // tests it, or below 0 as printed (`Coeffs::drop_below`).
        let dropped = s.and(active, s.lt(w, drop_below));
        let w_kept = s.select(dropped, zero, w);
        nm = s.sub(nm, s.select(dropped, one, zero));
        // Lanes where slot k is not in use get a meaningless value: a slot at or past a
        // pixel's count is never read before a new component overwrites it whole.
        grp.set(s, k, 0, w_kept);
        // The owner moves up past every component whose weight is not larger.
        let mut moving = owner;
        let mut i = k;
        while i > 0 && s.bits(moving) != 0 {
            let up = grp.get(s, i - 1, 0);
            let swap = s.and_not(moving, s.lt(w, up));
            grp.swap_down(i, s.bits(swap));
            moving = swap;
            i -= 1;
        }
        total = s.select(active, s.add(total, w_kept), total);
    }

    renormalise(s, grp, most, total);

    // A sample no component owns starts a new one (replacing the weakest when full).
    let new = if co.alpha > 0.0 {
        s.and_not(s.all(), fits)
    } else {
        s.none()
    };
    let new_bits = s.bits(new);
    if new_bits != 0 {
        let full = s.eq(nm, s.splat(co.n_mix as f32));
        nm = s.add(nm, s.select(s.and_not(new, full), one, zero));
        most = (most + 1).min(co.n_mix);
        // The new component's lanes scale their older components by 1 - α (the others by
        // 1, which is exact), vector-wide.
        for k in 0..most - 1 {
            let older = s.and(new, above(s, nm, k + 1));
            let w = grp.get(s, k, 0);
            grp.set(s, k, 0, s.mul(w, s.select(older, alpha1, one)));
        }
        // Then, lane by lane, the component itself goes into slot count - 1 and moves up
        // past every weight not larger than α.
        s.store_counts(modes, nm);
        let mut xs = [[0.0f32; LANES]; C];
        for (xc, v) in xs.iter_mut().zip(x) {
            s.store(xc, *v);
        }
        let mut bits = new_bits;
        while bits != 0 {
            let l = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let n = usize::from(modes[l]);
            let k = n - 1;
            *grp.lane(k, 0, l) = if n == 1 { 1.0 } else { co.alpha };
            *grp.lane(k, 1, l) = co.var_init;
            for (c, xc) in xs.iter().enumerate() {
                *grp.lane(k, 2 + c, l) = xc[l];
            }
            let mut i = k;
            while i > 0 && not_less(co.alpha, *grp.lane(i - 1, 0, l)) {
                grp.swap_down(i, 1 << l);
                i -= 1;
            }
        }
    }

    s.store_counts(modes, nm);

    let shadow = if co.detect_shadows && s.bits(background) != (1 << LANES) - 1 {
        let foreground = s.and_not(s.all(), background);
        detect_shadow::<S, C>(s, grp, nm, most, x, foreground, co)
    } else {
        s.none()
    };
    s.mask_bytes(background, shadow, co.shadow_value)
}

/// The shadow test of Prati et al. as OpenCV's `detectShadowGMM` applies it: the sample is
/// a shadow if, for one of the background components (eq. 8, in order), it is that
/// component's mean scaled by a ∈ [τ, 1] and the colour distortion is within `tb`.
#[inline(always)]
fn detect_shadow<S: Simd, const C: usize>(
    s: S,
    grp: &Group<'_>,
    nm: S::F,
    most: usize,
    x: &[S::F; C],
    lanes: S::M,
    co: &Coeffs,
) -> S::M {
    let zero = s.splat(0.0);
    let tau = s.splat(co.tau);
    let tb = s.splat(co.tb);
    let big_tb = s.splat(co.background_ratio);
    let mut searching = lanes;
    let mut shadow = s.none();
    let mut weight_sum = zero;
    for k in 0..most {
        let live = s.and(searching, above(s, nm, k));
        if s.bits(live) == 0 {
            break;
        }
        let mut mean = [zero; C];
        for (c, m) in mean.iter_mut().enumerate() {
            *m = grp.get(s, k, 2 + c);
        }
        let mut num = s.mul(x[0], mean[0]);
        let mut den = s.mul(mean[0], mean[0]);
        for c in 1..C {
            num = s.add(num, s.mul(x[c], mean[c]));
            den = s.add(den, s.mul(mean[c], mean[c]));
        }
        let black = s.and(live, s.eq(den, zero));
        searching = s.and_not(searching, black);
        let live = s.and_not(live, black);
        let darker = s.and(live, s.and(s.le(num, den), s.le(s.mul(tau, den), num)));
        let mut hit = s.none();
        if s.bits(darker) != 0 {
            let a = s.div(num, den);
            let d0 = s.sub(s.mul(a, mean[0]), x[0]);
            let mut dist2a = s.mul(d0, d0);
            for c in 1..C {
                let dc = s.sub(s.mul(a, mean[c]), x[c]);
                dist2a = s.add(dist2a, s.mul(dc, dc));
            }
            let var = grp.get(s, k, 1);
            let bound = s.mul(s.mul(s.mul(tb, var), a), a);
            hit = s.and(darker, s.lt(dist2a, bound));
            shadow = s.or(shadow, hit);
            searching = s.and_not(searching, hit);
        }
        let live = s.and_not(live, hit);
        weight_sum = s.select(live, s.add(weight_sum, grp.get(s, k, 0)), weight_sum);
        searching = s.and_not(searching, s.and(live, s.lt(big_tb, weight_sum)));
    }
    shadow
}

// ---------------------------------------------------------------------------------------
// Rows.

/// Update one image row: `state` is the row's [`Layout::row_len`] lane vectors, `modes` one
/// `[u8; LANES]` per group, `frame` the row's `width * C` bytes and `mask` its `width`
/// output bytes. `learn`, when given (`width` flags), names the pixels whose model may
/// change: a group with a frozen pixel is updated as usual, then its frozen lanes get their
/// saved mixture back (see [`Frozen`]).
#[inline(always)]
fn update_row_generic<S: Simd, const C: usize>(
    s: S,
    state: &mut [Lanes],
    modes: &mut [[u8; LANES]],
    frame: &[u8],
    mask: &mut [u8],
    learn: Option<&[bool]>,
    co: &Coeffs,
) {
    let width = mask.len();
    let layout = Layout::new(width, co.n_mix, C);
    let mut grp = Group {
        row: state,
        layout,
        g: 0,
    };
    for (g, modes) in modes.iter_mut().enumerate() {
        grp.g = g;
        let x0 = g * LANES;
        let n = LANES.min(width - x0);
        let x = if n == LANES {
            s.load_pixels::<C>(&frame[x0 * C..(x0 + LANES) * C])
        } else {
            let mut padded = [0u8; LANES * 3];
            padded[..n * C].copy_from_slice(&frame[x0 * C..(x0 + n) * C]);
            s.load_pixels::<C>(&padded)
        };
        let frozen = learn.map_or(0, |l| frozen_bits(&l[x0..x0 + n]));
        let saved = (frozen != 0).then(|| Frozen::save(&grp, modes));
        let out = update_group::<S, C>(s, &mut grp, modes, &x, co);
        if let Some(saved) = saved {
            saved.restore(&mut grp, modes, frozen);
        }
        mask[x0..x0 + n].copy_from_slice(&out[..n]);
    }
}

/// Bit `l` set where pixel `l` of a group must not learn.
#[inline(always)]
fn frozen_bits(learn: &[bool]) -> u32 {
    let mut bits = 0;
    for (l, &ok) in learn.iter().enumerate() {
        if !ok {
            bits |= 1 << l;
        }
    }
    bits
}

/// A group's whole mixture state (every slot, and the component counts), saved before the
/// update so that its frozen lanes can be put back exactly: a frozen pixel's model is left
/// bit for bit as it was (no weight decays, no component starts, none is dropped). Only
/// groups with a frozen pixel pay for it; without an update mask nothing is copied.
struct Frozen {
    slots: [[f32; LANES]; MAX_SLOT_VECTORS],
    modes: [u8; LANES],
}

/// Lane vectors per group at most: `MAX_MIXTURES` slots of `2 + 3` fields.
const MAX_SLOT_VECTORS: usize = super::MAX_MIXTURES * 5;

impl Frozen {
    #[inline(always)]
    fn save(grp: &Group<'_>, modes: &[u8; LANES]) -> Self {
        let mut slots = [[0.0f32; LANES]; MAX_SLOT_VECTORS];
        let stride = grp.layout.stride;
        for k in 0..grp.layout.n_mix {
            for f in 0..stride {
                slots[k * stride + f] = grp.row[grp.at(k, f)];
            }
        }
        Self {
            slots,
            modes: *modes,
        }
    }

    #[inline(always)]
    fn restore(&self, grp: &mut Group<'_>, modes: &mut [u8; LANES], mut bits: u32) {
        let stride = grp.layout.stride;
        while bits != 0 {
            let l = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            for k in 0..grp.layout.n_mix {
                for f in 0..stride {
                    *grp.lane(k, f, l) = self.slots[k * stride + f][l];
                }
            }
            modes[l] = self.modes[l];
        }
    }
}

/// Instruction set used for the rows, chosen once per frame.
#[derive(Clone, Copy)]
pub(super) enum Isa {
    Portable,
    #[cfg(target_arch = "x86_64")]
    Avx2(avx2::Avx2),
}

impl Isa {
    pub fn detect() -> Isa {
        #[cfg(target_arch = "x86_64")]
        if let Some(a) = avx2::Avx2::detect() {
            return Isa::Avx2(a);
        }
        Isa::Portable
    }

    /// Every instruction set this CPU can run (the tests compare them).
    #[cfg(test)]
    pub fn available() -> Vec<Isa> {
        let mut v = vec![Isa::Portable];
        #[cfg(target_arch = "x86_64")]
        if let Some(a) = avx2::Avx2::detect() {
            v.push(Isa::Avx2(a));
        }
        v
    }
}

/// The generic row compiled with AVX2 enabled, so the intrinsics inline.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[allow(clippy::too_many_arguments)]
fn update_row_avx2(
    s: avx2::Avx2,
    channels: usize,
    state: &mut [Lanes],
    modes: &mut [[u8; LANES]],
    frame: &[u8],
    mask: &mut [u8],
    learn: Option<&[bool]>,
    co: &Coeffs,
) {
    if channels == 1 {
        update_row_generic::<_, 1>(s, state, modes, frame, mask, learn, co)
    } else {
        update_row_generic::<_, 3>(s, state, modes, frame, mask, learn, co)
    }
}

/// Update one row with `channels` (1 or 3) interleaved channels; `learn` as in
/// `update_row_generic`.
#[allow(clippy::too_many_arguments)]
pub(super) fn update_row(
    isa: Isa,
    channels: usize,
    state: &mut [Lanes],
    modes: &mut [[u8; LANES]],
    frame: &[u8],
    mask: &mut [u8],
    learn: Option<&[bool]>,
    co: &Coeffs,
) {
    match isa {
        Isa::Portable if channels == 1 => {
            update_row_generic::<_, 1>(Portable, state, modes, frame, mask, learn, co)
        }
        Isa::Portable => update_row_generic::<_, 3>(Portable, state, modes, frame, mask, learn, co),
        #[cfg(target_arch = "x86_64")]
        // SAFETY: an `Avx2` token exists only after AVX2 was detected on this CPU.
        Isa::Avx2(a) => unsafe {
            update_row_avx2(a, channels, state, modes, frame, mask, learn, co)
        },
    }
}

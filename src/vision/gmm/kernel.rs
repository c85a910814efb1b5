//! The per-pixel update of the adaptive mixture, run on [`LANES`] neighbouring pixels in
//! lock-step so that the compiler turns every step into one SIMD instruction.
//!
//! Each pixel follows exactly the scalar recursion of the paper as OpenCV orders it (see the
//! parent module): the lanes differ only in which components exist, which one owns the sample
//! and where it moves in the weight order, and those differences become lane masks and
//! blends. No arithmetic is reordered or fused, so every lane computes bit for bit what the
//! scalar per-pixel loop computes (the unit tests compare the two on random sequences).
//!
//! State layout: a row of the image is `ceil(width / LANES)` groups; a group is `n_mix`
//! component slots; a slot is `2 + C` lane vectors `[weight, variance, mean_0 .. mean_C-1]`,
//! each `[f32; LANES]`. Slots of a group are contiguous, so a group whose pixels use few
//! components touches only the start of its block. Lanes past the right edge of the image
//! compute on zeros and are never read back.

/// Pixels updated together. Eight `f32` lanes fill one AVX register (two SSE registers).
pub(super) const LANES: usize = 8;

/// Per-frame constants of the update, already in the precision OpenCV uses (`f32`).
#[derive(Debug, Clone, Copy)]
pub(super) struct Coeffs {
    /// Learning rate α.
    pub alpha: f32,
    /// `1 - α`.
    pub alpha1: f32,
    /// `-α c_T`: the Dirichlet-prior term of eq. 14.
    pub prune: f32,
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

// ---------------------------------------------------------------------------------------
// Lane vectors. Plain arrays with element-wise loops: LLVM maps each to one vector op.

#[derive(Clone, Copy)]
struct F([f32; LANES]);

/// Lane mask: every lane is 0 or `u32::MAX`.
#[derive(Clone, Copy)]
struct B([u32; LANES]);

/// Per-lane unsigned counts (number of components).
#[derive(Clone, Copy)]
struct U([u32; LANES]);

macro_rules! lanewise {
    ($a:expr, $b:expr, |$x:ident, $y:ident| $e:expr) => {{
        let (a, b) = ($a, $b);
        let mut out = [Default::default(); LANES];
        for l in 0..LANES {
            let ($x, $y) = (a[l], b[l]);
            out[l] = $e;
        }
        out
    }};
}

#[inline(always)]
fn mask(c: bool) -> u32 {
    if c { u32::MAX } else { 0 }
}

impl F {
    #[inline(always)]
    fn splat(v: f32) -> Self {
        F([v; LANES])
    }
    #[inline(always)]
    fn add(self, o: F) -> F {
        F(lanewise!(self.0, o.0, |a, b| a + b))
    }
    #[inline(always)]
    fn sub(self, o: F) -> F {
        F(lanewise!(self.0, o.0, |a, b| a - b))
    }
    #[inline(always)]
    fn mul(self, o: F) -> F {
        F(lanewise!(self.0, o.0, |a, b| a * b))
    }
    #[inline(always)]
    fn div(self, o: F) -> F {
        F(lanewise!(self.0, o.0, |a, b| a / b))
    }
    #[inline(always)]
    fn lt(self, o: F) -> B {
        B(lanewise!(self.0, o.0, |a, b| mask(a < b)))
    }
    #[inline(always)]
    fn le(self, o: F) -> B {
        B(lanewise!(self.0, o.0, |a, b| mask(a <= b)))
    }
    #[inline(always)]
    fn ge(self, o: F) -> B {
        B(lanewise!(self.0, o.0, |a, b| mask(a >= b)))
    }
    #[inline(always)]
    fn gt(self, o: F) -> B {
        B(lanewise!(self.0, o.0, |a, b| mask(a > b)))
    }
    #[inline(always)]
    fn eq(self, o: F) -> B {
        B(lanewise!(self.0, o.0, |a, b| mask(a == b)))
    }
    #[inline(always)]
    fn abs(self) -> F {
        F(lanewise!(self.0, self.0, |a, _b| f32::from_bits(
            a.to_bits() & 0x7fff_ffff
        )))
    }
}

impl B {
    const NONE: B = B([0; LANES]);
    #[inline(always)]
    fn and(self, o: B) -> B {
        B(lanewise!(self.0, o.0, |a, b| a & b))
    }
    #[inline(always)]
    fn or(self, o: B) -> B {
        B(lanewise!(self.0, o.0, |a, b| a | b))
    }
    /// `self & !o`.
    #[inline(always)]
    fn and_not(self, o: B) -> B {
        B(lanewise!(self.0, o.0, |a, b| a & !b))
    }
    #[inline(always)]
    fn not(self) -> B {
        B(lanewise!(self.0, self.0, |a, _b| !a))
    }
    #[inline(always)]
    fn any(self) -> bool {
        self.0.iter().fold(0, |acc, &m| acc | m) != 0
    }
    /// `if self { t } else { f }` per lane.
    #[inline(always)]
    fn select(self, t: F, f: F) -> F {
        let mut out = [0.0; LANES];
        for l in 0..LANES {
            let m = self.0[l];
            out[l] = f32::from_bits((t.0[l].to_bits() & m) | (f.0[l].to_bits() & !m));
        }
        F(out)
    }
    #[inline(always)]
    fn select_u(self, t: U, f: U) -> U {
        t.blend(self, f)
    }
}

impl U {
    #[inline(always)]
    fn blend(self, m: B, f: U) -> U {
        let mut out = [0; LANES];
        for l in 0..LANES {
            out[l] = (self.0[l] & m.0[l]) | (f.0[l] & !m.0[l]);
        }
        U(out)
    }
    /// Lanes where `k < self`.
    #[inline(always)]
    fn above(self, k: u32) -> B {
        B(lanewise!(self.0, self.0, |a, _b| mask(k < a)))
    }
    #[inline(always)]
    fn eq(self, k: u32) -> B {
        B(lanewise!(self.0, self.0, |a, _b| mask(a == k)))
    }
    #[inline(always)]
    fn max(self) -> u32 {
        self.0.iter().fold(0, |acc, &m| acc.max(m))
    }
}

// ---------------------------------------------------------------------------------------
// One group of LANES pixels.

/// Index of field `f` (0 weight, 1 variance, 2.. mean) of slot `k` in a group block.
#[inline(always)]
fn at<const C: usize>(k: usize, f: usize) -> usize {
    k * (2 + C) + f
}

/// Swap slots `i` and `i - 1` in the lanes of `m`.
#[inline(always)]
fn swap_down<const C: usize>(blk: &mut [[f32; LANES]], i: usize, m: B) {
    for f in 0..2 + C {
        let hi = F(blk[at::<C>(i, f)]);
        let lo = F(blk[at::<C>(i - 1, f)]);
        blk[at::<C>(i, f)] = m.select(lo, hi).0;
        blk[at::<C>(i - 1, f)] = m.select(hi, lo).0;
    }
}

/// Update one group with the sample `x` (per channel) and return the mask bytes.
///
/// `blk` holds `n_mix * (2 + C)` lane vectors, `modes` the number of components per lane.
#[inline(always)]
fn update_group<const C: usize>(
    blk: &mut [[f32; LANES]],
    modes: &mut [u8; LANES],
    x: &[F; C],
    co: &Coeffs,
) -> [u8; LANES] {
    let alpha = F::splat(co.alpha);
    let alpha1 = F::splat(co.alpha1);
    let prune = F::splat(co.prune);
    let neg_prune = F::splat(-co.prune);
    let tb = F::splat(co.tb);
    let tg = F::splat(co.tg);
    let big_tb = F::splat(co.background_ratio);
    let zero = F::splat(0.0);

    let mut nm = U(std::array::from_fn(|l| u32::from(modes[l])));
    let mut fits = B::NONE;
    let mut background = B::NONE;
    let mut total = zero;

    // Eq. 4–6 and 14 for every existing component, in descending weight order; the first
    // component within `tg` owns the sample (OpenCV's order, not "closest").
    let visit = nm.max() as usize;
    for k in 0..visit {
        let active = nm.above(k as u32);
        if !active.any() {
            break;
        }
        let w_old = F(blk[at::<C>(k, 0)]);
        let mut w = alpha1.mul(w_old).add(prune);
        let open = active.and_not(fits);
        let mut owner = B::NONE;
        if open.any() {
            let var = F(blk[at::<C>(k, 1)]);
            let mut d = [zero; C];
            for c in 0..C {
                d[c] = F(blk[at::<C>(k, 2 + c)]).sub(x[c]);
            }
            let mut dist2 = d[0].mul(d[0]);
            for dc in d.iter().skip(1) {
                dist2 = dist2.add(dc.mul(*dc));
            }
            background = background.or(open.and(total.lt(big_tb)).and(dist2.lt(tb.mul(var))));
            owner = open.and(dist2.lt(tg.mul(var)));
            if owner.any() {
                let w_own = w.add(alpha);
                let kk = alpha.div(w_own);
                for c in 0..C {
                    let m = F(blk[at::<C>(k, 2 + c)]);
                    blk[at::<C>(k, 2 + c)] = owner.select(m.sub(kk.mul(d[c])), m).0;
                }
                let mut var_new = var.add(kk.mul(dist2.sub(var)));
                var_new = var_new
                    .lt(F::splat(co.var_min))
                    .select(F::splat(co.var_min), var_new);
                var_new = F::splat(co.var_max)
                    .lt(var_new)
                    .select(F::splat(co.var_max), var_new);
                blk[at::<C>(k, 1)] = owner.select(var_new, var).0;
                w = owner.select(w_own, w);
                fits = fits.or(owner);
            }
        }
        // Eq. 14's "drop the component when its weight goes negative", as OpenCV tests it.
        let dropped = active.and(w.lt(neg_prune));
        let w_kept = dropped.select(zero, w);
        nm = dropped.select_u(U(std::array::from_fn(|l| nm.0[l].wrapping_sub(1))), nm);
        blk[at::<C>(k, 0)] = active.select(w_kept, w_old).0;
        // The owner moves up past every component whose weight is not larger.
        let mut moving = owner;
        let mut i = k;
        while i > 0 && moving.any() {
            let up = F(blk[at::<C>(i - 1, 0)]);
            let swap = moving.and(w.lt(up).not());
            swap_down::<C>(blk, i, swap);
            moving = swap;
            i -= 1;
        }
        total = active.select(total.add(w_kept), total);
    }

    // Normalise (eq. 14 is followed by a renormalisation).
    let nonzero = total.abs().gt(F::splat(f32::EPSILON));
    let inv = nonzero.select(F::splat(1.0).div(total), zero);
    for k in 0..nm.max() as usize {
        let live = nm.above(k as u32);
        let w = F(blk[at::<C>(k, 0)]);
        blk[at::<C>(k, 0)] = live.select(w.mul(inv), w).0;
    }

    // A sample no component owns starts a new one (replacing the weakest when full).
    let new = if co.alpha > 0.0 { fits.not() } else { B::NONE };
    if new.any() {
        let full = nm.eq(co.n_mix as u32);
        let nm_new = U(std::array::from_fn(|l| nm.0[l] + 1));
        nm = new.and_not(full).select_u(nm_new, nm);
        let only = new.and(nm.eq(1));
        let w_new = only.select(F::splat(1.0), alpha);
        for k in 0..co.n_mix {
            let is_slot = new.and(nm.eq(k as u32 + 1));
            let older = new.and_not(only).and(nm.above(k as u32 + 1));
            let w = F(blk[at::<C>(k, 0)]);
            blk[at::<C>(k, 0)] = is_slot.select(w_new, older.select(w.mul(alpha1), w)).0;
            let v = F(blk[at::<C>(k, 1)]);
            blk[at::<C>(k, 1)] = is_slot.select(F::splat(co.var_init), v).0;
            for c in 0..C {
                let m = F(blk[at::<C>(k, 2 + c)]);
                blk[at::<C>(k, 2 + c)] = is_slot.select(x[c], m).0;
            }
        }
        let mut moving = new;
        for i in (1..co.n_mix).rev() {
            if !moving.any() {
                break;
            }
            let in_play = moving.and(nm.above(i as u32));
            let up = F(blk[at::<C>(i - 1, 0)]);
            let swap = in_play.and(alpha.lt(up).not());
            swap_down::<C>(blk, i, swap);
            moving = moving.and_not(in_play.and_not(swap));
        }
    }

    for l in 0..LANES {
        modes[l] = nm.0[l] as u8;
    }

    let mut out = [0u8; LANES];
    let foreground = background.not();
    let shadow = if co.detect_shadows && foreground.any() {
        detect_shadow::<C>(blk, nm, x, foreground, co)
    } else {
        B::NONE
    };
    for l in 0..LANES {
        out[l] = if background.0[l] != 0 {
            0
        } else if shadow.0[l] != 0 {
            co.shadow_value
        } else {
            255
        };
    }
    out
}

/// The shadow test of Prati et al. as OpenCV's `detectShadowGMM` applies it: the sample is
/// a shadow if, for one of the background components (eq. 8, in order), it is that
/// component's mean scaled by a ∈ [τ, 1] and the colour distortion is within `tb`.
#[inline(always)]
fn detect_shadow<const C: usize>(
    blk: &[[f32; LANES]],
    nm: U,
    x: &[F; C],
    lanes: B,
    co: &Coeffs,
) -> B {
    let zero = F::splat(0.0);
    let tau = F::splat(co.tau);
    let tb = F::splat(co.tb);
    let big_tb = F::splat(co.background_ratio);
    let mut searching = lanes;
    let mut shadow = B::NONE;
    let mut weight_sum = zero;
    for k in 0..co.n_mix {
        let live = searching.and(nm.above(k as u32));
        if !live.any() {
            break;
        }
        let mean: [F; C] = std::array::from_fn(|c| F(blk[at::<C>(k, 2 + c)]));
        let mut num = x[0].mul(mean[0]);
        let mut den = mean[0].mul(mean[0]);
        for c in 1..C {
            num = num.add(x[c].mul(mean[c]));
            den = den.add(mean[c].mul(mean[c]));
        }
        let black = live.and(den.eq(zero));
        searching = searching.and_not(black);
        let live = live.and_not(black);
        let darker = live.and(num.le(den)).and(num.ge(tau.mul(den)));
        let mut hit = B::NONE;
        if darker.any() {
            let a = num.div(den);
            let d0 = a.mul(mean[0]).sub(x[0]);
            let mut dist2a = d0.mul(d0);
            for c in 1..C {
                let dc = a.mul(mean[c]).sub(x[c]);
                dist2a = dist2a.add(dc.mul(dc));
            }
            let var = F(blk[at::<C>(k, 1)]);
            hit = darker.and(dist2a.lt(tb.mul(var).mul(a).mul(a)));
            shadow = shadow.or(hit);
            searching = searching.and_not(hit);
        }
        let live = live.and_not(hit);
        weight_sum = live.select(weight_sum.add(F(blk[at::<C>(k, 0)])), weight_sum);
        searching = searching.and_not(live.and(weight_sum.gt(big_tb)));
    }
    shadow
}

// ---------------------------------------------------------------------------------------
// Rows.

/// Update one image row: `state` is the row's groups, `modes` one `[u8; LANES]` per group,
/// `frame` the row's `width * C` bytes and `mask` its `width` output bytes.
#[inline(always)]
fn update_row_generic<const C: usize>(
    state: &mut [[f32; LANES]],
    modes: &mut [[u8; LANES]],
    frame: &[u8],
    mask: &mut [u8],
    co: &Coeffs,
) {
    let width = mask.len();
    let block = co.n_mix * (2 + C);
    for (g, (blk, modes)) in state
        .chunks_exact_mut(block)
        .zip(modes.iter_mut())
        .enumerate()
    {
        let x0 = g * LANES;
        let n = LANES.min(width - x0);
        let mut x = [F::splat(0.0); C];
        if n == LANES {
            let src = &frame[x0 * C..(x0 + LANES) * C];
            for l in 0..LANES {
                for c in 0..C {
                    x[c].0[l] = f32::from(src[l * C + c]);
                }
            }
        } else {
            for l in 0..n {
                for c in 0..C {
                    x[c].0[l] = f32::from(frame[(x0 + l) * C + c]);
                }
            }
        }
        let out = update_group::<C>(blk, modes, &x, co);
        mask[x0..x0 + n].copy_from_slice(&out[..n]);
    }
}

fn update_row_portable(
    channels: usize,
    state: &mut [[f32; LANES]],
    modes: &mut [[u8; LANES]],
    frame: &[u8],
    mask: &mut [u8],
    co: &Coeffs,
) {
    if channels == 1 {
        update_row_generic::<1>(state, modes, frame, mask, co)
    } else {
        update_row_generic::<3>(state, modes, frame, mask, co)
    }
}

/// The same code compiled for AVX2: only the instruction selection differs, the IEEE
/// operations and their order are the same, so the results are identical.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn update_row_avx2(
    channels: usize,
    state: &mut [[f32; LANES]],
    modes: &mut [[u8; LANES]],
    frame: &[u8],
    mask: &mut [u8],
    co: &Coeffs,
) {
    if channels == 1 {
        update_row_generic::<1>(state, modes, frame, mask, co)
    } else {
        update_row_generic::<3>(state, modes, frame, mask, co)
    }
}

/// Instruction set used for the rows, chosen once per frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Isa {
    Portable,
    #[cfg(target_arch = "x86_64")]
    Avx2,
}

impl Isa {
    pub(super) fn detect() -> Isa {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            return Isa::Avx2;
        }
        Isa::Portable
    }
}

/// Update one row with `channels` (1 or 3) interleaved channels.
pub(super) fn update_row(
    isa: Isa,
    channels: usize,
    state: &mut [[f32; LANES]],
    modes: &mut [[u8; LANES]],
    frame: &[u8],
    mask: &mut [u8],
    co: &Coeffs,
) {
    match isa {
        Isa::Portable => update_row_portable(channels, state, modes, frame, mask, co),
        #[cfg(target_arch = "x86_64")]
        // SAFETY: `Isa::Avx2` is only constructed after `is_x86_feature_detected!("avx2")`.
        Isa::Avx2 => unsafe { update_row_avx2(channels, state, modes, frame, mask, co) },
    }
}

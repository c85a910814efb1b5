//! Ghost removal by edge matching (our addition, not in seed 004).
//!
//! A background started from the first frame holds everyone standing in it; when they walk
//! away, the place they left is segmented as foreground — a *ghost* with a person's shape,
//! which the selective update (frozen under the foreground) never learns away. A ghost and a
//! person are told apart by where the silhouette's edge is: around a person the edge is in the
//! current frame (the person stands before the background); around a ghost it is in the
//! background model (the frame shows the floor and wall continuing across the place). So for
//! every connected foreground region the test sums the luminance gradient magnitude (3×3
//! Sobel) over a band along its contour — the pixels within `band_px` of both the region and
//! the outside — in the current frame and in a luminance background kept beside the features
//! with the same update; a region whose band has more gradient in the background than in the
//! frame is a ghost. Once a pixel has lain in ghost regions for `frames` frames running (a
//! ghost stands still; a wrong verdict on a walking person moves with them), it is cleared
//! from the mask and the model there is replaced by the current frame — over the region grown
//! by the band and then by `grow_px` (the features within the filter's radius of a ghost see
//! it through the kernel). The comparison has no threshold of its own (more edge in the one image
//! than in the other); the band follows from the Gabor envelope, which spreads a silhouette
//! by about σ, so the edge lies within about 2σ of the mask's contour.
//!
//! Written by hand: the Sobel magnitude on an `f32` plane and the band are a few lines, the
//! labelling is [`crate::vision::blobs::label`]. The idea of testing a still foreground
//! region's border against the image's edges is a common ghost test in background
//! subtraction; nothing here is taken from another implementation.
//!
//! Not here: a region holding a person and the ghost they are leaving is judged as one (the
//! two part within a body width of walking); a person standing still from the first frame is
//! in the background and stays missed until they move.

use super::{Features, dilate};
use crate::vision::blobs::{self, Connectivity};

/// The edge-matching ghost test.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GhostTest {
    /// Half-width of the contour band (pixels).
    pub band_px: u32,
    /// A pixel is learnt once it has lain in a ghost region this many frames running
    /// (1: at the first verdict).
    pub frames: u32,
    /// The learnt pixels grown by this much (pixels; 0: the region grown by the band only):
    /// the features within the filter's radius of a ghost still see it through the kernel.
    pub grow_px: u32,
}

/// Scratch of the test, reused between frames; `heal` holds the last frame's ghost pixels.
#[derive(Debug, Default, Clone)]
pub(super) struct GhostScratch {
    grown: Vec<u8>,
    outside: Vec<u8>,
    near_outside: Vec<u8>,
    rows: Vec<u8>,
    labels: Vec<u32>,
    /// Frames running each pixel has lain in a ghost region.
    age: Vec<u32>,
    /// 1 where a ghost region (grown by the band) has lain `frames` frames running.
    pub heal: Vec<u8>,
}

/// Luminance `Y = 0.299 R + 0.587 G + 0.114 B` in [0, 1] of interleaved RGB bytes.
pub(super) fn luma(raw: &[u8], out: &mut Vec<f32>) {
    out.clear();
    out.extend(raw.chunks_exact(3).map(|p| {
        (0.299 * f32::from(p[0]) + 0.587 * f32::from(p[1]) + 0.114 * f32::from(p[2])) / 255.0
    }));
}

/// The 3×3 Sobel gradient magnitude `√(Gx² + Gy²)` of a row-major plane (`w × h`, both > 0)
/// at `(x, y)`, replicated borders.
fn sobel_at(plane: &[f32], w: usize, h: usize, x: usize, y: usize) -> f32 {
    let (x, y) = (x as isize, y as isize);
    let at = |x: isize, y: isize| {
        let x = x.clamp(0, w as isize - 1) as usize;
        let y = y.clamp(0, h as isize - 1) as usize;
        plane[y * w + x]
    };
    let gx = (at(x + 1, y - 1) + 2.0 * at(x + 1, y) + at(x + 1, y + 1))
        - (at(x - 1, y - 1) + 2.0 * at(x - 1, y) + at(x - 1, y + 1));
    let gy = (at(x - 1, y + 1) + 2.0 * at(x, y + 1) + at(x + 1, y + 1))
        - (at(x - 1, y - 1) + 2.0 * at(x, y - 1) + at(x + 1, y - 1));
    (gx * gx + gy * gy).sqrt()
}

/// The 3×3 Sobel gradient magnitude `√(Gx² + Gy²)` of a row-major plane, replicated borders.
pub fn sobel_magnitude(plane: &[f32], w: usize, h: usize, out: &mut Vec<f32>) {
    out.clear();
    out.resize(plane.len(), 0.0);
    if w == 0 || h == 0 {
        return;
    }
    for y in 0..h {
        for x in 0..w {
            out[y * w + x] = sobel_at(plane, w, h, x, y);
        }
    }
}

/// Judge every region of `mask` (0/1, `w` wide) with the luminance of the frame (`cur`) and of
/// the background (`bg`); `s.heal` marks the pixels of ghost regions (grown by the band) that
/// have been in one for `test.frames` frames running. Returns how many regions were ghosts.
pub(super) fn find(
    mask: &[u8],
    w: usize,
    cur: &[f32],
    bg: &[f32],
    test: GhostTest,
    s: &mut GhostScratch,
) -> usize {
    let n = mask.len();
    s.heal.clear();
    s.heal.resize(n, 0);
    s.age.resize(n, 0);
    if w == 0 || n == 0 || !mask.contains(&1) {
        s.age.fill(0);
        return 0;
    }
    let h = n / w;
    let b = test.band_px as usize;
    dilate(mask, w, b, &mut s.rows, &mut s.grown);
    s.outside.clear();
    s.outside.extend(mask.iter().map(|&m| u8::from(m == 0)));
    dilate(&s.outside, w, b, &mut s.rows, &mut s.near_outside);
    s.labels.clear();
    s.labels.resize(n, 0);
    let Ok(regions) = blobs::label(&s.grown, w, h, Connectivity::Eight, 1, &mut s.labels) else {
        return 0;
    };
    // band energy per region: [frame, background]; the gradient only where it is summed
    let mut energy = vec![[0.0f64; 2]; regions.len() + 1];
    for i in 0..n {
        let l = s.labels[i] as usize;
        if l != 0 && s.near_outside[i] == 1 {
            let (x, y) = (i % w, i / w);
            energy[l][0] += f64::from(sobel_at(cur, w, h, x, y));
            energy[l][1] += f64::from(sobel_at(bg, w, h, x, y));
        }
    }
    let ghost: Vec<bool> = energy.iter().map(|[c, g]| g > c).collect();
    let frames = test.frames.max(1);
    for ((h, a), &l) in s.heal.iter_mut().zip(s.age.iter_mut()).zip(&s.labels) {
        *a = if l != 0 && ghost[l as usize] {
            a.saturating_add(1)
        } else {
            0
        };
        *h = u8::from(*a >= frames);
    }
    if test.grow_px > 0 && s.heal.contains(&1) {
        s.outside.clone_from(&s.heal);
        dilate(
            &s.outside,
            w,
            test.grow_px as usize,
            &mut s.rows,
            &mut s.heal,
        );
    }
    ghost.iter().skip(1).filter(|&&g| g).count()
}

/// Learn the ghost pixels (`heal` = 1) at once: the model's features and luminance there become
/// the frame's.
pub(super) fn learn(
    model: &mut Features,
    current: &Features,
    luma_bg: &mut [f32],
    luma: &[f32],
    heal: &[u8],
) {
    for (b, m) in model.planes.iter_mut().zip(&current.planes) {
        for ((b, m), &g) in b.iter_mut().zip(m).zip(heal) {
            if g == 1 {
                *b = *m;
            }
        }
    }
    for ((b, m), &g) in luma_bg.iter_mut().zip(luma).zip(heal) {
        if g == 1 {
            *b = *m;
        }
    }
}

//! [`Sequence`]: ground truth and hypotheses checked, given dense ids and grouped by frame,
//! the form every metric reads.
//!
//! Rows of each side sit in one array in (frame, input order); a frame is a pair of
//! contiguous slices of those arrays (a stable sort by frame, skipped when the input is
//! already in frame order, as files usually are). Geometry is kept prepared for the pair
//! tests: a box as (left, top, right, bottom, area), computed with the very operations of
//! [`iou`](super::iou), so every distance is bit-identical to it.
//!
//! CLEAR MOT and IDF1 need only the **allowed** pairs of a frame (distance within the
//! rule's gate); they are found once per sequence, on first use, and kept sparse
//! ([`AllowedFrames`]). With an IoU gate above zero a pair whose boxes do not overlap cannot be
//! allowed, so a cheap overlap test skips most of a frame's `gt × hyp` pairs. HOTA needs the
//! similarity of every pair and still visits dense frames ([`Frames`]).

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use std::sync::OnceLock;

use super::{Frame, Frames, Geometry, MatchRule, MotError, Observation, Side};

/// An allowed pair of one frame: frame-local ground-truth row `i`, hypothesis row `j`, and
/// its CLEAR distance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Pair {
    pub i: u32,
    pub j: u32,
    pub dist: f64,
}

/// One frame as CLEAR MOT and IDF1 see it: dense ids of its rows and its allowed pairs,
/// sorted by `(i, j)`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct AllowedFrame<'a> {
    pub frame: i64,
    pub gt: &'a [u32],
    pub hyp: &'a [u32],
    pub pairs: &'a [Pair],
}

/// Frames visited in ascending order with their allowed pairs only.
pub(crate) trait AllowedFrames {
    fn num_frames(&self) -> usize;
    fn each_allowed(&self, visit: &mut dyn FnMut(&AllowedFrame));
}

/// One frame's rows: `start..end` in [`Sequence`]'s row arrays.
#[derive(Debug, Clone, Copy)]
struct Span {
    frame: i64,
    gt: (u32, u32),
    hyp: (u32, u32),
}

/// A box as (left, top, right, bottom, area) or a point as (x, y, 0, 0, 0).
type Prepared = [f64; 5];

/// One side's rows in frame order.
#[derive(Debug, Clone, Default)]
struct Rows {
    id: Vec<u32>,
    geometry: Vec<Prepared>,
}

/// Every frame's allowed pairs, back to back; frame `k` owns `pairs[start[k]..start[k + 1]]`.
#[derive(Debug, Clone, Default)]
struct Allowed {
    pairs: Vec<Pair>,
    start: Vec<u32>,
}

/// Ground truth and hypotheses of one sequence, checked and grouped by frame (rows in frame
/// order, within a frame in input order), under a [`MatchRule`]: build once, then compute any
/// of the metrics.
#[derive(Debug, Clone)]
pub struct Sequence {
    pub(super) rule: MatchRule,
    pub(super) gt_ids: Vec<i64>,
    pub(super) hyp_ids: Vec<i64>,
    spans: Vec<Span>,
    gt: Rows,
    hyp: Rows,
    allowed: OnceLock<Allowed>,
}

impl Sequence {
    /// Check the observations (finite, the geometry the rule needs, one row per id and frame)
    /// and group them by frame. Frames are those where either side has an observation,
    /// ascending; within a frame, observations keep their input order (which decides ties,
    /// as in motmetrics).
    pub fn new(gt: &[Observation], hyp: &[Observation], rule: MatchRule) -> Result<Self, MotError> {
        rule.validate()?;
        for (obs, side) in [(gt, Side::GroundTruth), (hyp, Side::Hypothesis)] {
            if u32::try_from(obs.len()).is_err() {
                return Err(MotError::TooLarge { side });
            }
        }
        let (gt_ids, gt_dense) = intern(gt, Side::GroundTruth, rule)?;
        let (hyp_ids, hyp_dense) = intern(hyp, Side::Hypothesis, rule)?;
        let mut sides = [
            SideInput::new(gt, gt_dense, gt_ids.len(), Side::GroundTruth),
            SideInput::new(hyp, hyp_dense, hyp_ids.len(), Side::Hypothesis),
        ];
        let mut spans: Vec<Span> = Vec::new();
        loop {
            let frame = match (sides[0].next_frame(), sides[1].next_frame()) {
                (Some(a), Some(b)) => a.min(b),
                (Some(a), None) | (None, Some(a)) => a,
                (None, None) => break,
            };
            let fi = spans.len();
            let [g, h] = &mut sides;
            spans.push(Span {
                frame,
                gt: g.take_frame(frame, fi)?,
                hyp: h.take_frame(frame, fi)?,
            });
        }
        let [g, h] = sides;
        Ok(Sequence {
            rule,
            gt_ids,
            hyp_ids,
            spans,
            gt: g.rows,
            hyp: h.rows,
            allowed: OnceLock::new(),
        })
    }

    /// Every frame's allowed pairs, found on first use and kept when they are few (at most
    /// [`KEPT_PAIRS_PER_ROW`] per row); `None` when they are too many to keep.
    fn allowed(&self) -> Option<&Allowed> {
        let allowed = self.allowed.get_or_init(|| {
            let rows = self.gt.id.len() + self.hyp.id.len();
            let limit = KEPT_PAIRS_PER_ROW * rows + 1024;
            let mut out = Allowed {
                pairs: Vec::with_capacity(rows),
                start: Vec::with_capacity(self.spans.len() + 1),
            };
            let mut scratch = Overlaps::default();
            for s in &self.spans {
                out.start.push(out.pairs.len() as u32);
                self.frame_pairs(s, &mut scratch, &mut out.pairs);
                if out.pairs.len() > limit {
                    return Allowed::default();
                }
            }
            out.start.push(out.pairs.len() as u32);
            out
        });
        (!allowed.start.is_empty()).then_some(allowed)
    }

    /// Append the allowed pairs of one frame, by `(i, j)`.
    fn frame_pairs(&self, s: &Span, scratch: &mut Overlaps, out: &mut Vec<Pair>) {
        let max_dist = self.rule.max_dist();
        let g = &self.gt.geometry[s.gt.0 as usize..s.gt.1 as usize];
        let h = &self.hyp.geometry[s.hyp.0 as usize..s.hyp.1 as usize];
        // With an IoU gate above zero, boxes that do not overlap (IoU 0) are never allowed.
        if !(matches!(self.rule, MatchRule::Iou { .. }) && max_dist < 1.0) {
            for (i, a) in g.iter().enumerate() {
                for (j, b) in h.iter().enumerate() {
                    push_allowed(out, i, j, prepared_pair(a, b, self.rule, max_dist).0);
                }
            }
            return;
        }
        scratch.load(h);
        for (i, a) in g.iter().enumerate() {
            scratch.test(a, h);
            for &j in &scratch.hits {
                let d = prepared_pair(a, &h[j as usize], self.rule, max_dist).0;
                push_allowed(out, i, j as usize, d);
            }
        }
    }
}

fn push_allowed(out: &mut Vec<Pair>, i: usize, j: usize, dist: f64) {
    if dist.is_finite() {
        out.push(Pair {
            i: i as u32,
            j: j as u32,
            dist,
        });
    }
}

/// One frame's hypothesis boxes, loaded to find the boxes that overlap one ground-truth box.
///
/// A frame of at most [`COLUMN_SCAN_MAX`] boxes keeps its boxes of positive width and height
/// as `[left, top, right, bottom]` rows in index order and tests each against the ground
/// truth with four comparisons and no branch until a hit: for a few dozen people a frame is
/// tested faster so than by the search below, and hits come out ascending.
///
/// A larger frame is sorted by left edge, to skip most boxes: a box can overlap only if its
/// left edge is left of the ground truth's right edge (a prefix of the order) and if some
/// box at or before it in the order reaches past the ground truth's left edge (the running
/// maximum of right edges, non-decreasing, gives where that starts). Both ends are found by
/// binary search with exact comparisons; each box between them is then tested exactly.
#[derive(Debug, Default)]
struct Overlaps {
    /// Column mode: the boxes of positive width and height as `[left, top, right, bottom]`,
    /// and their indices.
    rows: Vec<[f64; 4]>,
    row_index: Vec<u32>,
    /// Sweep mode (`order` empty in column mode): hypothesis indices by left edge.
    order: Vec<u32>,
    left: Vec<f64>,
    /// Running maximum of the right edges, in `order`.
    reach: Vec<f64>,
    /// The hypotheses that overlap the box of the last [`Overlaps::test`], ascending.
    hits: Vec<u32>,
}

impl Overlaps {
    fn load(&mut self, boxes: &[Prepared]) {
        self.order.clear();
        self.rows.clear();
        self.row_index.clear();
        if boxes.len() <= COLUMN_SCAN_MAX {
            for (k, &[l, t, r, b, _]) in boxes.iter().enumerate() {
                if r > l && b > t {
                    self.rows.push([l, t, r, b]);
                    self.row_index.push(k as u32);
                }
            }
            return;
        }
        self.order.extend(0..boxes.len() as u32);
        self.order
            .sort_unstable_by(|&a, &b| boxes[a as usize][0].total_cmp(&boxes[b as usize][0]));
        self.left.clear();
        self.left
            .extend(self.order.iter().map(|&k| boxes[k as usize][0]));
        self.reach.clear();
        let mut reach = f64::NEG_INFINITY;
        for &k in &self.order {
            reach = reach.max(boxes[k as usize][2]);
            self.reach.push(reach);
        }
    }

    /// The boxes of `boxes` (as loaded) with `min(right) − max(left) > 0` and the same
    /// vertically against `a`, as [`overlaps`] computes it: for finite numbers `x − y > 0`
    /// exactly when `x > y`, and `min(a, b) > max(c, d)` exactly when each of `a`, `b`
    /// exceeds each of `c`, `d`.
    fn test(&mut self, a: &Prepared, boxes: &[Prepared]) {
        self.hits.clear();
        let [al, at, ar, ab, _] = *a;
        if !(ar > al && ab > at) {
            return;
        }
        if self.order.is_empty() {
            for (&[l, t, r, b], &k) in self.rows.iter().zip(&self.row_index) {
                // `&`, not `&&`: all four comparisons, no branch per comparison
                if (l < ar) & (r > al) & (t < ab) & (b > at) {
                    self.hits.push(k);
                }
            }
            return;
        }
        let end = self.left.partition_point(|&l| l < ar);
        let start = self.reach[..end].partition_point(|&r| r <= al);
        for &k in &self.order[start..end] {
            let [l, t, r, b, _] = boxes[k as usize];
            if r > l && r > al && b > t && ab > t && b > at {
                self.hits.push(k);
            }
        }
        self.hits.sort_unstable();
    }
}

/// Hypotheses in a frame up to which [`Overlaps`] tests every box rather than searching.
const COLUMN_SCAN_MAX: usize = 64;

/// Allowed pairs per observation up to which a [`Sequence`] keeps them all (CLEAR MOT and
/// IDF1 both read them); beyond it (a gate that lets most pairs through) they are found
/// again per frame on each visit, so memory stays proportional to the rows.
const KEPT_PAIRS_PER_ROW: usize = 8;

impl Frames for Sequence {
    fn num_frames(&self) -> usize {
        self.spans.len()
    }

    fn each(&self, visit: &mut dyn FnMut(&Frame)) {
        let max_dist = self.rule.max_dist();
        let mut f = Frame::default();
        for s in &self.spans {
            let (g0, g1) = (s.gt.0 as usize, s.gt.1 as usize);
            let (h0, h1) = (s.hyp.0 as usize, s.hyp.1 as usize);
            f.frame = s.frame;
            f.gt.clear();
            f.gt.extend(self.gt.id[g0..g1].iter().map(|&d| d as usize));
            f.hyp.clear();
            f.hyp
                .extend(self.hyp.id[h0..h1].iter().map(|&d| d as usize));
            f.dist.clear();
            f.sim.clear();
            for a in &self.gt.geometry[g0..g1] {
                for b in &self.hyp.geometry[h0..h1] {
                    let (d, s) = prepared_pair(a, b, self.rule, max_dist);
                    f.dist.push(d);
                    f.sim.push(s);
                }
            }
            visit(&f);
        }
    }
}

impl AllowedFrames for Sequence {
    fn num_frames(&self) -> usize {
        self.spans.len()
    }

    fn each_allowed(&self, visit: &mut dyn FnMut(&AllowedFrame)) {
        let allowed = self.allowed();
        let (mut scratch, mut overlaps) = (Vec::new(), Overlaps::default());
        for (k, s) in self.spans.iter().enumerate() {
            let pairs = match allowed {
                Some(a) => &a.pairs[a.start[k] as usize..a.start[k + 1] as usize],
                None => {
                    scratch.clear();
                    self.frame_pairs(s, &mut overlaps, &mut scratch);
                    &scratch[..]
                }
            };
            visit(&AllowedFrame {
                frame: s.frame,
                gt: &self.gt.id[s.gt.0 as usize..s.gt.1 as usize],
                hyp: &self.hyp.id[s.hyp.0 as usize..s.hyp.1 as usize],
                pairs,
            });
        }
    }
}

/// Dense frames (tests build them by hand) seen through their allowed entries.
impl AllowedFrames for &[Frame] {
    fn num_frames(&self) -> usize {
        self.len()
    }

    fn each_allowed(&self, visit: &mut dyn FnMut(&AllowedFrame)) {
        for f in self.iter() {
            let gt: Vec<u32> = f.gt.iter().map(|&d| d as u32).collect();
            let hyp: Vec<u32> = f.hyp.iter().map(|&d| d as u32).collect();
            let nh = f.hyp.len();
            let pairs: Vec<Pair> = (0..f.gt.len() * nh)
                .filter(|&k| f.dist[k].is_finite())
                .map(|k| Pair {
                    i: (k / nh) as u32,
                    j: (k % nh) as u32,
                    dist: f.dist[k],
                })
                .collect();
            visit(&AllowedFrame {
                frame: f.frame,
                gt: &gt,
                hyp: &hyp,
                pairs: &pairs,
            });
        }
    }
}

/// One side while [`Sequence::new`] walks the frames: its rows in frame order, where the walk
/// is, and the frame in which each dense id was last seen (to find an id twice in a frame).
struct SideInput<'a> {
    obs: &'a [Observation],
    dense: Vec<u32>,
    /// Row indices in (frame, input order); `None` when the input already is in that order.
    order: Option<Vec<u32>>,
    next: usize,
    seen: Vec<usize>,
    side: Side,
    rows: Rows,
}

impl<'a> SideInput<'a> {
    fn new(obs: &'a [Observation], dense: Vec<u32>, num_ids: usize, side: Side) -> Self {
        let order = (!obs.is_sorted_by_key(|o| o.frame)).then(|| {
            let mut idx: Vec<u32> = (0..obs.len() as u32).collect();
            idx.sort_by_key(|&k| obs[k as usize].frame);
            idx
        });
        SideInput {
            obs,
            dense,
            order,
            next: 0,
            seen: vec![usize::MAX; num_ids],
            side,
            rows: Rows {
                id: Vec::with_capacity(obs.len()),
                geometry: Vec::with_capacity(obs.len()),
            },
        }
    }

    /// Input index of the `k`-th row in frame order.
    fn row(&self, k: usize) -> Option<usize> {
        match &self.order {
            Some(order) => order.get(k).map(|&r| r as usize),
            None => (k < self.obs.len()).then_some(k),
        }
    }

    fn next_frame(&self) -> Option<i64> {
        self.row(self.next).map(|r| self.obs[r].frame)
    }

    /// Move the rows of `frame` (frame index `fi`) into `rows`; their range.
    fn take_frame(&mut self, frame: i64, fi: usize) -> Result<(u32, u32), MotError> {
        let start = self.rows.id.len() as u32;
        while let Some(r) = self.row(self.next) {
            let o = &self.obs[r];
            if o.frame != frame {
                break;
            }
            let d = self.dense[r];
            if std::mem::replace(&mut self.seen[d as usize], fi) == fi {
                return Err(MotError::DuplicateId {
                    side: self.side,
                    frame,
                    id: o.id,
                });
            }
            self.rows.id.push(d);
            self.rows.geometry.push(prepare(&o.geometry));
            self.next += 1;
        }
        Ok((start, self.rows.id.len() as u32))
    }
}

/// A multiplicative hash for integer ids (FxHash's constant): the id maps are built from
/// our own inputs, where a keyed hash buys nothing and costs a third of [`Sequence::new`].
#[derive(Default)]
struct IdHasher(u64);

impl Hasher for IdHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    fn write_i64(&mut self, v: i64) {
        self.write_u64(v as u64);
    }
}

/// Check one side's observations and map its ids to dense indices (in order of first
/// appearance). Returns (dense → original id, per-observation dense index).
fn intern(
    obs: &[Observation],
    side: Side,
    rule: MatchRule,
) -> Result<(Vec<i64>, Vec<u32>), MotError> {
    let mut ids = Vec::new();
    let mut index: HashMap<i64, u32, BuildHasherDefault<IdHasher>> = HashMap::default();
    let mut dense = Vec::with_capacity(obs.len());
    for o in obs {
        if !(o.geometry.is_finite() && o.confidence.is_finite()) {
            return Err(MotError::NonFinite {
                side,
                frame: o.frame,
                id: o.id,
            });
        }
        if o.geometry.kind() != rule.geometry() {
            return Err(MotError::WrongGeometry {
                side,
                frame: o.frame,
                id: o.id,
                rule: rule.name(),
                expected: rule.geometry().name(),
                found: o.geometry.kind().name(),
            });
        }
        let next = u32::try_from(ids.len()).map_err(|_| MotError::TooLarge { side })?;
        let d = *index.entry(o.id).or_insert(next);
        if d == next {
            ids.push(o.id);
        }
        dense.push(d);
    }
    Ok((ids, dense))
}

/// The prepared form of a geometry, with the operations of [`iou`](super::iou).
fn prepare(g: &Geometry) -> Prepared {
    match g {
        Geometry::Box(b) => {
            let (right, bottom) = (b.left_px + b.width_px, b.top_px + b.height_px);
            let area = (right - b.left_px).max(0.0) * (bottom - b.top_px).max(0.0);
            [b.left_px, b.top_px, right, bottom, area]
        }
        Geometry::Point(p) => [p.x_m, p.y_m, 0.0, 0.0, 0.0],
    }
}

/// Whether two prepared boxes overlap with a positive width and height (otherwise their
/// intersection, hence their IoU, is zero): the reference for [`Overlaps::test`].
#[cfg(test)]
fn overlaps(a: &Prepared, b: &Prepared) -> bool {
    a[2].min(b[2]) - a[0].max(b[0]) > 0.0 && a[3].min(b[3]) - a[1].max(b[1]) > 0.0
}

/// (CLEAR distance or NaN when not allowed, HOTA similarity) of one prepared pair, as
/// [`pair`](super::pair) computes it for the geometries.
fn prepared_pair(a: &Prepared, b: &Prepared, rule: MatchRule, max_dist: f64) -> (f64, f64) {
    match rule {
        MatchRule::Iou { .. } => {
            let inter_w = (a[2].min(b[2]) - a[0].max(b[0])).max(0.0);
            let inter_h = (a[3].min(b[3]) - a[1].max(b[1])).max(0.0);
            let inter = inter_w * inter_h;
            let s = if inter == 0.0 {
                0.0
            } else {
                inter / (a[4] + b[4] - inter)
            };
            let d = 1.0 - s;
            (if d > max_dist { f64::NAN } else { d }, s)
        }
        MatchRule::Euclidean { max_m } => {
            let (dx, dy) = (a[0] - b[0], a[1] - b[1]);
            let d2 = dx * dx + dy * dy;
            let d = d2.sqrt();
            let s = (1.0 - d / (2.0 * max_m)).max(0.0);
            (if d2 > max_dist { f64::NAN } else { d }, s)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{bx, pt};
    use super::super::{Geometry, iou, pair};
    use super::*;

    /// The prepared distances are bit-identical to `iou` / `pair` on the geometries, and the
    /// sparse allowed pairs are exactly the finite entries of the dense frames.
    #[test]
    fn prepared_pairs_equal_the_direct_formulas() {
        let boxes = [
            bx(1, 1, 0.1, 0.2, 10.3, 20.7),
            bx(1, 2, 5.0, 0.0, 10.0, 10.0),
            bx(1, 3, 0.1 + 0.2, 0.2, 10.3, 20.70000000000001),
            bx(1, 4, 10.4, 0.0, 1.0, 1.0),
            bx(1, 5, -3.0, -4.0, 0.0, 5.0),
            bx(2, 1, 0.0, 0.0, 1e-200, 1e-200),
        ];
        for rule in [
            MatchRule::Iou { min_iou: 0.5 },
            MatchRule::Iou { min_iou: 0.0 },
            MatchRule::Iou { min_iou: 1.0 },
        ] {
            for a in &boxes {
                for b in &boxes {
                    let (Geometry::Box(ga), Geometry::Box(gb)) = (a.geometry, b.geometry) else {
                        unreachable!()
                    };
                    let want = pair(&a.geometry, &b.geometry, rule, rule.max_dist());
                    let got = prepared_pair(
                        &prepare(&a.geometry),
                        &prepare(&b.geometry),
                        rule,
                        rule.max_dist(),
                    );
                    assert_eq!(got.1.to_bits(), iou(&ga, &gb).to_bits());
                    assert_eq!(got.1.to_bits(), want.1.to_bits());
                    assert_eq!(got.0.to_bits(), want.0.to_bits());
                }
            }
            check_sparse_matches_dense(&boxes, &boxes[1..4], rule);
        }
        let points = [pt(1, 1, 0.0, 0.0), pt(1, 2, 0.3, 0.4), pt(2, 1, 5.0, 5.0)];
        check_sparse_matches_dense(&points, &points, MatchRule::Euclidean { max_m: 0.5 });
    }

    fn check_sparse_matches_dense(gt: &[Observation], hyp: &[Observation], rule: MatchRule) {
        let seq = Sequence::new(gt, hyp, rule).expect("valid test input");
        let mut dense = Vec::new();
        seq.each(&mut |f| dense.push(f.clone()));
        let mut sparse = Vec::new();
        seq.each_allowed(&mut |f| {
            sparse.push((f.frame, f.gt.to_vec(), f.hyp.to_vec(), f.pairs.to_vec()))
        });
        let mut from_dense = Vec::new();
        (&dense[..]).each_allowed(&mut |f| {
            from_dense.push((f.frame, f.gt.to_vec(), f.hyp.to_vec(), f.pairs.to_vec()))
        });
        assert_eq!(sparse, from_dense, "{rule:?}");
        assert_eq!(sparse.len(), seq.num_frames());
    }

    #[test]
    fn column_overlap_test_equals_the_min_max_formula() {
        let v = [-1e308, -3.0, -1e-300, 0.0, 5e-324, 1.0, 2.5, 1e308];
        let mut boxes = Vec::new();
        for &l in &v {
            for &w in &[-1.0, 0.0, 5e-324, 1.0, 1e308] {
                boxes.push(prepare(&Geometry::Box(super::super::BoxPx {
                    left_px: l,
                    top_px: -l,
                    width_px: w,
                    height_px: 2.0,
                })));
            }
        }
        // 40 boxes are scanned as columns, the same twice over (80) by the sorted sweep
        let twice = [boxes.clone(), boxes].concat();
        for (boxes, column_mode) in [(&twice[..40], true), (&twice[..], false)] {
            let mut o = Overlaps::default();
            o.load(boxes);
            assert_eq!(o.order.is_empty(), column_mode);
            let mut hits = 0;
            for a in boxes {
                o.test(a, boxes);
                let want: Vec<u32> = (0..boxes.len() as u32)
                    .filter(|&k| overlaps(a, &boxes[k as usize]))
                    .collect();
                assert_eq!(o.hits, want, "{a:?}");
                hits += want.len();
            }
            assert!(hits > 50 && hits < boxes.len() * boxes.len() / 2, "{hits}");
        }
    }

    #[test]
    fn unsorted_input_is_grouped_by_frame_in_input_order() {
        let rule = MatchRule::Iou { min_iou: 0.5 };
        let gt = [
            bx(3, 7, 0.0, 0.0, 1.0, 1.0),
            bx(1, 8, 0.0, 0.0, 1.0, 1.0),
            bx(3, 9, 0.0, 0.0, 1.0, 1.0),
            bx(1, 7, 5.0, 0.0, 1.0, 1.0),
        ];
        let hyp = [bx(2, 1, 0.0, 0.0, 1.0, 1.0), bx(3, 1, 0.0, 0.0, 1.0, 1.0)];
        let seq = Sequence::new(&gt, &hyp, rule).expect("valid test input");
        let mut got = Vec::new();
        seq.each_allowed(&mut |f| {
            let ids = |d: &[u32], ids: &[i64]| d.iter().map(|&k| ids[k as usize]).collect();
            let (g, h): (Vec<i64>, Vec<i64>) = (ids(f.gt, &seq.gt_ids), ids(f.hyp, &seq.hyp_ids));
            got.push((f.frame, g, h, f.pairs.len()));
        });
        assert_eq!(
            got,
            vec![
                (1, vec![8, 7], vec![], 0),
                (2, vec![], vec![1], 0),
                (3, vec![7, 9], vec![1], 2),
            ]
        );
    }
}

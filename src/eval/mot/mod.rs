//! Multi-object tracking metrics: CLEAR MOT, identity metrics (IDF1) and HOTA, from
//! ground-truth and hypothesis observations (one box or ground-plane point per object per
//! frame), plus MOTChallenge CSV import and export.
//!
//! **What it computes, and whose convention it follows.**
//! - [`ClearMot`]: CLEAR MOT (Bernardin & Stiefelhagen, EURASIP JIVP 2008) exactly as
//!   py-motmetrics 1.4.0 (`MOTAccumulator.update` + `metrics.py`) computes it. Per frame:
//!   (1) a ground-truth object keeps its previous hypothesis if that hypothesis is present and
//!   still within the threshold (the continuity rule, even when a cheaper pairing exists);
//!   (2) the rest are matched by an optimal assignment that first maximises the number of
//!   pairs and then minimises their total distance; (3) unmatched objects are misses,
//!   unmatched hypotheses false positives. A match whose object was last matched to another
//!   hypothesis is an ID switch. MOTA = 1 − (FN + FP + IDSW) / GT; MOTP = mean distance over
//!   matches and switches — mean (1 − IoU) for boxes, metres for points (MOTChallenge reports
//!   (1 − MOTP) · 100 for boxes). Fragmentations count interruptions (tracked → missed) between
//!   an object's first and last tracked frame; an object is mostly tracked when matched in
//!   ≥ 80 % of its frames, mostly lost below 20 %, partially tracked otherwise. Transfers,
//!   ascends and migrations are counted as motmetrics does. Every decision is returned as an
//!   [`Event`] (MATCH, SWITCH, MISS, FP) in motmetrics' order.
//! - [`IdMetrics`]: IDF1, IDP, IDR (Ristani et al., ECCV-W 2016, eq. 6–8): one global
//!   bipartite matching between ground-truth and hypothesis trajectories that maximises the
//!   number of frames in which matched trajectories are within the threshold (equivalently,
//!   minimises IDFN + IDFP), as motmetrics' `id_global_assignment`.
//! - [`Hota`]: HOTA, DetA, AssA, LocA (Luiten et al., IJCV 2021, eq. 1–11) as TrackEval's
//!   `HOTA.eval_sequence`: per frame an optimal matching maximising alignment × similarity,
//!   then detection and association scores at α = 0.05, 0.10, …, 0.95, averaged over α.
//!   Similarity is IoU for boxes and `max(0, 1 − d / (2 · max_m))` for points (TrackEval's
//!   Euclidean similarity with `zero_distance = 2 · max_m`, so α = 0.5 is the CLEAR gate).
//! - [`Metrics::overall`]: several sequences combined as motmetrics' `OVERALL` row (counts
//!   summed, MOTP weighted by matches, ratios recomputed from the sums) and TrackEval's
//!   `COMBINED_SEQ` (HOTA counts summed, AssA and LocA weighted by true positives).
//!
//! **Matching rule.** [`MatchRule::Iou`]: distance 1 − IoU, a pair is allowed when
//! 1 − IoU ≤ 1 − `min_iou` (motmetrics `iou_matrix(max_iou = 1 − min_iou)` forbids only
//! `dist > max_iou`, so IoU exactly at the threshold matches). [`MatchRule::Euclidean`]:
//! allowed when dx² + dy² ≤ `max_m`² (motmetrics `'euc'`), distance √(dx² + dy²) in metres.
//! Optimal assignments use `pathfinding`'s Kuhn–Munkres (see [`assign`]).
//!
//! **What it does not do.** No MOTChallenge 16/17 preprocessing (class filter, `conf = 0`
//! ignore rows, distractor removal, visibility, crowd regions) and no confidence threshold:
//! every row scores. No `max_switch_time`. No 3-D boxes or re-identification across
//! sequences. motmetrics' Matlab offset (bb_left/top − 1 on load) is not applied: it cannot
//! change an IoU. Nothing here opens files: the CSV functions take and return text.

pub use crate::assign;
mod clear;
mod error;
mod hota;
mod identity;
mod moda;
mod motchallenge;
mod sequence;

pub use clear::{ClearMot, Event, EventKind};
pub use error::{MotError, Side};
pub use hota::{HOTA_ALPHAS, Hota, HotaAtAlpha, hota_alpha};
pub use identity::IdMetrics;
pub use moda::{Moda, PointFrame, moda_modp};
pub use motchallenge::{parse_motchallenge, write_motchallenge};
pub use sequence::Sequence;
pub(crate) use sequence::{AllowedFrame, AllowedFrames, Pair};

/// An axis-aligned image box in pixels: top-left corner, width and height.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct BoxPx {
    pub left_px: f64,
    pub top_px: f64,
    pub width_px: f64,
    pub height_px: f64,
}

/// A position on the ground plane in metres.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct GroundPoint {
    pub x_m: f64,
    pub y_m: f64,
}

/// Where an observed object is.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Geometry {
    Box(BoxPx),
    Point(GroundPoint),
}

/// Which kind of [`Geometry`] a file holds or a rule needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GeometryKind {
    Box,
    Point,
}

impl Geometry {
    pub fn kind(&self) -> GeometryKind {
        match self {
            Geometry::Box(_) => GeometryKind::Box,
            Geometry::Point(_) => GeometryKind::Point,
        }
    }

    fn is_finite(&self) -> bool {
        match self {
            Geometry::Box(b) => [b.left_px, b.top_px, b.width_px, b.height_px]
                .iter()
                .all(|v| v.is_finite()),
            Geometry::Point(p) => p.x_m.is_finite() && p.y_m.is_finite(),
        }
    }
}

impl GeometryKind {
    fn name(self) -> &'static str {
        match self {
            GeometryKind::Box => "a box",
            GeometryKind::Point => "a ground-plane point",
        }
    }
}

/// One object (ground truth) or hypothesis in one frame.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Observation {
    pub frame: i64,
    pub id: i64,
    pub geometry: Geometry,
    /// Detector or tracker confidence as written in the file (ground truth: usually 1);
    /// carried through, never used to filter.
    pub confidence: f64,
}

/// When a ground-truth object and a hypothesis may be matched, and their distance.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[serde(tag = "rule", rename_all = "snake_case")]
pub enum MatchRule {
    /// Boxes: distance 1 − IoU; allowed when IoU ≥ `min_iou` (MOTChallenge: 0.5).
    Iou { min_iou: f64 },
    /// Ground-plane points: distance in metres; allowed when ≤ `max_m`.
    Euclidean { max_m: f64 },
}

impl MatchRule {
    /// The geometry the rule compares.
    pub fn geometry(&self) -> GeometryKind {
        match self {
            MatchRule::Iou { .. } => GeometryKind::Box,
            MatchRule::Euclidean { .. } => GeometryKind::Point,
        }
    }

    fn name(&self) -> &'static str {
        match self {
            MatchRule::Iou { .. } => "IoU",
            MatchRule::Euclidean { .. } => "Euclidean",
        }
    }

    /// 1 − min_iou for boxes, max_m² for points (see [`pair`]).
    fn max_dist(&self) -> f64 {
        match *self {
            MatchRule::Iou { min_iou } => 1.0 - min_iou,
            MatchRule::Euclidean { max_m } => max_m * max_m,
        }
    }

    fn validate(&self) -> Result<(), MotError> {
        match *self {
            MatchRule::Iou { min_iou } if !(0.0..=1.0).contains(&min_iou) => {
                Err(MotError::BadThreshold {
                    rule: "IoU",
                    value: min_iou,
                    allowed: "0 ≤ min_iou ≤ 1",
                })
            }
            MatchRule::Euclidean { max_m } if !(max_m.is_finite() && max_m > 0.0) => {
                Err(MotError::BadThreshold {
                    rule: "Euclidean",
                    value: max_m,
                    allowed: "a finite distance > 0 m",
                })
            }
            _ => Ok(()),
        }
    }
}

/// Intersection over union of two boxes, 0 when they do not overlap (py-motmetrics
/// `distances.boxiou`; negative sizes count as empty).
pub fn iou(a: &BoxPx, b: &BoxPx) -> f64 {
    let (a_right, a_bottom) = (a.left_px + a.width_px, a.top_px + a.height_px);
    let (b_right, b_bottom) = (b.left_px + b.width_px, b.top_px + b.height_px);
    let inter_w = (a_right.min(b_right) - a.left_px.max(b.left_px)).max(0.0);
    let inter_h = (a_bottom.min(b_bottom) - a.top_px.max(b.top_px)).max(0.0);
    let inter = inter_w * inter_h;
    if inter == 0.0 {
        return 0.0;
    }
    let a_area = (a_right - a.left_px).max(0.0) * (a_bottom - a.top_px).max(0.0);
    let b_area = (b_right - b.left_px).max(0.0) * (b_bottom - b.top_px).max(0.0);
    inter / (a_area + b_area - inter)
}

/// One frame of a [`Sequence`]: dense object and hypothesis indices in input order, and the
/// row-major `gt × hyp` matrices of CLEAR distance (NaN = not allowed) and HOTA similarity.
/// The metrics see one frame at a time ([`Frames`]); a [`Sequence`] computes each frame's
/// matrices when it is visited and keeps only the observations, so memory grows with the
/// rows, not with the pairs (10⁶ rows of 100 people per frame held 2.2 GB of matrices).
#[derive(Debug, Clone, Default)]
pub(crate) struct Frame {
    pub frame: i64,
    pub gt: Vec<usize>,
    pub hyp: Vec<usize>,
    pub dist: Vec<f64>,
    pub sim: Vec<f64>,
}

/// Frames visited in ascending order, one at a time.
pub(crate) trait Frames {
    fn num_frames(&self) -> usize;
    fn each(&self, visit: &mut dyn FnMut(&Frame));
}

impl Frames for &[Frame] {
    fn num_frames(&self) -> usize {
        self.len()
    }

    fn each(&self, visit: &mut dyn FnMut(&Frame)) {
        self.iter().for_each(visit);
    }
}

/// All metrics of one sequence (or of several, combined with [`Metrics::overall`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Metrics {
    pub clear: ClearMot,
    pub identity: IdMetrics,
    pub hota: Hota,
}

/// Metrics plus the per-frame CLEAR MOT events behind them.
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluation {
    pub metrics: Metrics,
    pub events: Vec<Event>,
}

/// Score hypotheses against ground truth: every metric and the CLEAR MOT events.
pub fn evaluate(
    gt: &[Observation],
    hyp: &[Observation],
    rule: MatchRule,
) -> Result<Evaluation, MotError> {
    Ok(Sequence::new(gt, hyp, rule)?.evaluate())
}

impl Sequence {
    pub fn rule(&self) -> MatchRule {
        self.rule
    }

    /// Frames in which either side has an observation.
    pub fn num_frames(&self) -> usize {
        Frames::num_frames(self)
    }

    /// CLEAR MOT and its per-frame events.
    pub fn clear_mot(&self) -> (ClearMot, Vec<Event>) {
        clear::accumulate(self, &self.gt_ids, &self.hyp_ids, true)
    }

    /// IDF1, IDP, IDR.
    pub fn identity(&self) -> IdMetrics {
        identity::compute(self, self.gt_ids.len(), self.hyp_ids.len())
    }

    /// HOTA and its sub-metrics, per α and averaged.
    pub fn hota(&self) -> Hota {
        hota::compute(self, self.gt_ids.len(), self.hyp_ids.len())
    }

    /// Every metric, without collecting the CLEAR MOT events (for large inputs: the events
    /// take about as much memory as the rows).
    pub fn metrics(&self) -> Metrics {
        Metrics {
            clear: clear::accumulate(self, &self.gt_ids, &self.hyp_ids, false).0,
            identity: self.identity(),
            hota: self.hota(),
        }
    }

    /// Every metric and the CLEAR MOT events.
    pub fn evaluate(&self) -> Evaluation {
        let (clear, events) = self.clear_mot();
        Evaluation {
            metrics: Metrics {
                clear,
                identity: self.identity(),
                hota: self.hota(),
            },
            events,
        }
    }
}

impl Metrics {
    /// Several sequences combined: motmetrics' `OVERALL` row and TrackEval's
    /// `COMBINED_SEQ` (see the module doc). An empty slice gives the metrics of no data.
    pub fn overall(parts: &[Metrics]) -> Metrics {
        let clear: Vec<&ClearMot> = parts.iter().map(|m| &m.clear).collect();
        let identity: Vec<&IdMetrics> = parts.iter().map(|m| &m.identity).collect();
        let hota: Vec<&Hota> = parts.iter().map(|m| &m.hota).collect();
        Metrics {
            clear: ClearMot::merge(&clear),
            identity: IdMetrics::merge(&identity),
            hota: Hota::merge(&hota),
        }
    }
}

/// (CLEAR distance or NaN when not allowed, HOTA similarity) of one pair. `max_dist` is
/// 1 − min_iou for boxes and max_m² for points. (The metrics use the same formulas on
/// prepared geometry, in `sequence`; this is their reference.)
#[cfg(test)]
fn pair(g: &Geometry, h: &Geometry, rule: MatchRule, max_dist: f64) -> (f64, f64) {
    match (g, h, rule) {
        (Geometry::Box(a), Geometry::Box(b), MatchRule::Iou { .. }) => {
            let s = iou(a, b);
            let d = 1.0 - s;
            (if d > max_dist { f64::NAN } else { d }, s)
        }
        (Geometry::Point(a), Geometry::Point(b), MatchRule::Euclidean { max_m }) => {
            let (dx, dy) = (a.x_m - b.x_m, a.y_m - b.y_m);
            let d2 = dx * dx + dy * dy;
            let d = d2.sqrt();
            let s = (1.0 - d / (2.0 * max_m)).max(0.0);
            (if d2 > max_dist { f64::NAN } else { d }, s)
        }
        // `intern` has checked every geometry against the rule.
        _ => (f64::NAN, 0.0),
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub fn bx(frame: i64, id: i64, l: f64, t: f64, w: f64, h: f64) -> Observation {
        Observation {
            frame,
            id,
            geometry: Geometry::Box(BoxPx {
                left_px: l,
                top_px: t,
                width_px: w,
                height_px: h,
            }),
            confidence: 1.0,
        }
    }

    pub fn pt(frame: i64, id: i64, x: f64, y: f64) -> Observation {
        Observation {
            frame,
            id,
            geometry: Geometry::Point(GroundPoint { x_m: x, y_m: y }),
            confidence: 1.0,
        }
    }

    fn b(l: f64, t: f64, w: f64, h: f64) -> BoxPx {
        BoxPx {
            left_px: l,
            top_px: t,
            width_px: w,
            height_px: h,
        }
    }

    #[test]
    fn iou_known_values() {
        let check = |a: BoxPx, c: BoxPx, want: f64| {
            let got = iou(&a, &c);
            assert!((got - want).abs() < 1e-15, "{a:?} {c:?}: {got} != {want}");
            assert_eq!(got, iou(&c, &a), "symmetric");
        };
        check(b(0.0, 0.0, 10.0, 10.0), b(0.0, 0.0, 10.0, 10.0), 1.0);
        check(b(0.0, 0.0, 10.0, 10.0), b(10.0, 0.0, 10.0, 10.0), 0.0); // touching edges
        check(b(0.0, 0.0, 10.0, 10.0), b(20.0, 20.0, 5.0, 5.0), 0.0);
        check(
            b(0.0, 0.0, 10.0, 10.0),
            b(5.0, 0.0, 10.0, 10.0),
            50.0 / 150.0,
        );
        check(b(0.0, 0.0, 10.0, 10.0), b(2.0, 2.0, 5.0, 5.0), 25.0 / 100.0); // inside
        check(b(0.0, 0.0, 2.0, 2.0), b(1.0, 1.0, 2.0, 2.0), 1.0 / 7.0);
        check(b(0.0, 0.0, 0.0, 10.0), b(0.0, 0.0, 10.0, 10.0), 0.0); // empty box
        check(b(0.0, 0.0, -5.0, 10.0), b(-5.0, 0.0, 10.0, 10.0), 0.0); // negative size
    }

    #[test]
    fn iou_exactly_at_the_threshold_matches() {
        // IoU = 50 / 100 = 0.5 exactly: motmetrics forbids only 1 − IoU > 0.5.
        let gt = [bx(1, 1, 0.0, 0.0, 10.0, 10.0)];
        let hyp = [bx(1, 7, 0.0, 0.0, 10.0, 5.0)];
        let (c, ev) = Sequence::new(&gt, &hyp, MatchRule::Iou { min_iou: 0.5 })
            .expect("valid test input")
            .clear_mot();
        assert_eq!((c.num_matches, c.num_misses), (1, 0));
        assert_eq!(ev[0].distance, Some(0.5));
        // ... and just below it does not.
        let hyp = [bx(1, 7, 0.0, 0.0, 10.0, 4.999)];
        let (c, _) = Sequence::new(&gt, &hyp, MatchRule::Iou { min_iou: 0.5 })
            .expect("valid test input")
            .clear_mot();
        assert_eq!(
            (c.num_matches, c.num_misses, c.num_false_positives),
            (0, 1, 1)
        );
    }

    #[test]
    fn euclidean_matching_gates_at_max_m_and_reports_metres() {
        let rule = MatchRule::Euclidean { max_m: 0.75 };
        let gt = [pt(1, 1, 0.0, 0.0), pt(1, 2, 5.0, 0.0), pt(2, 1, 0.0, 0.0)];
        // frame 1: h10 0.5 m from g1 (matches), h11 0.8 m from g2 (too far: miss + FP);
        // frame 2: h10 exactly 0.75 m from g1 (at the gate: matches).
        let hyp = [
            pt(1, 10, 0.3, 0.4),
            pt(1, 11, 5.8, 0.0),
            pt(2, 10, 0.0, 0.75),
        ];
        let e = evaluate(&gt, &hyp, rule).expect("valid test input");
        let c = &e.metrics.clear;
        assert_eq!(
            (c.num_matches, c.num_misses, c.num_false_positives),
            (2, 1, 1)
        );
        assert!((c.motp - (0.5 + 0.75) / 2.0).abs() < 1e-12, "{}", c.motp);
        assert!((c.mota - (1.0 - 2.0 / 3.0)).abs() < 1e-12);
        // IDF1: g1-h10 share 2 frames; 2·2 / (3 + 3).
        assert!((e.metrics.identity.idf1 - 4.0 / 6.0).abs() < 1e-12);
        // HOTA similarity 1 − d / (2 · 0.75): 0.5 m → 2/3, 0.8 m → 7/15.
        let s = |d: f64| 1.0 - d / 1.5;
        let seq = Sequence::new(&gt, &hyp, rule).expect("valid test input");
        let mut first = None;
        seq.each(&mut |f| {
            first.get_or_insert_with(|| f.sim.clone());
        });
        let f1 = first.expect("a frame");
        assert!((f1[0] - s(0.5)).abs() < 1e-12 && (f1[3] - s(0.8)).abs() < 1e-12);
    }

    #[test]
    fn euclidean_rule_in_three_frames_with_a_crossing() {
        // Two people cross; the tracker keeps its ids on the right people: no switch even
        // though at frame 2 both hypotheses are within 0.75 m of both people.
        let rule = MatchRule::Euclidean { max_m: 0.75 };
        let gt = [
            pt(1, 1, 0.0, 0.0),
            pt(1, 2, 1.0, 0.0),
            pt(2, 1, 0.4, 0.0),
            pt(2, 2, 0.6, 0.0),
            pt(3, 1, 1.0, 0.0),
            pt(3, 2, 0.0, 0.0),
        ];
        let hyp = [
            pt(1, 5, 0.05, 0.0),
            pt(1, 6, 1.05, 0.0),
            pt(2, 5, 0.65, 0.0), // closer to g2, but continuity keeps g1-h5
            pt(2, 6, 0.35, 0.0),
            pt(3, 5, 1.0, 0.1),
            pt(3, 6, 0.0, 0.1),
        ];
        let e = evaluate(&gt, &hyp, rule).expect("valid test input");
        assert_eq!(e.metrics.clear.num_switches, 0);
        assert_eq!(e.metrics.clear.num_matches, 6);
        assert_eq!(e.metrics.identity.idf1, 1.0);
    }

    #[test]
    fn bad_input_is_an_error_not_a_panic() {
        let iou5 = MatchRule::Iou { min_iou: 0.5 };
        let g = [bx(1, 1, 0.0, 0.0, 1.0, 1.0), bx(1, 1, 2.0, 0.0, 1.0, 1.0)];
        assert!(matches!(
            Sequence::new(&g, &[], iou5),
            Err(MotError::DuplicateId {
                side: Side::GroundTruth,
                frame: 1,
                id: 1
            })
        ));
        let h = [bx(1, 1, f64::NAN, 0.0, 1.0, 1.0)];
        assert!(matches!(
            Sequence::new(&[], &h, iou5),
            Err(MotError::NonFinite {
                side: Side::Hypothesis,
                ..
            })
        ));
        let p = [pt(1, 1, 0.0, 0.0)];
        let err = Sequence::new(&p, &[], iou5).expect_err("must fail");
        assert!(err.to_string().contains("needs a box"), "{err}");
        for bad in [
            MatchRule::Iou { min_iou: 1.5 },
            MatchRule::Iou { min_iou: f64::NAN },
            MatchRule::Euclidean { max_m: 0.0 },
            MatchRule::Euclidean {
                max_m: f64::INFINITY,
            },
        ] {
            assert!(matches!(
                Sequence::new(&[], &[], bad),
                Err(MotError::BadThreshold { .. })
            ));
        }
    }

    #[test]
    fn empty_inputs_give_defined_counts() {
        let e = evaluate(&[], &[], MatchRule::Iou { min_iou: 0.5 }).expect("valid test input");
        assert_eq!(e.metrics.clear.num_frames, 0);
        assert!(e.metrics.clear.mota.is_nan());
        assert!(e.events.is_empty());
        let h = [bx(1, 1, 0.0, 0.0, 1.0, 1.0)];
        let e = evaluate(&[], &h, MatchRule::Iou { min_iou: 0.5 }).expect("valid test input");
        assert_eq!(e.metrics.clear.num_false_positives, 1);
        assert_eq!(e.metrics.identity.idfp, 1);
        assert_eq!(e.metrics.hota.hota, 0.0);
    }
}

//! CLEAR MOT accumulation, frame by frame, as py-motmetrics 1.4.0 `MOTAccumulator.update`
//! (with `max_switch_time = ∞`) and the counts of `metrics.py`.

use super::{AllowedFrame, AllowedFrames, Pair};
use crate::assign::Assigner;

/// An object is mostly tracked when matched in at least this share of its frames (Li et al.,
/// CVPR 2009; motmetrics `mostly_tracked`).
pub const MOSTLY_TRACKED_MIN: f64 = 0.8;
/// An object is mostly lost when matched in less than this share of its frames.
pub const MOSTLY_LOST_BELOW: f64 = 0.2;

/// What happened to one object or hypothesis in one frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "SCREAMING_SNAKE_CASE")]
pub enum EventKind {
    /// Object and hypothesis matched, continuing the object's previous pairing (or its first).
    Match,
    /// Matched, but the object was last matched to a different hypothesis (an ID switch).
    Switch,
    /// Object with no hypothesis (false negative).
    Miss,
    /// Hypothesis with no object (false positive).
    #[serde(rename = "FP")]
    FalsePositive,
}

/// One CLEAR MOT decision: motmetrics' accumulator event (`FrameId, Type, OId, HId, D`).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Event {
    pub frame: i64,
    pub kind: EventKind,
    /// Ground-truth id; `None` for a false positive.
    pub gt_id: Option<i64>,
    /// Hypothesis id; `None` for a miss.
    pub hyp_id: Option<i64>,
    /// Distance of a match or switch (1 − IoU, or metres); `None` otherwise.
    pub distance: Option<f64>,
}

/// CLEAR MOT counts and scores, named as in py-motmetrics. Ratios are NaN where their
/// denominator is zero (motmetrics' `quiet_divide`).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ClearMot {
    /// Frames in which the ground truth or the hypotheses have an observation.
    pub num_frames: u64,
    /// Ground-truth observations (GT in MOTA's denominator).
    pub num_objects: u64,
    /// Hypothesis observations.
    pub num_predictions: u64,
    /// Distinct ground-truth ids.
    pub num_unique_objects: u64,
    /// Matches that are not switches.
    pub num_matches: u64,
    /// ID switches (IDSW).
    pub num_switches: u64,
    /// Matches whose hypothesis was last matched to another object.
    pub num_transfer: u64,
    /// Switches to a hypothesis never matched before.
    pub num_ascend: u64,
    /// Transfers to an object never matched before.
    pub num_migrate: u64,
    /// FP.
    pub num_false_positives: u64,
    /// FN.
    pub num_misses: u64,
    /// Matches plus switches (TP).
    pub num_detections: u64,
    /// Tracked → missed interruptions inside each object's tracked span (FM).
    pub num_fragmentations: u64,
    /// Objects matched in ≥ 80 % of their frames (MT).
    pub mostly_tracked: u64,
    /// Objects matched in 20 % to 80 % of their frames (PT).
    pub partially_tracked: u64,
    /// Objects matched in < 20 % of their frames (ML).
    pub mostly_lost: u64,
    /// Sum of the distances of all matches and switches.
    pub total_distance: f64,
    /// 1 − (FN + FP + IDSW) / GT.
    pub mota: f64,
    /// Mean distance over matches and switches (1 − IoU for boxes, metres for points).
    pub motp: f64,
    /// TP / GT.
    pub recall: f64,
    /// TP / (TP + FP).
    pub precision: f64,
}

impl ClearMot {
    /// Fill in the ratios from the counts.
    fn finish(mut self) -> Self {
        let d = self.num_detections as f64;
        self.mota = 1.0
            - (self.num_misses + self.num_switches + self.num_false_positives) as f64
                / self.num_objects as f64;
        self.motp = self.total_distance / d;
        self.recall = d / self.num_objects as f64;
        self.precision = d / (self.num_false_positives as f64 + d);
        self
    }

    /// motmetrics' `OVERALL`: counts summed (unique objects too, so ids are per sequence),
    /// MOTP weighted by detections, ratios from the sums.
    pub fn merge(parts: &[&ClearMot]) -> ClearMot {
        let sum = |f: fn(&ClearMot) -> u64| parts.iter().map(|p| f(p)).sum::<u64>();
        ClearMot {
            num_frames: sum(|c| c.num_frames),
            num_objects: sum(|c| c.num_objects),
            num_predictions: sum(|c| c.num_predictions),
            num_unique_objects: sum(|c| c.num_unique_objects),
            num_matches: sum(|c| c.num_matches),
            num_switches: sum(|c| c.num_switches),
            num_transfer: sum(|c| c.num_transfer),
            num_ascend: sum(|c| c.num_ascend),
            num_migrate: sum(|c| c.num_migrate),
            num_false_positives: sum(|c| c.num_false_positives),
            num_misses: sum(|c| c.num_misses),
            num_detections: sum(|c| c.num_detections),
            num_fragmentations: sum(|c| c.num_fragmentations),
            mostly_tracked: sum(|c| c.mostly_tracked),
            partially_tracked: sum(|c| c.partially_tracked),
            mostly_lost: sum(|c| c.mostly_lost),
            total_distance: parts.iter().map(|p| p.total_distance).sum(),
            mota: f64::NAN,
            motp: f64::NAN,
            recall: f64::NAN,
            precision: f64::NAN,
        }
        .finish()
    }
}

/// Per-object tallies for MT/PT/ML and fragmentations.
#[derive(Debug, Clone, Copy, Default)]
struct ObjectTally {
    frames: u64,
    tracked: u64,
    seen_tracked: bool,
    in_miss_run: bool,
    fragmentations: u64,
}

/// Run the accumulator over `frames` (ascending). `gt_ids` / `hyp_ids` map dense indices back
/// to the input ids for the events, which are collected only when `keep_events`.
pub(super) fn accumulate(
    frames: &dyn AllowedFrames,
    gt_ids: &[i64],
    hyp_ids: &[i64],
    keep_events: bool,
) -> (ClearMot, Vec<Event>) {
    // motmetrics state: `m` (object → its last hypothesis), `res_m` (hypothesis → its last
    // object), `last_match` and `hypHistory` (only whether an entry exists is ever read).
    let mut m: Vec<Option<u32>> = vec![None; gt_ids.len()];
    let mut res_m: Vec<Option<u32>> = vec![None; hyp_ids.len()];
    let mut ever_matched_gt = vec![false; gt_ids.len()];
    let mut ever_matched_hyp = vec![false; hyp_ids.len()];
    let mut tally = vec![ObjectTally::default(); gt_ids.len()];
    let mut events = Vec::new();
    let mut c = empty_counts(frames.num_frames() as u64);
    let mut gt_done = Vec::new();
    let mut hyp_done = Vec::new();
    let mut rest = Vec::new();
    let mut assigner = Assigner::default();
    let ids = (gt_ids, hyp_ids);
    frames.each_allowed(&mut |f| {
        let (ng, nh) = (f.gt.len(), f.hyp.len());
        gt_done.clear();
        gt_done.resize(ng, false);
        hyp_done.clear();
        hyp_done.resize(nh, false);
        // 1. Keep pairings from earlier frames that are still allowed (ids are unique in a
        //    frame, so the previous hypothesis is at most one allowed pair of the object).
        for p in f.pairs {
            let (i, j) = (p.i as usize, p.j as usize);
            let o = f.gt[i] as usize;
            if !gt_done[i] && !hyp_done[j] && m[o] == Some(f.hyp[j]) {
                gt_done[i] = true;
                hyp_done[j] = true;
                ever_matched_gt[o] = true;
                ever_matched_hyp[f.hyp[j] as usize] = true;
                record_match(f, p, EventKind::Match, ids, &mut c, &mut events);
            }
        }
        // 2. Optimal assignment of the rest.
        rest.clear();
        rest.extend(
            f.pairs
                .iter()
                .filter(|p| !gt_done[p.i as usize] && !hyp_done[p.j as usize])
                .map(|p| (p.i as usize, p.j as usize, p.dist)),
        );
        for &(i, j) in assigner.min_cost_max_pairs(ng, nh, &rest) {
            let (o, h) = (f.gt[i], f.hyp[j]);
            let switch = m[o as usize].is_some_and(|prev| prev != h);
            if switch && !ever_matched_hyp[h as usize] {
                c.num_ascend += 1;
            }
            if res_m[h as usize].is_some_and(|prev| prev != o) {
                if !ever_matched_gt[o as usize] {
                    c.num_migrate += 1;
                }
                c.num_transfer += 1;
            }
            ever_matched_hyp[h as usize] = true;
            ever_matched_gt[o as usize] = true;
            let kind = if switch {
                EventKind::Switch
            } else {
                EventKind::Match
            };
            let dist = rest
                .iter()
                .find(|e| (e.0, e.1) == (i, j))
                .map_or(f64::NAN, |e| e.2);
            let p = Pair {
                i: i as u32,
                j: j as u32,
                dist,
            };
            record_match(f, &p, kind, ids, &mut c, &mut events);
            gt_done[i] = true;
            hyp_done[j] = true;
            m[o as usize] = Some(h);
            res_m[h as usize] = Some(o);
        }
        // 3. Unmatched objects are missed; 4. unmatched hypotheses are false positives.
        for i in (0..ng).filter(|&i| !gt_done[i]) {
            if keep_events {
                events.push(Event {
                    frame: f.frame,
                    kind: EventKind::Miss,
                    gt_id: Some(gt_ids[f.gt[i] as usize]),
                    hyp_id: None,
                    distance: None,
                });
            }
            c.num_misses += 1;
        }
        for j in (0..nh).filter(|&j| !hyp_done[j]) {
            if keep_events {
                events.push(Event {
                    frame: f.frame,
                    kind: EventKind::FalsePositive,
                    gt_id: None,
                    hyp_id: Some(hyp_ids[f.hyp[j] as usize]),
                    distance: None,
                });
            }
            c.num_false_positives += 1;
        }
        for (i, &o) in f.gt.iter().enumerate() {
            let t = &mut tally[o as usize];
            t.frames += 1;
            if gt_done[i] {
                t.tracked += 1;
                if t.in_miss_run {
                    t.fragmentations += 1;
                }
                t.seen_tracked = true;
                t.in_miss_run = false;
            } else if t.seen_tracked {
                t.in_miss_run = true;
            }
        }
        c.num_objects += ng as u64;
        c.num_predictions += nh as u64;
        if !keep_events {
            events.clear();
        }
    });
    count_objects(&tally, &mut c);
    c.num_detections = c.num_matches + c.num_switches;
    (c.finish(), events)
}

/// Every count zero and every ratio NaN, for `num_frames` frames.
fn empty_counts(num_frames: u64) -> ClearMot {
    ClearMot {
        num_frames,
        num_objects: 0,
        num_predictions: 0,
        num_unique_objects: 0,
        num_matches: 0,
        num_switches: 0,
        num_transfer: 0,
        num_ascend: 0,
        num_migrate: 0,
        num_false_positives: 0,
        num_misses: 0,
        num_detections: 0,
        num_fragmentations: 0,
        mostly_tracked: 0,
        partially_tracked: 0,
        mostly_lost: 0,
        total_distance: 0.0,
        mota: f64::NAN,
        motp: f64::NAN,
        recall: f64::NAN,
        precision: f64::NAN,
    }
}

/// Per-object counts over the run: unique objects, fragmentations and the mostly tracked /
/// partially tracked / mostly lost classes.
fn count_objects(tally: &[ObjectTally], c: &mut ClearMot) {
    for t in tally.iter().filter(|t| t.frames > 0) {
        c.num_unique_objects += 1;
        c.num_fragmentations += t.fragmentations;
        let ratio = t.tracked as f64 / t.frames as f64;
        if ratio >= MOSTLY_TRACKED_MIN {
            c.mostly_tracked += 1;
        } else if ratio >= MOSTLY_LOST_BELOW {
            c.partially_tracked += 1;
        } else {
            c.mostly_lost += 1;
        }
    }
}

/// Append a MATCH or SWITCH event for an allowed pair of the frame and count it.
fn record_match(
    f: &AllowedFrame,
    p: &Pair,
    kind: EventKind,
    (gt_ids, hyp_ids): (&[i64], &[i64]),
    c: &mut ClearMot,
    events: &mut Vec<Event>,
) {
    events.push(Event {
        frame: f.frame,
        kind,
        gt_id: Some(gt_ids[f.gt[p.i as usize] as usize]),
        hyp_id: Some(hyp_ids[f.hyp[p.j as usize] as usize]),
        distance: Some(p.dist),
    });
    c.total_distance += p.dist;
    match kind {
        EventKind::Switch => c.num_switches += 1,
        _ => c.num_matches += 1,
    }
}

#[cfg(test)]
mod tests {
    use super::super::Frame;
    use super::*;

    const X: f64 = f64::NAN;

    /// A frame with ids equal to their dense indices and the given distance matrix.
    fn frame(frame: i64, gt: &[usize], hyp: &[usize], dist: &[&[f64]]) -> Frame {
        Frame {
            frame,
            gt: gt.to_vec(),
            hyp: hyp.to_vec(),
            dist: dist.iter().flat_map(|r| r.iter().copied()).collect(),
            sim: vec![0.0; gt.len() * hyp.len()],
        }
    }

    fn run(frames: &[Frame]) -> (ClearMot, Vec<Event>) {
        let ids: Vec<i64> = (0..10).collect();
        accumulate(&frames, &ids, &ids, true)
    }

    fn kinds(events: &[Event]) -> Vec<(i64, EventKind, Option<i64>, Option<i64>)> {
        events
            .iter()
            .map(|e| (e.frame, e.kind, e.gt_id, e.hyp_id))
            .collect()
    }

    /// py-motmetrics `tests/test_mot.py::test_events` and `test_metrics.py::test_mota_motp`
    /// (ids 1, 2 written here as 1, 2 with an unused 0).
    #[test]
    fn motmetrics_test_events_and_mota_motp() {
        use EventKind::*;
        let frames = [
            frame(0, &[], &[1, 2], &[]),
            frame(1, &[1, 2], &[], &[]),
            frame(2, &[1, 2], &[1, 2], &[&[1.0, 0.5], &[0.3, 1.0]]),
            frame(3, &[1, 2], &[1, 2], &[&[0.2, X], &[X, 0.1]]),
            // A better new pairing exists, but history wins.
            frame(4, &[1, 2], &[1, 2], &[&[5.0, 1.0], &[1.0, 5.0]]),
            frame(5, &[], &[], &[]),
        ];
        let (c, ev) = run(&frames);
        assert_eq!(
            kinds(&ev),
            vec![
                (0, FalsePositive, None, Some(1)),
                (0, FalsePositive, None, Some(2)),
                (1, Miss, Some(1), None),
                (1, Miss, Some(2), None),
                (2, Match, Some(1), Some(2)),
                (2, Match, Some(2), Some(1)),
                (3, Switch, Some(1), Some(1)),
                (3, Switch, Some(2), Some(2)),
                (4, Match, Some(1), Some(1)),
                (4, Match, Some(2), Some(2)),
            ]
        );
        assert_eq!(ev[4].distance, Some(0.5));
        assert_eq!(ev[8].distance, Some(5.0));
        assert_eq!(
            (c.num_matches, c.num_false_positives, c.num_misses),
            (4, 2, 2)
        );
        assert_eq!((c.num_switches, c.num_detections, c.num_objects), (2, 6, 8));
        assert_eq!((c.num_predictions, c.num_frames), (8, 6));
        assert!((c.mota - (1.0 - 6.0 / 8.0)).abs() < 1e-12);
        assert!((c.motp - 11.1 / 6.0).abs() < 1e-12);
        assert_eq!(c.num_transfer, 2);
    }

    /// py-motmetrics `tests/test_metrics.py::test_ids`: switches, transfers, ascend, migrate.
    #[test]
    fn motmetrics_test_ids() {
        let frames = [
            frame(0, &[], &[], &[]),
            frame(1, &[1, 2], &[1, 2], &[&[1.0, 0.0], &[0.0, 1.0]]),
            frame(2, &[1, 2], &[1, 2], &[&[0.4, X], &[X, 0.4]]),
            frame(3, &[1, 2], &[1, 2], &[&[0.0, 1.0], &[1.0, 0.0]]),
            frame(4, &[1, 2], &[2, 3], &[&[1.0, 0.0], &[0.4, 0.7]]),
            frame(5, &[1, 3], &[2, 3], &[&[1.0, 0.0], &[0.4, 0.7]]),
            frame(6, &[], &[], &[]),
        ];
        let (c, _) = run(&frames);
        assert_eq!(
            (c.num_matches, c.num_false_positives, c.num_misses),
            (7, 0, 0)
        );
        assert_eq!((c.num_switches, c.num_transfer), (3, 3));
        assert_eq!((c.num_ascend, c.num_migrate), (1, 1));
        assert_eq!(
            (c.num_detections, c.num_objects, c.num_predictions),
            (10, 10, 10)
        );
        assert!((c.mota - 0.7).abs() < 1e-12);
        assert!((c.motp - 0.16).abs() < 1e-12);
        assert_eq!(c.num_frames, 7);
    }

    #[test]
    fn fragmentations_count_interruptions_inside_the_tracked_span() {
        // Object 0 over 8 frames: miss, T, T, miss, miss, T, miss, T → two interruptions
        // (the leading miss is before the span). Object absent in a frame is no miss.
        let pattern = [false, true, true, false, false, true, false, true];
        let mut frames: Vec<Frame> = pattern
            .iter()
            .enumerate()
            .map(|(k, &hit)| {
                if hit {
                    frame(k as i64, &[0], &[0], &[&[0.1]])
                } else {
                    frame(k as i64, &[0], &[], &[])
                }
            })
            .collect();
        frames.push(frame(8, &[], &[0], &[]));
        frames.push(frame(9, &[0], &[0], &[&[0.1]]));
        let (c, _) = run(&frames);
        assert_eq!(c.num_fragmentations, 2);
        assert_eq!(c.num_misses, 4);
        // 5 of 9 frames tracked: partially tracked.
        assert_eq!(
            (c.mostly_tracked, c.partially_tracked, c.mostly_lost),
            (0, 1, 0)
        );
    }

    #[test]
    fn mostly_tracked_boundaries() {
        // Object 0 tracked 4 of 5 frames (0.8 → MT); object 1 1 of 5 (0.2 → PT);
        // object 2 0 of 5 (ML).
        let frames: Vec<Frame> = (0..5)
            .map(|k| {
                let h0 = k != 0;
                let h1 = k == 0;
                let mut hyp = Vec::new();
                if h0 {
                    hyp.push(0);
                }
                if h1 {
                    hyp.push(1);
                }
                let dist: Vec<Vec<f64>> = (0..3)
                    .map(|g| hyp.iter().map(|&h| if g == h { 0.2 } else { X }).collect())
                    .collect();
                let rows: Vec<&[f64]> = dist.iter().map(|r| r.as_slice()).collect();
                frame(k, &[0, 1, 2], &hyp, &rows)
            })
            .collect();
        let (c, _) = run(&frames);
        assert_eq!(
            (c.mostly_tracked, c.partially_tracked, c.mostly_lost),
            (1, 1, 1)
        );
        assert_eq!(c.num_unique_objects, 3);
    }

    #[test]
    fn merge_sums_counts_and_weights_motp() {
        let a = run(&[frame(0, &[0], &[0], &[&[0.2]])]).0;
        let b = run(&[frame(0, &[0, 1], &[0, 1], &[&[0.4, X], &[X, 0.6]])]).0;
        let m = ClearMot::merge(&[&a, &b]);
        assert_eq!(
            (m.num_detections, m.num_objects, m.num_unique_objects),
            (3, 3, 3)
        );
        assert!((m.motp - 0.4).abs() < 1e-12);
        assert_eq!(m.mota, 1.0);
    }
}

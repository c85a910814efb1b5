//! Why each false positive happened: the `fp_causes` table (per sequence × method), from the
//! CLEAR MOT events of the aggregation and the cached tracks and ground truth. Each false
//! positive (a hypothesis left unmatched on a scored scan) gets the first cause that applies:
//!
//! 1. `unannotated_scan`: the scan has no scored ground-truth row (on the real logs, a scan
//!    where nobody is annotated; the authors' rule counts every output there as false);
//! 2. `near_person`: a scored ground-truth person lies within [`NEAR_FACTOR`] × the match
//!    distance (a person's second track, or one pulled off the person);
//! 3. `static_track`: its track's positions in the fixed frame, over its whole life, fit in a
//!    box whose diagonal is under [`STATIC_EXTENT_M`] (a static leg-like object; on a log
//!    without odometry the fixed frame is the laser's, so an object counts as static only
//!    while the robot stands);
//! 4. `other`.
//!
//! Thresholds chosen a priori, not on the logs they describe.

use std::collections::BTreeMap;

use super::tables::{TrackRow, TruthRow};
use crate::table_row;

/// A ground-truth person within this many match distances makes a false positive `near_person`.
pub const NEAR_FACTOR: f64 = 2.0;

/// Largest diagonal (m) of a static track's fixed-frame bounding box: leg_tracker's 0.5 m a
/// person must travel before it is reported.
pub const STATIC_EXTENT_M: f64 = 0.5;

table_row! {
    /// One sequence × detector: `fp_causes`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct FpCauseRow {
        pub dataset: String,
        pub sequence: String,
        pub detector: String,
        pub false_positives: i64,
        pub unannotated_scan: i64,
        pub near_person: i64,
        pub static_track: i64,
        pub other: i64,
    }
}

/// The diagonal of each track's fixed-frame bounding box, by id.
fn extents(tracks: &[&TrackRow]) -> BTreeMap<i64, f64> {
    let mut boxes: BTreeMap<i64, [f64; 4]> = BTreeMap::new();
    for r in tracks {
        let b = boxes.entry(r.id).or_insert([
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ]);
        b[0] = b[0].min(r.world_x);
        b[1] = b[1].min(r.world_y);
        b[2] = b[2].max(r.world_x);
        b[3] = b[3].max(r.world_y);
    }
    boxes
        .into_iter()
        .map(|(id, b)| (id, (b[2] - b[0]).hypot(b[3] - b[1])))
        .collect()
}

/// The causes of `fps` (scan, hypothesis id) of `detector`; `truth` is the scored ground
/// truth (laser frame), `tracks` every track row of the session.
pub fn classify(
    row: FpCauseRow,
    fps: &[(i64, i64)],
    truth: &[&TruthRow],
    tracks: &[TrackRow],
    match_m: f64,
) -> FpCauseRow {
    let mine: Vec<&TrackRow> = tracks
        .iter()
        .filter(|t| t.detector == row.detector)
        .collect();
    let extent = extents(&mine);
    let at: BTreeMap<(i64, i64), &TrackRow> =
        mine.iter().map(|t| ((t.scan_idx, t.id), *t)).collect();
    let mut gt: BTreeMap<i64, Vec<&TruthRow>> = BTreeMap::new();
    for t in truth {
        gt.entry(t.scan_idx).or_default().push(t);
    }
    let mut out = FpCauseRow {
        false_positives: fps.len() as i64,
        ..row
    };
    for &(scan, id) in fps {
        let people = gt.get(&scan).map(Vec::as_slice).unwrap_or(&[]);
        let near = at.get(&(scan, id)).is_some_and(|h| {
            people
                .iter()
                .any(|g| (g.x - h.x).hypot(g.y - h.y) <= NEAR_FACTOR * match_m)
        });
        if people.is_empty() {
            out.unannotated_scan += 1;
        } else if near {
            out.near_person += 1;
        } else if extent.get(&id).is_some_and(|&e| e < STATIC_EXTENT_M) {
            out.static_track += 1;
        } else {
            out.other += 1;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn track(scan: i64, id: i64, x: f64, y: f64) -> TrackRow {
        TrackRow {
            detector: "legs".into(),
            scan_idx: scan,
            id,
            x,
            y,
            world_x: x,
            world_y: y,
        }
    }

    /// Four false positives, one per cause, in the order the causes are tried.
    #[test]
    fn each_false_positive_gets_the_first_cause_that_applies() {
        let tracks = vec![
            track(0, 1, 5.0, 5.0), // scan 0 has no ground truth
            track(1, 2, 1.2, 0.0), // 1.2 m from the person: near (≤ 1.5 m)
            track(1, 3, 4.0, 4.0), // static: never moves
            track(2, 3, 4.1, 4.0),
            track(1, 4, 8.0, 0.0), // moves 2 m: other
            track(2, 4, 8.0, 2.0),
            track(1, 9, 1.0, 1.0), // another detector's row is ignored
        ];
        let mut tracks = tracks;
        tracks[6].detector = "nearest".into();
        let truth = [TruthRow {
            scan_idx: 1,
            id: 7,
            x: 0.0,
            y: 0.0,
        }];
        let refs: Vec<&TruthRow> = truth.iter().collect();
        let row = FpCauseRow {
            dataset: "d".into(),
            sequence: "s".into(),
            detector: "legs".into(),
            false_positives: 0,
            unannotated_scan: 0,
            near_person: 0,
            static_track: 0,
            other: 0,
        };
        let got = classify(row, &[(0, 1), (1, 2), (1, 3), (1, 4)], &refs, &tracks, 0.75);
        assert_eq!(
            (
                got.false_positives,
                got.unannotated_scan,
                got.near_person,
                got.static_track,
                got.other
            ),
            (4, 1, 1, 1, 1)
        );
    }
}

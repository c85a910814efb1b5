//! `score` memory (issue 19, item 6): the metrics of a sequence hold memory in proportion to
//! its rows, not to the pairs of each frame. 10⁶ rows per side of 100 people per frame took
//! 2.15 GB (every frame's 100 × 100 distance and similarity matrices were kept for the whole
//! sequence, about 2 KB per row). Measured here with a counting global allocator (exact and
//! deterministic, unlike RSS): the peak heap of building a [`Sequence`] and computing every
//! metric, per row, with 100 people per frame stays within a small budget, and does not grow
//! with the number of people per frame.

use std::sync::atomic::Ordering::Relaxed;

use crate::support::counting_alloc::{CURRENT, PEAK};

use peopletrack::eval::mot::{BoxPx, Geometry, MatchRule, Observation, Sequence};

/// `people` side by side for `frames` frames; the hypothesis is the ground truth shifted by
/// 4 px (IoU 36/44 with 40 × 90 boxes), with its own ids.
fn sides(frames: i64, people: i64) -> (Vec<Observation>, Vec<Observation>) {
    let obs = |shift: f64, id0: i64| -> Vec<Observation> {
        (0..frames)
            .flat_map(|f| {
                (0..people).map(move |k| Observation {
                    frame: f,
                    id: id0 + k,
                    geometry: Geometry::Box(BoxPx {
                        left_px: 60.0 * k as f64 + shift,
                        top_px: 50.0,
                        width_px: 40.0,
                        height_px: 90.0,
                    }),
                    confidence: 1.0,
                })
            })
            .collect()
    };
    (obs(0.0, 1), obs(4.0, 1000))
}

/// Peak heap (bytes) of building the sequence and computing its metrics, above what was
/// allocated before; and the metrics' MOTA and IDF1.
fn peak_of_metrics(gt: &[Observation], hyp: &[Observation]) -> (usize, f64, f64) {
    let before = CURRENT.load(Relaxed);
    PEAK.store(before, Relaxed);
    let m = Sequence::new(gt, hyp, MatchRule::Iou { min_iou: 0.5 })
        .expect("valid input")
        .metrics();
    (PEAK.load(Relaxed) - before, m.clear.mota, m.identity.idf1)
}

#[test]
fn metrics_memory_grows_with_rows_not_with_pairs_per_frame() {
    let _alone = crate::support::counting_alloc::alone();
    // the same 20,000 rows per side, as 2,000 frames of 10 people and 200 frames of 100
    let mut per_row = Vec::new();
    for (frames, people) in [(2_000, 10), (200, 100)] {
        let (gt, hyp) = sides(frames, people);
        let rows = gt.len() + hyp.len();
        let (peak, mota, idf1) = peak_of_metrics(&gt, &hyp);
        // perfect tracking with other ids: every box matched, no switch
        assert_eq!((mota, idf1), (1.0, 1.0));
        per_row.push(peak as f64 / rows as f64);
    }
    eprintln!("peak heap per row (10, 100 people per frame): {per_row:?}");
    // Per row the sequence keeps a dense id and the geometry (48 bytes) and a sort index
    // (4 bytes), plus the id tables; a frame's matrices (100 × 100 × 16 bytes = 160 kB) are
    // built one at a time. Before the fix: about 1,000 bytes per row at 100 people per frame.
    for b in &per_row {
        assert!(*b < 100.0, "{b:.0} bytes per row ({per_row:?})");
    }
    assert!(
        per_row[1] < per_row[0] * 1.5 + 16.0,
        "100 people per frame cost more per row than 10: {per_row:?}"
    );
}

//! MEASURED: frames per second of the 3-D stage (`track::cylinders`) in the main run, from
//! the per-frame times each session recorded (each frame the fastest of 3 steps on tracker
//! clones): median and quartiles over all frames. Varies between runs and machines;
//! `tools/compare_out.py` leaves `timing_*` tables out.

use std::collections::BTreeMap;

use super::{median, percentile};
use crate::pipelines::s004_mohedano_multicam::scored::Scored;
use crate::report::Table;
use crate::report::rows::Rows;

crate::table_row! {
    /// The 3-D stage of one detector's main run.
    #[derive(Debug, Clone, PartialEq)]
    pub(crate) struct Timing3dSummaryRow {
        pub detector: String,
        pub association: String,
        pub cameras: i64,
        pub frames: i64,
        pub median_objects_2d: f64,
        pub median_ms: f64,
        pub q1_ms: f64,
        pub q3_ms: f64,
        pub frames_per_s: f64,
    }
}

/// `(detector, association, cameras)` → (milliseconds, 2-D objects) of every frame.
type Groups = BTreeMap<(String, String, i64), (Vec<f64>, Vec<f64>)>;

pub(super) fn table(s: &Scored) -> anyhow::Result<Table> {
    let mut groups = Groups::new();
    for r in s.data.iter().flat_map(|d| &d.timing) {
        let g = groups
            .entry((r.detector.clone(), r.association.clone(), r.cameras))
            .or_default();
        g.0.push(r.seconds * 1e3);
        g.1.push(r.objects_2d as f64);
    }
    let rows: Vec<Timing3dSummaryRow> = groups
        .into_iter()
        .map(|((detector, association, cameras), (ms, objs))| {
            let med = median(&ms).unwrap_or(f64::NAN);
            Timing3dSummaryRow {
                detector,
                association,
                cameras,
                frames: ms.len() as i64,
                median_objects_2d: median(&objs).unwrap_or(f64::NAN),
                median_ms: med,
                q1_ms: percentile(&ms, 0.25).unwrap_or(f64::NAN),
                q3_ms: percentile(&ms, 0.75).unwrap_or(f64::NAN),
                frames_per_s: 1e3 / med,
            }
        })
        .collect();
    Ok(Table::new(
        "timing_3d",
        "MEASURED: the 3-D stage (association, cylinders, Kalman filters) per frame, main run".to_string(),
        Timing3dSummaryRow::frame(&rows)?,
    )
    .with_note("MEASURED on this machine and build: each frame's time is the fastest of 3 steps on clones of the tracker; frames_per_s = 1000 / median_ms. The 2-D stages (detection, 2-D tracking) are not included."))
}

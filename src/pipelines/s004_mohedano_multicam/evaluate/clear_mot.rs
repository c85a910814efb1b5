//! CLEAR MOT, IDF1 and HOTA on the ground plane, per detector and matching threshold
//! (0.5 m and 1 m by default), for the configured selection rule and `N_app`.

use crate::eval::mot::Evaluation;
use crate::pipelines::s004_mohedano_multicam::Params;
use crate::pipelines::s004_mohedano_multicam::scored::{Key, Scored};
use crate::pipelines::s004_mohedano_multicam::session::{GT_BOXES, TEMPLATES};
use crate::report::Table;
use crate::report::rows::Rows;

mod rows {
    #![allow(non_snake_case)]
    crate::table_row! {
        /// One detector at one matching threshold.
        #[derive(Debug, Clone, PartialEq)]
        pub(crate) struct ClearMotRow {
            pub detector: String,
            pub match_m: f64,
            pub MOTA: f64,
            pub MOTP_m: f64,
            pub IDF1: f64,
            pub HOTA: f64,
            pub recall: f64,
            pub precision: f64,
            pub IDP: f64,
            pub GT: i64,
            pub FP: i64,
            pub FN: i64,
            pub IDSW: i64,
            pub frag: i64,
            pub MT: i64,
            pub ML: i64,
            pub people: i64,
            pub paper: String,
        }
    }
}
pub(crate) use rows::ClearMotRow;

/// One evaluation as a row (the paper gives no numbers: '—').
pub(crate) fn row(detector: &str, match_m: f64, e: &Evaluation) -> ClearMotRow {
    let (c, i, h) = (&e.metrics.clear, &e.metrics.identity, &e.metrics.hota);
    ClearMotRow {
        detector: detector.to_string(),
        match_m,
        MOTA: c.mota,
        MOTP_m: c.motp,
        IDF1: i.idf1,
        HOTA: h.hota,
        recall: c.recall,
        precision: c.precision,
        IDP: i.idp,
        GT: c.num_objects as i64,
        FP: c.num_false_positives as i64,
        FN: c.num_misses as i64,
        IDSW: c.num_switches as i64,
        frag: c.num_fragmentations as i64,
        MT: c.mostly_tracked as i64,
        ML: c.mostly_lost as i64,
        people: c.num_unique_objects as i64,
        paper: "—".to_string(),
    }
}

pub(super) fn table(s: &Scored, p: &Params) -> anyhow::Result<Table> {
    let mut rows = Vec::new();
    for det in &s.detectors() {
        let key: Key = (det.clone(), s.main.1.clone(), s.main.2);
        for &t in &s.thresholds {
            if let Some(e) = s.eval(&key, t) {
                rows.push(row(det, t, e));
            }
        }
    }
    let table = Table::new(
        "clear_mot",
        format!(
            "CLEAR MOT, IDF1 and HOTA on the ground plane ({} selection, N_app = {}, N_dis = {})",
            s.main.1, p.n_app, p.n_dis
        ),
        ClearMotRow::frame(&rows)?,
    )
    .with_precision("match_m", 1)
    .with_note("Ground truth: every person inside the room at every frame (also those seen by fewer than two cameras, which no triangulation can place). A hypothesis matches a person within match_m on the ground (motmetrics 'euc' rule); MOTP is the mean matched distance in metres.")
    .with_note("Paper: no CLEAR MOT, IDF1 or error numbers are given (§6 reports figures 5–6 and qualitative statements only), hence '—'.")
    .with_note(format!("Detectors: `{TEMPLATES}` = the paper's chain (Gabor background, templates, graph-matching 2-D tracks); `{GT_BOXES}` = the ground-truth visible boxes of the log through the same 2-D and 3-D stages (head: the box's top row on the image of the person's vertical, from the calibration; the top centre with box_head_on_axis = false); `log` = Detection2DArray topics."));
    let note = super::bootstrap_note(p);
    Ok(if note.is_empty() {
        table
    } else {
        table.with_note(note)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipelines::s004_mohedano_multicam::evaluate::testdata;

    #[test]
    fn one_row_per_detector_and_threshold_with_the_counts_of_the_evaluation() {
        let s = testdata::scored();
        let t = table(&s, &Params::default()).expect("table");
        let rows = ClearMotRow::read(&t.df).expect("rows");
        // gt_boxes then templates, each at 0.5 and 1 m; 10 person-frames. gt_boxes: 0.7 m
        // off in 2 frames (misses and false positives at 0.5 m, matches at 1 m); templates:
        // no track in the first 3 frames, then the same
        let got: Vec<(&str, f64, i64, i64, i64)> = rows
            .iter()
            .map(|r| (r.detector.as_str(), r.match_m, r.GT, r.FP, r.FN))
            .collect();
        assert_eq!(
            got,
            [
                ("gt_boxes", 0.5, 10, 2, 2),
                ("gt_boxes", 1.0, 10, 0, 0),
                ("templates", 0.5, 10, 2, 5),
                ("templates", 1.0, 10, 0, 3),
            ]
        );
        let mota: Vec<f64> = rows.iter().map(|r| r.MOTA).collect();
        for (m, want) in mota.iter().zip([0.6, 1.0, 0.3, 0.7]) {
            assert!((m - want).abs() < 1e-12, "{mota:?}");
        }
        assert_eq!(rows[0].paper, "—");
    }
}

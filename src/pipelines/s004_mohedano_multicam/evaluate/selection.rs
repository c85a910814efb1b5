//! The selection rule: combinations chosen by the corrected error E_c = E_m / 10^N_c (eq. 5)
//! or by E_m (eq. 4), at the configured `N_app`.

use super::{mean, renamed};
use crate::pipelines::s004_mohedano_multicam::scored::{Key, Scored};
use crate::report::Table;
use crate::report::rows::Rows;

mod rows {
    #![allow(non_snake_case)]
    crate::table_row! {
        /// One detector with one selection rule.
        #[derive(Debug, Clone, PartialEq)]
        pub(crate) struct SelectionRow {
            pub detector: String,
            pub selection: String,
            /// Renamed `MOTA_<smaller threshold>m` in the table.
            pub mota_lo: f64,
            /// Renamed `MOTA_<larger threshold>m`.
            pub mota_hi: f64,
            /// Renamed `IDF1_<larger threshold>m`.
            pub idf1_hi: f64,
            pub FP: i64,
            pub FN: i64,
            pub IDSW: i64,
            pub mean_cameras: f64,
            pub mean_E_m_px: f64,
        }
    }
}
pub(crate) use rows::SelectionRow;

/// The rules compared, in table order.
const RULES: [&str; 2] = ["E_c", "E_m"];

/// One row per detector and rule evaluated at both thresholds.
pub(crate) fn rows(s: &Scored) -> Vec<SelectionRow> {
    let (lo, hi) = (s.thresholds[0], s.t_max());
    let mut rows = Vec::new();
    for det in &s.detectors() {
        for sel in RULES {
            let key: Key = (det.clone(), sel.to_string(), s.main.2);
            let (Some(a), Some(b)) = (s.eval(&key, lo), s.eval(&key, hi)) else {
                continue;
            };
            let mut cams = Vec::new();
            let mut ems = Vec::new();
            for r in s.data.iter().flat_map(|d| d.rows(&key)) {
                if r.cameras > 0 {
                    cams.push(r.cameras as f64);
                }
                if let Some(e) = r.e_m_px {
                    ems.push(e);
                }
            }
            let c = &b.metrics.clear;
            rows.push(SelectionRow {
                detector: det.clone(),
                selection: sel.to_string(),
                mota_lo: a.metrics.clear.mota,
                mota_hi: c.mota,
                idf1_hi: b.metrics.identity.idf1,
                FP: c.num_false_positives as i64,
                FN: c.num_misses as i64,
                IDSW: c.num_switches as i64,
                mean_cameras: mean(&cams).unwrap_or(f64::NAN),
                mean_E_m_px: mean(&ems).unwrap_or(f64::NAN),
            });
        }
    }
    rows
}

/// The comparison line of each detector that has both rules.
pub(crate) fn summary_lines(rows: &[SelectionRow], hi: f64) -> Vec<String> {
    let mut detectors: Vec<&str> = rows.iter().map(|r| r.detector.as_str()).collect();
    detectors.dedup();
    let mut out = Vec::new();
    for det in detectors {
        let find = |sel: &str| {
            rows.iter()
                .find(|r| r.detector == det && r.selection == sel)
        };
        if let (Some(ec), Some(em)) = (find(RULES[0]), find(RULES[1])) {
            out.push(format!(
                "Selection by E_c vs E_m ({det}): MOTA {:.3} vs {:.3} at {hi} m, {:.2} vs {:.2} supporting cameras on average.",
                ec.mota_hi, em.mota_hi, ec.mean_cameras, em.mean_cameras
            ));
        }
    }
    out
}

pub(super) fn table(s: &Scored, summary: &mut Vec<String>) -> anyhow::Result<Table> {
    let (lo, hi) = (s.thresholds[0], s.t_max());
    let rows = rows(s);
    summary.extend(summary_lines(&rows, hi));
    let df = renamed(
        SelectionRow::frame(&rows)?,
        &[
            ("mota_lo", format!("MOTA_{lo}m")),
            ("mota_hi", format!("MOTA_{hi}m")),
            ("idf1_hi", format!("IDF1_{hi}m")),
        ],
    )?;
    Ok(Table::new(
        "selection_rule",
        format!("Choosing combinations by the corrected error E_c = E_m / 10^N_c (eq. 5) or by E_m (eq. 4), N_app = {}", s.main.2),
        df,
    )
    .with_precision("mean_cameras", 2)
    .with_precision("mean_E_m_px", 2)
    .with_note("Both rules see the same 2-D objects and thresholds; only the choice among valid combinations (new objects and updates) differs. FP/FN/IDSW at the larger threshold.")
    .with_note("Paper: E_c 'has proved a good trade-off between different numbers of cameras' (§5); no numbers."))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipelines::s004_mohedano_multicam::evaluate::testdata;

    #[test]
    fn the_two_rules_side_by_side_with_their_support() {
        let s = testdata::scored();
        let rows = rows(&s);
        // gt_boxes ran E_c only, templates both rules (testdata)
        let runs: Vec<(&str, &str)> = rows
            .iter()
            .map(|r| (r.detector.as_str(), r.selection.as_str()))
            .collect();
        assert_eq!(
            runs,
            [
                ("gt_boxes", "E_c"),
                ("templates", "E_c"),
                ("templates", "E_m")
            ]
        );
        let (ec, em) = (&rows[1], &rows[2]);
        assert_eq!(
            (ec.selection.as_str(), em.selection.as_str()),
            ("E_c", "E_m")
        );
        // E_c: the main run (first 3 frames missed, 2 frames 0.7 m off); E_m: every frame
        // 0.1 m off
        assert!((ec.mota_lo - 0.3).abs() < 1e-12 && (ec.mota_hi - 0.7).abs() < 1e-12);
        assert_eq!((ec.FP, ec.FN, ec.IDSW), (0, 3, 0));
        assert_eq!((em.mota_lo, em.mota_hi, em.FN), (1.0, 1.0, 0));
        assert_eq!((ec.mean_cameras, em.mean_cameras), (3.0, 2.0));
        assert_eq!((ec.mean_E_m_px, em.mean_E_m_px), (2.0, 1.0));
        // one line, for the detector with both rules
        assert_eq!(
            summary_lines(&rows, 1.0),
            [
                "Selection by E_c vs E_m (templates): MOTA 0.700 vs 1.000 at 1 m, 3.00 vs 2.00 supporting cameras on average."
            ]
        );
    }

    #[test]
    fn the_threshold_columns_are_named_after_the_thresholds() {
        let s = testdata::scored();
        let t = table(&s, &mut Vec::new()).expect("table");
        let names: Vec<String> =
            t.df.get_column_names()
                .iter()
                .map(|c| c.to_string())
                .collect();
        assert_eq!(names[2..5], ["MOTA_0.5m", "MOTA_1m", "IDF1_1m"]);
    }
}

//! MODA and MODP on the ground plane (`eval::mot::moda_modp`), the multi-view detection scores
//! the WILDTRACK literature reports beside CLEAR MOT: per detector and matching threshold, for
//! the configured selection rule and `N_app`, every reported cylinder of a frame against the
//! people in the room at that frame, without identities.

use std::collections::BTreeMap;

use crate::eval::mot::{Geometry, Observation, PointFrame, moda_modp};
use crate::pipelines::s004_mohedano_multicam::scored::{
    Key, Scored, hypothesis_observations, truth_observations,
};
use crate::report::Table;
use crate::report::rows::Rows;

mod rows {
    #![allow(non_snake_case)]
    crate::table_row! {
        /// One detector at one matching threshold.
        #[derive(Debug, Clone, PartialEq)]
        pub(crate) struct ModaRow {
            pub detector: String,
            pub match_m: f64,
            pub MODA: f64,
            pub MODP: f64,
            pub precision: f64,
            pub recall: f64,
            pub GT: i64,
            pub TP: i64,
            pub FP: i64,
            pub FN: i64,
        }
    }
}
pub(crate) use rows::ModaRow;

type Frames = BTreeMap<i64, PointFrame>;

fn by_frame(gt: &[Observation], hyp: &[Observation]) -> Vec<PointFrame> {
    let mut frames: Frames = BTreeMap::new();
    for (side, obs) in [(0, gt), (1, hyp)] {
        for o in obs {
            if let Geometry::Point(p) = &o.geometry {
                let f = frames.entry(o.frame).or_default();
                let v = if side == 0 { &mut f.0 } else { &mut f.1 };
                v.push([p.x_m, p.y_m]);
            }
        }
    }
    frames.into_values().collect()
}

pub(super) fn table(s: &Scored) -> anyhow::Result<Table> {
    let gt = truth_observations(&s.data);
    let mut rows = Vec::new();
    for det in &s.detectors() {
        let key: Key = (det.clone(), s.main.1.clone(), s.main.2);
        let frames = by_frame(&gt, &hypothesis_observations(&s.data, &key));
        for &t in &s.thresholds {
            let m = moda_modp(&frames, t);
            rows.push(ModaRow {
                detector: det.clone(),
                match_m: t,
                MODA: m.moda,
                MODP: m.modp,
                precision: m.precision,
                recall: m.recall,
                GT: m.gt as i64,
                TP: m.tp as i64,
                FP: m.fp as i64,
                FN: m.fn_ as i64,
            });
        }
    }
    Ok(Table::new(
        "moda",
        format!(
            "MODA and MODP on the ground plane ({} selection, N_app = {})",
            s.main.1, s.main.2
        ),
        ModaRow::frame(&rows)?,
    )
    .with_precision("match_m", 1)
    .with_note("Per frame, reported cylinders are matched to the people in the room within match_m (most pairs, then least total distance), without identities: MODA = 1 − (FN + FP) / GT, MODP = mean of (1 − d / match_m) over matches (Kasturi et al. 2009, as the WILDTRACK / POM literature computes them)."))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipelines::s004_mohedano_multicam::evaluate::testdata;

    #[test]
    fn counts_agree_with_clear_mot_when_there_are_no_switches() {
        // the test sessions have no identity switches, so per-frame detection counts equal
        // CLEAR MOT's (see clear_mot's test): gt_boxes 2 FP / 2 FN at 0.5 m, none at 1 m
        let s = testdata::scored();
        let t = table(&s).expect("table");
        let rows = ModaRow::read(&t.df).expect("rows");
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
        assert!((rows[0].MODA - 0.6).abs() < 1e-12 && (rows[1].MODA - 1.0).abs() < 1e-12);
    }
}

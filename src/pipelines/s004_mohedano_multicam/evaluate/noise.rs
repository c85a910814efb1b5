//! With `detector_noise`: the 3-D stage on the exact boxes passed through the detector model
//! at each level (`session::noise`), per association, scored with CLEAR MOT and IDF1 at the
//! first matching threshold on the development frames (before `split_frame`), the held-out
//! ones and all — the table of issue 32, part 2.

use anyhow::Context;
use rayon::prelude::*;

use crate::eval::mot::{MatchRule, evaluate};
use crate::pipelines::s004_mohedano_multicam::Params;
use crate::pipelines::s004_mohedano_multicam::scored::{
    Key, STRIDE, Scored, SessionData, truth_observations,
};
use crate::pipelines::s004_mohedano_multicam::session::{association_label, told};
use crate::report::Table;
use crate::report::rows::Rows;

mod rows {
    #![allow(non_snake_case)]
    crate::table_row! {
        /// One noise level, one association, one part of the frames.
        #[derive(Debug, Clone, PartialEq)]
        pub(crate) struct NoiseRow {
            pub noise: String,
            pub association: String,
            pub frames: String,
            pub MOTA: f64,
            pub MOTP_m: f64,
            pub IDF1: f64,
            pub recall: f64,
            pub precision: f64,
            pub GT: i64,
            pub FP: i64,
            pub FN: i64,
            pub IDSW: i64,
            pub tracks: i64,
            /// Boxes after the detector model (all frames), and before it.
            pub boxes: i64,
            pub clean_boxes: i64,
        }
    }
}
pub(crate) use rows::NoiseRow;

/// The noise run `(level, association)` of every session, offset per session.
fn observations(data: &[SessionData], key: &Key) -> Vec<crate::eval::mot::Observation> {
    let mut out = Vec::new();
    for (s, d) in data.iter().enumerate() {
        let o = s as i64 * STRIDE;
        for t in d
            .noise_tracks
            .iter()
            .filter(|r| r.detector == key.0 && r.selection == key.1)
        {
            out.push(crate::eval::mot::Observation {
                frame: o + t.frame,
                id: o + t.id,
                geometry: crate::eval::mot::Geometry::Point(crate::eval::mot::GroundPoint {
                    x_m: t.x_m,
                    y_m: t.y_m,
                }),
                confidence: 1.0,
            });
        }
    }
    out
}

/// The parts of the frames: `(label, first, end)`.
fn parts(p: &Params) -> Vec<(String, i64, i64)> {
    let mut out = Vec::new();
    if p.split_frame > 0 {
        out.push((format!("0–{}", p.split_frame - 1), 0, p.split_frame));
        out.push((format!("{}–", p.split_frame), p.split_frame, STRIDE));
    }
    out.push(("all".to_string(), 0, STRIDE));
    out
}

/// One noise run as `table` lists them: the level's index and name, the association, and the level's key columns.
type NoiseJob = (usize, String, String, (String, i64, i64));

pub(super) fn table(s: &Scored, p: &Params) -> anyhow::Result<Table> {
    let t = s.thresholds[0];
    let gt_all = truth_observations(&s.data);
    let jobs: Vec<NoiseJob> = p
        .detector_noise
        .iter()
        .enumerate()
        .flat_map(|(k, n)| {
            p.noise_associations.iter().flat_map(move |&a| {
                parts(p)
                    .into_iter()
                    .map(move |part| (k, n.label(), association_label(a), part))
            })
        })
        .collect();
    let rows: Vec<anyhow::Result<NoiseRow>> = jobs
        .par_iter()
        .map(|(_, noise, assoc, (label, lo, hi))| {
            let keep = |f: i64| (lo..hi).contains(&&(f % STRIDE));
            let key: Key = (noise.clone(), assoc.clone(), i64::from(p.n_app));
            let gt: Vec<_> = gt_all.iter().filter(|o| keep(o.frame)).cloned().collect();
            let hyp: Vec<_> = observations(&s.data, &key)
                .into_iter()
                .filter(|o| keep(o.frame))
                .collect();
            let e = evaluate(&gt, &hyp, MatchRule::Euclidean { max_m: t })
                .with_context(|| format!("scoring noise {noise} ({assoc}) on frames {label}"))?;
            let c = &e.metrics.clear;
            let mut ids: Vec<i64> = hyp.iter().map(|o| o.id).collect();
            ids.sort_unstable();
            ids.dedup();
            let count =
                |f: fn(&crate::pipelines::s004_mohedano_multicam::tables::NoiseBoxRow) -> i64| {
                    s.data
                        .iter()
                        .flat_map(|d| &d.noise_boxes)
                        .filter(|b| &b.noise == noise)
                        .map(f)
                        .sum::<i64>()
                };
            Ok(NoiseRow {
                noise: noise.clone(),
                association: assoc.clone(),
                frames: label.clone(),
                MOTA: c.mota,
                MOTP_m: c.motp,
                IDF1: e.metrics.identity.idf1,
                recall: c.recall,
                precision: c.precision,
                GT: c.num_objects as i64,
                FP: c.num_false_positives as i64,
                FN: c.num_misses as i64,
                IDSW: c.num_switches as i64,
                tracks: ids.len() as i64,
                boxes: count(|b| b.noisy),
                clean_boxes: count(|b| b.clean),
            })
        })
        .collect();
    let rows = rows.into_iter().collect::<anyhow::Result<Vec<_>>>()?;
    let o = &p.occupancy;
    let told_note = p
        .detector_noise
        .iter()
        .map(|n| {
            let m = told(o, n);
            format!(
                "{}: P_D {:.3}, jitter {:.3}, λ {:.3}",
                n.label(),
                m.p_detect,
                m.jitter,
                m.false_per_frame
            )
        })
        .collect::<Vec<_>>()
        .join("; ");
    Ok(Table::new(
        "detector_noise",
        format!("The 3-D stage on the exact boxes through the detector model (seed {}): CLEAR MOT and IDF1 at {t} m", p.noise_seed),
        NoiseRow::frame(&rows)?,
    )
    .with_note("noise: the detector model's levels (log::import::detector_noise): drop = probability a box is missed; jitter = σ of each edge as a fraction of the box height; false = mean false person-shaped boxes per camera frame (Poisson), standing in the room where the camera sees them whole. The exact boxes are the log's detections (detector = \"log\") or the ground-truth boxes. boxes / clean_boxes: after and before the model, all frames.")
    .with_note(format!("occupancy is told each level's detector (P_D × (1 − drop), jitters added in quadrature, false boxes added to the configured model): {told_note}. ground ignores it (its p_Th stays)."))
    .with_note("Frames are numbered per session from 0; the development part (before split_frame) is where design values may be chosen, the held-out part is for reporting."))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_split_at_the_configured_frame() {
        let p = Params {
            split_frame: 200,
            ..Params::default()
        };
        let got = parts(&p);
        assert_eq!(got.len(), 3);
        assert_eq!((got[0].1, got[0].2), (0, 200));
        assert_eq!((got[1].1, got[1].2), (200, STRIDE));
        assert_eq!(parts(&Params::default()).len(), 1);
    }
}

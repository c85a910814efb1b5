//! With `decompose = true`: where the errors of the main run come from. `ghosts` splits each
//! run's reported cylinders (matched or not, per frame, without identities) by the number of
//! cameras supporting them and the annotated people (found or missed) by the number of
//! cameras that see them; `splits` scores the main run and the frame-by-frame run (the 3-D
//! association alone, `<detector>_per_frame`) on the frames before `split_frame` (a
//! development part), from it on (held out) and on all. All at the first matching threshold.

use std::collections::BTreeMap;

use anyhow::Context;

use crate::assign::min_cost_max_pairs;
use crate::eval::mot::{MatchRule, PointFrame, evaluate, moda_modp};
use crate::pipelines::s004_mohedano_multicam::Params;
use crate::pipelines::s004_mohedano_multicam::scored::{
    Key, STRIDE, Scored, hypothesis_observations, truth_observations,
};
use crate::report::Table;
use crate::report::rows::Rows;

mod rows {
    #![allow(non_snake_case)]
    crate::table_row! {
        /// Reported cylinders or annotated people with one number of cameras.
        #[derive(Debug, Clone, PartialEq)]
        pub(crate) struct GhostRow {
            pub detector: String,
            pub side: String,
            pub cameras: i64,
            pub count: i64,
            pub matched: i64,
            pub unmatched: i64,
        }
    }
    crate::table_row! {
        /// One run on one part of the frames.
        #[derive(Debug, Clone, PartialEq)]
        pub(crate) struct SplitRow {
            pub detector: String,
            pub frames: String,
            pub MOTA: f64,
            pub MOTP_m: f64,
            pub IDF1: f64,
            pub MODA: f64,
            pub MODP: f64,
            pub recall: f64,
            pub precision: f64,
            pub GT: i64,
            pub FP: i64,
            pub FN: i64,
            pub IDSW: i64,
            pub tracks: i64,
        }
    }
}
pub(crate) use rows::{GhostRow, SplitRow};

/// The main run and the frame-by-frame run, those present.
fn runs(s: &Scored) -> Vec<Key> {
    let per_frame = (
        format!("{}_per_frame", s.main.0),
        s.main.1.clone(),
        s.main.2,
    );
    [s.main.clone(), per_frame]
        .into_iter()
        .filter(|k| s.keys.contains(k))
        .collect()
}

/// `frame → (people (x, y, cameras), cylinders (x, y, cameras))` of one run.
type Frames = BTreeMap<i64, (Vec<[f64; 3]>, Vec<[f64; 3]>)>;

fn frames_of(s: &Scored, key: &Key) -> Frames {
    let mut out: Frames = BTreeMap::new();
    for (k, d) in s.data.iter().enumerate() {
        let o = k as i64 * STRIDE;
        for g in d.truth.iter().filter(|g| g.in_room) {
            let e = out.entry(o + g.frame).or_default();
            e.0.push([g.x_m, g.y_m, g.cameras_visible as f64]);
        }
        for t in d.rows(key) {
            let e = out.entry(o + t.frame).or_default();
            e.1.push([t.x_m, t.y_m, t.cameras as f64]);
        }
    }
    out
}

pub(super) fn ghosts(s: &Scored) -> anyhow::Result<Table> {
    let t = s.thresholds[0];
    let mut rows = Vec::new();
    for key in runs(s) {
        // (side, cameras) → (count, matched)
        let mut counts: BTreeMap<(&str, i64), (i64, i64)> = BTreeMap::new();
        for (g, h) in frames_of(s, &key).values() {
            let pairs = min_cost_max_pairs(g.len(), h.len(), |i, j| {
                let d = (g[i][0] - h[j][0]).hypot(g[i][1] - h[j][1]);
                if d <= t { d } else { f64::INFINITY }
            });
            let (mut gm, mut hm) = (vec![false; g.len()], vec![false; h.len()]);
            for (i, j) in pairs {
                gm[i] = true;
                hm[j] = true;
            }
            for (side, pts, m) in [("annotated", g, &gm), ("reported", h, &hm)] {
                for (p, &matched) in pts.iter().zip(m.iter()) {
                    let c = counts.entry((side, p[2] as i64)).or_default();
                    c.0 += 1;
                    c.1 += i64::from(matched);
                }
            }
        }
        for ((side, cameras), (count, matched)) in counts {
            rows.push(GhostRow {
                detector: key.0.clone(),
                side: side.to_string(),
                cameras,
                count,
                matched,
                unmatched: count - matched,
            });
        }
    }
    Ok(Table::new(
        "ghosts",
        format!("Reported cylinders and annotated people by number of cameras, matched within {t} m per frame"),
        GhostRow::frame(&rows)?,
    )
    .with_note("reported: cameras = the cylinder's supporting 2-D objects that frame (0: coasting); unmatched = false positives (ghosts). annotated: cameras = the cameras whose image holds the person's box; unmatched = misses. Matching as MODA: most pairs, then least total distance, no identities.")
    .with_note("`<detector>_per_frame`: the same association run on every frame with a fresh tracker (N_app = N_dis = 1): the 3-D association alone, without temporal tracking."))
}

pub(super) fn splits(s: &Scored, p: &Params) -> anyhow::Result<Table> {
    let t = s.thresholds[0];
    let gt_all = truth_observations(&s.data);
    let mut parts: Vec<(String, i64, i64)> = Vec::new();
    if p.split_frame > 0 {
        parts.push((format!("0–{}", p.split_frame - 1), 0, p.split_frame));
        parts.push((format!("{}–", p.split_frame), p.split_frame, STRIDE));
    }
    parts.push(("all".to_string(), 0, STRIDE));
    let mut rows = Vec::new();
    for key in runs(s) {
        let hyp_all = hypothesis_observations(&s.data, &key);
        for (label, lo, hi) in &parts {
            let keep = |f: i64| (lo..hi).contains(&&(f % STRIDE));
            let gt: Vec<_> = gt_all.iter().filter(|o| keep(o.frame)).cloned().collect();
            let hyp: Vec<_> = hyp_all.iter().filter(|o| keep(o.frame)).cloned().collect();
            let e = evaluate(&gt, &hyp, MatchRule::Euclidean { max_m: t })
                .with_context(|| format!("scoring {key:?} on frames {label}"))?;
            let points: Vec<PointFrame> = frames_of(s, &key)
                .into_iter()
                .filter(|(f, _)| keep(*f))
                .map(|(_, (g, h))| {
                    (
                        g.iter().map(|p| [p[0], p[1]]).collect(),
                        h.iter().map(|p| [p[0], p[1]]).collect(),
                    )
                })
                .collect();
            let m = moda_modp(&points, t);
            let c = &e.metrics.clear;
            let mut ids: Vec<i64> = hyp.iter().map(|o| o.id).collect();
            ids.sort_unstable();
            ids.dedup();
            rows.push(SplitRow {
                detector: key.0.clone(),
                frames: label.clone(),
                MOTA: c.mota,
                MOTP_m: c.motp,
                IDF1: e.metrics.identity.idf1,
                MODA: m.moda,
                MODP: m.modp,
                recall: c.recall,
                precision: c.precision,
                GT: c.num_objects as i64,
                FP: c.num_false_positives as i64,
                FN: c.num_misses as i64,
                IDSW: c.num_switches as i64,
                tracks: ids.len() as i64,
            });
        }
    }
    Ok(Table::new(
        "splits",
        format!("CLEAR MOT, IDF1, MODA and MODP at {t} m on parts of the frames (development frames before {}, held out from it)", p.split_frame),
        SplitRow::frame(&rows)?,
    )
    .with_note("Frames are numbered per session from 0. `<detector>_per_frame` has no temporal stage: its identities are new every frame, so only its MODA, MODP, FP and FN mean something."))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipelines::s004_mohedano_multicam::evaluate::testdata;

    #[test]
    fn ghosts_and_splits_count_what_clear_mot_counts() {
        // the main run of the test sessions (templates): 10 person-frames, no track in the
        // first 3 frames, 0.7 m off in 2 (clear_mot's test): 5 found, 5 missed, 2 ghosts
        let s = testdata::scored();
        let rows = GhostRow::read(&ghosts(&s).expect("ghosts").df).expect("rows");
        let sum = |side: &str| {
            rows.iter()
                .filter(|r| r.detector == "templates" && r.side == side)
                .fold((0, 0, 0), |a, r| {
                    (a.0 + r.count, a.1 + r.matched, a.2 + r.unmatched)
                })
        };
        assert_eq!(sum("annotated"), (10, 5, 5));
        assert_eq!(sum("reported"), (7, 5, 2));
        let p = Params {
            split_frame: 3,
            ..Params::default()
        };
        let rows = SplitRow::read(&splits(&s, &p).expect("splits").df).expect("rows");
        let got: Vec<(&str, &str, i64, i64, i64)> = rows
            .iter()
            .map(|r| (r.detector.as_str(), r.frames.as_str(), r.GT, r.FP, r.FN))
            .collect();
        // nothing reported before frame 3: every person there a miss
        let before = got[0];
        assert_eq!((before.0, before.1, before.3), ("templates", "0–2", 0));
        assert_eq!(before.2, before.4);
        let all = got.iter().find(|g| g.1 == "all").expect("all");
        assert_eq!((all.2, all.3, all.4), (10, 2, 5));
        assert_eq!(got[0].2 + got[1].2, 10);
        assert!((rows[2].MOTA - 0.3).abs() < 1e-12, "{rows:?}");
    }
}

//! 3-D ground-position, height and radius errors of the matched track-frames, per person and
//! over all people, per detector.

use std::collections::{BTreeMap, HashMap};

use super::{mean, median, percentile, std};
use crate::eval::mot::{Evaluation, EventKind};
use crate::pipelines::s004_mohedano_multicam::scored::{Key, STRIDE, Scored, SessionData};
use crate::report::Table;
use crate::report::rows::Rows;

crate::table_row! {
    /// One person's (or all people's) errors for one detector.
    #[derive(Debug, Clone, PartialEq)]
    pub(crate) struct PositionRow {
        pub detector: String,
        pub session: String,
        pub person: String,
        pub frames: i64,
        pub ground_error_m: Option<f64>,
        pub ground_error_std_m: Option<f64>,
        pub ground_error_p95_m: Option<f64>,
        pub height_error_m: Option<f64>,
        pub abs_height_error_m: Option<f64>,
        pub true_height_m: Option<f64>,
        pub radius_m: Option<f64>,
        pub true_radius_m: Option<f64>,
        pub paper: String,
    }
}

crate::table_row! {
    /// One matched person-frame.
    #[derive(Debug, Clone, PartialEq)]
    pub(crate) struct PositionSample {
        pub detector: String,
        pub session: String,
        pub frame: i64,
        pub person: i64,
        pub ground_error_m: f64,
        pub height_error_m: f64,
        pub radius_m: f64,
        pub true_radius_m: f64,
        pub t_s: f64,
    }
}

/// One matched person-frame with its session (index) and the truth's height.
pub(crate) struct Matched {
    pub session: usize,
    pub true_height_m: f64,
    pub sample: PositionSample,
}

/// Every matched person-frame of one evaluation, in event order.
pub(crate) fn matched(data: &[SessionData], det: &str, key: &Key, ev: &Evaluation) -> Vec<Matched> {
    // lookups: (global frame, global id) → row
    let mut hyp = HashMap::new();
    let mut gt = HashMap::new();
    for (si, d) in data.iter().enumerate() {
        let o = si as i64 * STRIDE;
        for r in d.rows(key) {
            hyp.insert((o + r.frame, o + r.id), r);
        }
        for g in &d.truth {
            gt.insert((o + g.frame, o + g.id), (si, g));
        }
    }
    let mut out = Vec::new();
    for e in &ev.events {
        if !matches!(e.kind, EventKind::Match | EventKind::Switch) {
            continue;
        }
        let (Some(g), Some(h)) = (e.gt_id, e.hyp_id) else {
            continue;
        };
        let (Some(&(si, g)), Some(t)) = (gt.get(&(e.frame, g)), hyp.get(&(e.frame, h))) else {
            continue;
        };
        out.push(Matched {
            session: si,
            true_height_m: g.height_m,
            sample: PositionSample {
                detector: det.to_string(),
                session: data[si].name.clone(),
                frame: g.frame,
                person: g.id,
                ground_error_m: (t.x_m - g.x_m).hypot(t.y_m - g.y_m),
                height_error_m: t.height_m - g.height_m,
                radius_m: t.radius_m,
                true_radius_m: g.radius_m,
                t_s: g.t_s,
            },
        });
    }
    out
}

/// The summary row of some matched person-frames.
pub(crate) fn summary_row(det: &str, session: &str, person: &str, v: &[&Matched]) -> PositionRow {
    let col = |f: fn(&Matched) -> f64| v.iter().map(|x| f(x)).collect::<Vec<f64>>();
    let g = col(|x| x.sample.ground_error_m);
    let h = col(|x| x.sample.height_error_m);
    PositionRow {
        detector: det.to_string(),
        session: session.to_string(),
        person: person.to_string(),
        frames: v.len() as i64,
        ground_error_m: mean(&g),
        ground_error_std_m: std(&g),
        ground_error_p95_m: percentile(&g, 0.95),
        height_error_m: mean(&h),
        abs_height_error_m: mean(&h.iter().map(|x| x.abs()).collect::<Vec<_>>()),
        true_height_m: mean(&col(|x| x.true_height_m)),
        radius_m: mean(&col(|x| x.sample.radius_m)),
        true_radius_m: mean(&col(|x| x.sample.true_radius_m)),
        paper: "—".to_string(),
    }
}

/// Per person (session order, then id) and over all people (last), for one detector.
pub(crate) fn rows(s: &Scored, det: &str, matched: &[Matched]) -> Vec<PositionRow> {
    let mut per: BTreeMap<(usize, i64), Vec<&Matched>> = BTreeMap::new();
    for m in matched {
        per.entry((m.session, m.sample.person)).or_default().push(m);
    }
    let mut rows = Vec::new();
    let mut all: Vec<&Matched> = Vec::new();
    for ((si, id), v) in &per {
        rows.push(summary_row(det, &s.data[*si].name, &id.to_string(), v));
        all.extend_from_slice(v);
    }
    rows.push(summary_row(det, "all", "all", &all));
    rows
}

pub(super) fn table(s: &Scored, summary: &mut Vec<String>) -> anyhow::Result<Table> {
    let t_match = s.t_max();
    let mut rows_all = Vec::new();
    let mut samples = Vec::new();
    for det in &s.detectors() {
        let key: Key = (det.clone(), s.main.1.clone(), s.main.2);
        let Some(ev) = s.eval(&key, t_match) else {
            continue;
        };
        let matched = matched(&s.data, det, &key, ev);
        let rows = rows(s, det, &matched);
        if det == &s.main.0
            && let Some(all) = rows.last()
        {
            let g: Vec<f64> = matched.iter().map(|x| x.sample.ground_error_m).collect();
            summary.push(format!(
                "Ground-position error {:.3} m (median {:.3}), |height error| {:.3} m over {} matched person-frames ({}).",
                all.ground_error_m.unwrap_or(f64::NAN),
                median(&g).unwrap_or(f64::NAN),
                all.abs_height_error_m.unwrap_or(f64::NAN),
                all.frames,
                det
            ));
        }
        rows_all.extend(rows);
        samples.extend(matched.into_iter().map(|x| x.sample));
    }
    Ok(Table::new(
        "position_error",
        format!("3-D ground-position error, height error and cylinder radius per person (frames matched within {t_match} m)"),
        PositionRow::frame(&rows_all)?,
    )
    .with_note("Errors are of the Kalman-smoothed cylinder against the ground truth: ground position = body centre on the floor; height = top of the head; radius = body (shoulder) radius. Height error is signed (estimate − truth).")
    .with_note("Paper: no numbers; §6 says the system locates a person 'accurately' and estimates the height 'with great precision' (fig. 5c).")
    .with_samples(PositionSample::frame(&samples)?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipelines::s004_mohedano_multicam::evaluate::testdata;

    #[test]
    fn errors_of_a_known_track_per_person_and_overall() {
        let s = testdata::scored();
        let key: Key = ("gt_boxes".into(), "E_c".into(), 5);
        let ev = s.eval(&key, 1.0).expect("evaluated");
        let matched = matched(&s.data, "gt_boxes", &key, ev);
        assert_eq!(matched.len(), 10);
        // frames 3 and 4: 0.7 m off in x; the others 0.1 m; height 1.80 vs 1.75
        let g: Vec<f64> = matched.iter().map(|x| x.sample.ground_error_m).collect();
        assert!((g[3] - 0.7).abs() < 1e-12 && (g[0] - 0.1).abs() < 1e-12);
        let rows = rows(&s, "gt_boxes", &matched);
        assert_eq!(rows.len(), 2);
        assert_eq!(
            (rows[0].person.as_str(), rows[1].person.as_str()),
            ("1", "all")
        );
        let r = &rows[1];
        assert_eq!(r.frames, 10);
        // mean ground error (8 · 0.1 + 2 · 0.7) / 10 = 0.22
        assert!((r.ground_error_m.expect("mean") - 0.22).abs() < 1e-12);
        assert!((r.height_error_m.expect("mean") - 0.05).abs() < 1e-12);
        assert!((r.true_height_m.expect("mean") - 1.75).abs() < 1e-12);
        assert_eq!(r.radius_m, Some(0.25));
        assert!((r.true_radius_m.expect("mean") - 0.2).abs() < 1e-12);
        // p95 of eight 0.1 and two 0.7: position 8.55 between 0.7 and 0.7
        assert!((r.ground_error_p95_m.expect("p95") - 0.7).abs() < 1e-12);
    }
}

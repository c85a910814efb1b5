//! `N_app` (with `N_dis = N_app`) against detection latency and false alarms, and the curve.

use std::collections::{BTreeMap, HashMap};

use super::{mean, median, renamed};
use crate::eval::mot::{Evaluation, EventKind};
use crate::pipelines::s004_mohedano_multicam::Params;
use crate::pipelines::s004_mohedano_multicam::scored::{Key, STRIDE, Scored, SessionData};
use crate::report::figure::{Event, FigureKind, LinePlot, Mark, Series};
use crate::report::rows::Rows;
use crate::report::{Figure, Table};

/// The paper's choice (§5).
const PAPER_N_APP: i64 = 5;

mod rows {
    #![allow(non_snake_case)]
    crate::table_row! {
        /// One detector at one `N_app`.
        #[derive(Debug, Clone, PartialEq)]
        pub(crate) struct SweepRow {
            pub detector: String,
            pub N_app: i64,
            pub latency_frames: Option<f64>,
            pub latency_s: Option<f64>,
            pub median_latency_s: Option<f64>,
            pub people_detected: i64,
            pub people_trackable: i64,
            pub false_alarm_tracks: i64,
            pub tracks: i64,
            pub FP_per_min: f64,
            /// Renamed `MOTA_<threshold>m` in the table.
            pub mota: f64,
            pub paper: String,
        }
    }
}
pub(crate) use rows::SweepRow;

/// Per-person detection latency and false-alarm tracks of one evaluation.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Latency {
    /// Seconds from the first frame a person is seen by ≥ 2 cameras to the first match.
    pub latencies_s: Vec<f64>,
    pub latencies_frames: Vec<f64>,
    pub trackable: usize,
    pub false_alarm_tracks: usize,
    pub tracks: usize,
}

/// Latency: per person, from the first frame in which they are inside the room and seen by
/// at least two cameras to their first match at or after it. A track is a false alarm when it
/// is matched in fewer than half of its frames.
pub(crate) fn latency(data: &[SessionData], key: &Key, ev: &Evaluation) -> Latency {
    let mut matched_frames: HashMap<i64, u64> = HashMap::new();
    // matches per person, in frame order (events are)
    let mut matches_by_gt: HashMap<i64, Vec<i64>> = HashMap::new();
    for e in &ev.events {
        if matches!(e.kind, EventKind::Match | EventKind::Switch) {
            if let Some(g) = e.gt_id {
                matches_by_gt.entry(g).or_default().push(e.frame);
            }
            if let (Some(_), Some(h)) = (e.gt_id, e.hyp_id) {
                *matched_frames.entry(h).or_default() += 1;
            }
        }
    }
    let mut out = Latency {
        latencies_s: Vec::new(),
        latencies_frames: Vec::new(),
        trackable: 0,
        false_alarm_tracks: 0,
        tracks: 0,
    };
    for (s, d) in data.iter().enumerate() {
        let o = s as i64 * STRIDE;
        let mut start: BTreeMap<i64, i64> = BTreeMap::new();
        for g in d
            .truth
            .iter()
            .filter(|g| g.in_room && g.cameras_visible >= 2)
        {
            start.entry(g.id).or_insert(g.frame);
        }
        for (id, f0) in start {
            out.trackable += 1;
            if let Some(f) = matches_by_gt
                .get(&(o + id))
                .and_then(|v| v.iter().copied().find(|&f| f >= o + f0))
            {
                let frames = (f - (o + f0)) as f64;
                out.latencies_frames.push(frames);
                out.latencies_s.push(frames * d.session.dt_s);
            }
        }
        let mut total: BTreeMap<i64, u64> = BTreeMap::new();
        for r in d.rows(key) {
            *total.entry(o + r.id).or_default() += 1;
        }
        for (h, n) in total {
            out.tracks += 1;
            let m = matched_frames.get(&h).copied().unwrap_or(0);
            if (m as f64) < 0.5 * n as f64 {
                out.false_alarm_tracks += 1;
            }
        }
    }
    out
}

/// One row of the sweep (`minutes`: of data, all sessions).
pub(crate) fn row(det: &str, n: i64, l: &Latency, ev: &Evaluation, minutes: f64) -> SweepRow {
    SweepRow {
        detector: det.to_string(),
        N_app: n,
        latency_frames: mean(&l.latencies_frames),
        latency_s: mean(&l.latencies_s),
        median_latency_s: median(&l.latencies_s),
        people_detected: l.latencies_s.len() as i64,
        people_trackable: l.trackable as i64,
        false_alarm_tracks: l.false_alarm_tracks as i64,
        tracks: l.tracks as i64,
        FP_per_min: if minutes > 0.0 {
            ev.metrics.clear.num_false_positives as f64 / minutes
        } else {
            f64::NAN
        },
        mota: ev.metrics.clear.mota,
        paper: if n == PAPER_N_APP {
            format!("chosen ({PAPER_N_APP})")
        } else {
            String::new()
        },
    }
}

fn mark(di: usize) -> Mark {
    if di == 0 {
        Mark::LinePoints
    } else {
        Mark::Dashed
    }
}

pub(super) fn table(s: &Scored, p: &Params) -> anyhow::Result<(Table, Figure)> {
    let t_match = s.t_max();
    let minutes: f64 = s.data.iter().map(|d| d.session.duration_s).sum::<f64>() / 60.0;
    let mut rows = Vec::new();
    let mut series = Vec::new();
    for (di, det) in s.detectors().iter().enumerate() {
        let (mut lat_pts, mut fa_pts) = (Vec::new(), Vec::new());
        let mut ns: Vec<i64> = s
            .keys
            .iter()
            .filter(|k| &k.0 == det && k.1 == s.main.1)
            .map(|k| k.2)
            .collect();
        ns.sort_unstable();
        for n in ns {
            if !p.n_app_sweep.contains(&(n as u32)) {
                continue;
            }
            let key: Key = (det.clone(), s.main.1.clone(), n);
            let Some(ev) = s.eval(&key, t_match) else {
                continue;
            };
            let l = latency(&s.data, &key, ev);
            let r = row(det, n, &l, ev, minutes);
            if let Some(m) = r.latency_frames {
                lat_pts.push((n as f64, m));
            }
            fa_pts.push((n as f64, l.false_alarm_tracks as f64));
            rows.push(r);
        }
        series.push(
            Series::line(format!("{det}: mean latency (frames)"), lat_pts, 2 * di + 1)
                .with_mark(mark(di)),
        );
        series.push(
            Series::line(format!("{det}: false-alarm tracks"), fa_pts, 2 * di + 5)
                .with_mark(mark(di)),
        );
    }
    let df = renamed(
        SweepRow::frame(&rows)?,
        &[("mota", format!("MOTA_{t_match}m"))],
    )?;
    let table = Table::new(
        "n_app_sweep",
        format!("Detection latency and false alarms against N_app (N_dis = N_app; matches within {t_match} m)"),
        df,
    )
    .with_precision("latency_frames", 1)
    .with_precision("latency_s", 2)
    .with_precision("median_latency_s", 2)
    .with_precision("FP_per_min", 1)
    .with_note("Latency: per person, from the first frame in which at least two cameras see them to the first frame a 3-D track is matched to them. A false-alarm track is matched to a person in fewer than half of its frames; FP_per_min counts unmatched track-frames per minute of data.")
    .with_note(format!("Paper: N_app = {PAPER_N_APP} 'is a good trade-off between 3D object detection latency and false alarm rate' (§5); no latency or false-alarm numbers are given."));
    let fig = Figure::new(
        "n_app_latency_false_alarms",
        "Latency and false alarms against N_app",
        FigureKind::Lines(LinePlot {
            x_label: "N_app (frames; N_dis = N_app)".into(),
            y_label: "frames / tracks".into(),
            series,
            events: vec![Event {
                x: PAPER_N_APP as f64,
                label: format!("paper: N_app = {PAPER_N_APP}"),
                color: 0,
            }],
            ..Default::default()
        }),
    );
    Ok((table, fig))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipelines::s004_mohedano_multicam::evaluate::testdata;

    #[test]
    fn latency_counts_from_the_first_frame_two_cameras_see_a_person() {
        // the person is seen by two cameras from frame 2 (testdata); the N_app = 5 track
        // appears at frame 3 but is 0.7 m off in frames 3–4, so at 0.5 m its first match at
        // or after frame 2 is frame 5: 3 frames, 3 · 0.04 s
        let s = testdata::scored();
        let key: Key = ("templates".into(), "E_c".into(), 5);
        let l = latency(&s.data, &key, s.eval(&key, 0.5).expect("evaluated"));
        assert_eq!(l.trackable, 1);
        assert_eq!(l.latencies_frames, [3.0]);
        assert!((l.latencies_s[0] - 0.12).abs() < 1e-12);
        // one track, matched in 5 of its 7 frames: no false alarm
        assert_eq!((l.tracks, l.false_alarm_tracks), (1, 0));
    }

    #[test]
    fn a_track_matched_in_under_half_its_frames_is_a_false_alarm() {
        let s = testdata::scored();
        let key: Key = ("templates".into(), "E_c".into(), 1);
        let l = latency(&s.data, &key, s.eval(&key, 0.5).expect("evaluated"));
        // N_app = 1 (testdata): the real track plus a ghost never near anybody
        assert_eq!((l.tracks, l.false_alarm_tracks), (2, 1));
        assert_eq!(l.latencies_frames, [0.0]);
    }

    #[test]
    fn the_table_names_the_mota_column_after_the_threshold() {
        let s = testdata::scored();
        let p = Params {
            n_app_sweep: vec![1, 5],
            ..Params::default()
        };
        let (t, _) = table(&s, &p).expect("table");
        let names: Vec<String> =
            t.df.get_column_names()
                .iter()
                .map(|c| c.to_string())
                .collect();
        assert_eq!(names[10], "MOTA_1m");
        // gt_boxes at 5; templates at 1 and 5
        assert_eq!(t.df.height(), 3);
    }
}

//! The figures from the cached tables: the error CDF of the direction of arrival per
//! acoustic condition, the GCC-PHAT correlogram of the first session with the true lags, the
//! first session's anchor-state timelines with the speaking bars, its focus of attention over
//! time (system against truth), and the variants' scores side by side.

use super::aggregate::{DoaCell, SessionData, variant_rows};
use crate::report::figure::{
    Figure, FigureKind, GroupedBars, ImageOverlay, LinePlot, Mark, Series,
};

pub fn all(data: &[SessionData], cells: &[DoaCell]) -> Vec<Figure> {
    let mut out = vec![doa_cdf(data, cells)];
    if let Some(s) = data.first() {
        if let Some(img) = &s.correlogram {
            out.push(Figure::new(
                format!("correlogram_{}", s.name),
                format!(
                    "GCC-PHAT correlogram of {} (nominal audio): time 0.1 s per column, lag +0.82 ms (top) to -0.82 ms; white: true lags of the talkers",
                    s.name
                ),
                FigureKind::Overlay(ImageOverlay {
                    image: img.clone(),
                    shapes: Vec::new(),
                }),
            ));
        }
        out.push(timeline(s));
        out.push(focus(s));
    }
    out.push(variant_bars(data));
    out
}

fn doa_cdf(data: &[SessionData], cells: &[DoaCell]) -> Figure {
    let mut series = Vec::new();
    for (i, c) in cells.iter().enumerate() {
        let mut e: Vec<f64> = data
            .iter()
            .flat_map(|s| &s.doa)
            .filter(|r| (r.rt60_ms, r.snr_db) == (c.rt60_ms, c.snr_db))
            .map(|r| r.err_deg.min(30.0))
            .collect();
        e.sort_by(f64::total_cmp);
        let n = e.len().max(1) as f64;
        let pts: Vec<(f64, f64)> = e
            .iter()
            .enumerate()
            .map(|(k, v)| (*v, (k + 1) as f64 / n))
            .collect();
        let mark = match c.snr_db {
            s if s >= 30 => Mark::Line,
            s if s >= 10 => Mark::Dashed,
            _ => Mark::Points,
        };
        series.push(
            Series::line(
                format!("RT60 {} ms, SNR {} dB", c.rt60_ms, c.snr_db),
                pts,
                i / 3,
            )
            .with_mark(mark),
        );
    }
    Figure::new(
        "doa_error_cdf",
        "Direction of arrival: cumulative share of 0.5 s blocks by cone-angle error",
        FigureKind::Lines(LinePlot {
            x_label: "error (deg, capped at 30)".into(),
            y_label: "share of blocks".into(),
            series,
            x_range: Some((0.0, 20.0)),
            y_range: Some((0.0, 1.0)),
            ..LinePlot::default()
        }),
    )
}

fn timeline(s: &SessionData) -> Figure {
    let mut anchors: Vec<i64> = s.timeline.iter().map(|r| r.anchor).collect();
    anchors.sort_unstable();
    anchors.dedup();
    let lane = |a: i64| anchors.iter().position(|x| *x == a).unwrap_or(0) as f64;
    let names = ["legs", "face", "torso", "voice"];
    let mut series = Vec::new();
    for (c, name) in names.iter().enumerate() {
        let pts: Vec<(f64, f64)> = s
            .timeline
            .iter()
            .filter(|r| [r.legs, r.face, r.torso, r.voice][c] == 2)
            .map(|r| (r.t_s, lane(r.anchor) + 0.15 * c as f64))
            .collect();
        series.push(Series::points(format!("{name} grounded"), pts, c).with_mark(Mark::Dots));
    }
    let speaking: Vec<(f64, f64)> = s
        .timeline
        .iter()
        .filter(|r| r.speaking)
        .map(|r| (r.t_s, lane(r.anchor) + 0.65))
        .collect();
    series.push(Series::points("matched person speaks (truth)", speaking, 5));
    Figure::new(
        format!("anchor_timeline_{}", s.name),
        format!(
            "Person anchors of {} (full system): grounded components per anchor lane, speaking bars",
            s.name
        ),
        FigureKind::Lines(LinePlot {
            x_label: "time (s)".into(),
            y_label: "anchor (lane)".into(),
            series,
            ..LinePlot::default()
        }),
    )
}

fn focus(s: &SessionData) -> Figure {
    let full: Vec<_> = s.steps.iter().filter(|r| r.variant == "full").collect();
    let est: Vec<(f64, f64)> = full
        .iter()
        .map(|r| (r.t_s, r.focus_person as f64 + 0.1))
        .collect();
    let truth: Vec<(f64, f64)> = full.iter().map(|r| (r.t_s, r.true_focus as f64)).collect();
    let top: Vec<(f64, f64)> = full
        .iter()
        .filter(|r| r.mode == "interact")
        .map(|r| (r.t_s, -1.5))
        .collect();
    let true_top: Vec<(f64, f64)> = full
        .iter()
        .filter(|r| r.true_mode == "interact")
        .map(|r| (r.t_s, -1.7))
        .collect();
    Figure::new(
        format!("focus_{}", s.name),
        format!(
            "Focus of attention in {}: the person the system attends (matched at 0.5 m) and the true focus; -1: nobody; bars: top-down",
            s.name
        ),
        FigureKind::Lines(LinePlot {
            x_label: "time (s)".into(),
            y_label: "person id".into(),
            series: vec![
                Series::points("true focus", truth, 0).with_mark(Mark::Dots),
                Series::points("system focus", est, 1).with_mark(Mark::Dots),
                Series::points("system top-down", top, 2).with_mark(Mark::Dots),
                Series::points("true top-down", true_top, 3).with_mark(Mark::Dots),
            ],
            ..LinePlot::default()
        }),
    )
}

fn variant_bars(data: &[SessionData]) -> Figure {
    let rows = variant_rows(data);
    let groups: Vec<String> = rows.iter().map(|r| r.variant.clone()).collect();
    let fin = |v: f64| v.is_finite().then_some(v);
    Figure::new(
        "variants",
        "Speaker identification, focus of attention and MOTA per system variant",
        FigureKind::GroupedBars(GroupedBars {
            y_label: "share / MOTA".into(),
            groups,
            series: vec![
                (
                    "speaker identification".into(),
                    rows.iter().map(|r| fin(r.speaker_id)).collect(),
                ),
                (
                    "focus right".into(),
                    rows.iter().map(|r| fin(r.focus_right)).collect(),
                ),
                (
                    "MOTA (0.5 m)".into(),
                    rows.iter().map(|r| fin(r.mota)).collect(),
                ),
            ],
            ..GroupedBars::default()
        }),
    )
}

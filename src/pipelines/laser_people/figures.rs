//! Figures, from the cached per-session tables only:
//!
//! - `top_view_<sequence>`: one panel per method, in the fixed frame over the scored scans —
//!   the laser's returns of the sampled scans (`points`, faint), the ground-truth paths
//!   (black, dashed), the method's track paths coloured by id, and the laser at the first and
//!   last scored scan. Every real sequence and the first session of each synthetic dataset.
//!   Ground truth (cached in the laser frame) goes to the fixed frame through the scan's pose
//!   (`poses`; without one, the laser frame is the fixed frame, as for the tracks). A path
//!   breaks where its id is unseen for more than [`BREAK_S`] or jumps more than [`BREAK_M`].
//! - `mota_per_method`: MOTA and MOTP per sequence (groups: real sequences, then the synthetic
//!   sessions) and method (bars).

use std::collections::BTreeMap;

use super::aggregate::{ResultRow, SessionData};
use super::params::{Params, Sequence};
use super::view::{self, PointRow, PoseRow};
use crate::names::sanitize;
use crate::report::Figure;
use crate::report::figure::{FigureKind, GroupedBars, Mark, Panels, Sensor, Series, TopView};
use crate::run::Aggregate;

/// A path breaks where its id is unseen for longer than this (s) …
pub const BREAK_S: f64 = 1.0;
/// … or moves farther than this between two of its positions (m).
pub const BREAK_M: f64 = 1.0;
/// Returns drawn farther than this from every path and laser position are left out (m).
pub const MARGIN_M: f64 = 3.0;
/// At most this many returns are drawn per panel (every k-th beyond).
pub const MAX_DOTS: usize = 30_000;

/// Every figure of the pipeline. `data` is in the order of `ctx.sessions`.
pub(super) fn all(
    ctx: &Aggregate,
    p: &Params,
    data: &[SessionData],
    results: &[ResultRow],
) -> anyhow::Result<Vec<Figure>> {
    let mut figures = vec![scores(p, results)];
    let mut datasets_shown = Vec::new();
    for (d, (_, t)) in data.iter().zip(ctx.sessions) {
        if !p.is_listed(&d.name) {
            if datasets_shown.contains(&d.dataset) {
                continue;
            }
            datasets_shown.push(d.dataset.clone());
        }
        let (poses, points) = view::read(t, &format!("{}/{}", d.dataset, d.name))?;
        figures.push(top_view(p, d, &poses, &points));
    }
    Ok(figures)
}

/// A laser pose `(x, y, yaw)` in the fixed frame by scan.
type Poses = BTreeMap<i64, (f64, f64, f64)>;

/// One track id and its path (fixed frame, m).
type IdPath = (i64, Vec<(f64, f64)>);

fn to_fixed(poses: &Poses, idx: i64, x: f64, y: f64) -> (f64, f64) {
    match poses.get(&idx) {
        Some(&(px, py, yaw)) => {
            let (s, c) = yaw.sin_cos();
            (px + c * x - s * y, py + s * x + c * y)
        }
        None => (x, y),
    }
}

/// Paths of `(id, time s, x, y)` in time order per id, broken at gaps and jumps.
fn paths(rows: impl Iterator<Item = (i64, f64, f64, f64)>) -> Vec<(i64, Vec<(f64, f64)>)> {
    let mut by_id: BTreeMap<i64, Vec<(f64, f64, f64)>> = BTreeMap::new();
    for (id, t, x, y) in rows {
        by_id.entry(id).or_default().push((t, x, y));
    }
    let mut out = Vec::new();
    for (id, pts) in by_id {
        let mut cur: Vec<(f64, f64)> = Vec::new();
        let mut last: Option<(f64, f64, f64)> = None;
        for (t, x, y) in pts {
            if let Some((t0, x0, y0)) = last
                && (t - t0 > BREAK_S || (x - x0).hypot(y - y0) > BREAK_M)
            {
                out.push((id, std::mem::take(&mut cur)));
            }
            cur.push((x, y));
            last = Some((t, x, y));
        }
        out.push((id, cur));
    }
    out
}

fn top_view(p: &Params, d: &SessionData, poses: &[PoseRow], points: &[PointRow]) -> Figure {
    let seq: &Sequence = p.sequence(&d.name);
    let pose: Poses = poses
        .iter()
        .filter_map(|r| Some((r.scan_idx, (r.x?, r.y?, r.yaw?))))
        .collect();
    let time: BTreeMap<i64, f64> = d
        .scans
        .iter()
        .map(|s| (s.scan_idx, s.stamp_ns as f64 * 1e-9))
        .collect();
    let at = |idx: i64| time.get(&idx).copied().unwrap_or(0.0);
    let truth = paths(
        d.truth
            .iter()
            .filter(|r| seq.scores_scan(r.scan_idx))
            .map(|r| {
                let (x, y) = to_fixed(&pose, r.scan_idx, r.x, r.y);
                (r.id, at(r.scan_idx), x, y)
            }),
    );
    let window: Vec<i64> = d
        .scans
        .iter()
        .map(|s| s.scan_idx)
        .filter(|&i| seq.scores_scan(i))
        .collect();
    let mut sensors = Vec::new();
    for (k, idx) in [window.first(), window.last()]
        .into_iter()
        .flatten()
        .enumerate()
    {
        if k == 1 && window.len() == 1 {
            break;
        }
        let (x, y, yaw) = pose.get(idx).copied().unwrap_or((0.0, 0.0, 0.0));
        if k == 1 && !pose.contains_key(idx) {
            break; // no TF: the laser is the origin on every scan
        }
        sensors.push(Sensor {
            x,
            y,
            heading: Some(yaw),
            label: format!("laser, scan {idx}"),
        });
    }
    let methods: Vec<(&str, Vec<IdPath>)> = p
        .methods
        .iter()
        .map(|m| {
            let rows = d
                .tracks
                .iter()
                .filter(|r| r.detector == m.name() && seq.scores_scan(r.scan_idx))
                .map(|r| (r.id, at(r.scan_idx), r.world_x, r.world_y));
            (m.name(), paths(rows))
        })
        .collect();
    // returns near what is drawn
    let near: Vec<(f64, f64)> = truth
        .iter()
        .chain(methods.iter().flat_map(|(_, t)| t))
        .flat_map(|(_, pts)| pts.iter().copied())
        .chain(sensors.iter().map(|s| (s.x, s.y)))
        .collect();
    let dots = returns_near(points, &near);
    let scans_shown = {
        let mut s: Vec<i64> = points.iter().map(|r| r.scan_idx).collect();
        s.dedup();
        s.len()
    };
    let panels = methods
        .iter()
        .map(|(name, tracks)| {
            let mut traj = vec![
                Series::points(format!("returns of {scans_shown} scans"), dots.clone(), 0)
                    .with_mark(Mark::Dots),
            ];
            for (k, (_, pts)) in truth.iter().enumerate() {
                traj.push(
                    Series::line(if k == 0 { "ground truth" } else { "" }, pts.clone(), 0)
                        .with_mark(Mark::Dashed),
                );
            }
            for (k, (id, pts)) in tracks.iter().enumerate() {
                let name = if k == 0 { "tracks (colour: id)" } else { "" };
                let colour = id.rem_euclid(7) as usize + 1;
                traj.push(Series::line(name, pts.clone(), colour));
            }
            let ids = {
                let mut v: Vec<i64> = tracks.iter().map(|(id, _)| *id).collect();
                v.dedup();
                v.len()
            };
            Figure {
                size: (560, 580),
                ..Figure::new(
                    name.to_string(),
                    format!("{name}: {ids} track id{}", if ids == 1 { "" } else { "s" }),
                    FigureKind::TopView(TopView {
                        sensors: sensors.clone(),
                        trajectories: traj,
                        ..TopView::default()
                    }),
                )
            }
        })
        .collect();
    let frame = if d.session.fixed_frame.is_empty() {
        "laser"
    } else {
        d.session.fixed_frame.as_str()
    };
    let scans = match (window.first(), window.last()) {
        (Some(a), Some(b)) => format!("scans {a}..{b}"),
        _ => "no scans".into(),
    };
    Figure::new(
        format!("top_view_{}", sanitize(&d.name)),
        format!(
            "Top view of {}/{} in the {frame} frame ({scans}): returns, ground truth, tracks",
            d.dataset, d.name
        ),
        FigureKind::Panels(Panels {
            columns: p.methods.len().min(3),
            panels,
        }),
    )
}

/// The returns within [`MARGIN_M`] of the box around `near` (all of them without `near`),
/// thinned to at most [`MAX_DOTS`].
fn returns_near(points: &[PointRow], near: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let bounds = near
        .iter()
        .fold(None, |b: Option<(f64, f64, f64, f64)>, &(x, y)| {
            Some(match b {
                None => (x, x, y, y),
                Some((x0, x1, y0, y1)) => (x0.min(x), x1.max(x), y0.min(y), y1.max(y)),
            })
        });
    let inside: Vec<(f64, f64)> = points
        .iter()
        .map(|r| (r.x, r.y))
        .filter(|&(x, y)| {
            bounds.is_none_or(|(x0, x1, y0, y1)| {
                x >= x0 - MARGIN_M && x <= x1 + MARGIN_M && y >= y0 - MARGIN_M && y <= y1 + MARGIN_M
            })
        })
        .collect();
    let step = inside.len().div_ceil(MAX_DOTS).max(1);
    inside.into_iter().step_by(step).collect()
}

/// MOTA (top) and MOTP (bottom) per sequence and method.
fn scores(p: &Params, results: &[ResultRow]) -> Figure {
    let mut groups: Vec<String> = p.sequences.iter().map(|s| s.name.clone()).collect();
    for r in results {
        if !groups.contains(&r.sequence) {
            groups.push(r.sequence.clone());
        }
    }
    let real = p.sequences.len();
    let get = |seq: &str, method: &str| {
        results
            .iter()
            .find(|r| r.sequence == seq && r.detector == method)
    };
    let notes: Vec<String> = groups
        .iter()
        .map(|g| {
            let skipped = p
                .methods
                .iter()
                .all(|m| get(g, m.name()).is_none_or(|r| r.status.starts_with("SKIPPED")));
            if skipped {
                "SKIPPED".into()
            } else {
                String::new()
            }
        })
        .collect();
    let panel = |y_label: &str, title: String, value: &dyn Fn(&ResultRow) -> Option<f64>| {
        let series: Vec<(String, Vec<Option<f64>>)> = p
            .methods
            .iter()
            .map(|m| {
                let v = groups
                    .iter()
                    .map(|g| get(g, m.name()).and_then(value))
                    .collect();
                (m.name().to_string(), v)
            })
            .collect();
        let labels = series
            .iter()
            .map(|(_, v)| {
                v.iter()
                    .map(|x| x.map_or_else(String::new, |x| format!("{x:.2}")))
                    .collect()
            })
            .collect();
        Figure::new(
            y_label.to_string(),
            title,
            FigureKind::GroupedBars(GroupedBars {
                y_label: y_label.into(),
                groups: groups.clone(),
                series,
                labels,
                group_notes: notes.clone(),
            }),
        )
    };
    let kinds = format!(
        "the first {real} groups are the real sequences, the others synthetic sessions; {} m match threshold, laser frame",
        p.match_m
    );
    Figure::new(
        "mota_per_method",
        format!("MOTA and MOTP per sequence and method ({kinds})"),
        FigureKind::Panels(Panels {
            columns: 1,
            panels: vec![
                panel("MOTA", "MOTA (higher is better)".into(), &|r| r.mota),
                panel(
                    "MOTP (m)",
                    "MOTP: mean distance of matched pairs (m, lower is better)".into(),
                    &|r| r.motp_m,
                ),
            ],
        }),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A path breaks at a jump over 1 m and at a gap over 1 s, not otherwise; ids apart.
    #[test]
    fn paths_break_at_jumps_and_gaps() {
        let rows = vec![
            (1, 0.0, 0.0, 0.0),
            (2, 0.0, 5.0, 5.0),
            (1, 0.1, 0.5, 0.0),
            (1, 0.2, 2.0, 0.0), // jump 1.5 m
            (1, 1.5, 2.1, 0.0), // gap 1.3 s
            (1, 1.6, 2.2, 0.0),
        ];
        let got = paths(rows.into_iter());
        assert_eq!(
            got,
            vec![
                (1, vec![(0.0, 0.0), (0.5, 0.0)]),
                (1, vec![(2.0, 0.0)]),
                (1, vec![(2.1, 0.0), (2.2, 0.0)]),
                (2, vec![(5.0, 5.0)]),
            ]
        );
    }

    #[test]
    fn laser_frame_positions_go_to_the_fixed_frame() {
        let poses = Poses::from([(3, (1.0, 2.0, std::f64::consts::FRAC_PI_2))]);
        let (x, y) = to_fixed(&poses, 3, 1.0, 0.0);
        assert!(
            (x - 1.0).abs() < 1e-12 && (y - 3.0).abs() < 1e-12,
            "{x} {y}"
        );
        assert_eq!(to_fixed(&poses, 4, 1.0, 0.0), (1.0, 0.0));
    }
}

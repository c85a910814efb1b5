//! The figures of seed 002 from the cached tables and the filter runs: fig. 3 (top view:
//! room, sensors, estimated path and truth, with the final 3σ ellipse), figs. 5 and 6 (height
//! over time with 3σ bounds, from the start and from the first camera observation), the
//! position error over time per method, camera only's height over time (constant vs random
//! walk), and §4's plane grid (time per frame, F1).

use super::aggregate::{
    CAMERA_ONLY, CAMERA_ONLY_WALK, FUSED, FUSED_CV, LASER_ONLY, METHODS, SessionData,
};
use super::params::{Params, plane_name};
use crate::report::figure::{
    Figure, FigureKind, GroupedBars, ImageOverlay, LinePlot, Mark, Panels, Sensor, Series, TopView,
};

/// Every figure (empty when there is no session).
pub fn all(data: &[SessionData], p: &Params) -> Vec<Figure> {
    let mut out = Vec::new();
    if let Some(s) = data.first() {
        out.push(top_view(s, p));
        out.push(height(s, false));
        out.push(height(s, true));
        out.push(errors_over_time(s));
        out.push(camera_only_height(s));
        out.extend(frame_panels(s));
    }
    if let Some(s) = data.get(1) {
        out.push(top_view(s, p));
    }
    out.push(planes(data));
    out
}

fn rel_s(t: i64, t0: i64) -> f64 {
    (t - t0) as f64 * 1e-9
}

fn top_view(s: &SessionData, p: &Params) -> Figure {
    let [x0, y0, x1, y1] = p.room_m;
    let mut sensors = Vec::new();
    if let Some(l) = s.laser.first() {
        sensors.push(Sensor {
            x: l.laser_x,
            y: l.laser_y,
            heading: Some(l.laser_yaw),
            label: "laser".into(),
        });
    }
    if let Some(c) = s.camera.first() {
        sensors.push(Sensor {
            x: c.cam_x,
            y: c.cam_y,
            heading: None,
            label: "camera".into(),
        });
    }
    let truth: Vec<(f64, f64)> = s.truth.iter().map(|t| (t.x, t.y)).collect();
    let mut traj = vec![Series::line("ground truth", truth, 0).with_mark(Mark::Dashed)];
    for (k, name) in [FUSED, CAMERA_ONLY].into_iter().enumerate() {
        if let Some((run, _)) = s.runs.get(name) {
            let pts: Vec<(f64, f64)> = run.estimates.iter().map(|e| (e.x, e.y)).collect();
            traj.push(Series::line(format!("{name} estimate"), pts, k + 1));
            if let Some(e) = run.last() {
                traj.push(Series::line(
                    format!("{name}: final 3σ ellipse"),
                    super::fig4::ellipse(e.x, e.y, e.pos_cov, 3.0),
                    k + 1,
                ));
            }
        }
    }
    Figure {
        size: (640, 560),
        ..Figure::new(
            format!("fig3_top_view_{}", s.name),
            format!(
                "Fig. 3: {} top view (camera only: height from {})",
                s.name, s.height_from
            ),
            FigureKind::TopView(TopView {
                outline: vec![(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)],
                sensors,
                trajectories: traj,
                ..TopView::default()
            }),
        )
    }
}

/// Fig. 4 (composed in the session stage, see [`super::fig4`]).
fn frame_panels(s: &SessionData) -> Option<Figure> {
    let row = s.fig4.first()?;
    let image = super::fig4::decode(row)?;
    let t0 = s.runs[FUSED]
        .0
        .estimates
        .first()
        .map_or(row.stamp_ns, |e| e.stamp_ns);
    Some(Figure::new(
        format!("fig4_frame_{}", s.name),
        format!(
            "Fig. 4: {} frame {} (t = {:.1} s): estimate +, detection □ | motion | skin | laser, 3σ",
            s.name,
            row.frame_idx,
            rel_s(row.stamp_ns, t0)
        ),
        FigureKind::Overlay(ImageOverlay {
            image,
            shapes: Vec::new(),
        }),
    ))
}

fn height(s: &SessionData, from_camera: bool) -> Figure {
    let (run, _) = &s.runs[FUSED];
    let t0 = run.estimates.first().map_or(0, |e| e.stamp_ns);
    let start = if from_camera {
        run.first_camera_ns.unwrap_or(t0)
    } else {
        t0
    };
    let est: Vec<_> = run
        .estimates
        .iter()
        .filter(|e| e.stamp_ns >= start)
        .collect();
    let pts: Vec<(f64, f64)> = est.iter().map(|e| (rel_s(e.stamp_ns, t0), e.h)).collect();
    let band: Vec<(f64, f64, f64)> = est
        .iter()
        .map(|e| {
            (
                rel_s(e.stamp_ns, t0),
                e.h - 3.0 * e.sigma_h,
                e.h + 3.0 * e.sigma_h,
            )
        })
        .collect();
    let truth = s.truth_m();
    let x_end = pts.last().map_or(1.0, |p| p.0);
    let x_start = pts.first().map_or(0.0, |p| p.0);
    let (fig, what, y_range) = if from_camera {
        (
            "fig6_height_from_first_camera",
            "from the first camera observation",
            None,
        )
    } else {
        ("fig5_height_over_time", "from the start", Some((-1.0, 4.0)))
    };
    Figure::new(
        format!("{fig}_{}", s.name),
        format!(
            "Fig. {}: {}: height estimate with 3σ bounds, {what}",
            if from_camera { 6 } else { 5 },
            s.name
        ),
        FigureKind::Lines(LinePlot {
            x_label: "time since the filter started (s)".into(),
            y_label: "height (m)".into(),
            series: vec![
                Series::line("estimate (±3σ)", pts, 1).with_band(band),
                Series::line(
                    format!("truth {truth:.2} m"),
                    vec![(x_start, truth), (x_end, truth)],
                    0,
                )
                .with_mark(Mark::Dashed),
            ],
            events: Vec::new(),
            x_range: None,
            y_range,
        }),
    )
}

/// Camera only's height over time with the constant height and the random walk (§5: the
/// camera alone cannot observe it).
fn camera_only_height(s: &SessionData) -> Figure {
    let t0 = s.truth.first().map_or(0, |t| t.stamp_ns);
    let mut series: Vec<Series> = [CAMERA_ONLY, CAMERA_ONLY_WALK]
        .iter()
        .enumerate()
        .filter_map(|(k, name)| {
            s.runs.get(name).map(|(run, _)| {
                Series::line(
                    *name,
                    run.estimates
                        .iter()
                        .map(|e| (rel_s(e.stamp_ns, t0), e.h))
                        .collect(),
                    k + 1,
                )
            })
        })
        .collect();
    if let (Some(a), Some(b)) = (s.truth.first(), s.truth.last()) {
        series.push(
            Series::line(
                format!("truth {:.2} m", a.height_m),
                vec![(0.0, a.height_m), (rel_s(b.stamp_ns, t0), a.height_m)],
                0,
            )
            .with_mark(Mark::Dashed),
        );
    }
    Figure::new(
        format!("camera_only_height_{}", s.name),
        format!("{}: camera only's height, constant vs random walk", s.name),
        FigureKind::Lines(LinePlot {
            x_label: "time (s)".into(),
            y_label: "height (m)".into(),
            series,
            ..LinePlot::default()
        }),
    )
}

fn errors_over_time(s: &SessionData) -> Figure {
    let t0 = s.truth.first().map_or(0, |t| t.stamp_ns);
    let series = METHODS
        .iter()
        .enumerate()
        .filter_map(|(k, name)| {
            s.runs.get(name).map(|(_, scored)| {
                Series::line(
                    *name,
                    scored
                        .iter()
                        .map(|r| (rel_s(r.stamp_ns, t0), r.error_m))
                        .collect(),
                    k + 1,
                )
            })
        })
        .collect();
    Figure::new(
        format!("position_error_{}", s.name),
        format!(
            "{}: position error over time per method (camera only from the height learned in {})",
            s.name, s.height_from
        ),
        FigureKind::Lines(LinePlot {
            x_label: "time (s)".into(),
            y_label: "position error (m)".into(),
            series,
            ..LinePlot::default()
        }),
    )
}

fn planes(data: &[SessionData]) -> Figure {
    let groups: Vec<String> = super::params::PLANE_GRID
        .iter()
        .map(|(c, e)| plane_name(*c, *e))
        .collect();
    let value = |f: &dyn Fn(&super::tables::PlanesRow) -> f64| -> Vec<Option<f64>> {
        groups
            .iter()
            .map(|g| {
                let v: Vec<f64> = data
                    .iter()
                    .flat_map(|s| s.planes.iter().filter(|r| &r.config == g))
                    .map(f)
                    .collect();
                (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
            })
            .collect()
    };
    let panel = |name: &str, title: &str, v: Vec<Option<f64>>| {
        let labels = vec![
            v.iter()
                .map(|x| x.map_or_else(String::new, |x| format!("{x:.2}")))
                .collect(),
        ];
        Figure::new(
            name.to_string(),
            title.to_string(),
            FigureKind::GroupedBars(GroupedBars {
                y_label: name.into(),
                groups: groups.clone(),
                series: vec![(name.to_string(), v)],
                labels,
                group_notes: Vec::new(),
            }),
        )
    };
    Figure::new(
        "planes_scaling",
        "Seed 002 §4: background subtraction time per frame and moving-pixel F1 for 1 / 3 colour × 0 / 1 / 2 edge planes (mean over sessions)",
        FigureKind::Panels(Panels {
            columns: 1,
            panels: vec![
                panel(
                    "ms per frame",
                    "time per frame (ms, one thread)",
                    value(&|r| r.ms_per_frame),
                ),
                panel(
                    "F1",
                    "moving-pixel F1 against the exact person mask",
                    value(&|r| r.f1),
                ),
            ],
        }),
    )
}

/// Report lines: the height against the paper's, the errors of the four methods.
pub fn summary(data: &[SessionData]) -> Vec<String> {
    let mut out = Vec::new();
    for s in data {
        let truth = s.truth_m();
        if let Some(e) = s.runs[FUSED].0.last() {
            out.push(format!(
                "{}: height learned by laser + camera {:.3} m (σ {:.3}) vs truth {truth:.2} m (paper: 1.87 vs 1.84 m)",
                s.name, e.h, e.sigma_h
            ));
        }
        let mean = |name: &str| {
            let v = &s.runs[name].1;
            if v.is_empty() {
                f64::NAN
            } else {
                v.iter().map(|r| r.error_m).sum::<f64>() / v.len() as f64
            }
        };
        out.push(format!(
            "{}: mean position error laser+camera {:.3} m, laser only {:.3} m, camera only {:.3} m (height from {}; {:.3} m with the height random walk), CV {:.3} m",
            s.name,
            mean(FUSED),
            mean(LASER_ONLY),
            mean(CAMERA_ONLY),
            s.height_from,
            mean(CAMERA_ONLY_WALK),
            mean(FUSED_CV)
        ));
    }
    out
}

//! The figures, drawn from the cached rows of the synthetic run whose tracker was on the
//! person on the most scans (the paper shows a "typical run") (and method 1's rows of
//! all runs):
//!
//! - `fig4_trajectory`: the robot's path, joined to every 5th estimate of its own tracker, the
//!   estimated velocity as an arrow (0.5 s long) at each, the person's true path dashed;
//! - `fig5_covariance`: the covariance norm of the robot's tracker (every 3rd estimate) with the
//!   `x` (occlusion), `gnd` (laser on the ground) and `rst` marks from the ground truth and log;
//! - `fig7_following`: `fig7_window_s` of following error E_follow and bearing to the person;
//! - `method1_loss`: method 1's loss rate per robot-speed bin (paper fig. 3: unreliable above
//!   1 m/s);
//! - `closed_loop_top_view`: the whole run, robot and person, with the `rst` positions.

use super::method1::{self, LossRow};
use super::params::Params;
use super::tables::{Method1Row, SessionData, TruthRow};
use crate::report::figure::{
    Bar, BarPlot, Circle, Event, Figure, FigureKind, LinePlot, Mark, Panels, Series, TopView,
};
use crate::report::rows::Rows;
use crate::report::table::Table;

/// `method1_loss` as a table.
pub fn method1_table(rows: &[Method1Row], p: &Params) -> anyhow::Result<Table> {
    let mut t = Table::new(
        "method1_loss",
        "Method 1 (egomotion-compensated frame differencing + particle filter): loss rate per robot-speed bin",
        LossRow::frame(&method1::loss_table(rows, p.method1_speed_bin))?,
    );
    for c in ["speed_lo", "speed_hi", "loss_rate"] {
        t = t.with_precision(c, 2);
    }
    Ok(t.with_note(format!(
        "Lost: no detection, or its bearing more than {} deg from the person's true bearing in the omni camera frame; every {}-th omni frame of the closed-loop runs. Paper (fig. 3): losses frequent, unreliable above 1 m/s.",
        p.method1_lost_deg, p.method1_every
    )))
}

/// A path of (x, y) points.
type Path = Vec<(f64, f64)>;

/// The robot's and the person's true paths.
fn truth_path(truth: &[TruthRow]) -> (Path, Path) {
    let robot = truth.iter().map(|r| (r.robot_x, r.robot_y)).collect();
    let person = truth
        .iter()
        .filter_map(|r| Some((r.target_x?, r.target_y?)))
        .collect();
    (robot, person)
}

fn robot_at(truth: &[TruthRow], t: f64) -> Option<&TruthRow> {
    truth
        .iter()
        .min_by(|a, b| (a.t_s - t).abs().total_cmp(&(b.t_s - t).abs()))
}

fn fig4(d: &SessionData) -> Figure {
    let (robot, person) = truth_path(&d.truth);
    let mut tr = vec![
        Series::line("robot", robot, 0),
        Series::line("person (truth)", person, 3).with_mark(Mark::Dashed),
    ];
    let est: Vec<_> = d
        .closed_loop
        .iter()
        .filter(|l| l.x.is_some())
        .step_by(5)
        .collect();
    for (k, l) in est.iter().enumerate() {
        let (Some(x), Some(y)) = (l.x, l.y) else {
            continue;
        };
        if let Some(r) = robot_at(&d.truth, l.t_s) {
            let name = if k == 0 { "robot to estimate" } else { "" };
            tr.push(Series::line(name, vec![(r.robot_x, r.robot_y), (x, y)], 2));
        }
        if let (Some(vx), Some(vy)) = (l.vx, l.vy) {
            let name = if k == 0 {
                "estimated velocity (0.5 s)"
            } else {
                ""
            };
            tr.push(Series::line(
                name,
                vec![(x, y), (x + 0.5 * vx, y + 0.5 * vy)],
                5,
            ));
        }
    }
    Figure::new(
        "fig4_trajectory",
        format!(
            "Fig. 4: robot path joined to every 5th estimate, {}",
            d.name
        ),
        FigureKind::TopView(TopView {
            trajectories: tr,
            ..TopView::default()
        }),
    )
}

/// Starts of the runs of `flag` in the truth rows.
fn starts(truth: &[TruthRow], flag: fn(&TruthRow) -> bool) -> Vec<f64> {
    let mut out = Vec::new();
    let mut was = false;
    for r in truth {
        let f = flag(r);
        if f && !was {
            out.push(r.t_s);
        }
        was = f;
    }
    out
}

fn fig5(d: &SessionData) -> Figure {
    let pts: Vec<(f64, f64)> = d
        .closed_loop
        .iter()
        .filter_map(|l| Some((l.t_s, l.cov_norm?)))
        .step_by(3)
        .collect();
    let mut events: Vec<Event> = starts(&d.truth, |r| r.occluded)
        .into_iter()
        .map(|x| Event {
            x,
            label: "x".into(),
            color: 2,
        })
        .collect();
    events.extend(starts(&d.truth, |r| r.ground).into_iter().map(|x| Event {
        x,
        label: "gnd".into(),
        color: 1,
    }));
    events.extend(d.closed_loop.iter().filter(|l| l.reset).map(|l| Event {
        x: l.t_s,
        label: "rst".into(),
        color: 5,
    }));
    Figure::new(
        "fig5_covariance",
        format!("Fig. 5: covariance norm of the robot's tracker, {}", d.name),
        FigureKind::Lines(LinePlot {
            x_label: "time (s)".into(),
            y_label: "sqrt of the largest eigenvalue of P_xy (m)".into(),
            series: vec![Series::points("covariance norm", pts, 4)],
            events,
            ..LinePlot::default()
        }),
    )
}

fn fig7(d: &SessionData, p: &Params) -> Figure {
    let t0 = d.truth.first().map_or(0.0, |r| r.t_s);
    let win: Vec<&TruthRow> = d
        .truth
        .iter()
        .filter(|r| r.t_s - t0 <= p.fig7_window_s && r.range_m.is_some())
        .collect();
    let err = win
        .iter()
        .map(|r| {
            let e = r.range_m.unwrap_or(0.0)
                - p.following_distance_m
                - r.robot_v * r.robot_v / (2.0 * p.max_decel_mps2);
            (r.t_s, e)
        })
        .collect();
    let bearing = win
        .iter()
        .map(|r| (r.t_s, r.bearing_rad.unwrap_or(0.0).to_degrees()))
        .collect();
    let panel = |name: &str, y: &str, s: Series| {
        Figure::new(
            name.to_string(),
            name.to_string(),
            FigureKind::Lines(LinePlot {
                x_label: "time (s)".into(),
                y_label: y.into(),
                series: vec![s],
                ..LinePlot::default()
            }),
        )
    };
    Figure::new(
        "fig7_following",
        format!("Fig. 7: {} s of following, {}", p.fig7_window_s, d.name),
        FigureKind::Panels(Panels {
            columns: 1,
            panels: vec![
                panel(
                    "following error E_follow",
                    "E_follow (m)",
                    Series::line("E_follow", err, 4),
                ),
                panel(
                    "bearing to the person",
                    "bearing (deg)",
                    Series::line("bearing", bearing, 5),
                ),
            ],
        }),
    )
}

fn method1_fig(rows: &[Method1Row], p: &Params) -> Figure {
    let bars = method1::loss_table(rows, p.method1_speed_bin)
        .into_iter()
        .map(|b| Bar {
            label: format!("{:.1}-{:.1} m/s (n={})", b.speed_lo, b.speed_hi, b.frames),
            value: b.loss_rate,
            error: 0.0,
        })
        .collect();
    Figure::new(
        "method1_loss",
        "Method 1: loss rate against robot speed (paper fig. 3: unreliable above 1 m/s)",
        FigureKind::Bars(BarPlot {
            y_label: "share of frames lost".into(),
            bars,
            significance: Vec::new(),
        }),
    )
}

fn top_view(d: &SessionData) -> Figure {
    let (robot, person) = truth_path(&d.truth);
    let circles = d
        .closed_loop
        .iter()
        .filter(|l| l.reset)
        .filter_map(|l| robot_at(&d.truth, l.t_s))
        .map(|r| Circle {
            x: r.robot_x,
            y: r.robot_y,
            r: 0.5,
            color: 5,
        })
        .collect();
    let est = d
        .closed_loop
        .iter()
        .filter_map(|l| Some((l.x?, l.y?)))
        .collect();
    Figure::new(
        "closed_loop_top_view",
        format!(
            "Closed loop, {}: robot, person, tracker estimates; circles: rst",
            d.name
        ),
        FigureKind::TopView(TopView {
            trajectories: vec![
                Series::line("robot (truth)", robot, 0),
                Series::line("person (truth)", person, 3).with_mark(Mark::Dashed),
                Series::points("robot's estimates", est, 2).with_mark(Mark::Dots),
            ],
            circles,
            ..TopView::default()
        }),
    )
}

/// Scans on which the robot's own estimate lay within `lock_m` of the person.
fn on_person(d: &SessionData, lock_m: f64) -> usize {
    d.closed_loop
        .iter()
        .filter(|l| {
            let (Some(x), Some(y)) = (l.x, l.y) else {
                return false;
            };
            robot_at(&d.truth, l.t_s)
                .and_then(|r| Some((r.target_x? - x).hypot(r.target_y? - y)))
                .is_some_and(|e| e <= lock_m)
        })
        .count()
}

/// Every figure (none for a part without data).
pub fn all(data: &[&SessionData], m1: &[Method1Row], p: &Params) -> Vec<Figure> {
    let mut out = Vec::new();
    // the run whose tracker was on the person on the most scans (the first of equals)
    let best = data
        .iter()
        .filter(|d| !d.closed_loop.is_empty())
        .rev()
        .max_by_key(|d| on_person(d, p.lock_m));
    if let Some(d) = best {
        out.extend([fig4(d), fig5(d), fig7(d, p), top_view(d)]);
    }
    if !m1.is_empty() {
        out.push(method1_fig(m1, p));
    }
    out
}

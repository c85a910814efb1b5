//! The filters of seed 002 §5 over one session's cached observations
//! ([`crate::track::height_ekf`]): laser + camera, laser only, camera only (the height and its
//! σ learned by laser + camera in another session, the paper's second trial), each with the
//! height a constant the filter learns (the paper) or a random walk (`walk`, a variant), and
//! our constant-velocity variant of laser + camera. Observations arrive in stamp order; of a
//! scan's leg pairs (or a frame's person detections) the one nearest the prediction
//! (Mahalanobis) inside the 3σ gate updates the filter. Scored against the ground truth at its
//! stamps with each filter's latest estimate (constant position: the estimate itself;
//! constant velocity: extrapolated).

use super::params::Params;
use super::tables::{CameraObsRow, LaserObsRow, TruthRow};
use crate::track::height_ekf::{HeightEkf, Motion, SensorAt};

/// Which sensors a filter uses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sensors {
    Fused,
    LaserOnly,
    /// Camera only, starting from a learned height and its σ (m).
    CameraOnly {
        h_m: f64,
        sigma_h_m: f64,
    },
}

/// A filter configuration of the comparison.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Method {
    pub name: &'static str,
    pub sensors: Sensors,
    pub motion: Motion,
    /// The height a random walk (`q_height_walk`) instead of `q_height` (the paper: 0).
    pub walk: bool,
}

/// The state after one observation event.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    pub stamp_ns: i64,
    pub camera_event: bool,
    pub x: f64,
    pub y: f64,
    pub h: f64,
    pub sigma_h: f64,
    pub vx: f64,
    pub vy: f64,
    pub pos_cov: [[f64; 2]; 2],
}

/// One filter run over a session.
#[derive(Debug, Clone, Default)]
pub struct Run {
    pub estimates: Vec<Estimate>,
    pub laser_accepted: usize,
    pub laser_rejected: usize,
    pub camera_accepted: usize,
    pub camera_rejected: usize,
    pub first_camera_ns: Option<i64>,
    /// Re-initialisations of the CV variant (`cv_reinit_after_s`).
    pub reinits: usize,
    /// Longest time from an accepted observation (or the start) to a later rejected event
    /// with no accepted one between: how long the filter was locked out of its gate (s).
    pub longest_lockout_s: f64,
}

impl Run {
    pub fn last(&self) -> Option<&Estimate> {
        self.estimates.last()
    }
}

enum Event<'a> {
    Laser(Vec<&'a LaserObsRow>),
    Camera(Vec<&'a CameraObsRow>),
}

/// Observations grouped per scan and per frame, in stamp order (laser first on ties).
fn events<'a>(
    laser: &'a [LaserObsRow],
    cam: &'a [CameraObsRow],
    s: Sensors,
) -> Vec<(i64, Event<'a>)> {
    let mut out: Vec<(i64, u8, i64, Event<'a>)> = Vec::new();
    if !matches!(s, Sensors::CameraOnly { .. }) {
        let mut k = 0;
        while k < laser.len() {
            let idx = laser[k].scan_idx;
            let group: Vec<&LaserObsRow> = laser[k..]
                .iter()
                .take_while(|r| r.scan_idx == idx)
                .collect();
            k += group.len();
            out.push((group[0].stamp_ns, 0, idx, Event::Laser(group)));
        }
    }
    if s != Sensors::LaserOnly {
        let mut k = 0;
        while k < cam.len() {
            let idx = cam[k].frame_idx;
            let group: Vec<&CameraObsRow> =
                cam[k..].iter().take_while(|r| r.frame_idx == idx).collect();
            k += group.len();
            out.push((group[0].stamp_ns, 1, idx, Event::Camera(group)));
        }
    }
    out.sort_by_key(|e| (e.0, e.1, e.2));
    out.into_iter().map(|(t, _, _, e)| (t, e)).collect()
}

fn laser_at(r: &LaserObsRow) -> SensorAt {
    SensorAt {
        x: r.laser_x,
        y: r.laser_y,
        z: 0.0,
        yaw: r.laser_yaw,
    }
}

fn cam_at(r: &CameraObsRow) -> SensorAt {
    SensorAt {
        x: r.cam_x,
        y: r.cam_y,
        z: r.cam_z,
        yaw: 0.0,
    }
}

/// Floor position of a laser observation (map frame).
fn laser_xy(r: &LaserObsRow) -> [f64; 2] {
    let a = r.laser_yaw + r.bearing_rad;
    [
        r.laser_x + r.range_m * a.cos(),
        r.laser_y + r.range_m * a.sin(),
    ]
}

/// Floor position a camera observation implies for a head of height `h` (level ground).
pub fn camera_xy(r: &CameraObsRow, h: f64) -> Option<[f64; 2]> {
    let rho = (h - r.cam_z) / r.elevation_rad.tan();
    (rho.is_finite() && rho > 0.0 && rho < 50.0).then(|| {
        [
            r.cam_x + rho * r.bearing_rad.cos(),
            r.cam_y + rho * r.bearing_rad.sin(),
        ]
    })
}

fn seconds(ns: i64) -> f64 {
    ns as f64 * 1e-9
}

/// Run `m` over a session's observations.
pub fn run(laser: &[LaserObsRow], cam: &[CameraObsRow], p: &Params, m: Method) -> Run {
    let ekf = if m.walk {
        p.ekf_walk(m.motion)
    } else {
        p.ekf(m.motion)
    };
    let mut out = Run::default();
    let mut f: Option<HeightEkf> = None;
    let mut last_accept_ns = i64::MIN;
    let reinit_ns = (m.motion == Motion::ConstantVelocity && p.cv_reinit_after_s > 0.0)
        .then(|| (p.cv_reinit_after_s * 1e9).round() as i64);
    for (t, ev) in events(laser, cam, m.sensors) {
        let is_cam = matches!(ev, Event::Camera(_));
        if is_cam && out.first_camera_ns.is_none() {
            out.first_camera_ns = Some(t);
        }
        let Some(filter) = f.as_mut() else {
            // start on the first observation that places the person
            f = match (&ev, m.sensors) {
                (Event::Laser(g), Sensors::Fused | Sensors::LaserOnly) => Some(HeightEkf::new(
                    ekf,
                    laser_xy(g[0]),
                    p.h0_m,
                    p.sigma_h0_m,
                    seconds(t),
                )),
                (Event::Camera(g), Sensors::CameraOnly { h_m, sigma_h_m }) => camera_xy(g[0], h_m)
                    .map(|xy| HeightEkf::new(ekf, xy, h_m, sigma_h_m, seconds(t))),
                _ => None,
            };
            if let Some(filter) = &f {
                out.estimates.push(estimate(filter, t, is_cam));
                last_accept_ns = t;
            }
            continue;
        };
        filter.predict(seconds(t));
        let mut best: Option<(f64, HeightEkf)> = None;
        let n_cand = match &ev {
            Event::Laser(g) => g.len(),
            Event::Camera(g) => g.len(),
        };
        for k in 0..n_cand {
            let mut trial = filter.clone();
            let u = match &ev {
                Event::Laser(g) => {
                    trial.update_laser(g[k].range_m, g[k].bearing_rad, &laser_at(g[k]))
                }
                Event::Camera(g) => {
                    trial.update_camera(g[k].bearing_rad, g[k].elevation_rad, &cam_at(g[k]))
                }
            };
            if u.accepted && best.as_ref().is_none_or(|(d2, _)| u.d2 < *d2) {
                best = Some((u.d2, trial));
            }
        }
        let accepted = best.is_some();
        if !accepted {
            out.longest_lockout_s = out
                .longest_lockout_s
                .max(seconds(t.saturating_sub(last_accept_ns)));
        }
        if let Some((_, trial)) = best {
            *filter = trial;
            last_accept_ns = t;
        } else if let (Some(after), Event::Laser(g)) = (reinit_ns, &ev)
            && t.saturating_sub(last_accept_ns) >= after
        {
            // our CV variant, locked out of its gate: restart at the leg pair, at rest,
            // keeping the learned height
            let (h, sigma_h) = (filter.height(), filter.sigma_height());
            *filter = HeightEkf::new(ekf, laser_xy(g[0]), h, sigma_h, seconds(t));
            last_accept_ns = t;
            out.reinits += 1;
        }
        match (is_cam, accepted) {
            (false, true) => out.laser_accepted += 1,
            (false, false) => out.laser_rejected += 1,
            (true, true) => out.camera_accepted += 1,
            (true, false) => out.camera_rejected += 1,
        }
        out.estimates.push(estimate(filter, t, is_cam));
    }
    out
}

fn estimate(f: &HeightEkf, t: i64, camera_event: bool) -> Estimate {
    let v = |i: usize| if f.x.len() > i { f.x[i] } else { 0.0 };
    Estimate {
        stamp_ns: t,
        camera_event,
        x: f.x[0],
        y: f.x[1],
        h: f.height(),
        sigma_h: f.sigma_height(),
        vx: v(3),
        vy: v(4),
        pos_cov: f.pos_cov(),
    }
}

/// A filter's error against the ground truth at one truth stamp.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scored {
    pub stamp_ns: i64,
    pub error_m: f64,
    /// Component of (truth − estimate) along the direction of motion, when the person moves
    /// faster than `lag_min_speed` (positive: the estimate lags behind).
    pub along_m: Option<f64>,
    pub speed: f64,
}

/// Score a run at every truth stamp from its first estimate on.
pub fn score(run: &Run, truth: &[TruthRow], p: &Params, motion: Motion) -> Vec<Scored> {
    let mut out = Vec::new();
    let stamps: Vec<i64> = run.estimates.iter().map(|e| e.stamp_ns).collect();
    for g in truth {
        let k = stamps.partition_point(|&s| s <= g.stamp_ns);
        let Some(e) = k.checked_sub(1).map(|k| &run.estimates[k]) else {
            continue;
        };
        let dt = seconds(g.stamp_ns - e.stamp_ns);
        let (x, y) = match motion {
            Motion::ConstantPosition => (e.x, e.y),
            Motion::ConstantVelocity => (e.x + e.vx * dt, e.y + e.vy * dt),
        };
        let (ex, ey) = (g.x - x, g.y - y);
        let speed = g.vx.hypot(g.vy);
        out.push(Scored {
            stamp_ns: g.stamp_ns,
            error_m: ex.hypot(ey),
            along_m: (speed > p.lag_min_speed).then(|| (ex * g.vx + ey * g.vy) / speed),
            speed,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camera_xy_inverts_a_known_elevation_and_laser_xy_a_known_bearing() {
        // camera at (8, 3, 2.2) looking at a 1.8 m head 4 m away along −x
        let e = (1.8f64 - 2.2).atan2(4.0);
        let r = CameraObsRow {
            frame_idx: 0,
            stamp_ns: 0,
            bearing_rad: std::f64::consts::PI,
            elevation_rad: e,
            cam_x: 8.0,
            cam_y: 3.0,
            cam_z: 2.2,
            u: 0.0,
            v: 0.0,
            x0: 0,
            y0: 0,
            x1: 0,
            y1: 0,
            skin_fraction: 1.0,
        };
        let xy = camera_xy(&r, 1.8).expect("in front");
        assert!(
            (xy[0] - 4.0).abs() < 1e-12 && (xy[1] - 3.0).abs() < 1e-12,
            "{xy:?}"
        );
        assert_eq!(
            camera_xy(&r, 2.5),
            None,
            "a head above the camera cannot look down"
        );
        let l = LaserObsRow {
            scan_idx: 0,
            stamp_ns: 0,
            range_m: 2.0,
            bearing_rad: 0.5,
            laser_x: 1.0,
            laser_y: 1.0,
            laser_yaw: std::f64::consts::FRAC_PI_2 - 0.5,
        };
        let xy = laser_xy(&l);
        assert!(
            (xy[0] - 1.0).abs() < 1e-12 && (xy[1] - 3.0).abs() < 1e-12,
            "{xy:?}"
        );
    }

    #[test]
    fn scoring_measures_the_lag_behind_a_moving_target() {
        // truth moves along +x at 1 m/s; a constant-position estimate 0.2 m behind at
        // every stamp: error 0.2, lag +0.2 m along the motion; extrapolated CV: no lag
        let p = Params::default();
        let truth: Vec<TruthRow> = (0..5)
            .map(|k| TruthRow {
                stamp_ns: k * 200_000_000,
                x: 0.2 * k as f64,
                y: 1.0,
                vx: 1.0,
                vy: 0.0,
                height_m: 1.8,
            })
            .collect();
        let est = |k: i64| Estimate {
            stamp_ns: k * 200_000_000,
            camera_event: false,
            x: 0.2 * k as f64 - 0.2,
            y: 1.0,
            h: 1.8,
            sigma_h: 0.1,
            vx: 1.0,
            vy: 0.0,
            pos_cov: [[0.01, 0.0], [0.0, 0.01]],
        };
        let run = Run {
            estimates: (0..5).map(est).collect(),
            ..Run::default()
        };
        let s = score(&run, &truth, &p, Motion::ConstantPosition);
        assert_eq!(s.len(), 5);
        for r in &s {
            assert!(
                (r.error_m - 0.2).abs() < 1e-12 && (r.along_m.expect("moving") - 0.2).abs() < 1e-12
            );
        }
        // a CV estimate from 0.2 s earlier, extrapolated with the true velocity, lands on the truth
        let run = Run {
            estimates: vec![Estimate {
                stamp_ns: 0,
                x: 0.0,
                ..est(0)
            }],
            ..Run::default()
        };
        let s = score(&run, &truth, &p, Motion::ConstantVelocity);
        assert!(s.iter().all(|r| r.error_m < 1e-9), "{s:?}");
    }
}

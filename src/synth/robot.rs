//! The robot's motion: standing still, touring between stops (turn in place, drive, dwell), or
//! following a person along their path (pure pursuit on the person's trail at a following
//! distance, speed and acceleration limited). A self-balancing base pitches forward while it
//! accelerates (first-order lag to `pitch_deg_per_mps2 · a`), which tilts a base-mounted laser
//! towards the ground — the "gnd" events of seed 001. Odometry integrates the true speeds with
//! relative speed error and yaw-rate noise, so it drifts as real odometry does.

use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use rand::RngExt;
use rand_distr::{Distribution, Normal};

use super::motion::{DT, Track};
use super::scenario::{Follow, Robot, RobotMode};
use crate::rng;

/// Robot state at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RobotState {
    pub x: f64,
    pub y: f64,
    pub yaw: f64,
    pub v: f64,
    pub w: f64,
    pub accel: f64,
    /// Positive pitch = nose down (REP 103).
    pub pitch: f64,
    pub pitch_rate: f64,
}

impl RobotState {
    /// `map_from_base_link`.
    pub fn pose(&self) -> Isometry3<f64> {
        Isometry3::from_parts(
            Translation3::new(self.x, self.y, 0.0),
            UnitQuaternion::from_euler_angles(0.0, self.pitch, self.yaw),
        )
    }
}

/// The robot's motion sampled every [`DT`].
#[derive(Debug, Clone)]
pub struct RobotTrack {
    pub samples: Vec<RobotState>,
}

impl RobotTrack {
    /// Whether [`RobotTrack::state`] at `t` interpolates between two held samples (rather
    /// than holding the last one): true for every `t` of a finished track's duration, and
    /// what a track still being simulated needs before it is read at `t`.
    pub fn holds(&self, t: f64) -> bool {
        let i = (t / DT).max(0.0).floor() as usize;
        i + 1 < self.samples.len()
    }

    pub fn state(&self, t: f64) -> RobotState {
        let f = (t / DT).max(0.0);
        let i = (f.floor() as usize).min(self.samples.len().saturating_sub(1));
        let j = (i + 1).min(self.samples.len().saturating_sub(1));
        let w = (f - i as f64).clamp(0.0, 1.0);
        let (a, b) = (self.samples[i], self.samples[j]);
        let l = |p: f64, q: f64| p + (q - p) * w;
        let mut dyaw = b.yaw - a.yaw;
        dyaw =
            (dyaw + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
        RobotState {
            x: l(a.x, b.x),
            y: l(a.y, b.y),
            yaw: a.yaw + dyaw * w,
            v: l(a.v, b.v),
            w: l(a.w, b.w),
            accel: l(a.accel, b.accel),
            pitch: l(a.pitch, b.pitch),
            pitch_rate: l(a.pitch_rate, b.pitch_rate),
        }
    }
}

/// Standard deviation of the balancing controller's pitch command noise (rad).
pub const PITCH_JITTER_RAD: f64 = 0.004;

/// One [`DT`] of a self-balancing base whose speed just changed from `prev_v` to `s.v` (yaw
/// rate `s.w` set): the acceleration, the pitch's first-order lag (time constant
/// `pitch_tau_s`) to `pitch_deg_per_mps2 · a` plus `jitter` (rad), then the pose integrated.
pub fn balance_and_drive(s: &mut RobotState, prev_v: f64, f: &Follow, jitter: f64) {
    s.accel = (s.v - prev_v) / DT;
    let pitch_cmd = f.pitch_deg_per_mps2.to_radians() * s.accel + jitter;
    let prev_pitch = s.pitch;
    s.pitch += (pitch_cmd - s.pitch) * DT / f.pitch_tau_s;
    s.pitch_rate = (s.pitch - prev_pitch) / DT;
    s.x += s.v * s.yaw.cos() * DT;
    s.y += s.v * s.yaw.sin() * DT;
    s.yaw = wrap(s.yaw + s.w * DT);
}

pub(crate) fn wrap(a: f64) -> f64 {
    (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
}

/// Simulate the robot for `duration` seconds. `target` is the followed person's track.
pub fn simulate(
    spec: &Robot,
    duration: f64,
    target: Option<&Track>,
    seed: u64,
    session: u64,
) -> RobotTrack {
    let n = (duration / DT).ceil() as usize + 2;
    let mut s = RobotState {
        x: spec.pose[0],
        y: spec.pose[1],
        yaw: spec.pose[2].to_radians(),
        ..Default::default()
    };
    let mut samples = Vec::with_capacity(n);
    let mut r = rng::stream(seed, "robot", session);
    match spec.mode {
        RobotMode::Static => samples.resize(n, s),
        RobotMode::Tour => {
            let tour = spec.tour.as_ref().expect("validated: tour mode has a tour");
            // a first stop the robot already stands on is where it dwells first
            let at_first = tour
                .stops
                .first()
                .is_some_and(|p| (p[0] - s.x).hypot(p[1] - s.y) < 0.1);
            let mut stop = usize::from(at_first);
            let mut dwell = if at_first { tour.dwell_s } else { 0.0 };
            for _ in 0..n {
                samples.push(s);
                let prev_v = s.v;
                if dwell > 0.0 {
                    dwell -= DT;
                    s.v = (s.v - 0.5 * DT).max(0.0);
                    s.w = 0.0;
                } else if let Some(goal) = tour.stops.get(stop) {
                    let (dx, dy) = (goal[0] - s.x, goal[1] - s.y);
                    let dist = dx.hypot(dy);
                    if dist > 0.05 {
                        let err = wrap(dy.atan2(dx) - s.yaw);
                        if err.abs() > 0.05 && s.v < 0.05 {
                            s.w = err.signum() * 0.6_f64.min(err.abs() / DT);
                            s.v = 0.0;
                        } else {
                            s.w = (2.0 * err).clamp(-0.6, 0.6);
                            let v_des = tour.speed.min((2.0 * 0.5 * dist).sqrt());
                            s.v += (v_des - s.v).clamp(-0.5 * DT, 0.5 * DT);
                        }
                    } else {
                        let err = wrap(goal[2].to_radians() - s.yaw);
                        s.v = 0.0;
                        if err.abs() > 0.02 {
                            s.w = err.signum() * 0.6_f64.min(err.abs() / DT);
                        } else {
                            s.w = 0.0;
                            stop += 1;
                            dwell = tour.dwell_s;
                        }
                    }
                    s.x += s.v * s.yaw.cos() * DT;
                    s.y += s.v * s.yaw.sin() * DT;
                    s.yaw = wrap(s.yaw + s.w * DT);
                } else {
                    s.v = 0.0;
                    s.w = 0.0;
                }
                s.accel = (s.v - prev_v) / DT;
            }
        }
        RobotMode::Follow => {
            let f = spec
                .follow
                .as_ref()
                .expect("validated: follow mode has parameters");
            let target = target.expect("validated: follow mode has a target track");
            let mut trail: Vec<(f64, f64)> = Vec::new();
            let mut progress = 0usize;
            let jitter = Normal::new(0.0, PITCH_JITTER_RAD).expect("valid sigma");
            for k in 0..n {
                samples.push(s);
                let t = k as f64 * DT;
                let Some(p) = target.state(t) else {
                    s.v = (s.v - f.max_accel * DT).max(0.0);
                    continue;
                };
                if trail
                    .last()
                    .is_none_or(|l| (l.0 - p.x).hypot(l.1 - p.y) > 0.05)
                {
                    trail.push((p.x, p.y));
                }
                // advance along the trail past points we have reached
                while progress + 1 < trail.len()
                    && (trail[progress].0 - s.x).hypot(trail[progress].1 - s.y) < 0.6
                {
                    progress += 1;
                }
                let range = (p.x - s.x).hypot(p.y - s.y);
                // close to the target: head straight for it (direct following); far: follow
                // its path, which keeps the robot on ground the person walked
                let aim = if range < 6.0 {
                    (p.x, p.y)
                } else {
                    trail[progress..]
                        .iter()
                        .find(|q| (q.0 - s.x).hypot(q.1 - s.y) > 1.0)
                        .copied()
                        .unwrap_or((p.x, p.y))
                };
                let err = wrap((aim.1 - s.y).atan2(aim.0 - s.x) - s.yaw);
                s.w = (2.0 * err).clamp(-1.5, 1.5);
                let v_des = if range > f.distance {
                    (1.2 * (range - f.distance) + p.speed).min(f.max_speed)
                } else {
                    0.0
                } * (1.0 - 0.6 * err.abs().min(1.0));
                let prev_v = s.v;
                s.v += (v_des - s.v).clamp(-f.max_accel * DT, f.max_accel * DT);
                balance_and_drive(&mut s, prev_v, f, jitter.sample(&mut r));
            }
        }
    }
    let _ = r.random::<u8>();
    RobotTrack { samples }
}

/// One odometry sample: time (s), pose `[x, y, yaw]` in `odom`, measured speed and yaw rate.
pub type OdometrySample = (f64, [f64; 3], f64, f64);

/// Odometry pose `(x, y, yaw)` in the `odom` frame at times `t_k = k / rate`, integrating the
/// true speeds with noise. `odom` starts at the robot's start pose.
pub fn odometry(
    track: &RobotTrack,
    noise: [f64; 2],
    rate: f64,
    duration: f64,
    seed: u64,
    session: u64,
) -> Vec<OdometrySample> {
    let mut o = Odometer::new(noise, rate, duration, seed, session);
    o.advance(track);
    o.samples
}

/// Wheel odometry integrated tick by tick as the robot's track grows, so a closed loop reads
/// at every scan exactly the pose `/odom` will carry ([`odometry`] runs it over a whole track:
/// the same draws in the same order).
pub struct Odometer {
    r: rand_chacha::ChaCha8Rng,
    dv: Normal<f64>,
    dw: Normal<f64>,
    /// A wheel-radius error: a constant relative speed error.
    bias: f64,
    pose: [f64; 3],
    t: f64,
    dt: f64,
    duration: f64,
    /// Every tick integrated so far.
    pub samples: Vec<OdometrySample>,
}

impl Odometer {
    pub fn new(noise: [f64; 2], rate: f64, duration: f64, seed: u64, session: u64) -> Self {
        let mut r = rng::stream(seed, "odometry", session);
        let dv = Normal::new(0.0, noise[0].max(0.0)).expect("valid sigma");
        let dw = Normal::new(0.0, noise[1].max(0.0)).expect("valid sigma");
        let bias = dv.sample(&mut r);
        Odometer {
            r,
            dv,
            dw,
            bias,
            pose: [0.0; 3],
            t: 0.0,
            dt: 1.0 / rate,
            duration,
            samples: Vec::new(),
        }
    }

    /// Integrate every tick whose true state `track` already holds (both samples around it).
    pub fn advance(&mut self, track: &RobotTrack) {
        while self.t < self.duration - 1e-9 && track.holds(self.t) {
            let s = track.state(self.t);
            let v = s.v * (1.0 + self.bias) + 0.2 * self.dv.sample(&mut self.r) * s.v.abs();
            let w = s.w + self.dw.sample(&mut self.r);
            let [x, y, yaw] = self.pose;
            self.samples.push((self.t, self.pose, v, w));
            self.pose = [
                x + v * yaw.cos() * self.dt,
                y + v * yaw.sin() * self.dt,
                wrap(yaw + w * self.dt),
            ];
            self.t += self.dt;
        }
    }

    /// The odometry pose at `t` and its measured speed: the last tick at or before `t`
    /// carried forward with that tick's speeds — what interpolating `/odom` (or `odom ->
    /// base_link` on `/tf`) between its ticks gives. `None` before the first tick.
    pub fn pose_at(&self, t: f64) -> Option<([f64; 3], f64)> {
        let k = self.samples.partition_point(|s| s.0 <= t);
        let (tk, [x, y, yaw], v, w) = *self.samples.get(k.checked_sub(1)?)?;
        let h = t - tk;
        Some((
            [
                x + v * yaw.cos() * h,
                y + v * yaw.sin() * h,
                wrap(yaw + w * h),
            ],
            v,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::motion::{Goal, walk};

    #[test]
    fn follower_keeps_its_distance_and_pitches_when_accelerating() {
        let mut r = rng::stream(3, "t", 0);
        let goals = [Goal {
            x: 30.0,
            y: 0.0,
            speed: 1.8,
            pause: 0.0,
        }];
        let target = walk((3.0, 0.0, 0.0), &goals, 0.0, 30.0, &mut r);
        let spec = Robot {
            mode: RobotMode::Follow,
            pose: [0.0, 0.0, 0.0],
            follow: Some(Follow {
                target: 1,
                distance: 1.8,
                max_speed: 2.2,
                max_accel: 1.0,
                pitch_deg_per_mps2: 6.0,
                pitch_tau_s: 0.3,
                closed_loop: false,
                controllers: vec![],
                max_decel: None,
                max_turn_rate: 1.5,
                estimator: Default::default(),
                pdaf: Default::default(),
                platform: Default::default(),
                lost: Default::default(),
            }),
            tour: None,
            odom_noise: [0.0, 0.0],
            odom_rate_hz: 50.0,
            imu_rate_hz: 100.0,
        };
        let tr = simulate(&spec, 30.0, Some(&target), 3, 0);
        let s = tr.state(12.0);
        let p = target.state(12.0).expect("walking");
        let range = (p.x - s.x).hypot(p.y - s.y);
        assert!(range > 1.5 && range < 3.0, "range {range}");
        let max_pitch = tr.samples.iter().map(|s| s.pitch).fold(0.0, f64::max);
        assert!(max_pitch.to_degrees() > 3.0, "{}", max_pitch.to_degrees());
        // noise-free odometry reproduces the true path
        let odo = odometry(&tr, [0.0, 0.0], 50.0, 10.0, 3, 0);
        let (t_last, [ox, oy, _], _, _) = odo[odo.len() - 1];
        let truth = tr.state(t_last);
        assert!((ox - truth.x).abs() < 0.05 && (oy - truth.y).abs() < 0.05);
    }
}

//! How people move: a walker that heads for goals with human speeds, accelerations and turn
//! rates, slowing to stop where it pauses, with a gait phase that advances with distance; goal
//! lists from waypoints, random wandering that avoids obstacles, visitors who enter and leave
//! by doors, passers-by crossing between a robot and its target; a cooperating jogger's route
//! and the people who run beside them ([`jog`]); and replay of real recorded trajectories
//! (`frame id x y` at 2.5 Hz, interpolated with Catmull–Rom splines).
//!
//! Tracks are sampled every 10 ms once, before any sensor runs, so sensors are pure functions
//! of time and can be rendered in any order.

use std::path::Path;

use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use super::person::{Body, PersonState};
use super::world::Obstacle;

pub mod jog;

/// Sample period of tracks (s).
pub const DT: f64 = 0.01;

/// A person's motion over a session.
#[derive(Debug, Clone, PartialEq)]
pub struct Track {
    /// Time of the first sample (the person enters).
    pub start: f64,
    /// `[x, y, heading, speed, phase]` every [`DT`].
    pub samples: Vec<[f64; 5]>,
    /// The person leaves (is absent) after this time.
    pub leave: f64,
}

impl Track {
    /// State at `t`, or `None` when the person is not in the scene.
    pub fn state(&self, t: f64) -> Option<PersonState> {
        if t < self.start || t > self.leave || self.samples.is_empty() {
            return None;
        }
        let f = (t - self.start) / DT;
        let i = (f.floor() as usize).min(self.samples.len() - 1);
        let j = (i + 1).min(self.samples.len() - 1);
        let w = (f - i as f64).clamp(0.0, 1.0);
        let (a, b) = (self.samples[i], self.samples[j]);
        let lerp = |k: usize| a[k] + (b[k] - a[k]) * w;
        let mut dh = b[2] - a[2];
        dh = (dh + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
        let heading = a[2] + dh * w;
        // velocity from neighbouring samples (central difference)
        let (p, n) = (self.samples[i.saturating_sub(1)], self.samples[j]);
        let span = (j - i.saturating_sub(1)).max(1) as f64 * DT;
        Some(PersonState {
            x: lerp(0),
            y: lerp(1),
            heading,
            speed: lerp(3),
            vx: (n[0] - p[0]) / span,
            vy: (n[1] - p[1]) / span,
            phase: lerp(4),
        })
    }

    /// Position at `t` (clamped to the track's span).
    pub fn position(&self, t: f64) -> Option<(f64, f64)> {
        self.state(t.clamp(self.start, self.leave))
            .map(|s| (s.x, s.y))
    }
}

/// Somewhere to walk to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Goal {
    pub x: f64,
    pub y: f64,
    pub speed: f64,
    /// Standing time on arrival (s).
    pub pause: f64,
}

const ACCEL: f64 = 1.2;
const TURN_RATE: f64 = 2.5;

fn wrap(a: f64) -> f64 {
    (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
}

/// Simulate a walker from `(x, y, heading)` through `goals`, from `t0` to `t1` (it stands at its
/// last goal afterwards). `rng` adds natural speed variation.
pub fn walk(
    start: (f64, f64, f64),
    goals: &[Goal],
    t0: f64,
    t1: f64,
    rng: &mut ChaCha8Rng,
) -> Track {
    let (mut x, mut y, mut h) = start;
    let (mut v, mut phase) = (0.0f64, rng.random::<f64>() * std::f64::consts::TAU);
    let mut samples = Vec::with_capacity(((t1 - t0) / DT) as usize + 2);
    let mut g = 0usize;
    let mut paused = 0.0f64;
    let wobble_f = 0.2 + 0.2 * rng.random::<f64>();
    let wobble_p = rng.random::<f64>() * std::f64::consts::TAU;
    let mut t = t0;
    while t <= t1 + 1e-9 {
        samples.push([x, y, h, v, phase]);
        if let Some(goal) = goals.get(g) {
            let (dx, dy) = (goal.x - x, goal.y - y);
            let dist = dx.hypot(dy);
            if paused > 0.0 {
                paused -= DT;
                v = (v - ACCEL * DT).max(0.0);
                if paused <= 0.0 {
                    g += 1;
                }
            } else if dist < 0.05 + v * DT {
                if goal.pause > 0.0 {
                    paused = goal.pause;
                } else {
                    g += 1;
                }
            } else {
                let want_h = dy.atan2(dx);
                let err = wrap(want_h - h);
                h = wrap(h + err.clamp(-TURN_RATE * DT, TURN_RATE * DT));
                // slow down for sharp turns and to stop where we pause
                let mut v_des = goal.speed
                    * (1.0 + 0.05 * (std::f64::consts::TAU * wobble_f * t + wobble_p).sin());
                if err.abs() > 1.0 {
                    v_des *= 0.3;
                }
                let next_pauses = goal.pause > 0.0 || g + 1 == goals.len();
                if next_pauses {
                    v_des = v_des.min((2.0 * ACCEL * dist).sqrt());
                }
                v += (v_des - v).clamp(-ACCEL * DT, ACCEL * DT);
                x += v * h.cos() * DT;
                y += v * h.sin() * DT;
            }
        } else {
            v = (v - ACCEL * DT).max(0.0);
        }
        phase += std::f64::consts::PI * v * DT / Body::stride(v.max(0.3));
        t += DT;
    }
    Track {
        start: t0,
        samples,
        leave: t1,
    }
}

/// True if the segment a–b keeps `margin` from every obstacle (checked every 5 cm).
pub fn segment_clear(a: (f64, f64), b: (f64, f64), obstacles: &[Obstacle], margin: f64) -> bool {
    let len = (b.0 - a.0).hypot(b.1 - a.1);
    let n = (len / 0.05).ceil().max(1.0) as usize;
    (0..=n).all(|k| {
        let u = k as f64 / n as f64;
        let (x, y) = (a.0 + u * (b.0 - a.0), a.1 + u * (b.1 - a.1));
        obstacles.iter().all(|o| o.distance(x, y) > margin)
    })
}

/// Random goals inside `area` reachable in straight lines, for `duration` seconds of walking.
#[allow(clippy::too_many_arguments)]
pub fn wander_goals(
    from: (f64, f64),
    area: [f64; 4],
    speed: [f64; 2],
    pause: [f64; 2],
    duration: f64,
    obstacles: &[Obstacle],
    rng: &mut ChaCha8Rng,
) -> Vec<Goal> {
    let mut goals = Vec::new();
    let mut at = from;
    let mut time = 0.0;
    let mut tries = 0;
    while time < duration && tries < 20_000 {
        tries += 1;
        let p = (
            area[0] + rng.random::<f64>() * (area[2] - area[0]),
            area[1] + rng.random::<f64>() * (area[3] - area[1]),
        );
        let len = (p.0 - at.0).hypot(p.1 - at.1);
        if len < 1.0 || !segment_clear(at, p, obstacles, 0.35) {
            continue;
        }
        let s = speed[0] + rng.random::<f64>() * (speed[1] - speed[0]);
        let ps = pause[0] + rng.random::<f64>() * (pause[1] - pause[0]);
        goals.push(Goal {
            x: p.0,
            y: p.1,
            speed: s,
            pause: ps,
        });
        time += len / s + ps + 1.0;
        at = p;
    }
    goals
}

/// Read track `id` from an ETH/UCY-style file (`frame id x y`, 2.5 Hz) and sample it every
/// [`DT`] with a Catmull–Rom spline, turned by `rotate` (rad) and moved by `offset`.
pub fn replay(
    path: &Path,
    id: u32,
    offset: [f64; 2],
    rotate: f64,
    t0: f64,
) -> Result<Track, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let mut pts: Vec<(f64, f64, f64)> = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let f: Vec<&str> = line.split_whitespace().collect();
        if f.len() < 4 {
            continue;
        }
        let parse = |s: &str| {
            s.parse::<f64>()
                .map_err(|_| format!("{}:{}: `{s}` is not a number", path.display(), n + 1))
        };
        let (frame, pid, x, y) = (parse(f[0])?, parse(f[1])?, parse(f[2])?, parse(f[3])?);
        if pid as u32 == id {
            let (s, c) = rotate.sin_cos();
            pts.push((
                frame / 10.0 * 0.4,
                c * x - s * y + offset[0],
                s * x + c * y + offset[1],
            ));
        }
    }
    if pts.len() < 2 {
        return Err(format!(
            "{}: track {id} has {} points (need 2)",
            path.display(),
            pts.len()
        ));
    }
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    let first = pts[0].0;
    let dur = pts[pts.len() - 1].0 - first;
    let at = |k: isize| {
        let k = k.clamp(0, pts.len() as isize - 1) as usize;
        (pts[k].1, pts[k].2)
    };
    let mut samples = Vec::new();
    let mut phase = 0.0;
    let n = (dur / DT) as usize;
    let mut prev: Option<(f64, f64)> = None;
    let mut heading = 0.0;
    for i in 0..=n {
        let t = i as f64 * DT;
        let seg = pts
            .partition_point(|p| p.0 - first <= t)
            .saturating_sub(1)
            .min(pts.len() - 2);
        let (ta, tb) = (pts[seg].0 - first, pts[seg + 1].0 - first);
        let u = ((t - ta) / (tb - ta)).clamp(0.0, 1.0);
        let s = seg as isize;
        let (p0, p1, p2, p3) = (at(s - 1), at(s), at(s + 1), at(s + 2));
        let cr = |a: f64, b: f64, c: f64, d: f64| {
            0.5 * (2.0 * b
                + (-a + c) * u
                + (2.0 * a - 5.0 * b + 4.0 * c - d) * u * u
                + (-a + 3.0 * b - 3.0 * c + d) * u * u * u)
        };
        let (x, y) = (cr(p0.0, p1.0, p2.0, p3.0), cr(p0.1, p1.1, p2.1, p3.1));
        let v = prev.map_or(0.0, |(px, py)| (x - px).hypot(y - py) / DT);
        if let Some((px, py)) = prev
            && v > 0.05
        {
            heading = (y - py).atan2(x - px);
        }
        phase += std::f64::consts::PI * v * DT / Body::stride(v.max(0.3));
        samples.push([x, y, heading, v, phase]);
        prev = Some((x, y));
    }
    Ok(Track {
        start: t0,
        leave: t0 + dur,
        samples,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng;

    #[test]
    fn walker_reaches_goals_at_human_speed_and_pauses() {
        let mut r = rng::stream(1, "t", 0);
        let goals = [
            Goal {
                x: 5.0,
                y: 0.0,
                speed: 1.2,
                pause: 2.0,
            },
            Goal {
                x: 5.0,
                y: 4.0,
                speed: 1.0,
                pause: 0.0,
            },
        ];
        let tr = walk((0.0, 0.0, 0.0), &goals, 0.0, 20.0, &mut r);
        let max_v = tr.samples.iter().map(|s| s[3]).fold(0.0, f64::max);
        assert!(max_v > 1.1 && max_v < 1.3, "{max_v}");
        let end = tr.state(20.0).expect("present");
        assert!(
            (end.x - 5.0).abs() < 0.1 && (end.y - 4.0).abs() < 0.1,
            "{end:?}"
        );
        // somewhere it stood still at the first goal for about two seconds
        let still = tr
            .samples
            .iter()
            .filter(|s| s[3] < 0.05 && (s[0] - 5.0).abs() < 0.1 && s[1].abs() < 0.1)
            .count();
        assert!(still as f64 * DT > 1.5, "{}", still as f64 * DT);
        assert!(tr.state(-1.0).is_none() && tr.state(21.0).is_none());
    }

    #[test]
    fn replay_of_a_real_eth_track_has_walking_speeds() {
        let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../shared/real/eth_ucy/biwi_eth.txt");
        if !path.exists() {
            eprintln!("SKIPPED: {} absent", path.display());
            return;
        }
        let tr = replay(&path, 1, [0.0, 0.0], 0.0, 0.0).expect("track 1");
        let first = tr.state(0.0).expect("start");
        assert!((first.x - 8.46).abs() < 1e-9 && (first.y - 3.59).abs() < 1e-9);
        let mean_v = tr.samples.iter().map(|s| s[3]).sum::<f64>() / tr.samples.len() as f64;
        assert!(mean_v > 0.5 && mean_v < 3.0, "{mean_v}");
    }
}

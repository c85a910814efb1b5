//! A cooperating jogger, as seed 001's subject ran with the robot (§VI: a park "with scattered
//! trees and small bushes", a person "of speeds near 3 m/s"; the bearing to them "does not
//! exceed 30°" in fig. 7), and the people who keep them company.
//!
//! - **Route** ([`route`]): straight stretches joined by turns a runner makes at speed. Each
//!   stretch (the first from the start heading) turns by at most `max_turn_deg` from the last
//!   (a corner of a path, never a U-turn: a runner who reverses stops first), is `stretch_m`
//!   long, keeps `clearance_m` from every tree and bush (paths between trees) and ends inside
//!   `area`; its pace is drawn from `speed`. When 200 draws find no such stretch (the park's edge), the bound widens by 15° at
//!   a time ([`Route::widened`] counts those turns).
//! - **Running** ([`run`]): heading rate bounded by the lateral acceleration a runner holds in a
//!   curve, `ω ≤ a_lat / v` (and [`MAX_TURN_RATE`] at a walk), pace changed at `accel`; the
//!   corner is rounded on its arc, starting at the tangent point `(v² / a_lat) · tan(Δψ / 2)`
//!   before it (at most half the next stretch). No slowing for the turns the bound allows.
//! - **Company** ([`companion`]): someone who runs beside the target (1 m to one side), then
//!   crosses behind them — between the following robot and the target, seed 001's "walk together
//!   with the tracked person and then cross the path" — and runs on at their other side.
//!
//! The bounds are a priori, not fitted to any result: `a_lat` 2 m/s² (about 0.2 g, a jogger's
//! comfortable cornering; sprinters on tight curves hold several times that), 90° turns at
//! most, `accel` 1 m/s².

use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use super::{DT, Goal, Track, segment_clear};
use crate::synth::person::Body;
use crate::synth::world::Obstacle;

/// Heading rate limit at low speed (rad/s), where `a_lat / v` would be larger.
pub const MAX_TURN_RATE: f64 = 2.5;
/// Draws per turn before the turn bound widens.
const TRIES_PER_BOUND: usize = 200;
/// How much the turn bound widens at a time (deg).
const WIDEN_DEG: f64 = 15.0;

/// The route's settings (`motion = { type = "jog", ... }`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RouteSpec {
    pub area: [f64; 4],
    pub speed: [f64; 2],
    pub stretch_m: [f64; 2],
    pub max_turn_deg: f64,
    pub clearance_m: f64,
}

/// A route: its corners (the first is the start) and their paces.
#[derive(Debug, Clone, PartialEq)]
pub struct Route {
    pub goals: Vec<Goal>,
    /// Turns that needed a wider bound than `max_turn_deg`.
    pub widened: usize,
}

fn wrap(a: f64) -> f64 {
    (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
}

/// A route from `start` heading `heading` (rad) long enough for `duration` seconds.
pub fn route(
    start: (f64, f64),
    heading: f64,
    spec: &RouteSpec,
    duration: f64,
    obstacles: &[Obstacle],
    rng: &mut ChaCha8Rng,
) -> Route {
    let mut goals = Vec::new();
    let (mut at, mut h) = (start, heading);
    let (mut time, mut widened) = (0.0, 0usize);
    let inside = |p: (f64, f64)| {
        p.0 >= spec.area[0] && p.0 <= spec.area[2] && p.1 >= spec.area[1] && p.1 <= spec.area[3]
    };
    let draw = |lo: f64, hi: f64, r: &mut ChaCha8Rng| lo + r.random::<f64>() * (hi - lo);
    while time < duration {
        let mut bound = spec.max_turn_deg.to_radians();
        let mut tries = 0usize;
        let next = loop {
            tries += 1;
            let turn = draw(-bound, bound, rng);
            let len = draw(spec.stretch_m[0], spec.stretch_m[1], rng);
            let dir = wrap(h + turn);
            let p = (at.0 + len * dir.cos(), at.1 + len * dir.sin());
            if inside(p) && segment_clear(at, p, obstacles, spec.clearance_m) {
                break Some((p, dir, len, bound > spec.max_turn_deg.to_radians()));
            }
            if tries.is_multiple_of(TRIES_PER_BOUND) {
                if bound >= std::f64::consts::PI {
                    break None;
                }
                bound = (bound + WIDEN_DEG.to_radians()).min(std::f64::consts::PI);
            }
        };
        let Some((p, dir, len, wide)) = next else {
            break;
        };
        let speed = draw(spec.speed[0], spec.speed[1], rng);
        goals.push(Goal {
            x: p.0,
            y: p.1,
            speed,
            pause: 0.0,
        });
        widened += usize::from(wide);
        time += len / speed;
        at = p;
        h = dir;
    }
    Route { goals, widened }
}

/// Run `goals` from `start` (x, y, heading) between `t0` and `t1` (see the module doc);
/// `lateral_accel` (m/s²) bounds the heading rate, `accel` (m/s²) the pace changes. The runner
/// slows to a stop at the last goal.
pub fn run(
    start: (f64, f64, f64),
    goals: &[Goal],
    lateral_accel: f64,
    accel: f64,
    (t0, t1): (f64, f64),
    rng: &mut ChaCha8Rng,
) -> Track {
    let (mut x, mut y, mut h) = start;
    let (mut v, mut phase) = (0.0f64, rng.random::<f64>() * std::f64::consts::TAU);
    let mut samples = Vec::with_capacity(((t1 - t0) / DT) as usize + 2);
    let mut g = 0usize;
    let mut t = t0;
    while t <= t1 + 1e-9 {
        samples.push([x, y, h, v, phase]);
        // round the corner on its arc: switch to the next stretch at the tangent point
        while let (Some(goal), Some(next)) = (goals.get(g), goals.get(g + 1)) {
            let (dx, dy) = (goal.x - x, goal.y - y);
            let dist = dx.hypot(dy);
            let turn = wrap((next.y - goal.y).atan2(next.x - goal.x) - dy.atan2(dx)).abs();
            let next_len = (next.x - goal.x).hypot(next.y - goal.y);
            let cut = (v * v / lateral_accel * (0.5 * turn).tan()).min(0.5 * next_len);
            if dist < 0.05 + v * DT || dist < cut {
                g += 1;
            } else {
                break;
            }
        }
        if let Some(goal) = goals.get(g) {
            let (dx, dy) = (goal.x - x, goal.y - y);
            let dist = dx.hypot(dy);
            if dist < 0.05 + v * DT {
                // the last goal: stand there
                g += 1;
                v = 0.0;
                t += DT;
                continue;
            }
            let want = dy.atan2(dx);
            let err = wrap(want - h);
            let w_max = (lateral_accel / v.max(1e-3)).min(MAX_TURN_RATE);
            h = wrap(h + err.clamp(-w_max * DT, w_max * DT));
            let mut v_des = goal.speed;
            if err.abs() > std::f64::consts::FRAC_PI_2 {
                // a turn wider than a corner (only where the route had to widen): slow to turn
                v_des = v_des.min(1.0);
            }
            if g + 1 == goals.len() {
                v_des = v_des.min((2.0 * accel * dist).sqrt());
            }
            v += (v_des - v).clamp(-accel * DT, accel * DT);
            x += v * h.cos() * DT;
            y += v * h.sin() * DT;
        } else {
            v = (v - accel * DT).max(0.0);
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

/// Where a companion runs relative to the target: beside it at `side · offset_m` (left
/// positive), and how it crosses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Company {
    /// +1: starts on the target's left; −1: on its right.
    pub side: f64,
    pub offset_m: f64,
    /// How far behind the target (towards the following robot) the crossing passes (m).
    pub behind_m: f64,
    /// Joins from `offset_m + 3` m to the side over this long (s).
    pub join_s: f64,
    /// Crosses this long after entering (s), over `cross_s`.
    pub cross_at_s: f64,
    pub cross_s: f64,
}

/// A companion's track from `enter` to `leave` beside `target` (see the module doc).
pub fn companion(target: &Track, c: &Company, enter: f64, leave: f64) -> Track {
    let mut samples = Vec::new();
    let mut t = enter;
    let (mut phase, mut prev): (f64, Option<(f64, f64)>) = (0.0, None);
    let mut heading = 0.0;
    while t <= leave + 1e-9 {
        let Some(s) = target.state(t) else {
            break;
        };
        let (fwd, left) = (
            (s.heading.cos(), s.heading.sin()),
            (-s.heading.sin(), s.heading.cos()),
        );
        let since = t - enter;
        let join = (1.0 - since / c.join_s.max(1e-9)).clamp(0.0, 1.0);
        let u = ((since - c.cross_at_s) / c.cross_s.max(1e-9)).clamp(0.0, 1.0);
        let lateral = c.side * (c.offset_m * (std::f64::consts::PI * u).cos() + 3.0 * join);
        let along = -c.behind_m * (std::f64::consts::PI * u).sin();
        let (x, y) = (
            s.x + along * fwd.0 + lateral * left.0,
            s.y + along * fwd.1 + lateral * left.1,
        );
        let v = prev.map_or(s.speed, |(px, py)| (x - px).hypot(y - py) / DT);
        if let Some((px, py)) = prev
            && v > 0.05
        {
            heading = (y - py).atan2(x - px);
        } else if prev.is_none() {
            heading = s.heading;
        }
        phase += std::f64::consts::PI * v * DT / Body::stride(v.max(0.3));
        samples.push([x, y, heading, v, phase]);
        prev = Some((x, y));
        t += DT;
    }
    let end = enter + (samples.len().saturating_sub(1)) as f64 * DT;
    Track {
        start: enter,
        samples,
        leave: leave.min(end),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng;

    fn spec() -> RouteSpec {
        RouteSpec {
            area: [6.0, 6.0, 44.0, 44.0],
            speed: [1.5, 3.0],
            stretch_m: [8.0, 25.0],
            max_turn_deg: 90.0,
            clearance_m: 0.6,
        }
    }

    /// Trees on a grid: every stretch keeps its clearance, stays in the area and turns by at
    /// most the bound from the one before unless the route had to widen.
    #[test]
    fn route_stretches_keep_clear_and_turn_within_the_bound() {
        let trees: Vec<Obstacle> = (0..6)
            .flat_map(|i| {
                (0..6).map(move |j| {
                    Obstacle::disc(8.0 + 6.5 * f64::from(i), 9.0 + 6.0 * f64::from(j), 0.3)
                })
            })
            .collect();
        let mut r = rng::stream(3, "jog", 0);
        let rt = route((25.0, 25.5), 0.8, &spec(), 180.0, &trees, &mut r);
        assert!(rt.goals.len() > 8, "{}", rt.goals.len());
        let mut at = (25.0, 25.5);
        let mut h = 0.8;
        let mut sharp = 0;
        for g in &rt.goals {
            let p = (g.x, g.y);
            assert!(segment_clear(at, p, &trees, 0.6));
            assert!(p.0 >= 6.0 && p.0 <= 44.0 && p.1 >= 6.0 && p.1 <= 44.0);
            assert!((1.5..=3.0).contains(&g.speed));
            let dir = (p.1 - at.1).atan2(p.0 - at.0);
            let turn = wrap(dir - h).abs().to_degrees();
            sharp += usize::from(turn > 90.0 + 1e-9);
            at = p;
            h = dir;
        }
        assert!(
            sharp <= rt.widened,
            "{sharp} sharp turns, {} widened",
            rt.widened
        );
    }

    /// Running the route: never faster than the pace drawn, never turning faster than a_lat / v
    /// (and the low-speed cap), and it rounds a right-angle corner on an arc of radius v²/a_lat.
    #[test]
    fn running_respects_the_lateral_acceleration_and_rounds_corners() {
        let goals = [
            Goal {
                x: 20.0,
                y: 0.0,
                speed: 3.0,
                pause: 0.0,
            },
            Goal {
                x: 20.0,
                y: 20.0,
                speed: 3.0,
                pause: 0.0,
            },
        ];
        let mut r = rng::stream(5, "jog", 0);
        let tr = run((0.0, 0.0, 0.0), &goals, 2.0, 1.0, (0.0, 20.0), &mut r);
        let mut worst_lat: f64 = 0.0;
        for w in tr.samples.windows(2) {
            let (a, b) = (w[0], w[1]);
            let rate = wrap(b[2] - a[2]).abs() / DT;
            assert!(rate <= MAX_TURN_RATE + 1e-9);
            worst_lat = worst_lat.max(rate * b[3]);
            assert!(b[3] <= 3.0 + 1e-9);
        }
        assert!(worst_lat <= 2.0 + 0.05, "lateral acceleration {worst_lat}");
        // the corner at (20, 0) is cut by the arc: the runner passes it about
        // R (√2 − 1) = 4.5 · 0.414 = 1.9 m away, never through it
        let closest = tr
            .samples
            .iter()
            .map(|s| (s[0] - 20.0).hypot(s[1]))
            .fold(f64::INFINITY, f64::min);
        assert!(closest > 1.2 && closest < 2.6, "closest {closest}");
        let end = tr.samples.last().expect("samples");
        assert!(
            (end[0] - 20.0).abs() < 0.3 && (end[1] - 20.0).abs() < 0.3,
            "{end:?}"
        );
    }

    /// A companion is beside the target, behind it in the middle of the crossing (between the
    /// robot and the target) and on the other side after it.
    #[test]
    fn a_companion_runs_beside_then_crosses_behind() {
        let mut r = rng::stream(1, "jog", 0);
        let goals = [Goal {
            x: 100.0,
            y: 0.0,
            speed: 2.5,
            pause: 0.0,
        }];
        let target = run((0.0, 0.0, 0.0), &goals, 2.0, 1.0, (0.0, 30.0), &mut r);
        let c = Company {
            side: 1.0,
            offset_m: 1.0,
            behind_m: 0.8,
            join_s: 2.0,
            cross_at_s: 6.0,
            cross_s: 2.0,
        };
        let tr = companion(&target, &c, 5.0, 20.0);
        let rel = |t: f64| {
            let a = tr.state(t).expect("companion");
            let b = target.state(t).expect("target");
            (a.x - b.x, a.y - b.y)
        };
        let (ax, ay) = rel(10.0);
        assert!(
            ax.abs() < 0.05 && (ay - 1.0).abs() < 0.05,
            "beside: {ax} {ay}"
        );
        let (mx, my) = rel(12.0);
        assert!(
            (mx + 0.8).abs() < 0.05 && my.abs() < 0.05,
            "behind: {mx} {my}"
        );
        let (ex, ey) = rel(15.0);
        assert!(
            ex.abs() < 0.05 && (ey + 1.0).abs() < 0.05,
            "other side: {ex} {ey}"
        );
        assert!(tr.state(21.0).is_none());
    }
}

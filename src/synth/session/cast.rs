//! The people of a session and the robot: scripted people (with the calibration walk first
//! when it is theirs; from `[variation]`'s first session on with clothes redrawn and some of
//! them away), the robot's trajectory, then the crowd (which may cross between the robot and
//! the person it follows).

use std::path::{Path, PathBuf};

use rand::RngExt;

use super::types::{Actor, SynthError};
use crate::rng;
use crate::synth::motion::{self, Goal, Track, jog};
use crate::synth::person::Body;
use crate::synth::robot::{self, RobotTrack};
use crate::synth::scenario::{Motion, PersonSpec, Scenario};
use crate::synth::world::World;

/// People first (the robot may follow one), then the robot, then people who cross its path.
pub(super) fn people_and_robot(
    s: &Scenario,
    world: &World,
    base: &Path,
    session: u64,
) -> Result<(Vec<Actor>, RobotTrack), SynthError> {
    // the crowd is numbered after every scripted person, whether they came or not
    let first_crowd_id = first_crowd_id(s);
    let varied = varied(s, session);
    let s = &varied;
    let dur = s.scenario.duration_s;
    let mut people = actors(
        first_crowd_id,
        &Scenario {
            crowd: None,
            ..s.clone()
        },
        world,
        base,
        session,
        None,
    )?;
    let target_track = s
        .robot
        .follow
        .as_ref()
        .and_then(|f| people.iter().find(|a| a.body.id == f.target))
        .map(|a| &a.track);
    let robot_track = robot::simulate(&s.robot, dur, target_track, s.scenario.seed, session);
    if s.crowd.is_some() {
        let crowd_only = Scenario {
            people: Vec::new(),
            ..s.clone()
        };
        let mut crowd = if s
            .crowd
            .as_ref()
            .is_some_and(|c| c.cross_between_robot_and.is_some())
        {
            // crossers need the target's track: build with the scripted people present
            let all = actors(first_crowd_id, s, world, base, session, Some(&robot_track))?;
            all.into_iter().skip(s.people.len()).collect()
        } else {
            actors(
                first_crowd_id,
                &crowd_only,
                world,
                base,
                session,
                Some(&robot_track),
            )?
        };
        people.append(&mut crowd);
    }
    Ok((people, robot_track))
}

/// The scenario with this session's visitors (`[variation]`): from `from_session` on, the
/// scripted people's clothes and hair are redrawn (tops without repeats) and some stay away,
/// from a stream of their own so that nothing else of the session changes. People the robot
/// follows or the calibration walk needs always come.
pub(super) fn varied(s: &Scenario, session: u64) -> Scenario {
    let mut out = s.clone();
    let Some(v) = s
        .variation
        .as_ref()
        .filter(|v| session >= u64::from(v.from_session))
    else {
        return out;
    };
    let mut r = rng::stream(s.scenario.seed, "variation", session);
    if v.clothes {
        let mut tops: Vec<usize> = (0..PALETTE.len()).collect();
        for p in &mut out.people {
            let k = r.random_range(0..tops.len().max(1));
            p.upper = tops
                .get(k)
                .map_or_else(|| random_color(&mut r), |&i| PALETTE[i]);
            if k < tops.len() {
                tops.remove(k);
            }
            p.lower = random_color(&mut r);
            p.hair = random_hair(&mut r);
            p.hat = None;
        }
    }
    let [least, most] = v.absent;
    let away = r.random_range(least..=most) as usize;
    let needed = |id: u32| {
        s.robot.follow.as_ref().is_some_and(|f| f.target == id)
            || s.calibration.as_ref().is_some_and(|c| c.person == id)
    };
    for _ in 0..away {
        let free: Vec<usize> = (0..out.people.len())
            .filter(|&i| !needed(out.people[i].id))
            .collect();
        if free.is_empty() {
            break;
        }
        out.people.remove(free[r.random_range(0..free.len())]);
    }
    out
}

/// The clothing palette of crowds and varied visitors.
const PALETTE: [[u8; 3]; 14] = [
    [180, 40, 40],
    [40, 70, 160],
    [30, 30, 35],
    [230, 230, 225],
    [200, 170, 60],
    [60, 120, 70],
    [120, 60, 140],
    [210, 120, 40],
    [90, 90, 95],
    [150, 180, 210],
    [120, 80, 50],
    [240, 200, 200],
    [20, 90, 100],
    [170, 40, 100],
];

fn random_color(r: &mut rand_chacha::ChaCha8Rng) -> [u8; 3] {
    PALETTE[r.random_range(0..PALETTE.len())]
}

fn random_hair(r: &mut rand_chacha::ChaCha8Rng) -> [u8; 3] {
    [
        50 + r.random_range(0..60u8),
        35 + r.random_range(0..40u8),
        25,
    ]
}

fn skin_tone(r: &mut rand_chacha::ChaCha8Rng) -> [u8; 3] {
    const SKIN: [[u8; 3]; 5] = [
        [232, 190, 160],
        [214, 160, 130],
        [180, 130, 95],
        [140, 95, 65],
        [100, 70, 50],
    ];
    SKIN[r.random_range(0..SKIN.len())]
}

/// Motion of a scripted person, with the calibration walk first when it is theirs.
fn scripted_track(
    s: &Scenario,
    p: &PersonSpec,
    world: &World,
    base: &Path,
    session: u64,
) -> Result<Track, SynthError> {
    let dur = s.scenario.duration_s;
    let leave = p.leave_s.unwrap_or(dur).min(dur);
    let mut r = rng::stream(s.scenario.seed, &format!("person{}", p.id), session);
    let mut goals: Vec<Goal> = Vec::new();
    let mut start = None;
    if let Some(c) = s.calibration.as_ref().filter(|c| c.person == p.id) {
        for at in &c.positions {
            goals.push(Goal {
                x: at[0],
                y: at[1],
                speed: c.speed,
                pause: c.dwell_s,
            });
        }
        start = c.positions.first().map(|a| (a[0], a[1], 0.0));
    }
    match &p.motion {
        Motion::Waypoints {
            points,
            speed,
            pause_s,
            repeat,
        } => {
            let mut list: Vec<Goal> = points
                .iter()
                .map(|q| Goal {
                    x: q[0],
                    y: q[1],
                    speed: *speed,
                    pause: *pause_s,
                })
                .collect();
            if *repeat {
                let lap: f64 = points
                    .windows(2)
                    .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
                    .sum::<f64>()
                    / speed
                    + pause_s * points.len() as f64;
                let laps = ((leave - p.enter_s) / lap.max(1.0)).ceil() as usize + 1;
                list = list
                    .iter()
                    .cycle()
                    .take(list.len() * laps)
                    .copied()
                    .collect();
            }
            let first = (points[0][0], points[0][1], 0.0);
            goals.extend(list);
            Ok(motion::walk(
                start.unwrap_or(first),
                &goals,
                p.enter_s,
                leave,
                &mut r,
            ))
        }
        Motion::Wander {
            area,
            speed,
            pause_s,
            start: wander_start,
        } => {
            // drawn whether used or not, so that datasets without `start` keep their walks
            let random = (
                area[0] + r.random::<f64>() * (area[2] - area[0]),
                area[1] + r.random::<f64>() * (area[3] - area[1]),
            );
            if start.is_none() {
                start = wander_start.map(|w| (w[0], w[1], 0.0));
            }
            let from = start.map(|s| (s.0, s.1)).unwrap_or(random);
            let from = goals.last().map_or(from, |g| (g.x, g.y));
            goals.extend(motion::wander_goals(
                from,
                *area,
                *speed,
                *pause_s,
                leave - p.enter_s + 10.0,
                &world.obstacles,
                &mut r,
            ));
            let first = start.unwrap_or((from.0, from.1, 0.0));
            Ok(motion::walk(first, &goals, p.enter_s, leave, &mut r))
        }
        Motion::Jog {
            area,
            speed,
            stretch_m,
            max_turn_deg,
            lateral_accel,
            accel,
            clearance_m,
            start,
            heading_deg,
        } => {
            let spec = jog::RouteSpec {
                area: *area,
                speed: *speed,
                stretch_m: *stretch_m,
                max_turn_deg: *max_turn_deg,
                clearance_m: *clearance_m,
            };
            let pace = (*lateral_accel, *accel);
            let at = (*start, *heading_deg);
            Ok(jog_track(
                &spec,
                pace,
                at,
                (p.enter_s, leave),
                world,
                &mut r,
            ))
        }
        Motion::Replay {
            file,
            track,
            offset,
            rotate_deg,
        } => {
            let path = if Path::new(file).is_absolute() {
                PathBuf::from(file)
            } else {
                base.join(file)
            };
            motion::replay(&path, *track, *offset, rotate_deg.to_radians(), p.enter_s)
                .map_err(SynthError::Scenario)
        }
    }
}

/// A `jog` motion's track (`synth::motion::jog`): its route from `at` (start, heading in
/// degrees; random when absent), then running it with `pace` (lateral acceleration, pace
/// change) between `span` (enter, leave).
fn jog_track(
    spec: &jog::RouteSpec,
    pace: (f64, f64),
    at: (Option<[f64; 2]>, Option<f64>),
    span: (f64, f64),
    world: &World,
    r: &mut rand_chacha::ChaCha8Rng,
) -> Track {
    let area = spec.area;
    let random = (
        area[0] + r.random::<f64>() * (area[2] - area[0]),
        area[1] + r.random::<f64>() * (area[3] - area[1]),
        r.random::<f64>() * std::f64::consts::TAU,
    );
    let from = (
        at.0.map_or(random.0, |p| p[0]),
        at.0.map_or(random.1, |p| p[1]),
        at.1.map_or(random.2, f64::to_radians),
    );
    let dur = span.1 - span.0 + 10.0;
    let route = jog::route((from.0, from.1), from.2, spec, dur, &world.obstacles, r);
    jog::run(from, &route.goals, pace.0, pace.1, span, r)
}

/// A companion runs this far beside the target (m): shoulder to shoulder with a step between.
const COMPANION_OFFSET_M: f64 = 1.0;
/// ... and crosses this far behind it (m), between the following robot and the target.
const COMPANION_BEHIND_M: f64 = 0.8;

/// The crowd's ids follow the scripted people's, so every person of a session has their own
/// id (ground truth and the rendered id buffer are keyed by it).
fn first_crowd_id(s: &Scenario) -> u32 {
    s.people.iter().map(|p| p.id).max().unwrap_or(0) + 1
}

/// Build every actor of a session (scripted people, then the crowd numbered from
/// `first_crowd_id`).
fn actors(
    first_crowd_id: u32,
    s: &Scenario,
    world: &World,
    base: &Path,
    session: u64,
    robot: Option<&RobotTrack>,
) -> Result<Vec<Actor>, SynthError> {
    let mut out = Vec::new();
    for p in &s.people {
        out.push(Actor {
            body: Body {
                height: p.height_in(session),
                ..Body::from_spec(p)
            },
            track: scripted_track(s, p, world, base, session)?,
        });
    }
    if let Some(c) = &s.crowd {
        let mut r = rng::stream(s.scenario.seed, "crowd", session);
        let dur = s.scenario.duration_s;
        for (k, next_id) in (0..c.count).zip(first_crowd_id..) {
            let height = c.height[0] + r.random::<f64>() * (c.height[1] - c.height[0]);
            let body = Body {
                id: next_id,
                height,
                width: 0.17 + 0.06 * r.random::<f64>(),
                leg_radius: {
                    let [lo, hi] = c.leg_radius.unwrap_or([0.055, 0.075]);
                    lo + (hi - lo) * r.random::<f64>()
                },
                upper: random_color(&mut r),
                lower: random_color(&mut r),
                skin: skin_tone(&mut r),
                hair: random_hair(&mut r),
                hat: None,
                hands: false,
            };
            let stay = c.stay_s[0] + r.random::<f64>() * (c.stay_s[1] - c.stay_s[0]);
            // spread arrivals over the session
            let enter = (dur - stay.min(dur)).max(0.0) * (k as f64 + r.random::<f64>())
                / f64::from(c.count.max(1));
            let leave = (enter + stay).min(dur);
            let speed = || c.speed[0];
            let track = if let (Some(_), Some(robot)) = (c.cross_between_robot_and, robot) {
                // cross the robot–target line at a random time
                let target = out
                    .iter()
                    .find(|a| Some(a.body.id) == c.cross_between_robot_and)
                    .map(|a| &a.track)
                    .ok_or_else(|| {
                        SynthError::Scenario("crowd.cross_between_robot_and names no person".into())
                    })?;
                if k < c.companions {
                    // run beside the target, then cross behind it (between robot and target)
                    let company = jog::Company {
                        side: if r.random::<bool>() { 1.0 } else { -1.0 },
                        offset_m: COMPANION_OFFSET_M,
                        behind_m: COMPANION_BEHIND_M,
                        join_s: 2.0,
                        cross_at_s: 0.5 * stay,
                        cross_s: 2.0,
                    };
                    out.push(Actor {
                        body,
                        track: jog::companion(target, &company, enter, leave),
                    });
                    continue;
                }
                let tc = enter + stay / 2.0;
                let rs = robot.state(tc);
                let tp = target.position(tc).unwrap_or((rs.x + 2.0, rs.y));
                let (mx, my) = ((rs.x + tp.0) / 2.0, (rs.y + tp.1) / 2.0);
                let (dx, dy) = (tp.0 - rs.x, tp.1 - rs.y);
                let len = dx.hypot(dy).max(1e-6);
                let (nx, ny) = (-dy / len, dx / len);
                let v = c.speed[0] + r.random::<f64>() * (c.speed[1] - c.speed[0]);
                let side = if r.random::<bool>() { 1.0 } else { -1.0 };
                let half = 0.5 * stay * v;
                let a = (mx - side * nx * half, my - side * ny * half);
                let b = (mx + side * nx * half, my + side * ny * half);
                motion::walk(
                    (a.0, a.1, (b.1 - a.1).atan2(b.0 - a.0)),
                    &[Goal {
                        x: b.0,
                        y: b.1,
                        speed: v,
                        pause: 0.0,
                    }],
                    enter,
                    leave,
                    &mut r,
                )
            } else {
                let doors = &world.doors;
                let (from, to) = if c.use_doors && !doors.is_empty() {
                    // step 0.4 m into the room from the door in the wall
                    let inside = |d: [f64; 2]| {
                        let (cx, cy) = (world.size[0] / 2.0, world.size[1] / 2.0);
                        let (dx, dy) = (cx - d[0], cy - d[1]);
                        let n = dx.hypot(dy).max(1e-9);
                        (d[0] + 0.4 * dx / n, d[1] + 0.4 * dy / n)
                    };
                    let a = inside(doors[r.random_range(0..doors.len())]);
                    let b = inside(doors[r.random_range(0..doors.len())]);
                    (a, Some(b))
                } else {
                    let area = c.area;
                    (
                        (
                            area[0] + r.random::<f64>() * (area[2] - area[0]),
                            area[1] + r.random::<f64>() * (area[3] - area[1]),
                        ),
                        None,
                    )
                };
                let mut goals = motion::wander_goals(
                    from,
                    c.area,
                    [speed(), c.speed[1]],
                    [0.0, 3.0],
                    stay * 0.8,
                    &world.obstacles,
                    &mut r,
                );
                if let Some(to) = to {
                    goals.push(Goal {
                        x: to.0,
                        y: to.1,
                        speed: c.speed[1],
                        pause: 0.0,
                    });
                }
                motion::walk((from.0, from.1, 0.0), &goals, enter, leave, &mut r)
            };
            out.push(Actor { body, track });
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn home_tour() -> Scenario {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("datasets/home_tour/scenario.toml");
        Scenario::load(&path, "full").expect("home_tour loads").0
    }

    fn looks(s: &Scenario) -> Vec<(u32, [u8; 3], [u8; 3])> {
        s.people.iter().map(|p| (p.id, p.upper, p.lower)).collect()
    }

    #[test]
    fn sessions_before_the_variation_keep_the_cast_and_later_ones_get_visitors_of_their_own() {
        let s = home_tour();
        assert_eq!(s.scenario.first_session, 1);
        let v = s.variation.as_ref().expect("[variation]");
        assert_eq!((v.from_session, v.absent), (1, [0, 1]));
        // session 0: the cast as written
        assert_eq!(looks(&varied(&s, 0)), looks(&s));
        let mut seen = Vec::new();
        for session in 1..=10 {
            let a = varied(&s, session);
            assert_eq!(looks(&a), looks(&varied(&s, session)), "deterministic");
            assert!(
                (5..=6).contains(&a.people.len()),
                "{} visitors",
                a.people.len()
            );
            let mut tops: Vec<[u8; 3]> = a.people.iter().map(|p| p.upper).collect();
            assert!(tops.iter().all(|t| PALETTE.contains(t)));
            tops.sort_unstable();
            tops.dedup();
            assert_eq!(tops.len(), a.people.len(), "tops all different");
            // the people who came walk as scripted
            for p in &a.people {
                let orig = s.people.iter().find(|q| q.id == p.id).expect("scripted");
                assert_eq!((p.height, p.enter_s), (orig.height, orig.enter_s));
            }
            seen.push(looks(&a));
        }
        seen.sort();
        seen.dedup();
        assert_eq!(seen.len(), 10, "every session has a cast of its own");
    }
}

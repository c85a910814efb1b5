//! Who comes, where they stand, where they look and what they say in one `biron_home`
//! session, drawn from the session's seed (seed 003's BIRON home tour: a user greets the robot,
//! talks to it and says good-bye or walks away, while other visitors come and go, talk to each
//! other or to the robot, some behind the robot, some at the same time).
//!
//! - **Visitors** (2–5): visitor 1 is the *user*; the others stand in front of the robot
//!   (bearing within ±75°) or behind it (the microphones' mirror side), 1.2–3 m away, for a
//!   while, and may leave. Paths are [`crate::synth::motion::walk`]s from the door.
//! - **Utterances**: the user greets ("Hello BIRON") 1.5–3 s after arriving, says 1–3 more
//!   things to the robot, then says good-bye (60 %) or walks away without it. The others talk
//!   to a standing visitor (70 %) or to the robot, every 2–6 s while they stand.
//! - **Gaze**: a speaker looks at whom they address; a listener addressed by a speaker looks
//!   at the speaker; otherwise a visitor looks at the robot, at another visitor or somewhere
//!   else, drawn every 2–4 s; heads turn at most [`HEAD_RATE`]; a standing body faces where
//!   the head looks, a walking one where it walks.

use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use super::speech::Voice;
use crate::synth::motion::{self, DT, Goal, Track};
use crate::synth::person::{Body, PersonState};
use crate::synth::scenario::Rgb;

/// Largest head turn rate (rad/s).
pub const HEAD_RATE: f64 = 3.5;

/// Whom an utterance is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Addressee {
    Robot,
    Person(u32),
}

/// What an utterance does in the dialog.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    Greeting,
    Talk,
    Goodbye,
}

/// One utterance.
#[derive(Debug, Clone, PartialEq)]
pub struct Utterance {
    pub speaker: u32,
    pub start: f64,
    pub end: f64,
    pub addressee: Addressee,
    pub kind: Kind,
}

/// One visitor: body, voice, path and the head yaw every [`DT`] from the path's start.
pub struct Visitor {
    pub body: Body,
    pub voice: Voice,
    pub track: Track,
    /// World head yaw (rad) every [`DT`] from `track.start`.
    pub head: Vec<f64>,
}

impl Visitor {
    /// State (body heading set to face where the head looks while standing) and head yaw.
    pub fn at(&self, t: f64) -> Option<(PersonState, f64)> {
        let mut s = self.track.state(t)?;
        let i = (((t - self.track.start) / DT).round().max(0.0) as usize).min(self.head.len() - 1);
        let yaw = self.head[i];
        if s.speed < 0.15 {
            s.heading = yaw;
        }
        Some((s, yaw))
    }

    /// The mouth (m, world): 9 cm in front of the head centre along its yaw, 5 cm below it.
    pub fn mouth(&self, s: &PersonState, yaw: f64) -> [f64; 3] {
        let c = self.body.head_center(s);
        [c.x + 0.09 * yaw.cos(), c.y + 0.09 * yaw.sin(), c.z - 0.05]
    }
}

/// A whole session's script.
pub struct Script {
    pub visitors: Vec<Visitor>,
    /// Sorted by start.
    pub utterances: Vec<Utterance>,
}

/// Where the robot is and where it looks from.
#[derive(Debug, Clone, Copy)]
pub struct Stage {
    /// Robot `[x, y, yaw]` (m, rad).
    pub robot: [f64; 3],
    /// The camera's position (m): what "looking at the robot" looks at.
    pub camera: [f64; 3],
    /// Door `[x, y]` visitors enter and leave by.
    pub door: [f64; 2],
    pub room: [f64; 2],
    pub duration: f64,
}

const CLOTHES: [Rgb; 8] = [
    [180, 30, 40],
    [40, 90, 160],
    [40, 120, 60],
    [230, 180, 40],
    [100, 60, 140],
    [220, 220, 215],
    [30, 30, 35],
    [200, 110, 50],
];
const SKINS: [Rgb; 4] = [
    [224, 172, 140],
    [198, 140, 105],
    [150, 100, 70],
    [236, 190, 160],
];
const HAIRS: [Rgb; 4] = [[60, 42, 30], [20, 15, 10], [150, 110, 60], [110, 70, 40]];

fn wrap(a: f64) -> f64 {
    crate::audio::doa::wrap(a)
}

/// A standing spot at `bearing` (rad, robot frame) and `range` from the robot, in the room.
fn spot(st: &Stage, bearing: f64, range: f64) -> [f64; 2] {
    let a = st.robot[2] + bearing;
    let p = [st.robot[0] + range * a.cos(), st.robot[1] + range * a.sin()];
    [
        p[0].clamp(0.5, st.room[0] - 0.5),
        p[1].clamp(0.5, st.room[1] - 0.5),
    ]
}

/// Draw the script of one session; the heads stay empty until `gaze::plan_heads` fills them.
pub fn draw(st: &Stage, n_range: [u32; 2], rng: &mut ChaCha8Rng) -> Script {
    let n = rng.random_range(n_range[0]..=n_range[1]).max(1);
    let dur = st.duration;
    let mut plans: Vec<Plan> = Vec::new();
    let mut taken: Vec<[f64; 2]> = Vec::new();
    for k in 0..n {
        let user = k == 0;
        let behind = !user && rng.random::<f64>() < 0.35;
        let mut place = [0.0; 2];
        for _ in 0..20 {
            let bearing = if user {
                rng.random_range(-0.7..0.7)
            } else if behind {
                std::f64::consts::PI + rng.random_range(-0.8..0.8)
            } else {
                rng.random_range(-1.3..1.3)
            };
            let range = if user {
                rng.random_range(1.3..2.0)
            } else {
                rng.random_range(1.3..2.8)
            };
            place = spot(st, bearing, range);
            if taken
                .iter()
                .all(|q| (q[0] - place[0]).hypot(q[1] - place[1]) > 1.0)
            {
                break;
            }
        }
        taken.push(place);
        let enter = if user {
            rng.random_range(0.5..2.0)
        } else {
            rng.random_range(0.0..0.45 * dur)
        };
        plans.push(Plan {
            id: k + 1,
            place,
            enter,
            arrive: 0.0,
            leave: dur,
        });
    }
    let mut visitors = Vec::new();
    let mut utterances = Vec::new();
    for p in &mut plans {
        let body = body(p.id, rng);
        let voice = if rng.random::<f64>() < 0.5 {
            Voice {
                f0_hz: rng.random_range(100.0..130.0),
                formant_scale: 1.0,
            }
        } else {
            Voice {
                f0_hz: rng.random_range(190.0..230.0),
                formant_scale: 1.15,
            }
        };
        let walk_s = (st.door[0] - p.place[0]).hypot(st.door[1] - p.place[1]) / 0.9 + 1.0;
        p.arrive = p.enter + walk_s;
        if p.id == 1 {
            user_lines(p, dur, rng, &mut utterances);
        } else if rng.random::<f64>() < 0.5 {
            p.leave = (p.arrive + rng.random_range(8.0..25.0)).min(dur);
        }
        visitors.push((body, voice, p.clone()));
    }
    others_lines(&plans, dur, rng, &mut utterances);
    utterances.sort_by(|a, b| a.start.total_cmp(&b.start));
    let tracks: Vec<Track> = plans.iter().map(|p| path(st, p, dur, rng)).collect();
    let visitors: Vec<Visitor> = visitors
        .into_iter()
        .zip(tracks)
        .map(|((body, voice, _), track)| Visitor {
            body,
            voice,
            track,
            head: Vec::new(),
        })
        .collect();
    Script {
        visitors,
        utterances,
    }
}

/// A visitor's plan: where they stand and when they are there.
#[derive(Debug, Clone)]
pub struct Plan {
    pub id: u32,
    pub place: [f64; 2],
    pub enter: f64,
    pub arrive: f64,
    /// Starts walking out (the person is gone once out of the door).
    pub leave: f64,
}

fn body(id: u32, rng: &mut ChaCha8Rng) -> Body {
    Body {
        id,
        height: rng.random_range(1.58..1.92),
        width: 0.2,
        leg_radius: 0.065,
        upper: CLOTHES[rng.random_range(0..CLOTHES.len())],
        lower: [40, 40, 50],
        skin: SKINS[rng.random_range(0..SKINS.len())],
        hair: HAIRS[rng.random_range(0..HAIRS.len())],
        hat: None,
        hands: false,
    }
}

/// The user's lines: greeting, 1–3 more (1.5–3 s apart), good-bye (60 %) or walking away.
fn user_lines(p: &mut Plan, dur: f64, rng: &mut ChaCha8Rng, out: &mut Vec<Utterance>) {
    let mut t = p.arrive + rng.random_range(1.5..3.0);
    let mut say = |t: &mut f64, kind: Kind, rng: &mut ChaCha8Rng| {
        let len = match kind {
            Kind::Greeting | Kind::Goodbye => rng.random_range(0.9..1.4),
            Kind::Talk => rng.random_range(1.2..2.5),
        };
        if *t + len < dur - 1.0 {
            out.push(Utterance {
                speaker: p.id,
                start: *t,
                end: *t + len,
                addressee: Addressee::Robot,
                kind,
            });
        }
        *t += len + rng.random_range(1.5..3.0);
    };
    say(&mut t, Kind::Greeting, rng);
    for _ in 0..rng.random_range(1..=3) {
        say(&mut t, Kind::Talk, rng);
    }
    if rng.random::<f64>() < 0.6 {
        say(&mut t, Kind::Goodbye, rng);
        p.leave = (t - 1.0).min(dur);
    } else {
        p.leave = (t - 1.5).min(dur);
    }
}

/// The other visitors' lines while they stand.
fn others_lines(plans: &[Plan], dur: f64, rng: &mut ChaCha8Rng, out: &mut Vec<Utterance>) {
    for p in plans.iter().filter(|p| p.id != 1) {
        let mut t = p.arrive + rng.random_range(1.0..4.0);
        loop {
            let len = rng.random_range(1.0..2.5);
            if t + len > p.leave.min(dur - 0.5) {
                break;
            }
            let listeners: Vec<u32> = plans
                .iter()
                .filter(|q| q.id != p.id && q.arrive < t && q.leave > t + len)
                .map(|q| q.id)
                .collect();
            let addressee = if !listeners.is_empty() && rng.random::<f64>() < 0.7 {
                Addressee::Person(listeners[rng.random_range(0..listeners.len())])
            } else {
                Addressee::Robot
            };
            out.push(Utterance {
                speaker: p.id,
                start: t,
                end: t + len,
                addressee,
                kind: Kind::Talk,
            });
            t += len + rng.random_range(2.0..6.0);
        }
    }
}

/// The walk: door → place (standing until `leave`) → door.
fn path(st: &Stage, p: &Plan, dur: f64, rng: &mut ChaCha8Rng) -> Track {
    let speed = rng.random_range(0.8..1.0);
    let stand = (p.leave - p.arrive).max(0.0);
    let goals = [
        Goal {
            x: p.place[0],
            y: p.place[1],
            speed,
            pause: stand,
        },
        Goal {
            x: st.door[0],
            y: st.door[1],
            speed,
            pause: 0.0,
        },
    ];
    let h0 = (p.place[1] - st.door[1]).atan2(p.place[0] - st.door[0]);
    let mut track = motion::walk((st.door[0], st.door[1], h0), &goals, p.enter, dur, rng);
    // gone once back at the door
    if p.leave < dur {
        let back = track.samples.iter().enumerate().rev().find(|(i, s)| {
            let t = p.enter + *i as f64 * DT;
            t > p.leave && (s[0] - st.door[0]).hypot(s[1] - st.door[1]) > 0.3
        });
        if let Some((i, _)) = back {
            track.leave = (p.enter + (i + 1) as f64 * DT).min(dur);
        }
    }
    track
}

/// The angle (rad) from `from` toward `to` on the floor.
pub fn bearing(from: [f64; 2], to: [f64; 2]) -> f64 {
    (to[1] - from[1]).atan2(to[0] - from[0])
}

/// True when a head at `head` with yaw `yaw` looks at `target` within `tol` (rad).
pub fn looks_at(head: [f64; 2], yaw: f64, target: [f64; 2], tol: f64) -> bool {
    wrap(bearing(head, target) - yaw).abs() <= tol
}

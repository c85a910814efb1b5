//! Where each visitor's head points, every [`DT`] (see [`super::script`] for the rules): the
//! addressee while speaking, the walking direction while walking, a speaker who addresses
//! them while listening, else an idle target drawn every 2–4 s — the robot (45 %), another
//! visitor (30 %) or somewhere 60–150° away from the robot; turned at most [`HEAD_RATE`].

use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use super::script::{Addressee, HEAD_RATE, Script, Stage, bearing};
use crate::synth::motion::DT;

#[derive(Clone, Copy)]
enum Idle {
    Robot,
    Person(usize),
    /// Offset (rad) from the bearing to the robot.
    Away(f64),
}

fn wrap(a: f64) -> f64 {
    crate::audio::doa::wrap(a)
}

/// Fill every visitor's `head` (see the module doc).
pub fn plan_heads(script: &mut Script, st: &Stage, rng: &mut ChaCha8Rng) {
    let n = script.visitors.len();
    let ids: Vec<u32> = script.visitors.iter().map(|v| v.body.id).collect();
    let index = |id: u32| ids.iter().position(|&x| x == id);
    for k in 0..n {
        let v = &script.visitors[k];
        let len = v.track.samples.len();
        let mut head = Vec::with_capacity(len);
        let mut yaw = v.track.samples.first().map_or(0.0, |s| s[2]);
        let mut idle = Idle::Robot;
        let mut next_idle = v.track.start;
        for (i, s) in v.track.samples.iter().enumerate() {
            let t = v.track.start + i as f64 * DT;
            let me = [s[0], s[1]];
            let pos = |j: usize| script.visitors[j].track.state(t).map(|p| [p.x, p.y]);
            let to_robot = bearing(me, [st.camera[0], st.camera[1]]);
            let speaking = script
                .utterances
                .iter()
                .find(|u| u.speaker == ids[k] && u.start <= t && t < u.end);
            let addressed = script
                .utterances
                .iter()
                .find(|u| u.addressee == Addressee::Person(ids[k]) && u.start <= t && t < u.end);
            if t >= next_idle {
                let r: f64 = rng.random();
                let others: Vec<usize> = (0..n).filter(|&j| j != k && pos(j).is_some()).collect();
                idle = if r < 0.45 || others.is_empty() && r < 0.7 {
                    Idle::Robot
                } else if r < 0.75 && !others.is_empty() {
                    Idle::Person(others[rng.random_range(0..others.len())])
                } else {
                    let side = if rng.random::<bool>() { 1.0 } else { -1.0 };
                    Idle::Away(side * rng.random_range(1.05..2.6))
                };
                next_idle = t + rng.random_range(2.0..4.0);
            }
            let target = if let Some(u) = speaking {
                match u.addressee {
                    Addressee::Robot => Some(to_robot),
                    Addressee::Person(id) => index(id).and_then(pos).map(|p| bearing(me, p)),
                }
            } else if s[3] >= 0.15 {
                Some(s[2])
            } else if let Some(u) = addressed {
                index(u.speaker).and_then(pos).map(|p| bearing(me, p))
            } else {
                match idle {
                    Idle::Robot => Some(to_robot),
                    Idle::Person(j) => pos(j).map(|p| bearing(me, p)),
                    Idle::Away(off) => Some(to_robot + off),
                }
            };
            if let Some(want) = target {
                let step = HEAD_RATE * DT;
                yaw = wrap(yaw + wrap(want - yaw).clamp(-step, step));
            }
            head.push(yaw);
        }
        script.visitors[k].head = head;
    }
}

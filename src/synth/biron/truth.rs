//! The ground truth of a `biron_home` step: every present person (position, mouth, head yaw,
//! speaking and to whom, looking at the robot, in the sensed region, the true category, the
//! face the camera shows), the true attention — the same state machine as the system's
//! ([`crate::anchoring::attention`]) run on these true cues, with the dialog's greeting and
//! good-bye taking effect when the utterance ends and a partner who leaves the sensed region
//! ending the interaction — and the list of utterances.
//!
//! "Looking at the robot" is the head turned within [`LOOK_TOLERANCE_DEG`] of the camera;
//! the sensed region is the laser's half-plane in front of the robot within [`REGION_M`]
//! (persons behind the robot are observed by nothing but the microphones).

use nalgebra::Point3;

use super::script::{Addressee, Kind, Script, Stage, bearing, looks_at};
use crate::anchoring::attention::{Attention, Command, Observed, category};
use crate::anchoring::view::CameraView;
use crate::groundtruth::PersonTruth;
use crate::groundtruth::biron::{
    BironFrame, BironPerson, FaceTruth, UtteranceTruth, UtterancesFrame,
};
use crate::synth::person::HEAD_HALF_HEIGHT;
use crate::time::Nanos;

/// A head within this angle of the camera looks at the robot (deg).
pub const LOOK_TOLERANCE_DEG: f64 = 20.0;
/// The sensed region's range (m).
pub const REGION_M: f64 = 6.0;

fn addressee(a: Addressee) -> String {
    match a {
        Addressee::Robot => "robot".into(),
        Addressee::Person(id) => id.to_string(),
    }
}

fn kind(k: Kind) -> &'static str {
    match k {
        Kind::Greeting => "greeting",
        Kind::Talk => "talk",
        Kind::Goodbye => "goodbye",
    }
}

/// `/ground_truth/utterances`.
pub fn utterances(script: &Script, t0: Nanos, at: impl Fn(f64) -> Nanos) -> UtterancesFrame {
    UtterancesFrame {
        stamp_ns: t0.0,
        utterances: script
            .utterances
            .iter()
            .enumerate()
            .map(|(index, u)| {
                let mouth = script
                    .visitors
                    .iter()
                    .find(|v| v.body.id == u.speaker)
                    .and_then(|v| v.at(u.start).map(|(s, yaw)| v.mouth(&s, yaw)))
                    .unwrap_or([0.0; 3]);
                UtteranceTruth {
                    index,
                    speaker: u.speaker,
                    start_ns: at(u.start).0,
                    end_ns: at(u.end).0,
                    addressee: addressee(u.addressee),
                    kind: kind(u.kind).into(),
                    mouth,
                }
            })
            .collect(),
    }
}

/// The true attention, stepped with the session.
#[derive(Default)]
pub struct TrueAttention {
    att: Attention,
    /// Utterances whose end took effect.
    done: usize,
}

impl TrueAttention {
    /// The ground truth at step `t`: `/ground_truth/people` and `/ground_truth/biron`.
    pub fn step(
        &mut self,
        script: &Script,
        st: &Stage,
        t: f64,
        stamp: Nanos,
        view: &CameraView,
        ids: &[u32],
    ) -> (Vec<PersonTruth>, BironFrame) {
        let mut people = Vec::new();
        let mut persons = Vec::new();
        for v in &script.visitors {
            let Some((s, yaw)) = v.at(t) else {
                continue;
            };
            let id = v.body.id;
            let head = v.body.head_center(&s);
            let speaking_u = script
                .utterances
                .iter()
                .find(|u| u.speaker == id && u.start <= t && t < u.end);
            let looking = looks_at(
                [head.x, head.y],
                yaw,
                [st.camera[0], st.camera[1]],
                LOOK_TOLERANCE_DEG.to_radians(),
            );
            let rel = crate::audio::doa::wrap(
                bearing([st.robot[0], st.robot[1]], [s.x, s.y]) - st.robot[2],
            );
            let range = (s.x - st.robot[0]).hypot(s.y - st.robot[1]);
            let in_region = rel.abs() <= std::f64::consts::FRAC_PI_2 && range <= REGION_M;
            let cat = category(speaking_u.is_some(), Some(looking));
            persons.push(BironPerson {
                id,
                x: s.x,
                y: s.y,
                mouth: v.mouth(&s, yaw),
                head_yaw_deg: yaw.to_degrees(),
                speaking: speaking_u.is_some(),
                addressee: speaking_u
                    .map(|u| addressee(u.addressee))
                    .unwrap_or_default(),
                looking_at_robot: looking,
                in_region,
                category: cat,
                face: face(view, head, yaw, v.body.object(), ids),
            });
            let legs = v.body.legs_at(&s, super::LASER_XZ[1]);
            people.push(PersonTruth {
                id,
                x: s.x,
                y: s.y,
                vx: s.vx,
                vy: s.vy,
                height: v.body.height,
                head_z: head.z,
                radius: v.body.width,
                legs,
                leg_radius: v.body.leg_radius,
                cameras: Vec::new(),
            });
        }
        // dialog events of the utterances that ended by now
        let mut commands = Vec::new();
        let mut events = Vec::new();
        let ended: Vec<_> = script.utterances.iter().filter(|u| u.end <= t).collect();
        let mut done = 0;
        for u in &ended {
            done += 1;
            if done <= self.done {
                continue;
            }
            let c = match u.kind {
                Kind::Greeting => Command::Greeting,
                Kind::Goodbye => Command::Goodbye,
                Kind::Talk => continue,
            };
            commands.push((c, u64::from(u.speaker)));
            events.push(format!("{}:{}", kind(u.kind), u.speaker));
        }
        self.done = done.max(self.done);
        let observed: Vec<Observed> = persons
            .iter()
            .filter(|p| p.in_region)
            .map(|p| Observed {
                id: u64::from(p.id),
                category: p.category,
                distance_m: (p.x - st.robot[0]).hypot(p.y - st.robot[1]),
            })
            .collect();
        // a greeting reaches the true machine from the speaker, who is its focus by then
        for (c, who) in &commands {
            if *c == Command::Greeting && !self.att.mode.top_down() {
                self.att.focus = Some(*who);
            }
        }
        self.att.step(&commands, &observed);
        let frame = BironFrame {
            stamp_ns: stamp.0,
            people: persons,
            mode: self.att.mode.name().into(),
            focus: self.att.focus.map(|f| f as u32),
            events,
        };
        (people, frame)
    }
}

/// What the camera shows of a head: its projected centre and width, the face's angle away
/// from the camera, and the share of the head's box with this person's pixels.
fn face(
    view: &CameraView,
    head: Point3<f64>,
    yaw: f64,
    object: u32,
    ids: &[u32],
) -> Option<FaceTruth> {
    let px = view.pixel(&head, 0.0)?;
    let o = view.origin();
    let dist = (head - o).norm();
    let width = view.focal_px() * 0.17 / dist;
    let height = view.focal_px() * 2.0 * HEAD_HALF_HEIGHT / dist;
    let to_cam = bearing([head.x, head.y], [o.x, o.y]);
    let yaw_deg = crate::audio::doa::wrap(yaw - to_cam).abs().to_degrees();
    let (w, h) = (view.model.width as i64, view.model.height as i64);
    let (x0, x1) = ((px[0] - width / 2.0) as i64, (px[0] + width / 2.0) as i64);
    let (y0, y1) = ((px[1] - height / 2.0) as i64, (px[1] + height / 2.0) as i64);
    let (mut all, mut mine) = (0u64, 0u64);
    for y in y0..=y1 {
        for x in x0..=x1 {
            all += 1;
            if (0..w).contains(&x) && (0..h).contains(&y) && ids[(y * w + x) as usize] == object {
                mine += 1;
            }
        }
    }
    Some(FaceTruth {
        center_px: px,
        width_px: width,
        yaw_deg,
        visible: if all > 0 {
            mine as f64 / all as f64
        } else {
            0.0
        },
    })
}

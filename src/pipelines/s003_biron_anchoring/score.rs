//! The session's scores from the pass's records: faces against the true faces of each frame;
//! per system variant the person anchors' CLEAR MOT at [`Params::mot_max_m`] against the
//! persons in the sensed region (every anchor is a hypothesis), the focus of attention at
//! each 100 ms step (the focus anchor's matched person against the true focus), where each
//! active sound block landed (speaker identification), and the anchor-state timeline of the
//! full system; and the replay against the logged `/attention/state`.

use std::collections::BTreeMap;

use super::params::{Params, VARIANTS};
use super::tables::{self as t, FaceRow, MotRow, ReplayRow, SpeakerRow, StepRow, TimelineRow};
use crate::anchoring::component::State;
use crate::anchoring::system::{StepOutput, System};
use crate::eval::mot::{self, EventKind, Geometry, GroundPoint, MatchRule, Observation};
use crate::frames::truth::Stamped;
use crate::groundtruth::biron::{AttentionState, BironFrame};
use crate::report::rows::Rows;
use crate::run::SessionTables;
use crate::time::Nanos;
use crate::vision::faces::Face;

/// One anchor at a step.
#[derive(Debug, Clone, PartialEq)]
pub struct AnchorRecord {
    pub id: u64,
    pub position: [f64; 2],
    pub states: [State; 4],
    pub category: u8,
}

/// What a variant did at a step.
#[derive(Debug, Clone, PartialEq)]
pub struct StepRecord {
    pub mode: String,
    pub focus: Option<u64>,
    pub sound_anchor: Option<u64>,
    /// The step's sound block was active (`None`: no block yet).
    pub sound_active: Option<bool>,
    pub anchors: Vec<AnchorRecord>,
}

/// What the pass keeps of a frame for scoring.
pub struct FrameRecord {
    pub k: i64,
    pub t: f64,
    pub stamp: Nanos,
    pub truth: Option<BironFrame>,
    /// Per variant: the step's record.
    pub variants: Vec<StepRecord>,
}

/// A variant's record of a step.
pub fn record(sys: &System, out: &StepOutput, t: f64, sound_active: Option<bool>) -> StepRecord {
    StepRecord {
        mode: out.mode.name().to_string(),
        focus: out.focus,
        sound_anchor: out.sound_anchor,
        sound_active,
        anchors: sys
            .fusion
            .anchors
            .iter()
            .map(|a| {
                let (speaking, looking) = sys.fusion.cues(a, t);
                AnchorRecord {
                    id: a.id,
                    position: a.position,
                    states: a.states(t),
                    category: crate::anchoring::attention::category(speaking, looking),
                }
            })
            .collect(),
    }
}

/// The true faces of a frame with whether a detection found them, and the detections that
/// match no true face.
pub fn faces(k: i64, truth: &BironFrame, found: &[Face], p: &Params) -> (Vec<FaceRow>, i64) {
    let matches = |f: &Face, c: [f64; 2], w: f64| {
        let d = f.center();
        (d[0] - c[0]).hypot(d[1] - c[1]) <= p.face_match_share * w
            && f.width >= 0.5 * w
            && f.width <= 2.0 * w
    };
    let mut rows = Vec::new();
    for person in &truth.people {
        let Some(face) = &person.face else { continue };
        if face.visible < p.face_visible_min {
            continue;
        }
        rows.push(FaceRow {
            k,
            person: i64::from(person.id),
            width_px: face.width_px,
            yaw_deg: face.yaw_deg,
            visible: face.visible,
            detected: found
                .iter()
                .any(|f| matches(f, face.center_px, face.width_px)),
        });
    }
    let falses = found
        .iter()
        .filter(|f| {
            !truth.people.iter().any(|person| {
                person
                    .face
                    .as_ref()
                    .is_some_and(|face| matches(f, face.center_px, face.width_px))
            })
        })
        .count();
    (rows, falses as i64)
}

fn state_code(s: State) -> i64 {
    match s {
        State::Lost => 0,
        State::Associated => 1,
        State::Grounded => 2,
    }
}

fn point(frame: i64, id: i64, x: f64, y: f64) -> Observation {
    Observation {
        frame,
        id,
        geometry: Geometry::Point(GroundPoint { x_m: x, y_m: y }),
        confidence: 1.0,
    }
}

/// Per frame index: anchor id → matched person id.
type Matching = BTreeMap<(i64, i64), i64>;

/// CLEAR MOT of variant `v` and its per-frame matching.
fn mot_of(frames: &[FrameRecord], v: usize, p: &Params) -> anyhow::Result<(MotRow, Matching)> {
    let mut gt = Vec::new();
    let mut hyp = Vec::new();
    for f in frames {
        let Some(tr) = &f.truth else { continue };
        for person in tr.people.iter().filter(|q| q.in_region) {
            gt.push(point(f.k, i64::from(person.id), person.x, person.y));
        }
        for a in &f.variants[v].anchors {
            hyp.push(point(f.k, a.id as i64, a.position[0], a.position[1]));
        }
    }
    let e = mot::evaluate(&gt, &hyp, MatchRule::Euclidean { max_m: p.mot_max_m })?;
    let mut matching = Matching::new();
    for ev in &e.events {
        if matches!(ev.kind, EventKind::Match | EventKind::Switch)
            && let (Some(g), Some(h)) = (ev.gt_id, ev.hyp_id)
        {
            matching.insert((ev.frame, h), g);
        }
    }
    let c = &e.metrics.clear;
    let top_down = frames
        .iter()
        .filter(|f| f.variants[v].mode == "interact")
        .count();
    let row = MotRow {
        variant: VARIANTS[v].0.to_string(),
        objects: c.num_objects as i64,
        misses: c.num_misses as i64,
        false_positives: c.num_false_positives as i64,
        switches: c.num_switches as i64,
        matches: c.num_matches as i64,
        distance_m: c.total_distance,
        mota: if c.num_objects > 0 { c.mota } else { f64::NAN },
        top_down_steps: top_down as i64,
    };
    Ok((row, matching))
}

/// Every per-variant table and the replay check.
pub fn tables(
    frames: &[FrameRecord],
    logged: &Stamped<AttentionState>,
    p: &Params,
) -> anyhow::Result<SessionTables> {
    let mut steps = Vec::new();
    let mut speaker = Vec::new();
    let mut mots = Vec::new();
    let mut timeline = Vec::new();
    for (v, (name, _)) in VARIANTS.iter().enumerate() {
        let (row, matching) = mot_of(frames, v, p)?;
        mots.push(row);
        let person_of = |k: i64, a: Option<u64>| {
            a.and_then(|a| matching.get(&(k, a as i64)).copied())
                .unwrap_or(-1)
        };
        for f in frames {
            let Some(tr) = &f.truth else { continue };
            let r = &f.variants[v];
            let focus_person = person_of(f.k, r.focus);
            let true_focus = tr.focus.map_or(-1, i64::from);
            steps.push(StepRow {
                variant: (*name).into(),
                k: f.k,
                t_s: f.t,
                mode: r.mode.clone(),
                focus_anchor: r.focus.map_or(-1, |a| a as i64),
                focus_person,
                true_mode: tr.mode.clone(),
                true_focus,
                right: focus_person == true_focus,
            });
            let speaking: Vec<_> = tr.people.iter().filter(|q| q.speaking).collect();
            if r.sound_active == Some(true) {
                let single = (speaking.len() == 1).then(|| speaking[0]);
                let anchor_person = person_of(f.k, r.sound_anchor);
                speaker.push(SpeakerRow {
                    variant: (*name).into(),
                    k: f.k,
                    t_s: f.t,
                    speakers: speaking.len() as i64,
                    speaker: single.map_or(-1, |q| i64::from(q.id)),
                    in_region: single.is_some_and(|q| q.in_region),
                    anchor: r.sound_anchor.map_or(-1, |a| a as i64),
                    anchor_person,
                    right: match single {
                        Some(q) if q.in_region => anchor_person == i64::from(q.id),
                        Some(_) => r.sound_anchor.is_none(),
                        None => false,
                    },
                });
            }
            if v == 0 {
                for a in &r.anchors {
                    let person = person_of(f.k, Some(a.id));
                    timeline.push(TimelineRow {
                        k: f.k,
                        t_s: f.t,
                        anchor: a.id as i64,
                        person,
                        legs: state_code(a.states[0]),
                        face: state_code(a.states[1]),
                        torso: state_code(a.states[2]),
                        voice: state_code(a.states[3]),
                        category: i64::from(a.category),
                        speaking: tr
                            .people
                            .iter()
                            .any(|q| i64::from(q.id) == person && q.speaking),
                    });
                }
            }
        }
    }
    let mut replay = ReplayRow {
        steps: frames.len() as i64,
        logged: 0,
        mode_agree: 0,
        focus_agree: 0,
    };
    for f in frames {
        if let Some(s) = logged.nearest(f.stamp, 1_000) {
            replay.logged += 1;
            replay.mode_agree += i64::from(s.mode == f.variants[0].mode);
            replay.focus_agree += i64::from(s.focus == f.variants[0].focus);
        }
    }
    let mut out = SessionTables::new();
    out.insert(t::STEPS.into(), StepRow::frame(&steps)?);
    out.insert(t::SPEAKER.into(), SpeakerRow::frame(&speaker)?);
    out.insert(t::MOT.into(), MotRow::frame(&mots)?);
    out.insert(t::TIMELINE.into(), TimelineRow::frame(&timeline)?);
    out.insert(t::REPLAY.into(), ReplayRow::frame(&[replay])?);
    Ok(out)
}

//! Person anchors and the association of each modality's percepts with them (see the module
//! doc of [`super`]). Positions are in the world (the fixed frame the laser tracker uses);
//! bearings are world azimuths seen from the camera or from the microphones' centre.
//!
//! - **Legs**: each confirmed track of the laser people tracker that a detection updated in
//!   this scan grounds the anchor that holds its id (a track coasting on its prediction is no
//!   percept: the legs component is then associated, for as long as the tracker coasts; until
//!   round 6 a coasting track grounded it too, [`FusionParams::coasting_grounds_legs`]); a new
//!   track is adopted by the nearest anchor within [`FusionParams::adopt_m`] that has no track
//!   or whose track the tracker dropped, else starts a new anchor. The anchor's position is its
//!   track's, predicted or updated.
//! - **Faces**: a face's bearing is associated with the anchor nearest in bearing within
//!   [`FusionParams::face_gate_rad`] whose distance agrees with the face's width within
//!   [`FusionParams::face_range_ratio`]; it grounds the face component and gives the person's
//!   height (from its elevation). An unassociated face starts an anchor at the distance its
//!   width gives; an anchor without legs moves to its face's position.
//! - **Torso**: the colour below a person's first associated face becomes the torso model;
//!   each frame the colour tracker starts where the anchor's torso projects and grounds the
//!   torso component when it settles within [`FusionParams::torso_gate_rad`] with a
//!   Bhattacharyya coefficient of at least [`FusionParams::torso_min_rho`], within
//!   [`FusionParams::torso_hold_s`] of the legs' or face's last percept.
//! - **Voice**: the sound lands on the anchor in front of the microphones whose own cone
//!   (from its bearing and its elevation: mouth height from the person's height, range from
//!   the microphones) is nearest to the sound's, compared in the delay's units sin θ = c·τ/d
//!   within sin([`FusionParams::voice_gate_rad`]) ([`VoiceGate::Delay`], since the eighth
//!   session); rounds 1–4 turned the cone into each anchor's front azimuth and gated the
//!   bearing difference ([`VoiceGate::Azimuth`]), a gate that narrows in delay towards the
//!   microphone axis, where one sample of delay spans the most degrees.
//!
//! An anchor is dropped when its legs and its face are both lost: the two percepts that give
//! a position on their own (since round 7; chosen on the development split, where of 356
//! anchor-steps held by torso or voice alone, or by legs the tracker had dropped, 6 lay within
//! 0.5 m of a person). The torso and the voice label and move an anchor one of them holds;
//! rounds 1–6 kept an anchor while any component was alive ([`FusionParams::cues_keep_anchor`]).

use nalgebra::Point3;

use super::Modalities;
use super::component::{Component, State};
use super::torso::Torso;
use super::view::CameraView;
use crate::audio::doa;
use crate::vision::faces::Face;

/// Head centre below the top of the head (m): half an adult head's height.
pub const HEAD_HALF_HEIGHT_M: f64 = 0.12;

/// Where a sound is compared with an anchor's direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum VoiceGate {
    /// In the delay's units, sin θ = c·τ/d: the gate is `sin(voice_gate_rad)` wide
    /// everywhere, as the delay's error is (a priori: 10° at broadside, wider in degrees
    /// towards the microphone axis, where the DOA errs most in degrees).
    Delay,
    /// In front azimuth, `voice_gate_rad` wide (rounds 1–4).
    Azimuth,
}

/// Gates, timeouts and defaults (our choices: the seed gives none).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FusionParams {
    /// Component timeouts (s): legs as long as the tracker coasts (1 s), faces and voice
    /// half a second (a blink, a pause between syllables), torso 1 s.
    pub legs_timeout_s: f64,
    pub face_timeout_s: f64,
    pub torso_timeout_s: f64,
    pub voice_timeout_s: f64,
    /// Bearing gates (rad): faces 6°, torso 8° (several times each percept's spread at 2 m,
    /// less than the bearing between two people standing 0.5 m apart there), voice 10°
    /// (first 8°, widened on the quick profile: the nominal condition's DOA errs by a median
    /// 7–9° in 0.5 s blocks).
    pub face_gate_rad: f64,
    pub torso_gate_rad: f64,
    pub voice_gate_rad: f64,
    /// Where the voice gate is applied ([`VoiceGate`]).
    pub voice_gate_space: VoiceGate,
    /// A face's width-derived distance must be within this factor of the anchor's.
    pub face_range_ratio: f64,
    /// A new leg track is adopted by an anchor without a live track this close (m): about a
    /// face-derived distance's error at 2 m.
    pub adopt_m: f64,
    /// Height of a person before a face gives it (m).
    pub default_height_m: f64,
    pub torso_min_rho: f64,
    /// The torso grounds a person only this long (s) after its legs or face last did (the
    /// colour alone would hold a phantom on a background of its own colour).
    pub torso_hold_s: f64,
    /// A confirmed track that coasted (no detection this scan) grounds the legs too: rounds
    /// 1–6, when a person who left kept a grounded anchor for the tracker's coast (1 s) and an
    /// associated one for the timeout after it. Off by default (the component's own
    /// definition: grounded by a percept).
    pub coasting_grounds_legs: bool,
    /// The torso or the voice alone keeps an anchor (rounds 1–6; module doc). Off by default.
    pub cues_keep_anchor: bool,
}

impl Default for FusionParams {
    fn default() -> Self {
        let deg = std::f64::consts::PI / 180.0;
        FusionParams {
            legs_timeout_s: 1.0,
            face_timeout_s: 0.5,
            torso_timeout_s: 1.0,
            voice_timeout_s: 0.5,
            face_gate_rad: 6.0 * deg,
            torso_gate_rad: 8.0 * deg,
            voice_gate_rad: 10.0 * deg,
            voice_gate_space: VoiceGate::Delay,
            face_range_ratio: 1.6,
            adopt_m: 0.8,
            default_height_m: 1.70,
            torso_min_rho: 0.6,
            torso_hold_s: 3.0,
            coasting_grounds_legs: false,
            cues_keep_anchor: false,
        }
    }
}

/// A leg track of the laser tracker (confirmed), world position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LegTrack {
    pub id: u64,
    pub position: [f64; 2],
    /// A detection updated it in this scan (else it coasted on its prediction).
    pub updated: bool,
}

/// A person anchor.
#[derive(Debug, Clone)]
pub struct PersonAnchor {
    pub id: u64,
    pub position: [f64; 2],
    pub height_m: f64,
    pub leg_track: Option<u64>,
    pub legs: Component,
    pub face: Component,
    pub torso: Component,
    pub voice: Component,
    pub torso_model: Option<Torso>,
    /// The anchor's head was in the camera's view at the last frame.
    pub in_view: bool,
}

impl PersonAnchor {
    /// States of legs, face, torso, voice at `t`.
    pub fn states(&self, t: f64) -> [State; 4] {
        [
            self.legs.state(t),
            self.face.state(t),
            self.torso.state(t),
            self.voice.state(t),
        ]
    }

    pub fn head_z(&self) -> f64 {
        self.height_m - HEAD_HALF_HEIGHT_M
    }

    pub fn mouth_z(&self) -> f64 {
        self.head_z() - 0.05
    }
}

/// The anchors of one robot.
#[derive(Debug, Clone)]
pub struct Fusion {
    pub params: FusionParams,
    pub modalities: Modalities,
    pub anchors: Vec<PersonAnchor>,
    next_id: u64,
}

fn wrap(a: f64) -> f64 {
    doa::wrap(a)
}

fn bearing_from(o: [f64; 2], p: [f64; 2]) -> f64 {
    (p[1] - o[1]).atan2(p[0] - o[0])
}

impl Fusion {
    pub fn new(params: FusionParams, modalities: Modalities) -> Fusion {
        Fusion {
            params,
            modalities,
            anchors: Vec::new(),
            next_id: 1,
        }
    }

    fn create(&mut self, position: [f64; 2]) -> usize {
        let p = &self.params;
        self.anchors.push(PersonAnchor {
            id: self.next_id,
            position,
            height_m: p.default_height_m,
            leg_track: None,
            legs: Component::new(p.legs_timeout_s),
            face: Component::new(p.face_timeout_s),
            torso: Component::new(p.torso_timeout_s),
            voice: Component::new(p.voice_timeout_s),
            torso_model: None,
            in_view: false,
        });
        self.next_id += 1;
        self.anchors.len() - 1
    }

    /// The confirmed leg tracks of the latest scan at `t`.
    pub fn legs(&mut self, t: f64, tracks: &[LegTrack]) {
        if !self.modalities.legs {
            return;
        }
        for tr in tracks {
            let k = match self.anchors.iter().position(|a| a.leg_track == Some(tr.id)) {
                Some(k) => k,
                None => {
                    // anchors without a track, or whose track the tracker dropped
                    let near = self
                        .anchors
                        .iter()
                        .enumerate()
                        .filter(|(_, a)| {
                            a.leg_track
                                .is_none_or(|id| tracks.iter().all(|x| x.id != id))
                        })
                        .map(|(k, a)| {
                            let d = (a.position[0] - tr.position[0])
                                .hypot(a.position[1] - tr.position[1]);
                            (k, d)
                        })
                        .filter(|(_, d)| *d <= self.params.adopt_m)
                        .min_by(|a, b| a.1.total_cmp(&b.1));
                    match near {
                        Some((k, _)) => k,
                        None => self.create(tr.position),
                    }
                }
            };
            let a = &mut self.anchors[k];
            a.leg_track = Some(tr.id);
            a.position = tr.position;
            if tr.updated || self.params.coasting_grounds_legs {
                a.legs.ground(t);
            }
        }
    }

    /// The faces of the frame at `t` seen by `view`; marks which anchors are in view.
    pub fn faces(&mut self, t: f64, view: &CameraView, faces: &[Face]) {
        for a in &mut self.anchors {
            let head = Point3::new(a.position[0], a.position[1], a.head_z());
            a.in_view = view.pixel(&head, 4.0).is_some();
        }
        if !self.modalities.faces {
            return;
        }
        let o = view.origin();
        let cam = [o.x, o.y];
        let p = self.params;
        for f in faces {
            let (az, el) = view.bearing_elevation(f.center());
            let dist = view.face_distance(f.width);
            let range_h = dist * el.cos();
            let best = self
                .anchors
                .iter()
                .enumerate()
                .filter_map(|(k, a)| {
                    let r = (a.position[0] - cam[0]).hypot(a.position[1] - cam[1]);
                    let ratio = (range_h / r.max(0.1)).max(r / range_h.max(0.1));
                    let db = wrap(bearing_from(cam, a.position) - az).abs();
                    (db <= p.face_gate_rad && ratio <= p.face_range_ratio).then_some((k, db))
                })
                .min_by(|a, b| a.1.total_cmp(&b.1));
            let at = [cam[0] + range_h * az.cos(), cam[1] + range_h * az.sin()];
            let k = match best {
                Some((k, _)) => k,
                None => self.create(at),
            };
            let a = &mut self.anchors[k];
            let r = (a.position[0] - cam[0]).hypot(a.position[1] - cam[1]);
            let head_z = o.z + r * el.tan();
            a.height_m = head_z + HEAD_HALF_HEIGHT_M;
            if !a.legs.alive(t) {
                a.position = at;
            }
            a.face.ground(t);
            a.in_view = true;
            if self.modalities.torso && a.torso_model.is_none() {
                a.torso_model = Some(Torso::pending(*f));
            }
        }
    }

    /// Anchors' torso colour in the frame at `t` (`bins`: the frame binned for the colour
    /// tracker).
    pub fn torso(&mut self, t: f64, view: &CameraView, bins: &crate::vision::colortrack::BinImage) {
        if !self.modalities.torso {
            return;
        }
        let o = view.origin();
        let gate = self.params.torso_gate_rad;
        let min_rho = self.params.torso_min_rho;
        let hold = self.params.torso_hold_s;
        for a in &mut self.anchors {
            let Some(model) = a.torso_model.as_mut() else {
                continue;
            };
            let Some((center, rho)) = model.track(bins, view, a.position, a.height_m) else {
                continue;
            };
            let (az, _) = view.bearing_elevation(center);
            let db = wrap(bearing_from([o.x, o.y], a.position) - az).abs();
            let held = [a.legs.last_s, a.face.last_s]
                .iter()
                .flatten()
                .any(|l| t - l <= hold);
            if rho >= min_rho && db <= gate && held {
                a.torso.ground(t);
                if !a.legs.alive(t) && !a.face.alive(t) {
                    let r = (a.position[0] - o.x).hypot(a.position[1] - o.y);
                    a.position = [o.x + r * az.cos(), o.y + r * az.sin()];
                }
            }
        }
    }

    /// A sound of cone angle `cone` (rad) at `t`, heard by microphones centred at `mics`
    /// (world, z their height) on a robot of yaw `robot_yaw`: the anchor it lands on.
    pub fn sound(&mut self, t: f64, cone: f64, mics: [f64; 3], robot_yaw: f64) -> Option<u64> {
        if !self.modalities.sound {
            return None;
        }
        let gate = self.params.voice_gate_rad;
        let best = self
            .anchors
            .iter()
            .enumerate()
            .filter_map(|(k, a)| {
                let r = (a.position[0] - mics[0]).hypot(a.position[1] - mics[1]);
                let el = doa::elevation(a.mouth_z(), mics[2], r);
                if self.params.voice_gate_space == VoiceGate::Delay {
                    // the anchor's own cone: sin θ = cos ε · sin φ of its bearing φ from the
                    // microphone axis; compared in sin θ = c·τ/d, the delay's units
                    let rel = wrap(bearing_from([mics[0], mics[1]], a.position) - robot_yaw);
                    let d = (cone.sin() - el.cos() * rel.sin()).abs();
                    return (rel.cos() >= 0.0 && d <= gate.sin()).then_some((k, d));
                }
                let az = wrap(doa::azimuth(cone, el) + robot_yaw);
                let db = wrap(bearing_from([mics[0], mics[1]], a.position) - az).abs();
                (db <= gate).then_some((k, db))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1));
        let (k, _) = best?;
        self.anchors[k].voice.ground(t);
        Some(self.anchors[k].id)
    }

    /// Drop the anchors whose legs and face are lost (or, with
    /// [`FusionParams::cues_keep_anchor`], whose every component is lost).
    pub fn prune(&mut self, t: f64) {
        let cues = self.params.cues_keep_anchor;
        self.anchors.retain(|a| {
            a.legs.alive(t) || a.face.alive(t) || (cues && (a.torso.alive(t) || a.voice.alive(t)))
        });
    }

    /// Speaking (voice alive) and looking (`None`: out of the camera's view; else a face
    /// alive) of an anchor at `t`.
    pub fn cues(&self, a: &PersonAnchor, t: f64) -> (bool, Option<bool>) {
        let speaking = a.voice.alive(t);
        let looking = a.in_view.then(|| a.face.alive(t));
        (speaking, looking)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::anchoring::attention::category;

    fn at(r: f64, deg: f64) -> [f64; 2] {
        let a = deg.to_radians();
        [r * a.cos(), r * a.sin()]
    }

    fn two_people() -> Fusion {
        let mut f = Fusion::new(FusionParams::default(), Modalities::ALL);
        f.legs(
            0.0,
            &[
                LegTrack {
                    id: 7,
                    position: at(2.0, 20.0),
                    updated: true,
                },
                LegTrack {
                    id: 9,
                    position: at(1.5, -30.0),
                    updated: true,
                },
            ],
        );
        f
    }

    #[test]
    fn leg_tracks_start_anchors_and_keep_their_ids() {
        let mut f = two_people();
        assert_eq!(f.anchors.len(), 2);
        f.legs(
            0.1,
            &[LegTrack {
                id: 7,
                position: at(2.1, 20.0),
                updated: true,
            }],
        );
        assert_eq!(f.anchors.len(), 2, "a known track moves its anchor");
        assert!((f.anchors[0].position[0] - at(2.1, 20.0)[0]).abs() < 1e-12);
        assert_eq!(f.anchors[0].legs.state(0.1), State::Grounded);
        assert_eq!(f.anchors[1].legs.state(0.1), State::Grounded);
        assert_eq!(f.anchors[1].legs.state(0.5), State::Associated);
        f.prune(2.0);
        assert!(
            f.anchors.is_empty(),
            "every component lost after the legs' 1 s timeout"
        );
    }

    #[test]
    fn the_torso_or_the_voice_alone_keeps_an_anchor_only_in_the_old_variant() {
        for (cues_keep_anchor, face, kept) in [
            (false, false, false),
            (true, false, true),
            (false, true, true),
        ] {
            let p = FusionParams {
                cues_keep_anchor,
                ..FusionParams::default()
            };
            let mut f = Fusion::new(p, Modalities::ALL);
            let track = LegTrack {
                id: 2,
                position: at(2.0, 0.0),
                updated: true,
            };
            f.legs(0.0, &[track]);
            // legs last seen at 0.0 (lost after 1.0); torso and voice grounded at 1.1
            let a = &mut f.anchors[0];
            a.torso.ground(1.1);
            a.voice.ground(1.1);
            if face {
                a.face.ground(1.1);
            }
            f.prune(1.2);
            assert_eq!(!f.anchors.is_empty(), kept, "{cues_keep_anchor} {face}");
        }
    }

    #[test]
    fn a_coasting_track_moves_its_anchor_but_grounds_it_only_in_the_old_variant() {
        // a person walks out at 1 m/s: detections until t = 1.0, then the tracker coasts
        // (reports its prediction) for 1 s before deleting the track
        let run = |coasting_grounds_legs: bool| {
            let p = FusionParams {
                coasting_grounds_legs,
                ..FusionParams::default()
            };
            let mut f = Fusion::new(p, Modalities::ALL);
            let mut alive_until = 0.0;
            for k in 0..=40 {
                let t = f64::from(k) * 0.1;
                if t <= 2.0 + 1e-9 {
                    let track = LegTrack {
                        id: 4,
                        position: [2.0 + t, 0.0],
                        updated: t <= 1.0 + 1e-9,
                    };
                    f.legs(t, &[track]);
                }
                f.prune(t);
                if !f.anchors.is_empty() {
                    alive_until = t;
                    assert!((f.anchors[0].position[0] - (2.0 + t.min(2.0))).abs() < 1e-9);
                }
            }
            alive_until
        };
        // grounded by the last detection at 1.0, associated for the 1 s timeout: gone after 2.0
        assert!((run(false) - 2.0).abs() < 1e-9, "{}", run(false));
        // rounds 1-6: the coast grounds it until 2.0, then the 1 s timeout: gone after 3.0
        assert!((run(true) - 3.0).abs() < 1e-9, "{}", run(true));
    }

    #[test]
    fn a_sound_lands_on_the_person_in_its_direction_once_the_mouth_height_is_corrected() {
        let mut f = two_people();
        let mics = [0.0, 0.0, doa::BIRON_MIC_HEIGHT_M];
        // the true cone of the first person's mouth (1.53 m high at 2 m, 20° left)
        let (id, mouth_z) = (f.anchors[0].id, f.anchors[0].mouth_z());
        let el = doa::elevation(mouth_z, mics[2], 2.0);
        let cone = (20f64.to_radians().sin() * el.cos()).asin();
        assert!(
            cone.to_degrees() < 19.5,
            "the raw cone angle is smaller than the azimuth"
        );
        assert_eq!(f.sound(0.0, cone, mics, 0.0), Some(id));
        let (speaking, looking) = f.cues(&f.anchors[0], 0.0);
        assert!(speaking);
        assert_eq!(looking, None, "never in a camera's view: cannot be judged");
        assert_eq!(category(speaking, looking), 2);
        // a direction between the two people lands on nobody
        assert_eq!(f.sound(0.0, (-5f64).to_radians(), mics, 0.0), None);
    }

    /// A person at 60° whose sound reads 12° too close to broadside (the reverberant bias):
    /// outside the azimuth gate of 10°, inside the delay gate (sin 60° − sin 48° = 0.12 <
    /// sin 10° = 0.17); at broadside the two gates agree.
    #[test]
    fn the_delay_gate_widens_towards_the_axis_and_equals_the_azimuth_gate_at_broadside() {
        for (space, want) in [(VoiceGate::Delay, true), (VoiceGate::Azimuth, false)] {
            let heard = |deg_person: f64, deg_sound: f64| {
                let p = FusionParams {
                    voice_gate_space: space,
                    ..FusionParams::default()
                };
                let mut f = Fusion::new(p, Modalities::ALL);
                let (id, position) = (3, at(2.0, deg_person));
                f.legs(
                    0.0,
                    &[LegTrack {
                        id,
                        position,
                        updated: true,
                    }],
                );
                // microphones at the mouth's height: no elevation
                let mics = [0.0, 0.0, f.anchors[0].mouth_z()];
                f.sound(0.0, deg_sound.to_radians(), mics, 0.0).is_some()
            };
            assert_eq!(heard(60.0, 48.0), want, "{space:?} at 60°");
            assert!(heard(0.0, 9.5), "{space:?}: 9.5° off at broadside lands");
            assert!(
                !heard(0.0, 10.5),
                "{space:?}: 10.5° off at broadside does not"
            );
        }
    }

    #[test]
    fn a_source_behind_the_robot_lands_on_a_person_at_its_mirror_in_front() {
        let mut f = two_people();
        let mics = [0.0, 0.0, doa::BIRON_MIC_HEIGHT_M];
        // a talker behind at 160° has the cone of 20° in front: the first person gets it
        let (id, mouth_z) = (f.anchors[0].id, f.anchors[0].mouth_z());
        let el = doa::elevation(mouth_z, mics[2], 2.0);
        let cone = (160f64.to_radians().sin() * el.cos()).asin();
        assert_eq!(f.sound(0.0, cone, mics, 0.0), Some(id));
    }

    #[test]
    fn without_the_sound_modality_no_sound_lands() {
        let mut f = two_people();
        f.modalities.sound = false;
        assert_eq!(f.sound(0.0, 0.3, [0.0, 0.0, 1.06], 0.0), None);
    }
}

//! The ground truth of an instant: every present person (position, velocity, height, legs at
//! the laser's height, and what each camera that captured the instant saw of them), and the
//! calibration target while the calibration person stands on a mark.

use super::rig::Channels;
use super::types::{Scene, Session, SynthError};
use crate::groundtruth::{CameraView, PeopleFrame, PersonTruth, Target, TargetsFrame};
use crate::log::SessionWriter;

/// A calibration target is published while the calibration person stands still within this
/// distance (m) of a mark; walkers stop up to `0.05 + v·dt` short of a goal, so 5 cm was too tight.
/// The published position is where the hat really is, not the mark.
const CALIBRATION_MARK_RADIUS: f64 = 0.15;

/// Every present person at `scene`, with `views[slot]` the camera views of `scene.states[slot]`.
pub(super) fn people(
    ses: &Session,
    scene: &Scene,
    views: Vec<Vec<CameraView>>,
) -> Vec<PersonTruth> {
    scene
        .states
        .iter()
        .zip(views)
        .map(|((i, st), cameras)| {
            let b = &ses.people[*i].body;
            PersonTruth {
                id: b.id,
                x: st.x,
                y: st.y,
                vx: st.vx,
                vy: st.vy,
                height: b.height,
                head_z: b.head_center(st).z,
                radius: b.width,
                legs: b.legs_at(st, ses.laser_height),
                leg_radius: b.leg_radius,
                cameras,
            }
        })
        .collect()
}

/// Write the people of an instant, then its calibration target when there is one.
pub(super) fn write(
    w: &mut SessionWriter,
    ses: &Session,
    ch: &Channels,
    scene: &Scene,
    people: Vec<PersonTruth>,
) -> Result<(), SynthError> {
    let stamp = scene.stamp;
    w.write_json(
        ch.people,
        stamp,
        &PeopleFrame {
            stamp_ns: stamp.0,
            people,
        },
    )?;
    if let (Some(target_ch), Some(c)) = (ch.targets, &ses.s.calibration)
        && let Some((i, st)) = scene
            .states
            .iter()
            .find(|(i, _)| ses.people[*i].body.id == c.person)
        && st.speed < 0.02
        && let Some(k) = c
            .positions
            .iter()
            .position(|p| (p[0] - st.x).hypot(p[1] - st.y) < CALIBRATION_MARK_RADIUS)
    {
        let b = &ses.people[*i].body;
        let hat = b.hat_center(st).unwrap_or_else(|| b.head_top(st));
        w.write_json(
            target_ch,
            stamp,
            &TargetsFrame {
                stamp_ns: stamp.0,
                targets: vec![Target {
                    id: k as u32,
                    x: hat.x,
                    y: hat.y,
                    z: hat.z,
                }],
            },
        )?;
    }
    Ok(())
}

//! The per-session stage of multi mode (our addition: several people, several cameras) —
//! sensing only, as [`super::session`]: every leg pair of every scan (the laser stage is the
//! same), the head-top observations of each camera of `cameras` (the camera stage of
//! [`super::camera`] run once per camera, with the skin histogram from that camera's view of
//! the skin-training logs), and the ground truth of every person. No plane grid and no fig. 4
//! (those are the paper run's). Mount mode (one person seen by cameras at several heights)
//! reads the same, plus the paper run's `truth` table of the one person.

use anyhow::Context;

use super::camera;
use super::params::{Mode, Params};
use super::session::{laser_observations, truth_rows};
use super::tables::{self, CameraObsRow, LaserObsRow, PersonRow, TruthRow};
use crate::frames::{rig, truth};
use crate::groundtruth::PEOPLE_TOPIC;
use crate::log::TfBuffer;
use crate::progress::Progress;
use crate::report::rows::Rows;
use crate::run::{Session, SessionTables};

/// Process one session in multi mode (see the module doc).
pub(super) fn process(
    s: &Session,
    p: &Params,
    bar: &dyn Progress,
) -> anyhow::Result<SessionTables> {
    let log = &s.log;
    let file = log.path().display().to_string();
    let mut out = SessionTables::new();
    if p.is_training(&s.info.path) {
        // the skin-training session: not evaluated (empty tables; the aggregation drops it)
        out.insert(tables::LASER.into(), LaserObsRow::frame(&[])?);
        out.insert(tables::PEOPLE_TRUTH.into(), PersonRow::frame(&[])?);
        for cam in &p.cameras {
            out.insert(tables::camera_table(cam), CameraObsRow::frame(&[])?);
        }
        if p.mode == Mode::Mount {
            out.insert(tables::TRUTH.into(), TruthRow::frame(&[])?);
        }
        return Ok(out);
    }
    if log.summary().channel(&p.scan_topic).is_none() {
        anyhow::bail!("{file}: missing laser topic {}", p.scan_topic);
    }
    let (gt, _) = truth::people(log, PEOPLE_TOPIC)
        .with_context(|| format!("{file}: ground truth {PEOPLE_TOPIC}"))?;
    let people: Vec<PersonRow> = gt
        .iter()
        .flat_map(|(t, f)| {
            f.people.iter().map(move |person| PersonRow {
                stamp_ns: i64::try_from(t.0).unwrap_or(i64::MAX),
                id: i64::from(person.id),
                x: person.x,
                y: person.y,
                height_m: person.height,
            })
        })
        .collect();
    bar.set_message("laser");
    out.insert(
        tables::LASER.into(),
        LaserObsRow::frame(&laser_observations(log, p)?)?,
    );
    let tf = TfBuffer::from_log(log, 0.5)?;
    let tolerance_ns = (p.gt_tolerance_s * 1e9).round() as u64;
    for cam in &p.cameras {
        bar.set_message(&format!("camera {cam}"));
        let pc = p.for_camera(cam);
        let rig = rig::camera(log, &tf, cam, &format!("/{cam}/camera_info"), "map", None)?;
        let model = rig.model()?;
        let (hist, _) = camera::train_skin(&pc, &s.info.path)?;
        let frames = camera::read_frames(log, &pc, &hist, &gt, tolerance_ns)?;
        let obs = camera::observations(&frames, &pc, &model, &rig.world_from_camera)?;
        out.insert(tables::camera_table(cam), CameraObsRow::frame(&obs)?);
    }
    out.insert(tables::PEOPLE_TRUTH.into(), PersonRow::frame(&people)?);
    if p.mode == Mode::Mount {
        out.insert(tables::TRUTH.into(), TruthRow::frame(&truth_rows(&gt))?);
    }
    Ok(out)
}

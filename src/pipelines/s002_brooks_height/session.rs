//! The per-session stage (sensing only; the filters run in the aggregation, because the
//! camera-only trial needs the height learned in another session):
//!
//! - **Laser (§3)**: every scan of `scan_topic` with its `map` pose from TF through the seed
//!   002 leg model of [`crate::laser::legs`] (the `laser_people` detector at its defaults);
//!   each leg pair → range–bearing of its midpoint in the laser frame.
//! - **Camera (§4)**: [`super::camera`] — the skin histogram from the training logs, the
//!   tracking run's head-top observations, and the 1/3 colour × 0/1/2 edge plane grid.
//! - **Ground truth**: the person's position, velocity and height from `/ground_truth/people`.

use anyhow::Context;
use nalgebra::UnitQuaternion;

use super::params::Params;
use super::tables::{self, LaserObsRow, TruthRow};
use super::{camera, fig4};
use crate::frames::laser::{self as laser_frames, LaserOptions};
use crate::frames::truth::Stamped;
use crate::frames::{rig, truth};
use crate::groundtruth::{PEOPLE_TOPIC, PeopleFrame};
use crate::laser::legs::{self, LegParams};
use crate::laser::points::{self, ScanGeometry};
use crate::laser::segment::{self, SegmentOptions};
use crate::log::{SessionLog, TfBuffer};
use crate::progress::Progress;
use crate::report::rows::Rows;
use crate::run::{Session, SessionTables};

/// Leg pairs of every scan as range–bearing observations.
pub(super) fn laser_observations(log: &SessionLog, p: &Params) -> anyhow::Result<Vec<LaserObsRow>> {
    let options = LaserOptions {
        fixed_frame: Some("map".into()),
        ..LaserOptions::default()
    };
    let mut out = Vec::new();
    for (idx, f) in laser_frames::scans(log, &p.scan_topic, &options)?.enumerate() {
        let f = f?;
        let Some(pose) = f.pose else { continue };
        let g = ScanGeometry::of(&f.scan);
        let pts = points::project(&f.scan.ranges, &g, Some(&pose));
        let segs = segment::segment(&pts, &SegmentOptions::default());
        let d = legs::detect(
            &pts,
            &segs,
            f.scan.ranges.len(),
            Some(&pose),
            &LegParams::default(),
        );
        let yaw = UnitQuaternion::from(pose.rotation).euler_angles().2;
        for person in d.people {
            out.push(LaserObsRow {
                scan_idx: idx as i64,
                stamp_ns: i64::try_from(f.stamp.0).unwrap_or(i64::MAX),
                range_m: person.sensor.coords.norm(),
                bearing_rad: person.sensor.y.atan2(person.sensor.x),
                laser_x: pose.translation.vector.x,
                laser_y: pose.translation.vector.y,
                laser_yaw: yaw,
            });
        }
    }
    Ok(out)
}

/// The (first) person's ground truth at every stamp.
pub(super) fn truth_rows(gt: &Stamped<PeopleFrame>) -> Vec<TruthRow> {
    gt.iter()
        .filter_map(|(t, f)| {
            f.people.first().map(|person| TruthRow {
                stamp_ns: i64::try_from(t.0).unwrap_or(i64::MAX),
                x: person.x,
                y: person.y,
                vx: person.vx,
                vy: person.vy,
                height_m: person.height,
            })
        })
        .collect()
}

/// Process one session (see the module doc).
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
        out.insert(tables::CAMERA.into(), tables::CameraObsRow::frame(&[])?);
        out.insert(tables::TRUTH.into(), TruthRow::frame(&[])?);
        out.insert(tables::PLANES.into(), tables::PlanesRow::frame(&[])?);
        out.insert(tables::FIG4.into(), tables::Fig4Row::frame(&[])?);
        return Ok(out);
    }
    if log.summary().channel(&p.scan_topic).is_none() {
        anyhow::bail!("{file}: missing laser topic {}", p.scan_topic);
    }
    let (gt, _) = truth::people(log, PEOPLE_TOPIC)
        .with_context(|| format!("{file}: ground truth {PEOPLE_TOPIC}"))?;
    let truth_rows = truth_rows(&gt);
    bar.set_message("laser");
    let laser = laser_observations(log, p)?;
    bar.set_message("camera");
    let tf = TfBuffer::from_log(log, 0.5)?;
    let cam = rig::camera(
        log,
        &tf,
        &p.camera,
        &format!("/{}/camera_info", p.camera),
        "map",
        None,
    )?;
    let model = cam.model()?;
    let (hist, _) = camera::train_skin(p, &s.info.path)?;
    let tolerance_ns = (p.gt_tolerance_s * 1e9).round() as u64;
    let frames = camera::read_frames(log, p, &hist, &gt, tolerance_ns)?;
    let obs = camera::observations(&frames, p, &model, &cam.world_from_camera)?;
    bar.set_message("plane grid");
    let planes = camera::plane_grid(&frames, p)?;
    bar.set_message("fig. 4");
    let fig4 = fig4::compose(
        log,
        p,
        &frames,
        &laser,
        &obs,
        &model,
        &cam.world_from_camera,
    )?;
    out.insert(tables::FIG4.into(), tables::Fig4Row::frame(&fig4)?);
    out.insert(tables::LASER.into(), LaserObsRow::frame(&laser)?);
    out.insert(tables::CAMERA.into(), tables::CameraObsRow::frame(&obs)?);
    out.insert(tables::TRUTH.into(), TruthRow::frame(&truth_rows)?);
    out.insert(tables::PLANES.into(), tables::PlanesRow::frame(&planes)?);
    Ok(out)
}

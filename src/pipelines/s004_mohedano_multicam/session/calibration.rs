//! The cameras of one session: each camera's first `CameraInfo` and its pose in the world
//! frame from TF.

use anyhow::Context;

use super::super::{Params, Topics};
use crate::geometry::triangulate::CalibratedView;
use crate::log::msgs::CameraInfo;
use crate::log::{SessionLog, TfBuffer, read_topic};
use crate::pipelines::s004_mohedano_multicam::tables::CalibRow;
use crate::time::Nanos;

/// The cameras of one session with their calibration.
#[derive(Debug, Clone)]
pub(crate) struct Calibration {
    pub views: Vec<CalibratedView>,
}

/// Read each camera's first `CameraInfo` and its pose in the world frame from TF.
pub(crate) fn read_calibration(
    log: &SessionLog,
    p: &Params,
    t: &Topics,
) -> anyhow::Result<Calibration> {
    let file = log.path().display().to_string();
    let tf = TfBuffer::from_log(log, 0.0)?;
    let mut views = Vec::new();
    for (cam, topic) in p.cameras.iter().zip(&t.info) {
        let (_, info) = read_topic::<CameraInfo>(log, topic)?
            .next()
            .with_context(|| format!("{file}: no CameraInfo on {topic}"))??;
        let model = info
            .model()
            .with_context(|| format!("{file}: {topic}: camera {cam}"))?;
        let frame = if info.header.frame_id.is_empty() {
            cam.clone()
        } else {
            info.header.frame_id.clone()
        };
        let at = info.header.stamp.nanos().unwrap_or(Nanos(0));
        let world_from_camera = tf.lookup(&p.world_frame, &frame, at).with_context(|| {
            format!(
                "{file}: no transform {} <- {frame} (camera {cam}) at {:.3} s",
                p.world_frame,
                at.0 as f64 * 1e-9
            )
        })?;
        views.push(CalibratedView::new(model, world_from_camera));
    }
    Ok(Calibration { views })
}

/// Each camera's centre and the heading of its optical axis on the ground.
pub(crate) fn calibration_rows(cameras: &[String], views: &[CalibratedView]) -> Vec<CalibRow> {
    cameras
        .iter()
        .zip(views)
        .map(|(name, v)| {
            let c = v.center();
            let axis = v.world_from_camera.rotation * nalgebra::Vector3::z();
            CalibRow {
                camera: name.clone(),
                x_m: c.x,
                y_m: c.y,
                z_m: c.z,
                heading_rad: axis.y.atan2(axis.x),
            }
        })
        .collect()
}

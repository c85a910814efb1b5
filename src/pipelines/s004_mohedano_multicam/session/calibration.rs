//! The cameras of one session (through `frames::rig`) and their positions as a table.

use super::super::{Params, Topics};
use crate::frames::rig;
use crate::geometry::triangulate::CalibratedView;
use crate::log::{SessionLog, TfBuffer};
use crate::pipelines::s004_mohedano_multicam::tables::CalibRow;

/// Each camera's first `CameraInfo` and its pose in the world frame from TF
/// (`frames::rig::views`), in camera order.
pub(crate) fn read_calibration(
    log: &SessionLog,
    p: &Params,
    t: &Topics,
) -> anyhow::Result<Vec<CalibratedView>> {
    let tf = TfBuffer::from_log(log, 0.0)?;
    let cameras: Vec<(String, String)> = p.cameras.iter().cloned().zip(t.info.clone()).collect();
    Ok(rig::views(log, &tf, &cameras, &p.world_frame)?)
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

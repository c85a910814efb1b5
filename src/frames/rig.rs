//! Calibrated cameras: each camera's first `CameraInfo` and its pose in a world frame from TF.

use nalgebra::Isometry3;

use crate::geometry::camera::{CameraError, CameraModel};
use crate::geometry::triangulate::CalibratedView;
use crate::log::msgs::CameraInfo;
use crate::log::tf::TfError;
use crate::log::{LogError, SessionLog, TfBuffer, read_topic};
use crate::time::Nanos;

/// Why a camera could not be calibrated; every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum RigError {
    #[error(transparent)]
    Log(#[from] LogError),
    #[error("{file}: no CameraInfo on {topic} (camera {camera})")]
    NoCameraInfo {
        file: String,
        topic: String,
        camera: String,
    },
    // `error`, not `source`: a source would be printed twice in an error chain
    #[error("{file}: {topic}: camera {camera}: {error}")]
    Model {
        file: String,
        topic: String,
        camera: String,
        error: Box<CameraError>,
    },
    #[error("{file}: no transform {world} <- {frame} (camera {camera}) at {at} s: {error}")]
    NoPose {
        file: String,
        camera: String,
        frame: String,
        world: String,
        at: Nanos,
        error: Box<TfError>,
    },
}

/// One calibrated camera.
#[derive(Debug, Clone, PartialEq)]
pub struct RigCamera {
    pub name: String,
    /// The first `CameraInfo` of the camera's info topic.
    pub info: CameraInfo,
    /// The TF frame of the camera: the info's `frame_id`, or the camera name when empty.
    pub frame: String,
    /// Maps camera-frame points into the world frame.
    pub world_from_camera: Isometry3<f64>,
}

impl RigCamera {
    /// The camera model of the info.
    pub fn model(&self) -> Result<CameraModel, CameraError> {
        self.info.model()
    }
}

/// The first `CameraInfo` on `topic` (error naming file and topic when there is none).
pub fn first_info(log: &SessionLog, camera: &str, topic: &str) -> Result<CameraInfo, RigError> {
    let none = || RigError::NoCameraInfo {
        file: log.path().display().to_string(),
        topic: topic.to_string(),
        camera: camera.to_string(),
    };
    if log.summary().channel(topic).is_none() {
        return Err(none());
    }
    match read_topic::<CameraInfo>(log, topic)?.next() {
        Some(r) => Ok(r?.1),
        None => Err(none()),
    }
}

/// Calibrate `camera` from its first `CameraInfo` on `info_topic` and the TF transform
/// `world_frame <- camera frame` at `at` (the info's header stamp when `None`; zero when that is
/// invalid).
pub fn camera(
    log: &SessionLog,
    tf: &TfBuffer,
    camera: &str,
    info_topic: &str,
    world_frame: &str,
    at: Option<Nanos>,
) -> Result<RigCamera, RigError> {
    let info = first_info(log, camera, info_topic)?;
    let frame = if info.header.frame_id.is_empty() {
        camera.to_string()
    } else {
        info.header.frame_id.clone()
    };
    let at = at.unwrap_or_else(|| info.header.stamp.nanos().unwrap_or(Nanos(0)));
    let world_from_camera =
        tf.lookup(world_frame, &frame, at)
            .map_err(|error| RigError::NoPose {
                file: log.path().display().to_string(),
                camera: camera.to_string(),
                frame: frame.clone(),
                world: world_frame.to_string(),
                at,
                error: Box::new(error),
            })?;
    Ok(RigCamera {
        name: camera.to_string(),
        info,
        frame,
        world_from_camera,
    })
}

/// Calibrate every camera `(name, info topic)` and return their [`CalibratedView`]s, in order.
pub fn views(
    log: &SessionLog,
    tf: &TfBuffer,
    cameras: &[(String, String)],
    world_frame: &str,
) -> Result<Vec<CalibratedView>, RigError> {
    cameras
        .iter()
        .map(|(name, topic)| {
            let cam = camera(log, tf, name, topic, world_frame, None)?;
            let model = cam.model().map_err(|error| RigError::Model {
                file: log.path().display().to_string(),
                topic: topic.clone(),
                camera: name.clone(),
                error: Box::new(error),
            })?;
            Ok(CalibratedView::new(model, cam.world_from_camera))
        })
        .collect()
}

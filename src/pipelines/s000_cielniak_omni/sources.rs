//! The pipeline's two reads of camera data through the frames layer ([`crate::frames`]):
//! decoded frames of a camera by name, and a camera calibrated from its CameraInfo and TF.

use anyhow::Context;
use image::RgbImage;

use crate::frames::{Skips, camera, rig};
use crate::log::{SessionLog, TfBuffer};

/// Every frame of camera `name` as `(stamp ns, RGB image)`, through the frames layer; messages
/// that do not decode are skipped and counted in `skips`.
pub(super) fn for_each_frame(
    log: &SessionLog,
    name: &str,
    skips: &mut Skips,
    mut f: impl FnMut(i64, RgbImage) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    let topic = camera::image_topic(log, name)
        .with_context(|| format!("no image topic for camera `{name}`"))?;
    let mut frames = camera::frames(log, &topic, None)?;
    for fr in &mut frames {
        let fr = fr?;
        f(fr.stamp.0 as i64, fr.rgb)?;
    }
    skips.merge(frames.into_skips());
    Ok(())
}

/// Camera `name` calibrated from its first `/<name>/camera_info` and its TF pose in `map` at
/// `t0`.
pub(super) fn rig_camera(
    log: &SessionLog,
    tf: &TfBuffer,
    name: &str,
    t0: crate::Nanos,
) -> anyhow::Result<rig::RigCamera> {
    Ok(rig::camera(
        log,
        tf,
        name,
        &format!("/{name}/camera_info"),
        "map",
        Some(t0),
    )?)
}

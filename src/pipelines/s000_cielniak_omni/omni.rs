//! The omni camera's per-frame features (sections 4.2–4.3): panorama unwrap, background from
//! the first person-free frames, depth-cue features and the person's bearing.

use anyhow::Context;

use super::params::Params;
use super::sources::{for_each_frame, rig_camera};
use super::tables::{OmniRow, PoseRow};
use crate::frames::Skips;
use crate::geometry::camera::CameraModel;
use crate::log::{SessionLog, TfBuffer};
use crate::vision::omni::{Background, Unwrapper, features};

/// The unwrapper for an omnidirectional camera model (a pinhole is refused).
fn unwrapper(model: &CameraModel, p: &Params) -> anyhow::Result<Unwrapper> {
    let (xc, yc, rim) = match model {
        CameraModel::ConicalMirror(c) => (c.xc, c.yc, c.r_rim()),
        CameraModel::Paracatadioptric(c) => (c.xc, c.yc, c.r_max),
        CameraModel::Pinhole(_) => anyhow::bail!(
            "camera `{}` is a pinhole, not an omnidirectional camera",
            p.omni
        ),
    };
    Ok(Unwrapper::new(
        xc,
        yc,
        p.inner_radius * rim,
        rim,
        p.panorama[0],
        p.panorama[1],
    ))
}

/// One row per omni frame after the background frames, and the camera's pose in the map.
pub fn features_of(
    log: &SessionLog,
    tf: &TfBuffer,
    t0: crate::Nanos,
    p: &Params,
    skips: &mut Skips,
) -> anyhow::Result<(Vec<OmniRow>, PoseRow)> {
    let cam = rig_camera(log, tf, &p.omni, t0)?;
    let model = cam
        .model()
        .with_context(|| format!("/{}/camera_info", p.omni))?;
    let unwrap = unwrapper(&model, p)?;
    let omni_pose = cam.world_from_camera;
    let ox = omni_pose.rotation * nalgebra::Vector3::x();
    let mut bg_frames: Vec<Vec<f32>> = Vec::new();
    let mut background: Option<Background> = None;
    let mut rows = Vec::new();
    for_each_frame(log, &p.omni, skips, |stamp, img| {
        let pano = unwrap.unwrap_grey(&img);
        if background.is_none() {
            bg_frames.push(pano);
            if bg_frames.len() == p.background_frames {
                background = Some(Background::learn(&bg_frames, p.panorama[0], p.panorama[1])?);
            }
            return Ok(());
        }
        let Some(bg) = &background else { return Ok(()) };
        let f = features(bg, &pano)?;
        rows.push(OmniRow {
            stamp,
            valid: f.is_some(),
            width: f.map_or(f64::NAN, |f| f.width),
            apparent_distance: f.map_or(f64::NAN, |f| f.apparent_distance),
            pixels: f.map_or(f64::NAN, |f| f.pixels),
            angle: f.map_or(f64::NAN, |f| unwrap.angle(f.mean_column)),
        });
        Ok(())
    })?;
    if background.is_none() {
        anyhow::bail!(
            "params.background_frames = {}: /{} has only {} image(s), none left after the background",
            p.background_frames,
            p.omni,
            bg_frames.len()
        );
    }
    let pose = PoseRow {
        x: omni_pose.translation.x,
        y: omni_pose.translation.y,
        yaw: ox.y.atan2(ox.x),
    };
    Ok((rows, pose))
}

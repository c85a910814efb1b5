//! The `--write-tracks` export step (the only part of the aggregation that reads the input
//! logs, so it needs them; it runs only when `--write-tracks` or the `write_tracks` parameter
//! names a folder, never in plain aggregation): tracks back into MCAP, a copy of each session
//! log with one more topic,
//! `visualization_msgs/msg/MarkerArray` at every frame — a translucent cylinder per person
//! (ground position, height, radius) and a text label with the track id, in the world frame.
//! Foxglove's 3-D panel draws them with the scene, and its image panel projects them over the
//! camera images through `/tf_static` and `camera_info`, which the copy keeps.
//!
//! Markers live for two frame periods, so a track that ends disappears without DELETE
//! messages. Messages keep their log times; the markers are stamped and logged at the frame's
//! header stamp and interleaved in time order with the copied messages.

use std::path::{Path, PathBuf};

use anyhow::Context;
use nalgebra::{Point3, Quaternion, Vector3};

use super::Params;
use super::scored::Scored;
use super::tables::TrackRow;
use crate::log::copy::copy_with_messages;
use crate::log::msgs::{Header, Marker, MarkerArray, Pose, Time};
use crate::report::figure::color;
use crate::run::Aggregate;
use crate::time::Nanos;

/// Markers of one frame: `(stamp, [(id, x, y, height, radius, cameras)])`.
pub(crate) type FrameTracks = (Nanos, Vec<(i64, f64, f64, f64, f64, i64)>);

/// The marker array of one frame.
pub(crate) fn markers_for(
    frame_id: &str,
    stamp: Nanos,
    life_s: f64,
    tracks: &[(i64, f64, f64, f64, f64, i64)],
) -> MarkerArray {
    let lifetime = Time {
        sec: life_s.floor() as i32,
        nanosec: ((life_s.fract()) * 1e9) as u32,
    };
    let mut markers = Vec::with_capacity(2 * tracks.len());
    for &(id, x, y, h, r, cams) in tracks {
        let c = color((id as usize % 7) + 1);
        let rgba = [
            f32::from(c.0) / 255.0,
            f32::from(c.1) / 255.0,
            f32::from(c.2) / 255.0,
            0.45,
        ];
        let r = if r.is_finite() && r > 0.0 { r } else { 0.2 };
        let h = if h.is_finite() && h > 0.0 { h } else { 1.7 };
        let header = Header::new(stamp, frame_id);
        markers.push(Marker {
            header: header.clone(),
            ns: "cylinders".into(),
            id: id as i32,
            kind: Marker::CYLINDER,
            action: Marker::ADD,
            pose: Pose {
                position: Point3::new(x, y, h / 2.0),
                orientation: Quaternion::identity(),
            },
            scale: Vector3::new(2.0 * r, 2.0 * r, h),
            color: rgba,
            lifetime,
            ..Default::default()
        });
        markers.push(Marker {
            header,
            ns: "labels".into(),
            id: id as i32,
            kind: Marker::TEXT_VIEW_FACING,
            action: Marker::ADD,
            pose: Pose {
                position: Point3::new(x, y, h + 0.25),
                orientation: Quaternion::identity(),
            },
            scale: Vector3::new(0.0, 0.0, 0.25),
            color: [rgba[0], rgba[1], rgba[2], 1.0],
            lifetime,
            text: format!("{id} ({cams} cams)"),
            ..Default::default()
        });
    }
    MarkerArray { markers }
}

/// Copy `input` to `output` with the tracks added as markers on `topic`; returns the number of
/// marker messages written (the copy itself is [`copy_with_messages`]).
pub(crate) fn write_tracks(
    input: &Path,
    output: &Path,
    topic: &str,
    frame_id: &str,
    life_s: f64,
    frames: &[FrameTracks],
) -> anyhow::Result<usize> {
    let markers = frames
        .iter()
        .map(|(stamp, tracks)| (*stamp, 0, markers_for(frame_id, *stamp, life_s, tracks)));
    Ok(copy_with_messages(input, output, &[topic], markers)?)
}

/// The folder of the export: `--write-tracks`, else the `write_tracks` parameter; none: no
/// export.
pub(crate) fn export_dir(ctx: &Aggregate, p: &Params) -> Option<PathBuf> {
    ctx.write_tracks
        .map(Path::to_path_buf)
        .or_else(|| (!p.write_tracks.is_empty()).then(|| PathBuf::from(&p.write_tracks)))
}

/// The markers of the main run of one session, one entry per frame with tracks.
pub(crate) fn frame_tracks(rows: &[&TrackRow]) -> Vec<FrameTracks> {
    let mut frames: Vec<FrameTracks> = Vec::new();
    for r in rows {
        let stamp = Nanos(r.stamp_ns as u64);
        if frames.last().is_none_or(|f| f.0 != stamp) {
            frames.push((stamp, Vec::new()));
        }
        if let Some(f) = frames.last_mut() {
            f.1.push((r.id, r.x_m, r.y_m, r.height_m, r.radius_m, r.cameras));
        }
    }
    frames
}

/// Write every session's tracks (main run) into copies of the logs under `dir` (reads the
/// logs).
pub(crate) fn export(s: &Scored, p: &Params, dir: &Path) -> anyhow::Result<Vec<String>> {
    let mut lines = Vec::new();
    for d in &s.data {
        let frames = frame_tracks(&d.rows(&s.main));
        let out = dir.join(&d.dataset).join(format!("{}_tracks.mcap", d.name));
        let n = write_tracks(
            &d.path,
            &out,
            &p.tracks_topic,
            &p.world_frame,
            2.0 * d.session.dt_s,
            &frames,
        )
        .with_context(|| {
            format!(
                "writing tracks of {} to {}",
                d.path.display(),
                out.display()
            )
        })?;
        lines.push(format!(
            "Tracks of {}/{} written to {} ({n} MarkerArray messages on {}).",
            d.dataset,
            d.name,
            out.display(),
            p.tracks_topic
        ));
    }
    Ok(lines)
}

//! The `--write-tracks` export (run only when asked; the one step of the aggregation that
//! reads the logs, to copy them): a copy of each session log with one more topic per method,
//! `/peopletrack/laser_people/<method>/markers` (`visualization_msgs/msg/MarkerArray`), for
//! Foxglove's 3-D panel. On every scan each method gets one array: a `DELETEALL` marker (the
//! previous scan's tracks go), then per track a sphere (ns `tracks`) and a text label with the
//! track id (ns `ids`), both with the track id as marker id, in the laser frame at the scan's
//! header stamp (`frame_id` as the scan names it), logged at the scan's log time so they
//! interleave with the scans (the real logs' stamps run ahead of log time). The copy itself is
//! [`copy_with_messages`]; the positions are the cached laser-frame tracks (`tracks` CSV).

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::Context;
use nalgebra::{Point3, Quaternion, Vector3};

use super::aggregate::SessionData;
use super::params::Params;
use super::tables::{ScanRow, TrackRow};
use super::view::{self, PoseRow};
use crate::log::copy::copy_with_messages;
use crate::log::msgs::{Header, Marker, MarkerArray, Pose};
use crate::report::figure::color;
use crate::run::Aggregate;
use crate::time::Nanos;

/// Sphere diameter (m), about a person's width at leg height.
pub const SPHERE_M: f64 = 0.3;
/// Height of the id label above the scan plane, and its text height (m).
pub const LABEL_Z_M: f64 = 0.4;
pub const LABEL_SIZE_M: f64 = 0.25;

/// The marker topic of one method.
pub fn topic(method: &str) -> String {
    format!("/peopletrack/laser_people/{method}/markers")
}

/// The array of one method on one scan: `DELETEALL`, then a sphere and a label per track.
pub fn markers_for(frame_id: &str, stamp: Nanos, tracks: &[&TrackRow]) -> MarkerArray {
    let header = Header::new(stamp, frame_id);
    let mut markers = vec![Marker {
        header: header.clone(),
        action: Marker::DELETEALL,
        ..Default::default()
    }];
    for t in tracks {
        let id = i32::try_from(t.id).unwrap_or(i32::MAX);
        let c = color((t.id.rem_euclid(7)) as usize + 1);
        let rgb = [c.0, c.1, c.2].map(|v| f32::from(v) / 255.0);
        let at = |z: f64| Pose {
            position: Point3::new(t.x, t.y, z),
            orientation: Quaternion::identity(),
        };
        markers.push(Marker {
            header: header.clone(),
            ns: "tracks".into(),
            id,
            kind: Marker::SPHERE,
            action: Marker::ADD,
            pose: at(0.0),
            scale: Vector3::new(SPHERE_M, SPHERE_M, SPHERE_M),
            color: [rgb[0], rgb[1], rgb[2], 0.8],
            ..Default::default()
        });
        markers.push(Marker {
            header: header.clone(),
            ns: "ids".into(),
            id,
            kind: Marker::TEXT_VIEW_FACING,
            action: Marker::ADD,
            pose: at(LABEL_Z_M),
            scale: Vector3::new(0.0, 0.0, LABEL_SIZE_M),
            color: [rgb[0], rgb[1], rgb[2], 1.0],
            text: t.id.to_string(),
            ..Default::default()
        });
    }
    MarkerArray { markers }
}

/// `(log time, method index, array)` for every scan and method, in log order.
fn session_markers(
    scans: &[ScanRow],
    poses: &[PoseRow],
    tracks: &[TrackRow],
    methods: &[&str],
) -> Vec<(Nanos, usize, MarkerArray)> {
    let frame: BTreeMap<i64, &str> = poses
        .iter()
        .map(|p| (p.scan_idx, p.frame_id.as_str()))
        .collect();
    let mut by_scan: BTreeMap<(&str, i64), Vec<&TrackRow>> = BTreeMap::new();
    for t in tracks {
        by_scan
            .entry((t.detector.as_str(), t.scan_idx))
            .or_default()
            .push(t);
    }
    let nanos = |v: i64| Nanos(u64::try_from(v).unwrap_or(0));
    let mut out = Vec::with_capacity(scans.len() * methods.len());
    for s in scans {
        let frame_id = frame.get(&s.scan_idx).copied().unwrap_or_default();
        for (k, m) in methods.iter().enumerate() {
            let rows = by_scan
                .get(&(*m, s.scan_idx))
                .map_or(&[][..], Vec::as_slice);
            out.push((
                nanos(s.log_time_ns),
                k,
                markers_for(frame_id, nanos(s.stamp_ns), rows),
            ));
        }
    }
    out
}

/// Write every session's copy under `dir/<dataset>/<session>_laser_people.mcap`; a session
/// whose log is gone (`--aggregate-only`) gets a line saying so. Returns the report lines.
pub(super) fn export(
    ctx: &Aggregate,
    p: &Params,
    data: &[SessionData],
    dir: &Path,
) -> anyhow::Result<Vec<String>> {
    let methods: Vec<&str> = p.methods.iter().map(|m| m.name()).collect();
    let topics: Vec<String> = methods.iter().map(|m| topic(m)).collect();
    let topic_refs: Vec<&str> = topics.iter().map(String::as_str).collect();
    let mut lines = Vec::new();
    for (d, (info, t)) in data.iter().zip(ctx.sessions) {
        let label = format!("{}/{}", d.dataset, d.name);
        if !info.path.exists() {
            lines.push(format!(
                "Tracks of {label} not written: its log {} is absent.",
                info.path.display()
            ));
            continue;
        }
        let (poses, _) = view::read(t, &label)?;
        let items = session_markers(&d.scans, &poses, &d.tracks, &methods);
        let out = dir
            .join(&d.dataset)
            .join(format!("{}_laser_people.mcap", d.name));
        let n = copy_with_messages(&info.path, &out, &topic_refs, items).with_context(|| {
            format!(
                "writing the tracks of {} to {}",
                info.path.display(),
                out.display()
            )
        })?;
        lines.push(format!(
            "Tracks of {label} written to {} ({n} MarkerArray messages on {}).",
            out.display(),
            topics.join(", ")
        ));
    }
    Ok(lines)
}

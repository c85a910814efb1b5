//! The per-camera image stages (templates detector): segmented fraction, MAD threshold,
//! detections and 2-D objects per frame, means over all frames of all sessions.

use std::collections::BTreeMap;

use crate::pipelines::s004_mohedano_multicam::scored::Scored;
use crate::pipelines::s004_mohedano_multicam::tables::CameraRow;
use crate::report::Table;
use crate::report::rows::Rows;

crate::table_row! {
    /// One camera's means.
    #[derive(Debug, Clone, PartialEq)]
    pub(crate) struct StageRow {
        pub camera: String,
        pub frames: i64,
        pub foreground_fraction: f64,
        pub mad_threshold: f64,
        pub detections_per_frame: f64,
        pub objects_2d_per_frame: f64,
    }
}

/// Per camera (by name), the means of its rows.
pub(crate) fn rows<'a>(rows: impl IntoIterator<Item = &'a CameraRow>) -> Vec<StageRow> {
    // per camera: Σ foreground, Σ threshold, Σ detections, Σ objects, frames
    let mut acc: BTreeMap<String, (f64, f64, f64, f64, usize)> = BTreeMap::new();
    for r in rows {
        let e = acc.entry(r.camera.clone()).or_default();
        e.0 += r.foreground_frac;
        e.1 += r.threshold;
        e.2 += r.detections as f64;
        e.3 += r.objects_2d as f64;
        e.4 += 1;
    }
    acc.into_iter()
        .map(|(camera, v)| {
            let m = v.4.max(1) as f64;
            StageRow {
                camera,
                frames: v.4 as i64,
                foreground_fraction: v.0 / m,
                mad_threshold: v.1 / m,
                detections_per_frame: v.2 / m,
                objects_2d_per_frame: v.3 / m,
            }
        })
        .collect()
}

pub(super) fn table(s: &Scored) -> anyhow::Result<Table> {
    let rows = rows(s.data.iter().flat_map(|d| &d.cameras));
    Ok(Table::new(
        "stages",
        "Per-camera image stages (templates detector): segmented fraction, MAD threshold, detections and 2-D objects per frame",
        StageRow::frame(&rows)?,
    )
    .with_precision("foreground_fraction", 4)
    .with_precision("mad_threshold", 4)
    .with_precision("detections_per_frame", 2)
    .with_precision("objects_2d_per_frame", 2)
    .with_note("Means over all frames of all sessions. The MAD threshold is in Gabor-feature distance units (median + k · 1.4826 · MAD of the frame's distance image). Empty when the detector is `log`."))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam(camera: &str, fg: f64, dets: i64) -> CameraRow {
        CameraRow {
            frame: 0,
            camera: camera.into(),
            threshold: 2.0,
            foreground_frac: fg,
            detections: dets,
            objects_2d: 1,
        }
    }

    #[test]
    fn means_per_camera_in_name_order() {
        let r = rows(&[
            cam("cam_1", 0.25, 3),
            cam("cam_0", 0.5, 1),
            cam("cam_1", 0.75, 0),
        ]);
        assert_eq!(
            r,
            [
                StageRow {
                    camera: "cam_0".into(),
                    frames: 1,
                    foreground_fraction: 0.5,
                    mad_threshold: 2.0,
                    detections_per_frame: 1.0,
                    objects_2d_per_frame: 1.0,
                },
                StageRow {
                    camera: "cam_1".into(),
                    frames: 2,
                    foreground_fraction: 0.5,
                    mad_threshold: 2.0,
                    detections_per_frame: 1.5,
                    objects_2d_per_frame: 1.0,
                },
            ]
        );
    }
}

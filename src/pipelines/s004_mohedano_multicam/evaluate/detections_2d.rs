//! The paper's detector (§2–3) alone: template detections against the log's visible
//! ground-truth boxes, per camera and over all cameras.

use std::collections::BTreeMap;

use crate::pipelines::s004_mohedano_multicam::scored::Scored;
use crate::pipelines::s004_mohedano_multicam::session::{DETECTION_HEAD_TOL, MIN_BOX_HEIGHT_PX};
use crate::pipelines::s004_mohedano_multicam::tables::Det2dRow;
use crate::report::Table;
use crate::report::rows::Rows;

/// The row over all cameras.
const ALL: &str = "all";

crate::table_row! {
    /// One camera (or all) over all frames.
    #[derive(Debug, Clone, PartialEq)]
    pub(crate) struct Detections2dRow {
        pub camera: String,
        pub frames: i64,
        pub people_per_frame: f64,
        pub detections_per_frame: f64,
        pub precision: f64,
        pub recall: f64,
        pub f1: f64,
        pub head_dx_abs_px: f64,
        pub head_dy_px: f64,
        pub height_ratio: f64,
    }
}

/// Sums of one camera: frames, truth, detections, matched, Σ|dx|, Σdy, Σ height ratio.
type Sums = (i64, i64, i64, i64, f64, f64, f64);

/// Per camera (by name) and over all cameras (last); none without rows.
pub(crate) fn rows<'a>(rows: impl IntoIterator<Item = &'a Det2dRow>) -> Vec<Detections2dRow> {
    let mut acc: BTreeMap<String, Sums> = BTreeMap::new();
    for r in rows {
        for key in [r.camera.clone(), ALL.to_string()] {
            let e = acc.entry(key).or_default();
            e.0 += 1;
            e.1 += r.truth;
            e.2 += r.detections;
            e.3 += r.matched;
            e.4 += r.head_dx_abs_px;
            e.5 += r.head_dy_px;
            e.6 += r.height_ratio;
        }
    }
    // cameras first, "all" last
    let mut keys: Vec<&String> = acc.keys().filter(|k| *k != ALL).collect();
    let all = ALL.to_string();
    if acc.contains_key(ALL) {
        keys.push(&all);
    }
    keys.into_iter().map(|k| row(k, &acc[k])).collect()
}

fn row(camera: &str, v: &Sums) -> Detections2dRow {
    let frames = v.0.max(1) as f64;
    let ratio = |a: i64, b: i64| if b > 0 { a as f64 / b as f64 } else { f64::NAN };
    let per_match = |x: f64| if v.3 > 0 { x / v.3 as f64 } else { f64::NAN };
    let (precision, recall) = (ratio(v.3, v.2), ratio(v.3, v.1));
    Detections2dRow {
        camera: camera.to_string(),
        frames: v.0,
        people_per_frame: v.1 as f64 / frames,
        detections_per_frame: v.2 as f64 / frames,
        precision,
        recall,
        f1: 2.0 * precision * recall / (precision + recall),
        head_dx_abs_px: per_match(v.4),
        head_dy_px: per_match(v.5),
        height_ratio: per_match(v.6),
    }
}

pub(super) fn table(s: &Scored, summary: &mut Vec<String>) -> anyhow::Result<Option<Table>> {
    let rows = rows(s.data.iter().flat_map(|d| &d.detections_2d));
    let Some(all) = rows.last() else {
        return Ok(None);
    };
    summary.push(format!(
        "template detector alone (head within {DETECTION_HEAD_TOL} box widths of the true head): precision {:.3}, recall {:.3}, {:.1} detections for {:.1} people per camera and frame",
        all.precision, all.recall, all.detections_per_frame, all.people_per_frame
    ));
    Ok(Some(
        Table::new(
            "detections_2d",
            "The template detector alone (§2–3): detections against the visible ground-truth boxes per camera",
            Detections2dRow::frame(&rows)?,
        )
        .with_precision("people_per_frame", 2)
        .with_precision("detections_per_frame", 2)
        .with_precision("head_dx_abs_px", 1)
        .with_precision("head_dy_px", 1)
        .with_precision("height_ratio", 2)
        .with_note(format!("A detection matches a ground-truth person (the visible box, at least {MIN_BOX_HEIGHT_PX} px tall) when its head point lies within {DETECTION_HEAD_TOL} × the visible box width of the person's projected head top (from the log's ground truth; the box's top centre when the log has none) — the point the 3-D stage triangulates; IoU would punish the full-body template box of a person whose legs a desk hides — one to one, nearest first. Head offsets and height ratios are means over matched pairs: head_dy_px < 0 puts the detected head above the projected head top; height_ratio is the template's silhouette height over the visible box height (a desk hides the legs, so > 1 is expected there)."))
        .with_note("Paper: no detection numbers (fig. 3 shows the process on one frame)."),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn d(camera: &str, truth: i64, detections: i64, matched: i64) -> Det2dRow {
        Det2dRow {
            frame: 0,
            camera: camera.into(),
            truth,
            detections,
            matched,
            head_dx_abs_px: 2.0 * matched as f64,
            head_dy_px: -(matched as f64),
            height_ratio: 1.5 * matched as f64,
        }
    }

    #[test]
    fn precision_recall_and_per_match_means_per_camera_and_overall() {
        let r = rows(&[
            d("cam_1", 2, 4, 2),
            d("cam_0", 2, 1, 1),
            d("cam_1", 2, 0, 0),
        ]);
        let names: Vec<&str> = r.iter().map(|x| x.camera.as_str()).collect();
        assert_eq!(names, ["cam_0", "cam_1", "all"]);
        let c1 = &r[1];
        assert_eq!(
            (c1.frames, c1.people_per_frame, c1.detections_per_frame),
            (2, 2.0, 2.0)
        );
        assert_eq!((c1.precision, c1.recall), (0.5, 0.5));
        assert_eq!(
            (c1.head_dx_abs_px, c1.head_dy_px, c1.height_ratio),
            (2.0, -1.0, 1.5)
        );
        let all = &r[2];
        // 3 matched of 5 detections and 6 people
        assert_eq!((all.precision, all.recall), (0.6, 0.5));
        assert!((all.f1 - 6.0 / 11.0).abs() < 1e-12);
    }

    #[test]
    fn no_rows_no_table_rows() {
        assert!(rows(&[]).is_empty());
    }
}

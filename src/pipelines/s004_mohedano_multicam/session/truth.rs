//! Per-frame rows against the ground truth: the people of each frame, and the template
//! detections of each camera scored against the visible ground-truth boxes.

use super::boxes::{BoxHead, boxes_from_truth};
use crate::groundtruth::PeopleFrame;
use crate::pipelines::s004_mohedano_multicam::tables::{Det2dRow, GtRow};
use crate::time::Nanos;
use crate::track::graph_match::Box2d;
use crate::vision::template::Detection;

/// A template detection matches a ground-truth person when its head point is within this many
/// visible-box widths of the person's projected head top.
pub(crate) const DETECTION_HEAD_TOL: f64 = 0.5;

/// The people of one frame (`k`, at `stamp`; `t0`: the session's first frame).
pub(crate) fn gt_rows(
    k: usize,
    stamp: Nanos,
    t0: Nanos,
    gt: &PeopleFrame,
    cameras: &[String],
    room: [f64; 4],
) -> Vec<GtRow> {
    gt.people
        .iter()
        .map(|person| GtRow {
            frame: k as i64,
            stamp_ns: stamp.0 as i64,
            t_s: (stamp.0.saturating_sub(t0.0)) as f64 * 1e-9,
            id: i64::from(person.id),
            x_m: person.x,
            y_m: person.y,
            height_m: person.height,
            radius_m: person.radius,
            cameras_visible: person
                .cameras
                .iter()
                .filter(|v| v.bbox.is_some() && v.visibility > 0.0 && cameras.contains(&v.camera))
                .count() as i64,
            in_room: person.x >= room[0]
                && person.x <= room[2]
                && person.y >= room[1]
                && person.y <= room[3],
        })
        .collect()
}

/// One-to-one matching of detections to the truth's visible boxes: greedy by increasing head
/// distance; a detection's head point must lie within `head_tol` visible-box widths of the
/// truth's head point (the point the 3-D stage triangulates; IoU would punish the full-body
/// template box of a person whose legs a desk hides). `(truth, detection)` pairs, nearest
/// first.
pub(crate) fn match_heads(
    truth: &[Box2d],
    dets: &[Detection],
    head_tol: f64,
) -> Vec<(usize, usize)> {
    let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
    for (i, t) in truth.iter().enumerate() {
        for (j, d) in dets.iter().enumerate() {
            let dist = (d.head_px[0] - t.head_px[0]).hypot(d.head_px[1] - t.head_px[1]);
            if dist <= head_tol * t.width_px {
                pairs.push((dist, i, j));
            }
        }
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    let (mut used_t, mut used_d) = (vec![false; truth.len()], vec![false; dets.len()]);
    let mut out = Vec::new();
    for (_, i, j) in pairs {
        if used_t[i] || used_d[j] {
            continue;
        }
        used_t[i] = true;
        used_d[j] = true;
        out.push((i, j));
    }
    out
}

/// Template detections of one camera against the truth's visible boxes ([`match_heads`]).
pub(crate) fn det2d_row(
    frame: usize,
    camera: &str,
    truth: &[Box2d],
    dets: &[Detection],
    head_tol: f64,
) -> Det2dRow {
    let (mut n, mut dx, mut dy, mut hr) = (0i64, 0.0, 0.0, 0.0);
    for (i, j) in match_heads(truth, dets, head_tol) {
        n += 1;
        dx += (dets[j].head_px[0] - truth[i].head_px[0]).abs();
        dy += dets[j].head_px[1] - truth[i].head_px[1];
        hr += dets[j].height_px / truth[i].height_px.max(1.0);
    }
    Det2dRow {
        frame: frame as i64,
        camera: camera.to_string(),
        truth: truth.len() as i64,
        detections: dets.len() as i64,
        matched: n,
        head_dx_abs_px: dx,
        head_dy_px: dy,
        height_ratio: hr,
    }
}

/// The rows of every camera at one frame.
pub(crate) fn det2d_rows(
    frame: usize,
    gt: &PeopleFrame,
    cameras: &[String],
    detections: &[Vec<Detection>],
) -> Vec<Det2dRow> {
    cameras
        .iter()
        .enumerate()
        .map(|(c, cam)| {
            let truth_boxes: Vec<Box2d> = boxes_from_truth(gt, cam, BoxHead::Truth)
                .into_iter()
                .map(|(_, b)| b)
                .collect();
            let dets = detections.get(c).map(Vec::as_slice).unwrap_or(&[]);
            det2d_row(frame, cam, &truth_boxes, dets, DETECTION_HEAD_TOL)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn truth_box(head: [f64; 2], width: f64, height: f64) -> Box2d {
        Box2d {
            bbox: [
                head[0] - width / 2.0,
                head[1],
                head[0] + width / 2.0,
                head[1] + height,
            ],
            head_px: head,
            width_px: width,
            height_px: height,
        }
    }

    fn det(head: [f64; 2], height: f64) -> Detection {
        Detection {
            bbox: [head[0] - 5.0, head[1], head[0] + 5.0, head[1] + height],
            head_px: head,
            centroid_px: head,
            width_px: 10.0,
            height_px: height,
            score: 1.0,
            template: 0,
        }
    }

    #[test]
    fn detections_match_one_to_one_nearest_head_first_within_the_tolerance() {
        // two people 20 px wide (tolerance 10 px); three detections: one 3 px right of the
        // first head and 2 px above, one 9 px from both heads, one far away
        let truth = [
            truth_box([100.0, 50.0], 20.0, 80.0),
            truth_box([118.0, 50.0], 20.0, 40.0),
        ];
        let dets = [
            det([103.0, 48.0], 80.0),
            det([109.0, 50.0], 60.0),
            det([300.0, 50.0], 10.0),
        ];
        let row = det2d_row(7, "cam_1", &truth, &dets, 0.5);
        assert_eq!(
            row,
            Det2dRow {
                frame: 7,
                camera: "cam_1".into(),
                truth: 2,
                detections: 3,
                matched: 2,
                // first: |3| + second: |109 − 118| = 9
                head_dx_abs_px: 12.0,
                head_dy_px: -2.0,
                // 80 / 80 + 60 / 40
                height_ratio: 2.5,
            }
        );
    }

    #[test]
    fn a_detection_beyond_the_tolerance_does_not_match() {
        let truth = [truth_box([100.0, 50.0], 20.0, 80.0)];
        let row = det2d_row(0, "c", &truth, &[det([110.5, 50.0], 80.0)], 0.5);
        assert_eq!((row.matched, row.head_dx_abs_px), (0, 0.0));
    }
}

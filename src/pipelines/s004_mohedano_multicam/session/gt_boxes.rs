//! The ground-truth-box run: the log's visible ground-truth boxes as the detector, through the
//! same 2-D tracker, so that the 3-D stage is measured apart from detection.

use super::super::Params;
use super::boxes::{box_head, boxes_from_truth, graph_params};
use crate::geometry::triangulate::CalibratedView;
use crate::groundtruth::PeopleFrame;
use crate::track::cylinders::Object2d;
use crate::track::graph_match::{Box2d, GraphTracker};

/// One box as head-vs-centroid input: `(box, head point, centroid)`.
pub(crate) type BoxPoints = ([f64; 4], [f64; 2], [f64; 2]);

/// The ground-truth-box run's 2-D objects per frame, and its boxes per frame and camera.
#[derive(Default)]
pub(crate) struct GtBoxRun {
    pub objects: Vec<Vec<Object2d>>,
    pub boxes: Vec<Vec<Vec<BoxPoints>>>,
}

/// A box's head point and its centre (the blob centroid of a box detector).
pub(crate) fn box_points(b: &Box2d) -> BoxPoints {
    (
        b.bbox,
        b.head_px,
        [(b.bbox[0] + b.bbox[2]) / 2.0, (b.bbox[1] + b.bbox[3]) / 2.0],
    )
}

/// Run every camera's 2-D tracker on the ground-truth boxes of each frame.
pub(crate) fn gt_box_run(
    p: &Params,
    views: &[CalibratedView],
    dt_s: f64,
    gt_for_frame: &[Option<&PeopleFrame>],
) -> GtBoxRun {
    let mut trackers: Vec<GraphTracker> = (0..p.cameras.len())
        .map(|_| GraphTracker::new(graph_params(p, dt_s)))
        .collect();
    let mut run = GtBoxRun::default();
    for gt in gt_for_frame {
        let mut objs = Vec::new();
        let mut cams = Vec::with_capacity(trackers.len());
        for (c, tr) in trackers.iter_mut().enumerate() {
            let boxes: Vec<Box2d> = gt
                .map(|g| boxes_from_truth(g, &p.cameras[c], box_head(p, &views[c])))
                .unwrap_or_default()
                .into_iter()
                .map(|(_, b)| b)
                .collect();
            cams.push(boxes.iter().map(box_points).collect());
            let box_head = super::box_head_for_3d(p);
            objs.extend(tr.step(&boxes).into_iter().map(|o| Object2d {
                camera: c,
                id: o.id,
                head_px: if box_head {
                    boxes[o.detection].head_px
                } else {
                    o.head_px
                },
                width_px: o.width_px,
                foot_px: Some([(o.bbox[0] + o.bbox[2]) / 2.0, o.bbox[3]]),
            }));
        }
        run.objects.push(objs);
        run.boxes.push(cams);
    }
    run
}

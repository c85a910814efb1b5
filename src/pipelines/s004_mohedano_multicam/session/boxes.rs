//! Boxes for the 2-D tracker: from a `Detection2DArray` or from the ground truth, with the
//! head point each source gives them; the 2-D tracker's parameters.

use super::super::Params;
use crate::geometry::triangulate::CalibratedView;
use crate::groundtruth::PeopleFrame;
use crate::log::msgs::Detection2DArray;
use crate::track::cylinders;
use crate::track::graph_match::{Box2d, GraphParams};

/// Ground-truth boxes lower or narrower than this (px) are not used.
pub(crate) const MIN_BOX_HEIGHT_PX: f64 = 8.0;
const MIN_BOX_WIDTH_PX: f64 = 2.0;

pub(crate) fn graph_params(p: &Params, dt_s: f64) -> GraphParams {
    GraphParams {
        min_iou: p.match_iou_2d,
        max_missed: p.max_missed_2d,
        dt_s,
        ..GraphParams::default()
    }
}

/// Where the head point of a box comes from.
#[derive(Clone, Copy)]
pub(crate) enum BoxHead<'a> {
    /// The top centre of the box.
    TopCentre,
    /// [`cylinders::box_head_px`]: the top row on the image of the person's vertical.
    Axis(&'a CalibratedView, f64),
    /// The ground truth's projected head top where the log has it (evaluation only).
    Truth,
}

impl BoxHead<'_> {
    pub fn of(self, b: [f64; 4], truth: Option<[f64; 2]>) -> [f64; 2] {
        let top_centre = [(b[0] + b[2]) / 2.0, b[1]];
        match self {
            BoxHead::TopCentre => top_centre,
            BoxHead::Axis(view, z) => cylinders::box_head_px(view, b, z).unwrap_or(top_centre),
            BoxHead::Truth => truth.unwrap_or(top_centre),
        }
    }
}

/// How the main run and the ground-truth-box run turn a box into a head point.
pub(crate) fn box_head<'a>(p: &Params, view: &'a CalibratedView) -> BoxHead<'a> {
    if p.box_head_on_axis {
        BoxHead::Axis(view, 0.5 * p.person_height_m)
    } else {
        BoxHead::TopCentre
    }
}

/// Boxes of one camera from a `Detection2DArray` (non-finite or empty boxes dropped).
pub(crate) fn boxes_from_detections(d: &Detection2DArray, head: BoxHead) -> Vec<Box2d> {
    d.detections
        .iter()
        .filter(|x| {
            [x.center_x, x.center_y, x.size_x, x.size_y]
                .iter()
                .all(|v| v.is_finite())
                && x.size_x > 0.0
                && x.size_y > 0.0
        })
        .map(|x| {
            let (x0, y0) = (x.center_x - x.size_x / 2.0, x.center_y - x.size_y / 2.0);
            let bbox = [x0, y0, x0 + x.size_x, y0 + x.size_y];
            Box2d {
                bbox,
                head_px: head.of(bbox, None),
                width_px: x.size_x,
                height_px: x.size_y,
            }
        })
        .collect()
}

/// Boxes of one camera from the ground truth: the visible box and its head point.
pub(crate) fn boxes_from_truth(gt: &PeopleFrame, camera: &str, head: BoxHead) -> Vec<(u32, Box2d)> {
    let mut out = Vec::new();
    for person in &gt.people {
        for v in person.cameras.iter().filter(|v| v.camera == camera) {
            let Some(b) = v.bbox else { continue };
            if b[3] - b[1] < MIN_BOX_HEIGHT_PX || b[2] - b[0] < MIN_BOX_WIDTH_PX {
                continue;
            }
            out.push((
                person.id,
                Box2d {
                    bbox: b,
                    head_px: head.of(b, v.head_px),
                    width_px: b[2] - b[0],
                    height_px: b[3] - b[1],
                },
            ));
        }
    }
    out
}

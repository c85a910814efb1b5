//! Head point vs blob centroid, per frame: each camera's detections are associated with the
//! ground-truth people by box overlap; the head points and the centroids of a person's
//! associated cameras are triangulated and their ground error measured.

use std::collections::BTreeMap;

use nalgebra::{Point2, Point3};

use super::gt_boxes::BoxPoints;
use crate::geometry::rect::iou;
use crate::geometry::triangulate::{CalibratedView, triangulate_dlt};
use crate::groundtruth::PeopleFrame;
use crate::pipelines::s004_mohedano_multicam::tables::HeadCentroidRow;

/// A detection is associated with a person when its box overlaps the person's visible box by
/// at least this IoU.
pub(crate) const ASSOCIATION_IOU: f64 = 0.25;
/// A person counts as unoccluded when every camera used sees at least this fraction of them.
pub(crate) const CLEAR_VISIBILITY: f64 = 0.95;

/// One camera's association: `(camera, head, centroid, visibility, statically occluded)`.
type Assoc = (usize, [f64; 2], [f64; 2], f64, bool);

/// What is fixed for a session.
pub(crate) struct HeadCentroid<'a> {
    pub cameras: &'a [String],
    pub views: &'a [CalibratedView],
    pub occluded_visibility: f64,
}

impl HeadCentroid<'_> {
    /// The rows of one frame: per person seen by ≥ 2 associated cameras.
    pub fn rows(
        &self,
        detector: &str,
        frame: usize,
        gt: &PeopleFrame,
        per_camera: &[Vec<BoxPoints>],
    ) -> Vec<HeadCentroidRow> {
        let assoc = self.associate(gt, per_camera);
        let mut out = Vec::new();
        for person in &gt.people {
            let Some(list) = assoc.get(&person.id) else {
                continue;
            };
            if list.len() < 2 {
                continue;
            }
            let heads: Vec<(&CalibratedView, Point2<f64>)> = list
                .iter()
                .map(|(c, h, _, _, _)| (&self.views[*c], Point2::new(h[0], h[1])))
                .collect();
            let cents: Vec<(&CalibratedView, Point2<f64>)> = list
                .iter()
                .map(|(c, _, m, _, _)| (&self.views[*c], Point2::new(m[0], m[1])))
                .collect();
            let (Ok(h), Ok(m)) = (triangulate_dlt(&heads), triangulate_dlt(&cents)) else {
                continue;
            };
            let err = |p: Point3<f64>| (p.x - person.x).hypot(p.y - person.y);
            out.push(HeadCentroidRow {
                detector: detector.to_string(),
                frame: frame as i64,
                id: i64::from(person.id),
                cameras: list.len() as i64,
                occluded: list.iter().any(|x| x.4),
                clear: list.iter().all(|x| x.3 >= CLEAR_VISIBILITY),
                min_visibility: list.iter().map(|x| x.3).fold(f64::INFINITY, f64::min),
                head_error_m: err(h),
                centroid_error_m: err(m),
            });
        }
        out
    }

    /// Per person, the cameras whose detection is associated with them (greedy by IoU).
    fn associate(
        &self,
        gt: &PeopleFrame,
        per_camera: &[Vec<BoxPoints>],
    ) -> BTreeMap<u32, Vec<Assoc>> {
        let mut assoc: BTreeMap<u32, Vec<Assoc>> = BTreeMap::new();
        for (c, cam) in self.cameras.iter().enumerate() {
            let Some(dets) = per_camera.get(c) else {
                continue;
            };
            let mut pairs = Vec::new();
            for person in &gt.people {
                let Some(view) = person.cameras.iter().find(|v| &v.camera == cam) else {
                    continue;
                };
                let Some(b) = view.bbox else { continue };
                for (j, d) in dets.iter().enumerate() {
                    let o = iou(&b, &d.0);
                    if o >= ASSOCIATION_IOU {
                        pairs.push((o, person.id, j, view.visibility, b));
                    }
                }
            }
            pairs.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
            let (mut used_p, mut used_d) = (Vec::new(), Vec::new());
            for (_, id, j, vis, b) in pairs {
                if used_p.contains(&id) || used_d.contains(&j) {
                    continue;
                }
                used_p.push(id);
                used_d.push(j);
                // static occlusion: partly hidden, and no other person's box overlaps this one
                let others_overlap = gt.people.iter().filter(|q| q.id != id).any(|q| {
                    q.cameras
                        .iter()
                        .filter(|v| &v.camera == cam)
                        .any(|v| v.bbox.is_some_and(|ob| iou(&ob, &b) > 0.0))
                });
                let occluded = vis < self.occluded_visibility && !others_overlap;
                assoc
                    .entry(id)
                    .or_default()
                    .push((c, dets[j].1, dets[j].2, vis, occluded));
            }
        }
        assoc
    }
}

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::camera::{CameraModel, Pinhole};
    use crate::geometry::look_at;
    use crate::groundtruth::{CameraView, PersonTruth};

    fn views() -> Vec<CalibratedView> {
        [[0.2, 0.2, 2.8], [7.8, 0.2, 2.8]]
            .iter()
            .map(|c| {
                CalibratedView::new(
                    CameraModel::Pinhole(Pinhole::from_fov(352, 288, 78.0)),
                    look_at(Point3::from(*c), Point3::new(4.0, 4.0, 0.9)),
                )
            })
            .collect()
    }

    fn px(v: &CalibratedView, x: f64, y: f64, z: f64) -> [f64; 2] {
        let p = v.project(&Point3::new(x, y, z)).expect("in view");
        [p.x, p.y]
    }

    #[test]
    fn exact_heads_triangulate_onto_the_person_and_shifted_centroids_off_by_the_shift() {
        let views = views();
        let cameras = vec!["cam_0".to_string(), "cam_1".to_string()];
        // each camera: a box around the person, the projected head top, and a "centroid"
        // that is the projection of a point 0.3 m beside the body centre
        let mut per_camera = Vec::new();
        let mut seen = Vec::new();
        for (v, name) in views.iter().zip(&cameras) {
            let head = px(v, 4.0, 4.0, 1.7);
            let centroid = px(v, 4.3, 4.0, 0.9);
            let foot = px(v, 4.0, 4.0, 0.0);
            let bbox = [head[0] - 15.0, head[1], head[0] + 15.0, foot[1]];
            per_camera.push(vec![(bbox, head, centroid)]);
            seen.push(CameraView {
                camera: name.clone(),
                bbox: Some(bbox),
                head_px: Some(head),
                visibility: if name == "cam_0" { 0.5 } else { 1.0 },
            });
        }
        let gt = PeopleFrame {
            stamp_ns: 0,
            people: vec![PersonTruth {
                id: 3,
                x: 4.0,
                y: 4.0,
                vx: 0.0,
                vy: 0.0,
                height: 1.7,
                head_z: 1.6,
                radius: 0.2,
                legs: [[4.0, 3.9], [4.0, 4.1]],
                leg_radius: 0.06,
                cameras: seen,
            }],
        };
        let hc = HeadCentroid {
            cameras: &cameras,
            views: &views,
            occluded_visibility: 0.8,
        };
        let rows = hc.rows("templates", 12, &gt, &per_camera);
        assert_eq!(rows.len(), 1);
        let r = &rows[0];
        assert_eq!((r.frame, r.id, r.cameras), (12, 3, 2));
        // cam_0 sees half of the person and nobody else overlaps: static occlusion
        assert!(r.occluded && !r.clear);
        assert_eq!(r.min_visibility, 0.5);
        assert!(r.head_error_m < 1e-6, "{r:?}");
        assert!((r.centroid_error_m - 0.3).abs() < 1e-6, "{r:?}");
        // one camera only: no triangulation, no row
        assert!(hc.rows("templates", 12, &gt, &per_camera[..1]).is_empty());
    }
}

//! 2-D tracking in one camera by graph matching of rectangles between consecutive frames
//! (seed 004 §4, after Gomila & Meyer [5]).
//!
//! Each frame, the tracks' predicted rectangles and the new detections' rectangles form a
//! bipartite graph with an edge wherever two rectangles overlap by at least `min_iou`. Every
//! connected component of that graph is resolved on its own: a component with one track and
//! one detection is a direct correspondence; larger ones (people crossing, a person split in
//! two detections, two people merged in one) take the assignment that maximises the total
//! overlap (Hungarian algorithm). Unmatched detections start new tracks; a track unmatched
//! for more than `max_missed` frames ends.
//!
//! Each track smooths the head position with a constant-velocity Kalman filter and the
//! template size (width, height) with a random-walk one, as the paper does to soften
//! inaccurate detections under static occlusion. The rectangle used for matching is the last
//! detection's, moved by the predicted head displacement.
//!
//! What it does not do: it never splits or merges tracks (the 3-D stage resolves the
//! ambiguities with the other cameras, §4–5), and it uses no appearance.

use nalgebra::{Matrix2, Matrix2x4, Vector2, Vector4};

use super::kalman::{Kalman, constant_velocity_2d};
use crate::assign::max_score_pairs;

/// One detection handed to the 2-D tracker (from the template detector or any other).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Box2d {
    /// `[x0, y0, x1, y1]` (pixels).
    pub bbox: [f64; 4],
    /// Top of the head (pixels).
    pub head_px: [f64; 2],
    /// Body width and height (pixels): the template's, or the box's for other detectors.
    pub width_px: f64,
    pub height_px: f64,
}

/// A tracked 2-D object in the current frame (only tracks matched in this frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Object2d {
    /// Track identifier, unique within the camera.
    pub id: u32,
    /// Smoothed head position (pixels).
    pub head_px: [f64; 2],
    /// Smoothed width and height (pixels).
    pub width_px: f64,
    pub height_px: f64,
    /// The matched detection's rectangle.
    pub bbox: [f64; 4],
    /// Index of the matched detection in this frame's input.
    pub detection: usize,
}

/// Tracker settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GraphParams {
    /// Minimum overlap (IoU) for an edge between a track and a detection.
    pub min_iou: f64,
    /// Frames a track survives without a detection.
    pub max_missed: u32,
    /// Frame period (s).
    pub dt_s: f64,
    /// White-noise acceleration of the head (pixels/s²).
    pub head_accel_px: f64,
    /// Measurement noise of the head (pixels).
    pub head_meas_px: f64,
    /// Random-walk rate of the size (pixels/√s).
    pub size_walk_px: f64,
    /// Measurement noise of the size (pixels).
    pub size_meas_px: f64,
}

impl Default for GraphParams {
    fn default() -> Self {
        GraphParams {
            min_iou: 0.1,
            max_missed: 2,
            dt_s: 0.04,
            head_accel_px: 200.0,
            head_meas_px: 2.0,
            size_walk_px: 10.0,
            size_meas_px: 4.0,
        }
    }
}

#[derive(Debug, Clone)]
struct Track {
    id: u32,
    head: Kalman<4>,
    size: Kalman<2>,
    bbox: [f64; 4],
    /// Head at the time of `bbox`.
    bbox_head: [f64; 2],
    missed: u32,
}

/// The 2-D tracker of one camera.
#[derive(Debug, Clone)]
pub struct GraphTracker {
    params: GraphParams,
    tracks: Vec<Track>,
    next_id: u32,
}

fn iou(a: &[f64; 4], b: &[f64; 4]) -> f64 {
    let iw = (a[2].min(b[2]) - a[0].max(b[0])).max(0.0);
    let ih = (a[3].min(b[3]) - a[1].max(b[1])).max(0.0);
    let inter = iw * ih;
    if inter <= 0.0 {
        return 0.0;
    }
    let area = |r: &[f64; 4]| (r[2] - r[0]).max(0.0) * (r[3] - r[1]).max(0.0);
    inter / (area(a) + area(b) - inter)
}

impl GraphTracker {
    pub fn new(params: GraphParams) -> GraphTracker {
        GraphTracker {
            params,
            tracks: Vec::new(),
            next_id: 1,
        }
    }

    /// Tracks alive (matched recently), for inspection.
    pub fn len(&self) -> usize {
        self.tracks.len()
    }

    pub fn is_empty(&self) -> bool {
        self.tracks.is_empty()
    }

    /// Advance one frame with this frame's detections; returns the tracks matched now.
    pub fn step(&mut self, detections: &[Box2d]) -> Vec<Object2d> {
        let p = self.params;
        let (f, q) = constant_velocity_2d(p.dt_s, p.head_accel_px);
        let q_size = Matrix2::identity() * (p.size_walk_px * p.size_walk_px * p.dt_s);
        let predicted: Vec<[f64; 4]> = self
            .tracks
            .iter_mut()
            .map(|t| {
                t.head.predict(&f, &q);
                t.size.predict(&Matrix2::identity(), &q_size);
                let (dx, dy) = (t.head.x[0] - t.bbox_head[0], t.head.x[1] - t.bbox_head[1]);
                [
                    t.bbox[0] + dx,
                    t.bbox[1] + dy,
                    t.bbox[2] + dx,
                    t.bbox[3] + dy,
                ]
            })
            .collect();
        let pairs = max_score_pairs(predicted.len(), detections.len(), |i, j| {
            let o = iou(&predicted[i], &detections[j].bbox);
            if o >= p.min_iou { o } else { 0.0 }
        });
        let mut matched_track = vec![false; self.tracks.len()];
        let mut matched_det = vec![false; detections.len()];
        let h_head = Matrix2x4::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0);
        let r_head = Matrix2::identity() * p.head_meas_px.powi(2);
        let r_size = Matrix2::identity() * p.size_meas_px.powi(2);
        let mut out = Vec::new();
        for (i, j) in pairs {
            matched_track[i] = true;
            matched_det[j] = true;
            let d = &detections[j];
            let t = &mut self.tracks[i];
            let ok_head =
                t.head
                    .update(&h_head, &r_head, &Vector2::new(d.head_px[0], d.head_px[1]));
            let ok_size = t.size.update(
                &Matrix2::identity(),
                &r_size,
                &Vector2::new(d.width_px, d.height_px),
            );
            if ok_head.is_err() || ok_size.is_err() {
                // a non-finite detection: restart the filters at it if possible
                continue;
            }
            t.bbox = d.bbox;
            t.bbox_head = [t.head.x[0], t.head.x[1]];
            t.missed = 0;
            out.push(Object2d {
                id: t.id,
                head_px: [t.head.x[0], t.head.x[1]],
                width_px: t.size.x[0],
                height_px: t.size.x[1],
                bbox: d.bbox,
                detection: j,
            });
        }
        for (t, m) in self.tracks.iter_mut().zip(&matched_track) {
            if !m {
                t.missed += 1;
            }
        }
        self.tracks.retain(|t| t.missed <= p.max_missed);
        for (j, d) in detections.iter().enumerate() {
            if matched_det[j]
                || !d.head_px.iter().chain(&d.bbox).all(|v| v.is_finite())
                || !(d.width_px.is_finite() && d.height_px.is_finite())
            {
                continue;
            }
            let id = self.next_id;
            self.next_id += 1;
            let mut pv = nalgebra::Matrix4::<f64>::identity();
            pv[(0, 0)] = p.head_meas_px.powi(2);
            pv[(1, 1)] = p.head_meas_px.powi(2);
            // a walking person moves up to ~150 px/s at this resolution
            pv[(2, 2)] = 100.0f64.powi(2);
            pv[(3, 3)] = 100.0f64.powi(2);
            self.tracks.push(Track {
                id,
                head: Kalman::new(Vector4::new(d.head_px[0], d.head_px[1], 0.0, 0.0), pv),
                size: Kalman::new(Vector2::new(d.width_px, d.height_px), r_size),
                bbox: d.bbox,
                bbox_head: d.head_px,
                missed: 0,
            });
            out.push(Object2d {
                id,
                head_px: d.head_px,
                width_px: d.width_px,
                height_px: d.height_px,
                bbox: d.bbox,
                detection: j,
            });
        }
        out.sort_by_key(|o| o.id);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn person(x: f64, y: f64) -> Box2d {
        Box2d {
            bbox: [x - 10.0, y, x + 10.0, y + 60.0],
            head_px: [x, y],
            width_px: 20.0,
            height_px: 60.0,
        }
    }

    #[test]
    fn a_walking_person_keeps_one_identity() {
        let mut t = GraphTracker::new(GraphParams::default());
        let mut ids = Vec::new();
        for k in 0..50 {
            let objs = t.step(&[person(50.0 + 2.0 * f64::from(k), 40.0)]);
            assert_eq!(objs.len(), 1);
            ids.push(objs[0].id);
        }
        assert!(ids.iter().all(|&i| i == ids[0]));
    }

    #[test]
    fn two_people_crossing_keep_their_identities() {
        // they approach, overlap, and separate; the predicted rectangles disambiguate
        let mut t = GraphTracker::new(GraphParams::default());
        let (mut a_ids, mut b_ids) = (Vec::new(), Vec::new());
        for k in 0..60 {
            let k = f64::from(k);
            let a = person(40.0 + 3.0 * k, 40.0);
            let b = person(220.0 - 3.0 * k, 44.0);
            let objs = t.step(&[a, b]);
            for o in &objs {
                if o.detection == 0 {
                    a_ids.push(o.id);
                } else {
                    b_ids.push(o.id);
                }
            }
        }
        // identity kept before the crossing and after it (one swap at most while merged)
        assert_eq!(a_ids[0], a_ids[10]);
        assert_eq!(b_ids[0], b_ids[10]);
        assert_ne!(a_ids[0], b_ids[0]);
    }

    #[test]
    fn a_track_survives_short_gaps_and_ends_after_long_ones() {
        let mut t = GraphTracker::new(GraphParams::default());
        let id = t.step(&[person(50.0, 40.0)])[0].id;
        assert!(t.step(&[]).is_empty());
        assert_eq!(t.step(&[person(50.0, 40.0)])[0].id, id);
        for _ in 0..3 {
            t.step(&[]);
        }
        assert!(t.is_empty());
        assert_ne!(t.step(&[person(50.0, 40.0)])[0].id, id);
    }
}

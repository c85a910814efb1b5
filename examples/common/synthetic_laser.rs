//! Shared by the laser examples (`laser_jpda_sweep`, `laser_free_space_sweep`,
//! `laser_confirm_probe`): a synthetic laser log read as the `laser_people` pipeline reads a
//! synthetic session — every `/scan` with its pose in `map`, the ground truth of the nearest
//! `/ground_truth/people` frame within 0.05 s (map frame) — and the pipeline's synthetic
//! scoring area.

#![allow(dead_code)] // each example uses part of it

use nalgebra::{Isometry3, Point2, Point3};
use peopletrack::eval::mot::{Geometry, GroundPoint, Observation};
use peopletrack::frames::laser::{LaserOptions, scans};
use peopletrack::frames::truth;
use peopletrack::laser::legs::{self, Detections, LegParams};
use peopletrack::laser::points::{self, ScanGeometry, ScanPoint};
use peopletrack::laser::segment::{self, SegmentOptions};
use peopletrack::log::SessionLog;

pub type Res<T> = Result<T, Box<dyn std::error::Error>>;

/// One scan of a synthetic log.
pub struct SynthScan {
    /// Since the first posed scan (s).
    pub time_s: f64,
    pub ranges: Vec<f32>,
    pub geometry: ScanGeometry,
    /// The laser in `map`.
    pub pose: Isometry3<f64>,
    /// Ground truth: id and position in `map` (m).
    pub truth: Vec<(i64, Point2<f64>)>,
}

/// A `map`-frame point in the laser frame of `pose`.
pub fn to_laser(pose: &Isometry3<f64>, p: Point2<f64>) -> Point2<f64> {
    let q = pose.inverse_transform_point(&Point3::new(p.x, p.y, 0.0));
    Point2::new(q.x, q.y)
}

/// The pipeline's synthetic scoring area: in front of the laser (180°) within 5 m.
pub fn scored(p: &Point2<f64>) -> bool {
    p.x >= 0.0 && p.coords.norm() <= 5.0
}

/// Every posed scan of the log at `path` (unposed scans are left out).
pub fn load(path: &str) -> Res<Vec<SynthScan>> {
    let log = SessionLog::open(path)?;
    let (gt, _) = truth::people(&log, "/ground_truth/people")?;
    let options = LaserOptions {
        fixed_frame: Some("map".into()),
        ..LaserOptions::default()
    };
    let mut out = Vec::new();
    let mut t0 = None;
    for f in scans(&log, "/scan", &options)? {
        let f = f?;
        let Some(pose) = f.pose else { continue };
        let t0 = *t0.get_or_insert(f.stamp);
        let truth = gt
            .nearest(f.stamp, 50_000_000)
            .map(|fr| {
                fr.people
                    .iter()
                    .map(|p| (i64::from(p.id), Point2::new(p.x, p.y)))
                    .collect()
            })
            .unwrap_or_default();
        out.push(SynthScan {
            time_s: f.stamp.signed_sub(t0) as f64 * 1e-9,
            geometry: ScanGeometry::of(&f.scan),
            ranges: f.scan.ranges.clone(),
            pose,
            truth,
        });
    }
    Ok(out)
}

/// A point observation for `eval::mot` (laser frame, m).
pub fn point(frame: i64, id: i64, p: Point2<f64>) -> Observation {
    Observation {
        frame,
        id,
        geometry: Geometry::Point(GroundPoint { x_m: p.x, y_m: p.y }),
        confidence: 1.0,
    }
}

/// The scan's returns in the fixed frame of `pose` and the seed 002 leg model's detections
/// at its defaults.
pub fn leg_model(
    ranges: &[f32],
    geometry: &ScanGeometry,
    pose: Option<&Isometry3<f64>>,
) -> (Vec<ScanPoint>, Detections) {
    let pts = points::project(ranges, geometry, pose);
    let segs = segment::segment(&pts, &SegmentOptions::default());
    let d = legs::detect(&pts, &segs, ranges.len(), pose, &LegParams::default());
    (pts, d)
}

//! The free-space people tracker: leg_tracker's three nodes together (Leigh et al., ICRA 2015:
//! `detect_leg_clusters`, `joint_leg_tracker.py`, `local_occupancy_grid_mapping`): the
//! [`JointTracker`] over every cluster of the scan and the [`LocalGrid`] it asks. Per scan
//! ([`FreeSpaceTracker::step_clusters`]):
//!
//! 1. every cluster (a segment of [`crate::laser::segment`], within [`MAX_DETECT_M`] of the
//!    laser) gets the detector's confidence and the grid's occupancy around it and goes to
//!    the tracker;
//! 2. the grid then takes the scan with leg_tracker's rule for which returns are *not*
//!    obstacles: the tracker publishes the "non-leg clusters" (every cluster it did not match
//!    to a person), and the grid node marks a cluster human — its beams free — unless it is
//!    one of those. So the clusters matched to people, and the clusters beyond
//!    [`MAX_DETECT_M`] (never published), are free; every other return is an obstacle,
//!    including points in no cluster (checked in `local_occupancy_grid_mapping.cpp` and
//!    `joint_leg_tracker.py` at c7ff1e4).
//!
//! The grid of a scan is the one built from the scans before it, as in leg_tracker, where the
//! tracker uses the last published map. Differences from leg_tracker, stated: clusters are our
//! jump-distance segments (0.1 m between adjacent beams, ≥ 3 returns) where leg_tracker
//! clusters by Euclidean distance (0.13 m, ≥ 3 points; 5 in its outdoor launch file); a leg's
//! position is the leg model's circle centre where leg_tracker takes the points' mean.
//!
//! [`FreeSpaceTracker::step`] (the leg model's detections, as `s001`'s replay calls it) turns
//! the scan's segments into clusters: confidence 1 (or the given one) for a detected leg, 0
//! for every other segment. The fixed frame is the one `pose` maps into (the laser's own
//! without a pose); a caller without odometry gets one from [`crate::laser::scan_match`].
//! Round 1 of issue 35 tracked leg pairs with `PeopleTracker` and
//! [`crate::laser::tracker::Confirmation::Motion`] instead; that option is still there. No I/O.

use nalgebra::Isometry3;

use super::joint::{Cluster, JointParams, JointTracker};
use super::legs::Detections;
use super::occupancy::{GridParams, LocalGrid};
use super::points::{ScanGeometry, ScanPoint, to_fixed};
use super::segment::{self, Segment, SegmentOptions};
use super::training::centroid;

/// Clusters farther than this from the laser (m) are not tracked (leg_tracker's
/// `max_detect_distance` default, kept by its launch files).
pub const MAX_DETECT_M: f64 = 10.0;

/// The tracker and its grid.
#[derive(Debug, Clone, PartialEq)]
pub struct FreeSpaceTracker {
    pub tracker: JointTracker,
    pub grid: LocalGrid,
}

impl Default for FreeSpaceTracker {
    fn default() -> Self {
        FreeSpaceTracker::new(JointParams::default(), GridParams::default())
    }
}

/// One cluster of a scan: its returns (a segment) with its position (fixed frame) and the
/// detector's confidence.
#[derive(Debug, Clone, PartialEq)]
pub struct ScanCluster {
    pub segment: Segment,
    /// Fixed frame (m).
    pub position: nalgebra::Point2<f64>,
    /// Laser frame range of the position (m).
    pub range: f64,
    pub confidence: f64,
}

/// The ranges of a scan of `beams` beams rebuilt from its returns (NaN where a beam has none:
/// invalid, so the grid leaves its cells unknown), for callers that kept only the points.
pub fn ranges_from_points(points: &[ScanPoint], beams: usize) -> Vec<f32> {
    let mut r = vec![f32::NAN; beams];
    for p in points {
        if let Some(v) = r.get_mut(p.beam) {
            *v = p.range as f32;
        }
    }
    r
}

/// The clusters of a scan for the leg model's detections `d`: each segment of `points`
/// (default segmentation); a detected leg's segment at its circle centre with its confidence
/// from `conf` (missing: 1), every other segment at its centroid with confidence 0.
pub fn clusters_of(
    points: &[ScanPoint],
    d: &Detections,
    conf: &[f64],
    pose: Option<&Isometry3<f64>>,
) -> Vec<ScanCluster> {
    segment::segment(points, &SegmentOptions::default())
        .into_iter()
        .map(|s| {
            let leg = d.legs.iter().position(|l| l.segment.points == s.points);
            match leg {
                Some(i) => ScanCluster {
                    position: d.legs[i].fixed,
                    range: d.legs[i].sensor.coords.norm(),
                    confidence: conf.get(i).copied().unwrap_or(1.0),
                    segment: s,
                },
                None => {
                    let c = centroid(points, &s);
                    ScanCluster {
                        position: to_fixed(pose, c),
                        range: c.coords.norm(),
                        confidence: 0.0,
                        segment: s,
                    }
                }
            }
        })
        .collect()
}

impl FreeSpaceTracker {
    pub fn new(tracker: JointParams, grid: GridParams) -> Self {
        FreeSpaceTracker {
            tracker: JointTracker::new(tracker),
            grid: LocalGrid::new(grid),
        }
    }

    /// One scan at `time_s`: the leg model's detections `d` (legs in the fixed frame) with
    /// each leg's confidence `conf` (missing: 1), the scan's `points`, `ranges` and beam
    /// geometry, and the laser's pose in the fixed frame (module doc).
    #[allow(clippy::too_many_arguments)]
    pub fn step(
        &mut self,
        time_s: f64,
        d: &Detections,
        conf: &[f64],
        points: &[ScanPoint],
        ranges: &[f32],
        g: &ScanGeometry,
        pose: Option<&Isometry3<f64>>,
    ) {
        let clusters = clusters_of(points, d, conf, pose);
        self.step_clusters(time_s, &clusters, points, ranges, g, pose);
    }

    /// One scan from its clusters (module doc).
    pub fn step_clusters(
        &mut self,
        time_s: f64,
        clusters: &[ScanCluster],
        points: &[ScanPoint],
        ranges: &[f32],
        g: &ScanGeometry,
        pose: Option<&Isometry3<f64>>,
    ) {
        let near: Vec<&ScanCluster> = clusters.iter().filter(|c| c.range < MAX_DETECT_M).collect();
        let input: Vec<Cluster> = near
            .iter()
            .map(|c| Cluster {
                position: c.position,
                confidence: c.confidence,
                occupancy: self.grid.occupancy_around(c.position),
            })
            .collect();
        let legs = self.tracker.step(time_s, &input);
        let mut human = vec![false; ranges.len()];
        let mut mark = |s: &Segment| {
            for p in points.get(s.points.clone()).unwrap_or(&[]) {
                if let Some(h) = human.get_mut(p.beam) {
                    *h = true;
                }
            }
        };
        for (c, &leg) in near.iter().zip(&legs) {
            if leg {
                mark(&c.segment);
            }
        }
        for c in clusters
            .iter()
            .filter(|c| c.range >= MAX_DETECT_M || c.range.is_nan())
        {
            mark(&c.segment);
        }
        self.grid.update(ranges, g, pose, &human);
    }
}

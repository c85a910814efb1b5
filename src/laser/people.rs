//! The free-space people tracker: [`PeopleTracker`] with leg_tracker's motion confirmation
//! ([`Confirmation::Motion`]) together with the [`LocalGrid`] it asks (Leigh et al., ICRA 2015:
//! `joint_leg_tracker.py` + `local_occupancy_grid_mapping`). Per scan ([`FreeSpaceTracker::step`]):
//!
//! 1. each leg pair and single leg of the detections gets its confidence and the grid's
//!    occupancy around it (a pair: the mean of its two legs', as leg_tracker averages its two
//!    legs' values) and goes to the tracker, which reports a track once it has moved through
//!    free space and lets reported people take only free-space observations;
//! 2. the grid then takes the scan, the beams of the legs that updated reported people
//!    counting as free (a person is not an obstacle; leg_tracker's "non-leg clusters" — every
//!    other cluster — are mapped).
//!
//! The grid of a scan is the one built from the scans before it, as in leg_tracker, where the
//! tracker uses the last published map. No I/O.

use nalgebra::Isometry3;

use super::legs::Detections;
use super::occupancy::{GridParams, LocalGrid};
use super::points::{ScanGeometry, ScanPoint};
use super::tracker::{
    Confirmation, MotionParams, Observation, PeopleTracker, TrackerParams, Update,
};

/// The tracker and its grid.
#[derive(Debug, Clone, PartialEq)]
pub struct FreeSpaceTracker {
    pub tracker: PeopleTracker,
    pub grid: LocalGrid,
}

/// The default tracker settings with [`Confirmation::Motion`] at leg_tracker's values.
pub fn free_space_params() -> TrackerParams {
    TrackerParams {
        confirmation: Confirmation::Motion(MotionParams::default()),
        ..TrackerParams::default()
    }
}

impl Default for FreeSpaceTracker {
    fn default() -> Self {
        FreeSpaceTracker::new(free_space_params(), GridParams::default())
    }
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

impl FreeSpaceTracker {
    pub fn new(tracker: TrackerParams, grid: GridParams) -> Self {
        FreeSpaceTracker {
            tracker: PeopleTracker::new(tracker),
            grid: LocalGrid::new(grid),
        }
    }

    /// One scan at `time_s`: detections `d` (legs in the fixed frame) with each leg's
    /// confidence `conf` (missing: 1), the scan's `points` (for the legs' beams), `ranges` and
    /// beam geometry, and the laser's pose in the fixed frame.
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
        let c = |i: usize| conf.get(i).copied().unwrap_or(1.0);
        let occ: Vec<f64> = d
            .legs
            .iter()
            .map(|l| self.grid.occupancy_around(l.fixed))
            .collect();
        let people: Vec<Observation> = d
            .people
            .iter()
            .map(|p| Observation {
                position: p.fixed,
                confidence: (c(p.legs.0) + c(p.legs.1)) / 2.0,
                occupancy: (occ[p.legs.0] + occ[p.legs.1]) / 2.0,
            })
            .collect();
        let single: Vec<Observation> = d
            .single_legs
            .iter()
            .map(|&i| Observation {
                position: d.legs[i].fixed,
                confidence: c(i),
                occupancy: occ[i],
            })
            .collect();
        self.tracker.step_observed(time_s, &people, &single);
        let mut human = vec![false; ranges.len()];
        let mut mark = |leg: usize| {
            if let Some(l) = d.legs.get(leg) {
                for p in points.get(l.segment.points.clone()).unwrap_or(&[]) {
                    if let Some(h) = human.get_mut(p.beam) {
                        *h = true;
                    }
                }
            }
        };
        for t in self.tracker.confirmed() {
            match t.last {
                Update::Person(zi) => {
                    if let Some(p) = d.people.get(zi) {
                        mark(p.legs.0);
                        mark(p.legs.1);
                    }
                }
                Update::Leg(zi) => {
                    if let Some(&i) = d.single_legs.get(zi) {
                        mark(i);
                    }
                }
                Update::Missed => {}
            }
        }
        self.grid.update(ranges, g, pose, &human);
    }
}

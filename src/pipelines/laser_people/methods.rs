//! The methods a session runs on every scan, chosen by `[params] methods` and reported in that
//! order: each turns one scan (already projected, segmented and through the seed 002 leg
//! model, see [`ScanView`]) into hypotheses `(id, fixed-frame position)`.
//!
//! - **`legs`**: seed 002 leg model → leg pairs (people) and single legs in the fixed frame →
//!   [`PeopleTracker`] (CV Kalman, GNN, M-of-N); its confirmed tracks after each scan.
//! - **`legs_jpda`**: the same with JPDA association ([`Association::Jpda`] at its defaults).
//! - **`legs_leg_limit`**: `legs` where single legs carry a track for at most
//!   [`LEG_ONLY_SCANS`] scans after its last leg-pair update (`max_leg_only_scans`).
//! - **`nearest`**: the baseline without a filter: the midpoint of the two legs nearest to the
//!   laser (any distance apart), one hypothesis with id 1 on each scan with two legs or more.
//!
//! A new method is a variant of [`Method`] (its name in the pipeline file) and of [`Runner`]
//! (its state across the scans of one session).

use nalgebra::Point2;
use serde::{Deserialize, Serialize};

use crate::frames::laser::LaserFrame;
use crate::laser::legs::{self, Detections, LegParams};
use crate::laser::points::{self, ScanGeometry, ScanPoint};
use crate::laser::segment::{self, Segment, SegmentOptions};
use crate::laser::tracker::{Association, JpdaParams, LEG_ONLY_SCANS, PeopleTracker, TrackerParams};

/// A detection + tracking method, by its name in the pipeline file and the tables.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    Legs,
    LegsJpda,
    LegsLegLimit,
    Nearest,
}

impl Method {
    /// The name in the pipeline file, the tables and the track files.
    pub fn name(self) -> &'static str {
        match self {
            Method::Legs => "legs",
            Method::LegsJpda => "legs_jpda",
            Method::LegsLegLimit => "legs_leg_limit",
            Method::Nearest => "nearest",
        }
    }

    /// One sentence for the results table's note.
    pub fn describe(self) -> &'static str {
        match self {
            Method::Legs => "seed 002 leg model + PeopleTracker (CV Kalman, GNN, M-of-N; confirmed tracks)",
            Method::LegsJpda => "seed 002 leg model + PeopleTracker with JPDA (P_D, clutter density at their synthetic-data defaults)",
            Method::LegsLegLimit => "legs, single legs carry a track at most 20 scans after its last leg pair (chosen on synthetic data)",
            Method::Nearest => {
                "midpoint of the two legs nearest to the laser, no filter, one id (the baseline)"
            }
        }
    }
}

/// One scan as every method sees it: its returns, segments and the seed 002 leg model's
/// detections, computed once.
#[allow(dead_code)] // frame, points and segments are for methods with their own leg detector
pub struct ScanView<'a> {
    pub frame: &'a LaserFrame,
    pub points: Vec<ScanPoint>,
    pub segments: Vec<Segment>,
    pub geometric: Detections,
}

impl<'a> ScanView<'a> {
    pub fn new(frame: &'a LaserFrame) -> Self {
        let g = ScanGeometry {
            angle_min: f64::from(frame.scan.angle_min),
            angle_increment: f64::from(frame.scan.angle_increment),
            range_min: f64::from(frame.scan.range_min),
            range_max: f64::from(frame.scan.range_max),
        };
        let points = points::project(&frame.scan.ranges, &g, frame.pose.as_ref());
        let segments = segment::segment(&points, &SegmentOptions::default());
        let geometric = legs::detect(
            &points,
            &segments,
            frame.scan.ranges.len(),
            frame.pose.as_ref(),
            &LegParams::default(),
        );
        ScanView {
            frame,
            points,
            segments,
            geometric,
        }
    }
}

/// A hypothesis of one method on one scan (m).
pub struct Hypothesis {
    pub id: i64,
    /// Fixed frame.
    pub world: Point2<f64>,
    /// Laser frame, when the method measured it there (a filtered track lives in the fixed
    /// frame only: the session puts it back through the inverse pose).
    pub laser: Option<Point2<f64>>,
}

/// One method's state across the scans of a session.
pub enum Runner {
    Tracked(Box<PeopleTracker>),
    Nearest,
}

impl Runner {
    pub fn new(method: Method) -> Runner {
        match method {
            Method::Legs => Runner::Tracked(Box::new(PeopleTracker::new(TrackerParams::default()))),
            Method::LegsJpda => Runner::Tracked(Box::new(PeopleTracker::new(TrackerParams {
                association: Association::Jpda(JpdaParams::default()),
                ..TrackerParams::default()
            }))),
            Method::LegsLegLimit => Runner::Tracked(Box::new(PeopleTracker::new(TrackerParams {
                max_leg_only_scans: Some(LEG_ONLY_SCANS),
                ..TrackerParams::default()
            }))),
            Method::Nearest => Runner::Nearest,
        }
    }

    /// The method's hypotheses after scan `view` at `time_s` (s since the session's first
    /// scan).
    pub fn step(&mut self, view: &ScanView, time_s: f64) -> Vec<Hypothesis> {
        match self {
            Runner::Tracked(tracker) => track(tracker, &view.geometric, time_s),
            Runner::Nearest => nearest_pair(&view.geometric)
                .map(|(laser, world)| Hypothesis {
                    id: 1,
                    world,
                    laser: Some(laser),
                })
                .into_iter()
                .collect(),
        }
    }
}

/// Leg pairs and single legs of `d` into `tracker`; its confirmed tracks.
fn track(tracker: &mut PeopleTracker, d: &Detections, time_s: f64) -> Vec<Hypothesis> {
    let people: Vec<Point2<f64>> = d.people.iter().map(|p| p.fixed).collect();
    let single: Vec<Point2<f64>> = d.single_legs.iter().map(|&i| d.legs[i].fixed).collect();
    tracker.step(time_s, &people, &single);
    tracker
        .confirmed()
        .map(|t| Hypothesis {
            id: i64::try_from(t.id).unwrap_or(i64::MAX),
            world: t.position(),
            laser: None,
        })
        .collect()
}

/// The `nearest` baseline: the midpoint of the two legs nearest to the laser, as
/// `(laser frame, fixed frame)`; ties by leg order.
pub fn nearest_pair(d: &Detections) -> Option<(Point2<f64>, Point2<f64>)> {
    let mut order: Vec<usize> = (0..d.legs.len()).collect();
    order.sort_by(|&a, &b| {
        let (ra, rb) = (
            d.legs[a].sensor.coords.norm(),
            d.legs[b].sensor.coords.norm(),
        );
        ra.total_cmp(&rb).then(a.cmp(&b))
    });
    let (a, b) = (&d.legs[*order.first()?], &d.legs[*order.get(1)?]);
    Some((
        nalgebra::center(&a.sensor, &b.sensor),
        nalgebra::center(&a.fixed, &b.fixed),
    ))
}

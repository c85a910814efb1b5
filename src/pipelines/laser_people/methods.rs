//! The methods a session runs on every scan, chosen by `[params] methods` and reported in that
//! order: each turns one scan (already projected, segmented and through the seed 002 leg
//! model, see [`ScanView`]) into hypotheses `(id, fixed-frame position)`.
//!
//! - **`legs`**: seed 002 leg model → leg pairs (people) and single legs in the fixed frame →
//!   [`PeopleTracker`] (CV Kalman, GNN, M-of-N); its confirmed tracks after each scan.
//! - **`legs_jpda`**: the same with JPDA association ([`Association::Jpda`] at its defaults).
//! - **`legs_leg_limit`**: `legs` where single legs carry a track for at most
//!   [`LEG_ONLY_SCANS`] scans after its last leg-pair update (`max_leg_only_scans`).
//! - **`learned`** / **`learned_synthetic`**: every segment through the random-forest leg
//!   classifier of [`super::learned`] (trained on the real leg_tracker CSVs / on the synthetic
//!   datasets; a leg when its probability reaches the threshold chosen by cross-validation),
//!   the legs paired into people as the seed 002 model pairs them ([`legs::pair`]) →
//!   [`PeopleTracker`]. A leg's position is its fitted circle's centre when a circle of radius
//!   ≤ [`LEARNED_MAX_RADIUS_M`] fits facing the laser, else the segment's centroid.
//! - **`legs_free_space`**: the seed 002 leg model → [`PeopleTracker`] with leg_tracker's
//!   motion confirmation ([`FreeSpaceTracker`]): a track is reported once it has moved
//!   0.5 m through free space of a local occupancy grid built online from the scans
//!   (leg_tracker's; the beams of the legs that updated reported people count as free), and
//!   reported people take no observation outside free space.
//! - **`learned_free_space`** / **`learned_synthetic_free_space`**: the same tracker and grid
//!   fed by a random forest over leg_tracker's 17 cluster features (`[params.learned_free_space]`:
//!   trained on the real CSVs / on the synthetic logs, `laser_clutter` included); a leg is a
//!   segment whose probability reaches the CV-chosen threshold, its confidence that
//!   probability.
//! - **`nearest`**: the baseline without a filter: the midpoint of the two legs nearest to the
//!   laser (any distance apart), one hypothesis with id 1 on each scan with two legs or more.
//!
//! A new method is a variant of [`Method`] (its name in the pipeline file) and of [`Runner`]
//! (its state across the scans of one session).

use std::sync::Arc;

use nalgebra::Point2;
use serde::{Deserialize, Serialize};

use super::learned::{self, LearnedParams, LegModel, Source, Unavailable};
use crate::laser::features;
use crate::laser::legs::Leg;
use crate::laser::points::to_fixed;
use crate::laser::training::{Segmented, centroid};

use crate::frames::laser::LaserFrame;
use crate::laser::legs::{self, Detections, LegParams};
use crate::laser::people::FreeSpaceTracker;
use crate::laser::points::{self, ScanGeometry, ScanPoint};
use crate::laser::segment::{self, Segment, SegmentOptions};
use crate::laser::tracker::{
    Association, JpdaParams, LEG_ONLY_SCANS, PeopleTracker, TrackerParams,
};

/// A detection + tracking method, by its name in the pipeline file and the tables.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    Legs,
    LegsJpda,
    LegsLegLimit,
    Nearest,
    Learned,
    LearnedSynthetic,
    LegsFreeSpace,
    LearnedFreeSpace,
    LearnedSyntheticFreeSpace,
}

impl Method {
    /// The name in the pipeline file, the tables and the track files.
    pub fn name(self) -> &'static str {
        match self {
            Method::Legs => "legs",
            Method::LegsJpda => "legs_jpda",
            Method::LegsLegLimit => "legs_leg_limit",
            Method::Nearest => "nearest",
            Method::Learned => "learned",
            Method::LearnedSynthetic => "learned_synthetic",
            Method::LegsFreeSpace => "legs_free_space",
            Method::LearnedFreeSpace => "learned_free_space",
            Method::LearnedSyntheticFreeSpace => "learned_synthetic_free_space",
        }
    }

    /// One sentence for the results table's note.
    pub fn describe(self) -> &'static str {
        match self {
            Method::Legs => {
                "seed 002 leg model + PeopleTracker (CV Kalman, GNN, M-of-N; confirmed tracks)"
            }
            Method::LegsJpda => {
                "seed 002 leg model + PeopleTracker with JPDA (P_D, clutter density at their synthetic-data defaults)"
            }
            Method::LegsLegLimit => {
                "legs, single legs carry a track at most 20 scans after its last leg pair (chosen on synthetic data)"
            }
            Method::Nearest => {
                "midpoint of the two legs nearest to the laser, no filter, one id (the baseline)"
            }
            Method::Learned => {
                "random-forest leg classifier trained on the real leg_tracker CSVs, seed 002 pairing + PeopleTracker"
            }
            Method::LearnedSynthetic => {
                "the same classifier trained on the synthetic datasets only (in-sample on the synthetic sequences), seed 002 pairing + PeopleTracker"
            }
            Method::LegsFreeSpace => {
                "seed 002 leg model + PeopleTracker with leg_tracker's motion confirmation (0.5 m through free space of the local occupancy grid; reported people take only free-space observations)"
            }
            Method::LearnedFreeSpace => {
                "random forest on leg_tracker's 17 features trained on the real leg_tracker CSVs, seed 002 pairing, occupancy grid + motion confirmation as legs_free_space"
            }
            Method::LearnedSyntheticFreeSpace => {
                "the same on leg_tracker's features trained on the synthetic datasets (laser_clutter included), grid + motion confirmation"
            }
        }
    }

    /// The training data of a learned method.
    pub fn source(self) -> Option<Source> {
        match self {
            Method::Learned | Method::LearnedFreeSpace => Some(Source::Real),
            Method::LearnedSynthetic | Method::LearnedSyntheticFreeSpace => Some(Source::Synthetic),
            _ => None,
        }
    }

    /// Whether the method's detector is trained with `[params.learned_free_space]` (else
    /// `[params.learned]`).
    pub fn free_space(self) -> bool {
        matches!(
            self,
            Method::LegsFreeSpace | Method::LearnedFreeSpace | Method::LearnedSyntheticFreeSpace
        )
    }
}

/// Largest fitted radius (m) a learned leg's position is taken from (the circle's centre);
/// above it, the segment's centroid.
pub const LEARNED_MAX_RADIUS_M: f64 = 0.15;

/// One scan as every method sees it: its returns, segments and the seed 002 leg model's
/// detections, computed once.
pub struct ScanView<'a> {
    pub frame: &'a LaserFrame,
    pub points: Vec<ScanPoint>,
    pub segments: Vec<Segment>,
    pub geometric: Detections,
}

impl<'a> ScanView<'a> {
    pub fn new(frame: &'a LaserFrame) -> Self {
        let g = ScanGeometry::of(&frame.scan);
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
    Learned(Arc<LegModel>, Box<PeopleTracker>),
    /// Occupancy grid + motion confirmation, with the leg model (`None`) or a forest.
    FreeSpace(Option<Arc<LegModel>>, Box<FreeSpaceTracker>),
}

impl Runner {
    /// The method's runner; `None` when a learned method's training data is absent (its rows
    /// say SKIPPED); an error when its training failed.
    /// `scan_topic` and `gt_topic` are those of the synthetic training logs.
    pub fn new(
        method: Method,
        p: &LearnedParams,
        scan_topic: &str,
        gt_topic: &str,
    ) -> anyhow::Result<Option<Runner>> {
        let tracker = || Box::new(PeopleTracker::new(TrackerParams::default()));
        let free = || Box::new(FreeSpaceTracker::default());
        Ok(Some(match method {
            Method::LegsFreeSpace => Runner::FreeSpace(None, free()),
            Method::LearnedFreeSpace | Method::LearnedSyntheticFreeSpace => {
                let source = method.source().unwrap_or(Source::Real);
                match learned::model(source, p, scan_topic, gt_topic) {
                    Ok(m) => Runner::FreeSpace(Some(m), free()),
                    Err(Unavailable::Absent(_)) => return Ok(None),
                    Err(Unavailable::Failed(e)) => {
                        anyhow::bail!("training the {} leg detector: {e}", method.name())
                    }
                }
            }
            Method::Legs => Runner::Tracked(tracker()),
            Method::LegsJpda => Runner::Tracked(Box::new(PeopleTracker::new(TrackerParams {
                association: Association::Jpda(JpdaParams::default()),
                ..TrackerParams::default()
            }))),
            Method::LegsLegLimit => Runner::Tracked(Box::new(PeopleTracker::new(TrackerParams {
                max_leg_only_scans: Some(LEG_ONLY_SCANS),
                ..TrackerParams::default()
            }))),
            Method::Nearest => Runner::Nearest,
            Method::Learned | Method::LearnedSynthetic => {
                let source = method.source().unwrap_or(Source::Real);
                match learned::model(source, p, scan_topic, gt_topic) {
                    Ok(m) => Runner::Learned(m, tracker()),
                    Err(Unavailable::Absent(_)) => return Ok(None),
                    Err(Unavailable::Failed(e)) => {
                        anyhow::bail!("training the {} leg detector: {e}", method.name())
                    }
                }
            }
        }))
    }

    /// The method's hypotheses after scan `view` at `time_s` (s since the session's first
    /// scan).
    pub fn step(&mut self, view: &ScanView, time_s: f64) -> Vec<Hypothesis> {
        match self {
            Runner::Tracked(tracker) => track(tracker, &view.geometric, time_s),
            Runner::Learned(model, tracker) => {
                let (d, _) = learned_legs(model, view);
                track(tracker, &d, time_s)
            }
            Runner::FreeSpace(model, fs) => match model {
                Some(m) => {
                    let (d, conf) = learned_legs(m, view);
                    track_free_space(fs, view, &d, &conf, time_s)
                }
                None => track_free_space(fs, view, &view.geometric, &[], time_s),
            },
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

/// The legs the classifier finds among the scan's segments, paired as seed 002 pairs them,
/// with each leg's probability. A classifier error (a model of another feature width) finds
/// no legs.
fn learned_legs(model: &LegModel, view: &ScanView) -> (Detections, Vec<f64>) {
    let s = Segmented {
        points: view.points.clone(),
        segments: view.segments.clone(),
        centroids: view
            .segments
            .iter()
            .map(|g| centroid(&view.points, g))
            .collect(),
        geometry: ScanGeometry::of(&view.frame.scan),
        ranges: view.frame.scan.ranges.clone(),
    };
    let rows: Vec<(usize, Vec<f64>)> = (0..s.segments.len())
        .filter_map(|i| model.features_of(&s, i).map(|f| (i, f)))
        .collect();
    let x: Vec<Vec<f64>> = rows.iter().map(|(_, f)| f.clone()).collect();
    let prob = model.probability(&x).unwrap_or_default();
    let pose = view.frame.pose.as_ref();
    let (legs, conf): (Vec<Leg>, Vec<f64>) = rows
        .iter()
        .zip(&prob)
        .filter(|(_, p)| **p >= model.threshold)
        .map(|(&(i, _), &p)| {
            let features = features::compute(&s.points, &s.segments[i]);
            let c = s.centroids[i];
            let (sensor, radius) = match features.circle {
                Some(k)
                    if k.radius <= LEARNED_MAX_RADIUS_M
                        && k.centre.coords.norm() > c.coords.norm() =>
                {
                    (k.centre, k.radius)
                }
                _ => (c, 0.0),
            };
            let leg = Leg {
                segment: s.segments[i].clone(),
                features,
                sensor,
                fixed: to_fixed(pose, sensor),
                radius,
            };
            (leg, p)
        })
        .unzip();
    let (people, single_legs) = legs::pair(&legs, LegParams::default().pair_distance);
    (
        Detections {
            legs,
            people,
            single_legs,
        },
        conf,
    )
}

/// One scan through a free-space method ([`FreeSpaceTracker::step`]); its reported people.
fn track_free_space(
    fs: &mut FreeSpaceTracker,
    view: &ScanView,
    d: &Detections,
    conf: &[f64],
    time_s: f64,
) -> Vec<Hypothesis> {
    let g = ScanGeometry::of(&view.frame.scan);
    let pose = view.frame.pose.as_ref();
    fs.step(
        time_s,
        d,
        conf,
        &view.points,
        &view.frame.scan.ranges,
        &g,
        pose,
    );
    hypotheses(&fs.tracker)
}

/// Leg pairs and single legs of `d` into `tracker`; its confirmed tracks.
fn track(tracker: &mut PeopleTracker, d: &Detections, time_s: f64) -> Vec<Hypothesis> {
    let people: Vec<Point2<f64>> = d.people.iter().map(|p| p.fixed).collect();
    let single: Vec<Point2<f64>> = d.single_legs.iter().map(|&i| d.legs[i].fixed).collect();
    tracker.step(time_s, &people, &single);
    hypotheses(tracker)
}

/// The confirmed tracks as hypotheses.
fn hypotheses(tracker: &PeopleTracker) -> Vec<Hypothesis> {
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

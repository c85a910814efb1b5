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
//! - **`legs_free_space`**: leg_tracker's design ([`FreeSpaceTracker`], issue 35 round 2):
//!   every segment of the scan is a cluster, tracked on its own with the seed 002 leg model's
//!   verdict as its confidence (1 for a leg, 0 otherwise); two tracks that move together
//!   through free space of a local occupancy grid become a person (0.5 m each, or our quick
//!   rule: the pair's midpoint moved 0.25 m with three scans of confidence, both in free
//!   space); people take only clusters in free space; the grid maps every cluster not matched
//!   to a person. The fixed frame is the log's (TF) or, without one, the scan-matched
//!   odometry of [`crate::laser::scan_match`] ([`ScanView::odometry`]).
//! - **`learned_free_space`** / **`learned_synthetic_free_space`**: the same, each cluster's
//!   confidence the probability of a random forest over leg_tracker's 17 cluster features
//!   (`[params.learned_free_space]`: trained on the real CSVs / on the synthetic logs,
//!   `laser_clutter` included); no threshold (leg_tracker's `detection_threshold = −1`).
//! - **`nearest`**: the baseline without a filter: the midpoint of the two legs nearest to the
//!   laser (any distance apart), one hypothesis with id 1 on each scan with two legs or more.
//!
//! A new method is a variant of [`Method`] (its name in the pipeline file) and of [`Runner`]
//! (its state across the scans of one session).

use std::sync::Arc;

use nalgebra::{Isometry3, Point2, Point3};
use serde::{Deserialize, Serialize};

use super::learned::{self, LearnedParams, LegModel, Source, Unavailable};
use crate::laser::features;
use crate::laser::legs::Leg;
use crate::laser::points::to_fixed;
use crate::laser::training::{Segmented, centroid};

use crate::frames::laser::LaserFrame;
use crate::laser::joint::JointParams;
use crate::laser::legs::{self, Detections, LegParams};
use crate::laser::occupancy::GridParams;
use crate::laser::people::{FreeSpaceTracker, ScanCluster, clusters_of};
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
                "leg_tracker's joint tracker (every cluster tracked, leg-model verdict as confidence; leg pairs moving together through free space of the local occupancy grid become people; quick rule) on the log's or scan-matched odometry"
            }
            Method::LearnedFreeSpace => {
                "legs_free_space with each cluster's confidence from a random forest on leg_tracker's 17 features trained on the real leg_tracker CSVs (no threshold)"
            }
            Method::LearnedSyntheticFreeSpace => {
                "the same forest trained on the synthetic datasets (laser_clutter included)"
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
/// detections, computed once, placed with `pose`; and the same placed with `odometry`, the
/// free-space methods' pose.
pub struct ScanView<'a> {
    pub frame: &'a LaserFrame,
    /// Fixed ← laser for every method but the free-space ones: the log's TF (`None`: the
    /// laser frame, also when the sequence withholds odometry).
    pub pose: Option<Isometry3<f64>>,
    pub points: Vec<ScanPoint>,
    pub segments: Vec<Segment>,
    pub geometric: Detections,
    /// Fixed ← laser for the free-space methods: the log's TF, else scan-matched odometry.
    pub odometry: Option<Isometry3<f64>>,
    pub odometry_points: Vec<ScanPoint>,
    pub odometry_geometric: Detections,
}

impl<'a> ScanView<'a> {
    pub fn new(frame: &'a LaserFrame, pose: Option<Isometry3<f64>>) -> Self {
        let g = ScanGeometry::of(&frame.scan);
        let points = points::project(&frame.scan.ranges, &g, pose.as_ref());
        let segments = segment::segment(&points, &SegmentOptions::default());
        let geometric = detect(frame, &points, &segments, pose.as_ref());
        ScanView {
            frame,
            pose,
            odometry: pose,
            odometry_points: points.clone(),
            odometry_geometric: geometric.clone(),
            points,
            segments,
            geometric,
        }
    }

    /// Place the free-space methods' returns and legs with `odometry`.
    pub fn set_odometry(&mut self, odometry: Option<Isometry3<f64>>) {
        if odometry == self.pose {
            return;
        }
        let g = ScanGeometry::of(&self.frame.scan);
        self.odometry = odometry;
        self.odometry_points = points::project(&self.frame.scan.ranges, &g, odometry.as_ref());
        self.odometry_geometric = detect(
            self.frame,
            &self.odometry_points,
            &self.segments,
            odometry.as_ref(),
        );
    }
}

fn detect(
    frame: &LaserFrame,
    points: &[ScanPoint],
    segments: &[Segment],
    pose: Option<&Isometry3<f64>>,
) -> Detections {
    legs::detect(
        points,
        segments,
        frame.scan.ranges.len(),
        pose,
        &LegParams::default(),
    )
}

/// A fixed-frame point in the laser frame (identity without a pose).
pub fn to_laser(pose: Option<&Isometry3<f64>>, p: Point2<f64>) -> Point2<f64> {
    match pose {
        Some(pose) => {
            let q = pose.inverse_transform_point(&Point3::new(p.x, p.y, 0.0));
            Point2::new(q.x, q.y)
        }
        None => p,
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
    /// `scan_topic` and `gt_topic` are those of the synthetic training logs; `publish_occluded`
    /// is the free-space methods' option of that name (the sequence's).
    pub fn new(
        method: Method,
        p: &LearnedParams,
        (scan_topic, gt_topic): (&str, &str),
        publish_occluded: bool,
    ) -> anyhow::Result<Option<Runner>> {
        let tracker = || Box::new(PeopleTracker::new(TrackerParams::default()));
        let joint = JointParams {
            publish_occluded,
            ..JointParams::default()
        };
        let free = || Box::new(FreeSpaceTracker::new(joint, GridParams::default()));
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
            Runner::FreeSpace(model, fs) => {
                let pose = view.odometry.as_ref();
                let clusters = match model {
                    Some(m) => learned_clusters(m, view),
                    None => clusters_of(&view.odometry_points, &view.odometry_geometric, &[], pose),
                };
                track_free_space(fs, view, &clusters, time_s)
            }
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
    let pose = view.pose.as_ref();
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

/// Every segment of the scan as a cluster with the forest's probability as its confidence
/// (no threshold; 0 where the features cannot be computed), placed with the odometry pose: at
/// its fitted circle's centre when a circle of radius ≤ [`LEARNED_MAX_RADIUS_M`] fits facing
/// the laser, else at its centroid.
fn learned_clusters(model: &LegModel, view: &ScanView) -> Vec<ScanCluster> {
    let s = Segmented {
        points: view.odometry_points.clone(),
        segments: view.segments.clone(),
        centroids: view
            .segments
            .iter()
            .map(|g| centroid(&view.odometry_points, g))
            .collect(),
        geometry: ScanGeometry::of(&view.frame.scan),
        ranges: view.frame.scan.ranges.clone(),
    };
    let rows: Vec<(usize, Vec<f64>)> = (0..s.segments.len())
        .filter_map(|i| model.features_of(&s, i).map(|f| (i, f)))
        .collect();
    let x: Vec<Vec<f64>> = rows.iter().map(|(_, f)| f.clone()).collect();
    let prob = model.probability(&x).unwrap_or_default();
    let mut conf = vec![0.0; s.segments.len()];
    for ((i, _), p) in rows.iter().zip(&prob) {
        conf[*i] = *p;
    }
    let pose = view.odometry.as_ref();
    s.segments
        .iter()
        .zip(&s.centroids)
        .zip(conf)
        .map(|((g, &c), confidence)| {
            let sensor = match features::compute(&s.points, g).circle {
                Some(k)
                    if k.radius <= LEARNED_MAX_RADIUS_M
                        && k.centre.coords.norm() > c.coords.norm() =>
                {
                    k.centre
                }
                _ => c,
            };
            ScanCluster {
                segment: g.clone(),
                position: to_fixed(pose, sensor),
                range: sensor.coords.norm(),
                confidence,
            }
        })
        .collect()
}

/// One scan through a free-space method ([`FreeSpaceTracker::step_clusters`]); its reported
/// people, in the laser frame through the odometry pose.
fn track_free_space(
    fs: &mut FreeSpaceTracker,
    view: &ScanView,
    clusters: &[ScanCluster],
    time_s: f64,
) -> Vec<Hypothesis> {
    let g = ScanGeometry::of(&view.frame.scan);
    let pose = view.odometry.as_ref();
    fs.step_clusters(
        time_s,
        clusters,
        &view.odometry_points,
        &view.frame.scan.ranges,
        &g,
        pose,
    );
    fs.tracker
        .confirmed()
        .map(|t| Hypothesis {
            id: i64::try_from(t.id).unwrap_or(i64::MAX),
            world: t.position(),
            laser: Some(to_laser(pose, t.position())),
        })
        .collect()
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

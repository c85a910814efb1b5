//! The geometric leg model of seed 002 §3 (Brooks & Williams): "a leg, as sensed by a laser
//! scanner, is modelled as a semi-circle with radius in a certain range, separated from its
//! background by a threshold distance … A human is defined as a pair of legs within a certain
//! distance of each other", and the observation is "a point midway between the two legs".
//!
//! A segment (sensor frame) is a **leg** when
//!
//! 1. it has at least `min_points` returns and a circle fits ([`crate::laser::features`]);
//! 2. the fitted radius lies in `[radius_min, radius_max]`;
//! 3. the arc faces the sensor (semi-circle seen from the front): the circle's centre is
//!    farther from the sensor than the segment's centroid;
//! 4. it stands in front of its background: at each end, the return on the beam just outside
//!    is either at least `background_jump` farther than that end or absent (no return:
//!    nothing within range behind) — *background* — or nearer than that end — *occluded*
//!    (the end is hidden behind something in front, e.g. the person's other leg); at least one
//!    end must be background. An end whose neighbour is farther by less than
//!    `background_jump` touches its background: not a leg. A segment touching the first or
//!    last beam of the scan is not a leg (its background is unseen).
//!
//! The leg's position is the fitted circle's centre. Legs are paired into people greedily,
//! closest pair first (ties by leg order), when their centres are at most `pair_distance`
//! apart; a person's observation is the midpoint of the two centres. Unpaired legs are kept
//! (the tracker uses them to carry a person through a one-leg occlusion).
//!
//! The seed gives the model but no numbers ("determined experimentally"); the defaults say
//! where each value comes from.

use nalgebra::{Isometry3, Point2};

use super::features::{self, SegmentFeatures};
use super::points::{ScanPoint, to_fixed};
use super::segment::Segment;

/// Parameters of the leg model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LegParams {
    /// Fewest returns in a leg segment.
    pub min_points: usize,
    /// Fitted radius range (m).
    pub radius_min: f64,
    pub radius_max: f64,
    /// Least depth step from a leg's ends to the background behind (m).
    pub background_jump: f64,
    /// Most distance between the two leg centres of one person (m).
    pub pair_distance: f64,
}

impl Default for LegParams {
    /// - `min_points` 3: the fewest points a circle fits through.
    /// - `radius_min` 0.03 m, `radius_max` 0.15 m: an adult calf between knee and ankle is
    ///   about 8–14 cm across (radius 4–7 cm); widened for trousers and for the fit's spread on
    ///   a few points; chosen on synthetic data (not on the real logs).
    /// - `background_jump` 0.1 m: chosen on synthetic data (seed 002: "determined
    ///   experimentally", no value given) so that the nearer of two legs 0.2 m apart on a
    ///   diagonal (0.14 m apart in range) still stands out; equal to the default segmentation
    ///   jump.
    /// - `pair_distance` 0.6 m: about an adult's step length at walking speed; chosen (seed
    ///   002: "within a certain distance", no value given).
    fn default() -> Self {
        LegParams {
            min_points: 3,
            radius_min: 0.03,
            radius_max: 0.15,
            background_jump: 0.1,
            pair_distance: 0.6,
        }
    }
}

/// A detected leg.
#[derive(Debug, Clone, PartialEq)]
pub struct Leg {
    pub segment: Segment,
    pub features: SegmentFeatures,
    /// Fitted circle centre, sensor frame (m).
    pub sensor: Point2<f64>,
    /// The same in the fixed frame.
    pub fixed: Point2<f64>,
    pub radius: f64,
}

/// A person: two legs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Person {
    /// Indices into [`Detections::legs`].
    pub legs: (usize, usize),
    /// Midpoint of the two leg centres, sensor frame (m).
    pub sensor: Point2<f64>,
    /// The same in the fixed frame.
    pub fixed: Point2<f64>,
}

/// The legs and people of one scan.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Detections {
    /// In segment order.
    pub legs: Vec<Leg>,
    /// In order of pairing (closest pair first).
    pub people: Vec<Person>,
    /// Indices of the legs not in a person, ascending.
    pub single_legs: Vec<usize>,
}

/// Legs and people among `segments` of a scan of `beam_count` beams whose returns are
/// `points`; `pose` places them in the fixed frame.
pub fn detect(
    points: &[ScanPoint],
    segments: &[Segment],
    beam_count: usize,
    pose: Option<&Isometry3<f64>>,
    params: &LegParams,
) -> Detections {
    let legs: Vec<Leg> = segments
        .iter()
        .filter_map(|s| leg(points, s, beam_count, pose, params))
        .collect();
    let (people, single_legs) = pair(&legs, params.pair_distance);
    Detections {
        legs,
        people,
        single_legs,
    }
}

/// `segment` as a leg, if it is one (see the module doc).
pub fn leg(
    points: &[ScanPoint],
    segment: &Segment,
    beam_count: usize,
    pose: Option<&Isometry3<f64>>,
    params: &LegParams,
) -> Option<Leg> {
    let seg = points.get(segment.points.clone())?;
    if seg.len() < params.min_points.max(3) {
        return None;
    }
    let f = features::compute(points, segment);
    let c = f.circle?;
    if !(c.radius >= params.radius_min && c.radius <= params.radius_max) {
        return None;
    }
    let centroid = seg
        .iter()
        .map(|p| p.sensor.coords)
        .sum::<nalgebra::Vector2<f64>>()
        / seg.len() as f64;
    let faces_sensor = c.centre.coords.norm() > centroid.norm(); // false on NaN
    if !faces_sensor {
        return None;
    }
    let (first, last) = (seg.first()?, seg.last()?);
    if first.beam == 0 || last.beam + 1 >= beam_count {
        return None;
    }
    let start = segment.points.start;
    let before = start.checked_sub(1).and_then(|i| points.get(i));
    let after = points.get(segment.points.end);
    let start_end = end_kind(before, first.beam - 1, first, params.background_jump);
    let last_end = end_kind(after, last.beam + 1, last, params.background_jump);
    let ok = |e: End| e != End::Attached;
    if !(ok(start_end)
        && ok(last_end)
        && (start_end == End::Background || last_end == End::Background))
    {
        return None;
    }
    Some(Leg {
        segment: segment.clone(),
        features: f,
        sensor: c.centre,
        fixed: to_fixed(pose, c.centre),
        radius: c.radius,
    })
}

/// What lies beyond one end of a segment.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum End {
    /// Background at least the jump farther, or no return on that beam.
    Background,
    /// A nearer return: the end is hidden behind something in front.
    Occluded,
    /// A return less than the jump farther: the segment touches its background.
    Attached,
}

/// `nb` is the point before/after the segment in the list, `beam` the adjacent beam.
fn end_kind(nb: Option<&ScanPoint>, beam: usize, end: &ScanPoint, jump: f64) -> End {
    match nb {
        Some(p) if p.beam == beam => {
            let step = p.range - end.range;
            if step >= jump {
                End::Background
            } else if step < 0.0 {
                End::Occluded
            } else {
                End::Attached
            }
        }
        _ => End::Background,
    }
}

/// Greedy closest-first pairing; returns the people and the unpaired legs' indices.
pub fn pair(legs: &[Leg], pair_distance: f64) -> (Vec<Person>, Vec<usize>) {
    let mut candidates: Vec<(f64, usize, usize)> = Vec::new();
    for i in 0..legs.len() {
        for j in i + 1..legs.len() {
            let d = (legs[j].sensor - legs[i].sensor).norm();
            if d <= pair_distance {
                candidates.push((d, i, j));
            }
        }
    }
    candidates.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    let mut used = vec![false; legs.len()];
    let mut people = Vec::new();
    for (_, i, j) in candidates {
        if used[i] || used[j] {
            continue;
        }
        used[i] = true;
        used[j] = true;
        people.push(Person {
            legs: (i, j),
            sensor: nalgebra::center(&legs[i].sensor, &legs[j].sensor),
            fixed: nalgebra::center(&legs[i].fixed, &legs[j].fixed),
        });
    }
    let single = (0..legs.len()).filter(|&i| !used[i]).collect();
    (people, single)
}

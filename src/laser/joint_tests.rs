//! Known-answer tests of leg_tracker's joint tracker ([`super::joint`]) and of the free-space
//! tracker with its grid ([`super::people`]) on synthetic scans.

use nalgebra::{Point2, Vector2};

use super::joint::{Cluster, JointParams, JointTracker, LONE};
use super::legs::{self, LegParams};
use super::occupancy::GridParams;
use super::people::FreeSpaceTracker;
use super::points;
use super::segment::{self, SegmentOptions};
use super::tests::{Synth, legs_of};

fn cluster(x: f64, y: f64, confidence: f64, occupancy: f64) -> Cluster {
    Cluster {
        position: Point2::new(x, y),
        confidence,
        occupancy,
    }
}

/// Two leg clusters 0.2 m apart (across the walking direction) whose midpoint is at `y` on
/// the line x = 2.
fn pair(y: f64, confidence: f64, occupancy: f64) -> [Cluster; 2] {
    [
        cluster(1.9, y, confidence, occupancy),
        cluster(2.1, y, confidence, occupancy),
    ]
}

/// The scan on which the first person is reported, walking at `speed` m/s (10 Hz) along y.
fn first_person(params: JointParams, speed: f64, confidence: f64, occupancy: f64) -> Option<usize> {
    let mut t = JointTracker::new(params);
    (0..60).find(|&k| {
        let y = speed * 0.1 * k as f64;
        t.step(0.1 * k as f64, &pair(y, confidence, occupancy));
        t.confirmed().count() > 0
    })
}

/// leg_tracker's rule: a pair standing still is never a person; a pair walking at 1 m/s
/// becomes one only after each leg's filtered path since pairing passed 0.5 m — not before
/// the legs truly moved 0.4 m (the first update's jump from the zero-velocity start counts
/// little: the filter starts on the first observation), and by 1 m.
#[test]
fn a_walking_pair_becomes_a_person_after_half_a_metre() {
    let lt = JointParams::leg_tracker();
    assert_eq!(first_person(lt, 0.0, 1.0, 0.0), None);
    let k = first_person(lt, 1.0, 1.0, 0.0).expect("a person");
    assert!((4..=10).contains(&k), "scan {k}");
}

/// The quick rule reports the same walker earlier (midpoint 0.25 m on, three confident
/// scans) and still never a pair standing still.
#[test]
fn the_quick_rule_reports_a_walker_earlier_and_never_a_still_pair() {
    let q = JointParams::default();
    assert_eq!(first_person(q, 0.0, 1.0, 0.0), None);
    let quick = first_person(q, 1.0, 1.0, 0.0).expect("a person");
    let lt = first_person(JointParams::leg_tracker(), 1.0, 1.0, 0.0).expect("a person");
    assert!(quick < lt, "{quick} vs {lt}");
    assert!(quick >= 3, "{quick}: the midpoint moved 0.25 m at scan 3");
}

/// The lone-cluster option: one confident cluster walking at 1 m/s through free space becomes
/// a person once its filtered path passed 0.5 m (in place: its id kept), never standing still,
/// never at confidence 0.3 (< 0.5); without the option never; and a walking leg pair still
/// makes exactly one person with it.
#[test]
fn a_lone_walking_cluster_becomes_a_person_only_with_the_lone_option() {
    let lone = JointParams {
        lone: Some(LONE),
        ..JointParams::default()
    };
    let first_lone = |params: JointParams, speed: f64, confidence: f64| {
        let mut t = JointTracker::new(params);
        (0..60).find_map(|k| {
            let y = speed * 0.1 * k as f64;
            t.step(0.1 * k as f64, &[cluster(2.0, y, confidence, 0.0)]);
            t.confirmed().next().map(|p| (k, p.id))
        })
    };
    let (k, id) = first_lone(lone, 1.0, 1.0).expect("a person");
    assert!((4..=10).contains(&k), "scan {k}");
    assert_eq!(id, 1, "the object track became the person");
    assert_eq!(first_lone(lone, 0.0, 1.0), None);
    assert_eq!(first_lone(lone, 1.0, 0.3), None);
    assert_eq!(first_lone(JointParams::default(), 1.0, 1.0), None);
    let mut t = JointTracker::new(lone);
    for k in 0..40 {
        t.step(0.1 * k as f64, &pair(0.1 * k as f64, 1.0, 0.0));
    }
    assert_eq!(t.tracks().iter().filter(|tr| tr.person).count(), 1);
}

/// Outside free space (occupancy 0.1 ≥ 0.06) or with no confidence (below 0.1 the legs never
/// pair) a walker is never a person.
#[test]
fn occupied_space_or_no_confidence_makes_no_person() {
    for p in [JointParams::leg_tracker(), JointParams::default()] {
        assert_eq!(first_person(p, 1.0, 1.0, 0.1), None);
        assert_eq!(first_person(p, 1.0, 0.0, 0.0), None);
    }
}

/// A person takes only clusters in free space: walking into occupied space its legs are not
/// matched (reported as occluded, or not at all without `publish_occluded`), and the step
/// returns which clusters it took.
#[test]
fn a_person_takes_only_free_clusters() {
    for publish_occluded in [true, false] {
        let mut t = JointTracker::new(JointParams {
            publish_occluded,
            ..JointParams::default()
        });
        let mut k = 0;
        while t.confirmed().count() == 0 && k < 30 {
            t.step(0.1 * k as f64, &pair(0.1 * k as f64, 1.0, 0.0));
            k += 1;
        }
        let id = t.confirmed().next().expect("a person").id;
        let taken = t.step(0.1 * k as f64, &pair(0.1 * k as f64, 1.0, 0.0));
        assert_eq!(taken, vec![true, true]);
        let taken = t.step(0.1 * (k + 1) as f64, &pair(0.1 * (k + 1) as f64, 1.0, 0.5));
        assert_eq!(taken, vec![false, false]);
        let person = t.tracks().iter().find(|tr| tr.id == id).expect("kept");
        assert!(!person.seen);
        assert_eq!(t.confirmed().count(), usize::from(publish_occluded));
    }
}

/// A person whose clusters all lose their confidence is deleted once its running confidence
/// (0.95 c + 0.05 c_z from 1) falls below 0.1: after ⌈ln 0.1 / ln 0.95⌉ = 45 scans.
#[test]
fn a_person_without_confidence_is_deleted_after_45_scans() {
    let mut t = JointTracker::new(JointParams::default());
    let mut k = 0;
    while t.confirmed().count() == 0 {
        t.step(0.1 * k as f64, &pair(0.1 * k as f64, 1.0, 0.0));
        k += 1;
    }
    let c0 = t.confirmed().next().expect("a person").confidence;
    let mut alive = 0;
    for j in 0..100 {
        let y = 0.1 * (k + j) as f64;
        t.step(0.1 * (k + j) as f64, &pair(y, 0.0, 0.0));
        if t.tracks().iter().any(|tr| tr.person) {
            alive += 1;
        }
    }
    let want = ((0.1f64 / c0).ln() / 0.95f64.ln()).ceil() as usize - 1;
    assert_eq!(alive, want, "c0 {c0}");
}

/// The whole chain on synthetic scans: a walker and a pair of static leg-like poles in front
/// of a wall, with the leg model's verdicts as confidences and the grid built online. The
/// walker is reported and followed; the poles never are, and the grid marks them occupied
/// while the walker's cells stay free. Until it is a person the walker's legs are non-leg
/// clusters, mapped as obstacles (leg_tracker's rule), so the cells it just left raise the
/// occupancy around its legs and its running free-space value (0.8 f + 0.2 f_z) takes a few
/// scans to fall below 0.06: it is reported within 1.5 s (15 scans), not at the quick rule's
/// 0.25 m.
#[test]
fn free_space_tracking_reports_a_walker_and_never_static_poles() {
    let s = Synth::new();
    let poles = [
        (Point2::new(4.0, 1.5), 0.06),
        (Point2::new(4.0, 1.75), 0.06),
    ];
    let mut fs = FreeSpaceTracker::new(JointParams::default(), GridParams::default());
    let mut reported = None;
    for k in 0..40 {
        let centre = Point2::new(2.0, -2.0 + 0.1 * k as f64);
        let mut circles = legs_of(centre, Vector2::new(0.0, 1.0)).to_vec();
        circles.extend(poles);
        let ranges = s.ranges(&circles);
        let pts = points::project(&ranges, &s.geometry, None);
        let segs = segment::segment(&pts, &SegmentOptions::default());
        let d = legs::detect(&pts, &segs, s.beams, None, &LegParams::default());
        fs.step(0.1 * k as f64, &d, &[], &pts, &ranges, &s.geometry, None);
        for tr in fs.tracker.confirmed() {
            assert!((tr.position() - poles[0].0).norm() > 1.0, "a pole reported");
            if k > 15 {
                assert!((tr.position() - centre).norm() < 0.15, "scan {k}: {tr:?}");
            }
        }
        if reported.is_none() && fs.tracker.confirmed().count() > 0 {
            reported = Some(k);
        }
    }
    let k = reported.expect("the walker is reported");
    assert!((3..=15).contains(&k), "first reported on scan {k}");
    assert!(fs.grid.occupancy_around(Point2::new(3.97, 1.5)) >= 0.06);
    assert!(fs.grid.occupancy_around(Point2::new(2.0, 1.9)) < 0.06);
}

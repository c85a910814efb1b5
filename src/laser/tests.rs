//! Known-answer tests of the laser chain: segmentation of a hand-made scan, features, the
//! tracker's filter against its closed form, two people crossing and a one-leg occlusion in
//! synthetic scans, and a structural run over a real log.

use nalgebra::Point2;

use super::features::{self, RADIUS_CAP};
use super::legs::{self, LegParams};
use super::points::{self, ScanGeometry, ScanPoint};
use super::segment::{self, SegmentOptions, Threshold};
use super::tracker::{
    Association, Confirmation, JpdaParams, MotionParams, Observation, PeopleTracker, TrackerParams,
    Update,
};

fn beams(segs: &[segment::Segment]) -> Vec<(usize, usize)> {
    segs.iter().map(|s| (s.first_beam, s.last_beam)).collect()
}

#[test]
fn segmentation_of_a_hand_made_scan_is_exact() {
    let nan = f32::NAN;
    let inf = f32::INFINITY;
    #[rustfmt::skip]
    let ranges = [
        1.0, 1.0, 1.05, nan, 1.0, 1.0, 2.0, 2.0, 2.0, inf, 3.0, 0.0, 3.0, 3.0, 3.0, -inf,
    ];
    let g = ScanGeometry {
        angle_min: -0.08,
        angle_increment: 0.01,
        range_min: 0.05,
        range_max: 10.0,
    };
    let pts = points::project(&ranges, &g, None);
    assert_eq!(pts.len(), 12);
    let fixed = |min_points| SegmentOptions {
        threshold: Threshold::Fixed(0.1),
        min_points,
    };
    let segs = segment::segment(&pts, &fixed(1));
    assert_eq!(
        beams(&segs),
        vec![(0, 2), (4, 5), (6, 8), (10, 10), (12, 14)]
    );
    assert_eq!(segs[1].points, 3..5);
    assert_eq!(
        beams(&segment::segment(&pts, &fixed(2))),
        vec![(0, 2), (4, 5), (6, 8), (12, 14)]
    );
    // adaptive: 0.005 + r · 2 sin(0.005) ≈ 0.015 m at 1 m breaks the 0.05 m step 1.0 → 1.05
    let adaptive = SegmentOptions {
        threshold: Threshold::Adaptive { c0: 0.005, c1: 1.0 },
        min_points: 1,
    };
    assert_eq!(
        beams(&segment::segment(&pts, &adaptive)),
        vec![(0, 1), (2, 2), (4, 5), (6, 8), (10, 10), (12, 14)]
    );
    assert!(segment::segment(&[], &fixed(1)).is_empty());
}

/// Scan points with consecutive beams from sensor-frame points.
fn scan_points(first_beam: usize, pts: &[Point2<f64>]) -> Vec<ScanPoint> {
    pts.iter()
        .enumerate()
        .map(|(i, p)| ScanPoint {
            beam: first_beam + i,
            range: p.coords.norm(),
            angle: p.y.atan2(p.x),
            sensor: *p,
            fixed: *p,
        })
        .collect()
}

fn whole(pts: &[ScanPoint]) -> segment::Segment {
    segment::Segment {
        points: 0..pts.len(),
        first_beam: pts[0].beam,
        last_beam: pts[pts.len() - 1].beam,
    }
}

#[test]
fn features_of_a_straight_line() {
    let line: Vec<_> = (0..7)
        .map(|i| Point2::new(2.0, -0.3 + 0.1 * f64::from(i)))
        .collect();
    let pts = scan_points(10, &line);
    let f = features::compute(&pts, &whole(&pts));
    assert_eq!(f.points, 7);
    assert!(f.linearity < 1e-24, "{f:?}");
    assert_eq!(f.radius, RADIUS_CAP);
    assert_eq!(f.circularity, f.linearity);
    assert!(f.circle.is_none());
    assert!((f.width - 0.6).abs() < 1e-12);
    assert!((f.boundary_length - 0.6).abs() < 1e-12);
    assert!(f.boundary_regularity < 1e-12);
    assert!(f.mean_curvature < 1e-9);
    // std: Σ y² / 6 = 0.28 / 6
    assert!((f.std_dev - (0.28f64 / 6.0).sqrt()).abs() < 1e-12);
    assert_eq!(f.to_vec().len(), features::FEATURE_NAMES.len());
}

#[test]
fn features_of_a_circle_arc_and_occlusion_flags() {
    // 90° of a circle of radius 0.1 centred at (2, 0), facing the sensor, 10 points
    let (r, n) = (0.1, 10);
    let arc: Vec<_> = (0..n)
        .map(|i| {
            let t = (135.0 + 90.0 * f64::from(i) / f64::from(n - 1)).to_radians();
            Point2::new(2.0 + r * t.cos(), r * t.sin())
        })
        .collect();
    // a nearer return on the beam before, a farther one on the beam after
    let mut all = vec![Point2::new(1.0, 0.2)];
    all.extend(&arc);
    all.push(Point2::new(5.0, -0.5));
    let pts = scan_points(40, &all);
    let seg = segment::Segment {
        points: 1..11,
        first_beam: 41,
        last_beam: 50,
    };
    let f = features::compute(&pts, &seg);
    assert!((f.radius - r).abs() < 1e-9, "{f:?}");
    assert!(f.circularity < 1e-18);
    assert!((f.mean_curvature - 1.0 / r).abs() < 1e-9);
    assert!((f.width - 2.0 * r * 45f64.to_radians().sin()).abs() < 1e-12);
    let chord = 2.0 * r * (90f64.to_radians() / 18.0).sin();
    assert!((f.boundary_length - 9.0 * chord).abs() < 1e-12);
    assert!(f.boundary_regularity < 1e-12);
    assert!(f.linearity > 1e-4);
    assert!(f.occluded_first && !f.occluded_last);
    let v = f.to_vec();
    assert_eq!((v[9], v[10]), (1.0, 0.0));
}

#[test]
fn the_tracker_filter_matches_the_closed_form_for_one_step() {
    let p = TrackerParams::default();
    let mut t = PeopleTracker::new(p);
    t.step(10.0, &[Point2::new(1.0, 2.0)], &[]);
    let dt = 0.1;
    t.step(10.0 + dt, &[Point2::new(1.05, 1.9)], &[]);
    let k = &t.tracks()[0].filter;
    // per axis: prior pos var a0 = σp², vel var c0 = σv², zero covariance; after predict
    //   a = a0 + dt² c0 + dt⁴/4 q,  b = dt c0 + dt³/2 q,  c = c0 + dt² q   (q = σa²)
    // update with S = a + σp²: K = (a, b)/S
    let (a0, c0, q, r) = (0.01, 2.25, 4.0, 0.01);
    let a = a0 + dt * dt * c0 + dt.powi(4) / 4.0 * q;
    let b = dt * c0 + dt.powi(3) / 2.0 * q;
    let c = c0 + dt * dt * q;
    let s = a + r;
    for (axis, (x0, z)) in [(1.0, 1.05), (2.0, 1.9)].into_iter().enumerate() {
        let innov = z - x0;
        assert!((k.x[axis] - (x0 + a / s * innov)).abs() < 1e-12);
        assert!((k.x[axis + 2] - b / s * innov).abs() < 1e-12);
        assert!((k.p[(axis, axis)] - (a - a * a / s)).abs() < 1e-12);
        assert!((k.p[(axis, axis + 2)] - (b - a * b / s)).abs() < 1e-12);
        assert!((k.p[(axis + 2, axis + 2)] - (c - b * b / s)).abs() < 1e-12);
    }
    assert!(k.p[(0, 1)].abs() < 1e-15 && k.p[(0, 3)].abs() < 1e-15);
}

/// A synthetic scanner at the origin: 512 beams over ±90° (0.35°), 10 m range, a wall at
/// x = 8 m, and legs as circles.
pub(super) struct Synth {
    pub(super) geometry: ScanGeometry,
    pub(super) beams: usize,
}

impl Synth {
    pub(super) fn new() -> Self {
        let inc = std::f64::consts::PI / 511.0;
        Synth {
            geometry: ScanGeometry {
                angle_min: -std::f64::consts::FRAC_PI_2,
                angle_increment: inc,
                range_min: 0.05,
                range_max: 10.0,
            },
            beams: 512,
        }
    }

    pub(super) fn ranges(&self, circles: &[(Point2<f64>, f64)]) -> Vec<f32> {
        (0..self.beams)
            .map(|k| {
                let th = self.geometry.angle(k);
                let d = nalgebra::Vector2::new(th.cos(), th.sin());
                let mut best = if d.x > 1e-9 { 8.0 / d.x } else { f64::INFINITY };
                for (c, r) in circles {
                    // |t d − c|² = r²: t² − 2 t (d·c) + |c|² − r² = 0
                    let dc = d.dot(&c.coords);
                    let disc = dc * dc - (c.coords.norm_squared() - r * r);
                    if disc >= 0.0 {
                        let t = dc - disc.sqrt();
                        if t > 0.0 {
                            best = best.min(t);
                        }
                    }
                }
                if best <= self.geometry.range_max {
                    best as f32
                } else {
                    f32::INFINITY
                }
            })
            .collect()
    }

    /// People and unpaired legs (fixed frame = sensor frame here).
    fn detect(&self, circles: &[(Point2<f64>, f64)]) -> (Vec<Point2<f64>>, Vec<Point2<f64>>) {
        let pts = points::project(&self.ranges(circles), &self.geometry, None);
        let segs = segment::segment(&pts, &SegmentOptions::default());
        let d = legs::detect(&pts, &segs, self.beams, None, &LegParams::default());
        let people = d.people.iter().map(|p| p.fixed).collect();
        let single = d.single_legs.iter().map(|&i| d.legs[i].fixed).collect();
        (people, single)
    }
}

/// Two legs of radius 0.06 m, 0.1 m either side of `centre` across the walking direction.
pub(super) fn legs_of(
    centre: Point2<f64>,
    heading: nalgebra::Vector2<f64>,
) -> [(Point2<f64>, f64); 2] {
    let n = nalgebra::Vector2::new(-heading.y, heading.x) * 0.1;
    [(centre + n, 0.06), (centre - n, 0.06)]
}

#[test]
fn two_people_crossing_keep_their_ids() {
    two_people_crossing(TrackerParams::default());
}

#[test]
fn two_people_crossing_keep_their_ids_with_jpda() {
    two_people_crossing(TrackerParams {
        association: Association::Jpda(JpdaParams::default()),
        ..TrackerParams::default()
    });
}

fn two_people_crossing(params: TrackerParams) {
    let synth = Synth::new();
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let (va, vb) = (nalgebra::Vector2::new(s, s), nalgebra::Vector2::new(s, -s));
    let cross = Point2::new(4.0, 0.0);
    // 1 m/s on lines crossing at (4, 0); A there at t = 2 s, B at t = 2.4 s (closest 0.28 m)
    let a_at = |t: f64| cross + va * (t - 2.0);
    let b_at = |t: f64| cross + vb * (t - 2.4);
    let mut tracker = PeopleTracker::new(params);
    let (mut id_a, mut id_b) = (None, None);
    let mut closest = f64::INFINITY;
    for i in 0..60 {
        let t = f64::from(i) * 0.1;
        let (a, b) = (a_at(t), b_at(t));
        closest = closest.min((a - b).norm());
        let mut circles = legs_of(a, va).to_vec();
        circles.extend(legs_of(b, vb));
        let (people, single) = synth.detect(&circles);
        tracker.step(t, &people, &single);
        if i < 5 {
            continue;
        }
        let confirmed: Vec<_> = tracker.confirmed().collect();
        assert_eq!(confirmed.len(), 2, "scan {i}: {confirmed:?}");
        for (truth, id) in [(a, &mut id_a), (b, &mut id_b)] {
            let near: Vec<u64> = confirmed
                .iter()
                .filter(|t| (t.position() - truth).norm() < 0.15)
                .map(|t| t.id)
                .collect();
            assert_eq!(near.len(), 1, "scan {i}: {confirmed:?}");
            assert_eq!(*id.get_or_insert(near[0]), near[0], "scan {i}: id switch");
        }
    }
    assert_ne!(id_a, id_b);
    assert!(
        closest < 0.36,
        "the test must bring the people close: {closest}"
    );
}

/// One person walking away from the sensor at 1 m/s; one leg hidden on scans 20..25. Returns
/// per scan the confirmed track ids and how each was updated.
fn one_leg_occlusion(params: TrackerParams, use_legs: bool) -> Vec<Vec<(u64, Update)>> {
    let synth = Synth::new();
    let v = nalgebra::Vector2::new(1.0, 0.0);
    let mut tracker = PeopleTracker::new(params);
    let mut out = Vec::new();
    for i in 0..40 {
        let t = f64::from(i) * 0.1;
        let centre = Point2::new(2.0, 0.5) + v * t;
        let [l, r] = legs_of(centre, v);
        let circles = if (20..25).contains(&i) {
            vec![l]
        } else {
            vec![l, r]
        };
        let (people, single) = synth.detect(&circles);
        let single = if use_legs { single } else { Vec::new() };
        tracker.step(t, &people, &single);
        for tr in tracker.confirmed() {
            assert!((tr.position() - centre).norm() < 0.2, "scan {i}: {tr:?}");
        }
        out.push(tracker.confirmed().map(|t| (t.id, t.last)).collect());
    }
    out
}

#[test]
fn a_one_leg_occlusion_of_five_scans_keeps_the_track() {
    // deletion after 3 scans without an update: coasting alone cannot bridge 5 scans
    let params = TrackerParams {
        delete_m: 1,
        delete_n: 3,
        ..TrackerParams::default()
    };
    let runs = one_leg_occlusion(params, true);
    for (i, scan) in runs.iter().enumerate().skip(2) {
        assert_eq!(scan.len(), 1, "scan {i}: {scan:?}");
        assert_eq!(scan[0].0, 1, "scan {i}: {scan:?}");
        let by_leg = matches!(scan[0].1, Update::Leg(_));
        assert_eq!(by_leg, (20..25).contains(&i), "scan {i}: {scan:?}");
    }
    // without the single-leg updates the track is lost during the occlusion
    let control = one_leg_occlusion(params, false);
    assert!(control[24].is_empty(), "{:?}", control[24]);
}

/// A person walks into view, then only one static leg-like object (radius 0.06 m, a pole)
/// remains where they stopped: single-leg updates keep the track for ever unless
/// `max_leg_only_scans` limits how long legs alone may carry it.
#[test]
fn a_static_single_leg_keeps_a_track_only_within_the_leg_only_limit() {
    let synth = Synth::new();
    let run = |limit: Option<usize>| {
        let mut t = PeopleTracker::new(TrackerParams {
            max_leg_only_scans: limit,
            ..TrackerParams::default()
        });
        let mut alive = Vec::new();
        for i in 0..60 {
            let time = f64::from(i) * 0.1;
            let centre = Point2::new(3.0, 0.0);
            let circles = if i < 10 {
                legs_of(centre, nalgebra::Vector2::new(1.0, 0.0)).to_vec()
            } else {
                vec![(centre + nalgebra::Vector2::new(0.0, 0.1), 0.06)]
            };
            let (people, single) = synth.detect(&circles);
            assert_eq!(
                (people.len(), single.len()),
                if i < 10 { (1, 0) } else { (0, 1) }
            );
            t.step(time, &people, &single);
            alive.push(t.confirmed().count());
        }
        alive
    };
    assert!(
        run(None)[10..].iter().all(|&n| n == 1),
        "legs alone carry the track"
    );
    let limited = run(Some(5));
    // pair updates on scans 0..9, legs on 10..14, misses from 15: the 10th miss (scan 24)
    // deletes it
    assert!(limited[2..24].iter().all(|&n| n == 1), "{limited:?}");
    assert!(limited[24..].iter().all(|&n| n == 0), "{limited:?}");
}

fn jpda(pd: f64, lambda: f64) -> TrackerParams {
    TrackerParams {
        association: Association::Jpda(JpdaParams {
            detection_probability: pd,
            clutter_density: lambda,
            max_events: 1000,
        }),
        ..TrackerParams::default()
    }
}

/// Two tracks started at (2, 0) and (2, 0.4), then at the same instant (dt = 0: no
/// prediction, `P = diag(σp², σp², σv², σv²)`) two observations between them, all four pairs
/// in the gate: one cluster of seven joint events. With `S = 2σp² I` the gain is ½ on position
/// and 0 on velocity, so each track moves by ½ Σ_j β_tj ν_tj, β from the hand enumeration.
#[test]
fn jpda_two_tracks_two_observations_match_the_hand_enumeration() {
    let (pd, lambda) = (0.8, 0.5);
    let p = jpda(pd, lambda);
    let mut t = PeopleTracker::new(p);
    let x = [Point2::new(2.0, 0.0), Point2::new(2.0, 0.4)];
    t.step(1.0, &x, &[]);
    let z = [Point2::new(2.0, 0.15), Point2::new(2.05, 0.3)];
    t.step(1.0, &z, &[]);
    let s = 2.0 * p.person_sigma.powi(2);
    let g = |a: &Point2<f64>, b: &Point2<f64>| {
        let d2 = (a - b).norm_squared() / s;
        assert!(d2 <= p.gate);
        pd * (-0.5 * d2).exp() / (2.0 * std::f64::consts::PI * s)
    };
    let m = lambda * (1.0 - pd * (1.0 - (-0.5 * p.gate).exp()));
    let w = |i: usize, j: usize| g(&x[i], &z[j]);
    // (track 0's, track 1's observation), None = missed
    let events = [
        (None, None, m * m),
        (Some(0), None, w(0, 0) * m),
        (Some(1), None, w(0, 1) * m),
        (None, Some(0), m * w(1, 0)),
        (None, Some(1), m * w(1, 1)),
        (Some(0), Some(1), w(0, 0) * w(1, 1)),
        (Some(1), Some(0), w(0, 1) * w(1, 0)),
    ];
    let total: f64 = events.iter().map(|e| e.2).sum();
    let beta = |track: usize, j: usize| {
        events
            .iter()
            .filter(|e| [e.0, e.1][track] == Some(j))
            .map(|e| e.2)
            .sum::<f64>()
            / total
    };
    assert_eq!(t.tracks().len(), 2, "both observations were taken");
    for (i, tr) in t.tracks().iter().enumerate() {
        let shift = (0..2).fold(nalgebra::Vector2::zeros(), |acc, j| {
            acc + beta(i, j) * (z[j] - x[i])
        });
        let want = x[i] + 0.5 * shift;
        assert!(
            (tr.position() - want).norm() < 1e-12,
            "track {i}: {tr:?} vs {want}"
        );
        assert!(tr.velocity().norm() < 1e-12);
        assert_eq!(
            tr.last,
            Update::Person(i),
            "the most probable event is 0→0, 1→1"
        );
    }
}

/// One track and two observations in its gate reduce to the PDAF weights
/// `β_j = e_j / (b + Σ e)`, `b = λ |2πS|^{1/2} (1 − P_D P_G) / P_D`; the covariance carries
/// the spread-of-innovations term. The observation outside the most probable event starts a
/// new track.
#[test]
fn jpda_one_track_is_the_pdaf() {
    let (pd, lambda) = (0.7, 2.0);
    let p = jpda(pd, lambda);
    let mut t = PeopleTracker::new(p);
    let x0 = Point2::new(3.0, 1.0);
    t.step(0.0, &[x0], &[]);
    let z = [Point2::new(3.1, 1.0), Point2::new(2.9, 0.8)];
    t.step(0.0, &z, &[]);
    let (sp, sv) = (p.person_sigma.powi(2), p.init_velocity_sigma.powi(2));
    let s = 2.0 * sp;
    let e: Vec<f64> = z
        .iter()
        .map(|z| (-0.5 * (z - x0).norm_squared() / s).exp())
        .collect();
    let pg = 1.0 - (-0.5 * p.gate).exp();
    let b = lambda * 2.0 * std::f64::consts::PI * s * (1.0 - pd * pg) / pd;
    let sum = b + e[0] + e[1];
    let beta = [e[0] / sum, e[1] / sum];
    let nu: Vec<nalgebra::Vector2<f64>> = z.iter().map(|z| z - x0).collect();
    let comb = beta[0] * nu[0] + beta[1] * nu[1];
    let k = sp / s; // position gain, velocity gain 0
    let tr = &t.tracks()[0];
    assert!((tr.position() - (x0 + k * comb)).norm() < 1e-12, "{tr:?}");
    // P⁺ = β0 P + (1 − β0) P_c + K (Σ β ν νᵀ − ν νᵀ) K
    let beta0 = b / sum;
    let spread = beta[0] * nu[0] * nu[0].transpose() + beta[1] * nu[1] * nu[1].transpose()
        - comb * comb.transpose();
    for (a, c) in [(0, 0), (0, 1), (1, 1)] {
        let eye = if a == c { 1.0 } else { 0.0 };
        let want =
            beta0 * sp * eye + (1.0 - beta0) * (sp - k * k * s) * eye + k * k * spread[(a, c)];
        assert!(
            (tr.filter.p[(a, c)] - want).abs() < 1e-12,
            "P[{a},{c}] {tr:?}"
        );
    }
    assert!((tr.filter.p[(2, 2)] - sv).abs() < 1e-12);
    assert_eq!(tr.last, Update::Person(0));
    assert_eq!(t.tracks().len(), 2);
    assert_eq!(t.tracks()[1].position(), z[1]);
}

/// With P_D = 1, no clutter and people far apart every cluster is one track and one
/// observation with β = 1: JPDA is the Kalman update, scan for scan the GNN tracker's state.
#[test]
fn jpda_without_clutter_and_misses_is_the_kalman_filter() {
    let synth = Synth::new();
    let mut gnn = PeopleTracker::new(TrackerParams::default());
    let mut jp = PeopleTracker::new(jpda(1.0, 0.0));
    for i in 0..30 {
        let t = f64::from(i) * 0.1;
        let a = Point2::new(2.0 + 0.8 * t, 2.0);
        let b = Point2::new(5.0, -2.0 + 0.5 * t);
        let mut circles = legs_of(a, nalgebra::Vector2::new(1.0, 0.0)).to_vec();
        circles.extend(legs_of(b, nalgebra::Vector2::new(1.0, 0.0)));
        let (people, single) = synth.detect(&circles);
        assert_eq!(people.len(), 2, "scan {i}");
        gnn.step(t, &people, &single);
        jp.step(t, &people, &single);
        assert_eq!(gnn.tracks().len(), jp.tracks().len());
        for (g, j) in gnn.tracks().iter().zip(jp.tracks()) {
            assert_eq!(
                (g.id, g.confirmed, g.last),
                (j.id, j.confirmed, j.last),
                "scan {i}"
            );
            assert!((g.filter.x - j.filter.x).norm() < 1e-9, "scan {i}");
            assert!((g.filter.p - j.filter.p).norm() < 1e-9, "scan {i}");
        }
    }
    assert_eq!(jp.confirmed().count(), 2);
    assert_eq!(jp.jpda_fallbacks(), 0);
}

#[test]
fn detection_and_tracking_run_over_a_real_log() {
    use crate::frames::laser::{LaserOptions, scans};
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let rel = "shared/real/laser/general_tracking_moving_1/general_tracking_moving_1.mcap";
    let Some(path) = [root.join("..").join(rel), root.join("../..").join(rel)]
        .into_iter()
        .find(|p| p.exists())
    else {
        println!("SKIPPED: {rel} not found");
        return;
    };
    let log = crate::log::SessionLog::open(&path).expect("open");
    let mut frames = scans(&log, "/scan", &LaserOptions::default()).expect("scans");
    let mut tracker = PeopleTracker::new(TrackerParams::default());
    let mut ids = std::collections::BTreeSet::new();
    let (mut n, mut people_seen) = (0, 0);
    for f in frames.by_ref().take(200) {
        let f = f.expect("scan");
        let s = &f.scan;
        let g = ScanGeometry::of(s);
        let pts = points::project(&s.ranges, &g, f.pose.as_ref());
        let segs = segment::segment(&pts, &SegmentOptions::default());
        let d = legs::detect(
            &pts,
            &segs,
            s.ranges.len(),
            f.pose.as_ref(),
            &LegParams::default(),
        );
        people_seen += d.people.len();
        let people: Vec<_> = d.people.iter().map(|p| p.fixed).collect();
        let single: Vec<_> = d.single_legs.iter().map(|&i| d.legs[i].fixed).collect();
        tracker.step(f.stamp.as_secs_f64(), &people, &single);
        for t in tracker.tracks() {
            assert!(t.filter.x.iter().all(|v| v.is_finite()), "{t:?}");
            if t.confirmed {
                ids.insert(t.id);
            }
        }
        n += 1;
    }
    println!(
        "{n} scans, fixed frame {:?}, {people_seen} people detections, {} confirmed tracks",
        frames.fixed_frame(),
        ids.len()
    );
    assert_eq!(n, 200);
    assert_eq!(frames.fixed_frame(), Some("odom"));
    assert!(!ids.is_empty());
}

fn motion() -> TrackerParams {
    TrackerParams {
        confirmation: Confirmation::Motion(MotionParams::default()),
        ..TrackerParams::default()
    }
}

fn at(x: f64, y: f64, occupancy: f64) -> Observation {
    Observation {
        position: Point2::new(x, y),
        confidence: 1.0,
        occupancy,
    }
}

/// A person standing still in free space, seen on every scan: M-of-N reports it from the
/// third scan, motion confirmation never (it has not moved).
#[test]
fn a_still_pair_is_confirmed_by_m_of_n_but_not_by_motion() {
    let mut mofn = PeopleTracker::new(TrackerParams::default());
    let mut mot = PeopleTracker::new(motion());
    for i in 0..30 {
        let time = f64::from(i) * 0.1;
        mofn.step_observed(time, &[at(2.0, 0.0, 0.0)], &[]);
        mot.step_observed(time, &[at(2.0, 0.0, 0.0)], &[]);
        assert_eq!(mofn.confirmed().count(), usize::from(i >= 2), "scan {i}");
        assert_eq!(mot.confirmed().count(), 0, "scan {i}");
    }
    assert_eq!(mot.tracks().len(), 1);
    assert_eq!(mot.tracks()[0].travelled_m, 0.0);
}

/// A person walking at 1 m/s through free space: the distance travelled is exactly the sum of
/// the filtered position's steps longer than 1 cm, and the track is reported on the first scan
/// where that sum reaches 0.5 m. The same walk through occupied space is never reported.
#[test]
fn motion_confirmation_counts_the_filtered_steps_through_free_space() {
    let mut t = PeopleTracker::new(motion());
    let mut occupied = PeopleTracker::new(motion());
    let (mut sum, mut prev) = (0.0, None::<Point2<f64>>);
    let mut first_confirmed = None;
    for i in 0..20 {
        let time = f64::from(i) * 0.1;
        let x = 1.0 + 0.1 * f64::from(i);
        t.step_observed(time, &[at(x, 0.0, 0.01)], &[]);
        occupied.step_observed(time, &[at(x, 0.0, 0.5)], &[]);
        assert_eq!(occupied.confirmed().count(), 0);
        let tr = &t.tracks()[0];
        if let Some(p) = prev {
            let step = (tr.position() - p).norm();
            if step > 0.01 {
                sum += step;
            }
        }
        prev = Some(tr.position());
        assert!((tr.travelled_m - sum).abs() < 1e-12, "scan {i}");
        assert_eq!(tr.confirmed, sum >= 0.5, "scan {i}: {sum}");
        if tr.confirmed && first_confirmed.is_none() {
            first_confirmed = Some(i);
        }
    }
    // the filter starts at rest and catches up: 0.5 m takes more than 5 scans, fewer than 10
    let k = first_confirmed.expect("confirmed");
    assert!((5..10).contains(&k), "{k}");
    assert_eq!(t.tracks().len(), 1);
}

/// A person whose legs pair on one scan in three: M-of-N (3 of 5, at most 2 early misses)
/// keeps deleting and restarting the track and never reports it; motion confirmation keeps one
/// track (deleted only after 10 scans without update) and reports it once it has walked 0.5 m.
#[test]
fn a_briefly_paired_walker_is_reported_by_motion_not_by_m_of_n() {
    let run = |params: TrackerParams| {
        let mut t = PeopleTracker::new(params);
        let mut reported = 0;
        for i in 0..40 {
            let time = f64::from(i) * 0.1;
            let x = 1.0 + 0.1 * f64::from(i);
            let seen = if i % 3 == 0 {
                vec![at(x, 0.0, 0.0)]
            } else {
                vec![]
            };
            t.step_observed(time, &seen, &[]);
            reported = reported.max(t.confirmed().count());
        }
        (reported, t.tracks().iter().map(|tr| tr.id).max())
    };
    let (mofn, _) = run(TrackerParams::default());
    assert_eq!(mofn, 0);
    let (mot, last_id) = run(motion());
    assert_eq!(mot, 1);
    assert_eq!(last_id, Some(1), "one track all along");
}

/// A confirmed track whose person vanishes next to a static leg-like object: under M-of-N the
/// track takes the object's observations and lives on; under motion confirmation the object
/// lies in occupied space, the track takes none of them (pairs or single legs) and is deleted
/// after 10 scans without update.
#[test]
fn confirmed_tracks_take_no_observation_outside_free_space() {
    let run = |params: TrackerParams| {
        let mut t = PeopleTracker::new(params);
        let mut alive = Vec::new();
        for i in 0..40 {
            let time = f64::from(i) * 0.1;
            let (people, legs) = if i < 15 {
                (vec![at(1.0 + 0.1 * f64::from(i), 0.0, 0.0)], vec![])
            } else {
                // a pole at the track's last position: a pair on odd scans, a leg on even ones
                let pole = at(2.45, 0.05, 0.8);
                if i % 2 == 1 {
                    (vec![pole], vec![])
                } else {
                    (vec![], vec![pole])
                }
            };
            t.step_observed(time, &people, &legs);
            alive.push(t.confirmed().any(|tr| tr.id == 1));
        }
        alive
    };
    let mofn = run(TrackerParams::default());
    assert!(mofn[2..].iter().all(|&a| a), "{mofn:?}");
    let mot = run(motion());
    assert!(mot[10..24].iter().all(|&a| a), "{mot:?}");
    assert!(mot[25..].iter().all(|&a| !a), "{mot:?}");
}

/// leg_tracker's features of four collinear points 0.1 m apart at x = 1, worked by hand from
/// its formulas (quirks included: `boundary_regularity` divides by `n`, so equal steps give
/// 0.05, not 0; `radius` is 0): the left neighbour (beam 9, 3 m) is farther (not occluded),
/// the right one (beam 14) has no return (occluded stays 1).
#[test]
fn leg_tracker_features_of_a_short_line_match_the_hand_computation() {
    let pts = scan_points(
        10,
        &[
            Point2::new(1.0, -0.15),
            Point2::new(1.0, -0.05),
            Point2::new(1.0, 0.05),
            Point2::new(1.0, 0.15),
        ],
    );
    let mut ranges = vec![f32::NAN; 20];
    ranges[9] = 3.0;
    for p in &pts {
        ranges[p.beam] = p.range as f32;
    }
    let g = ScanGeometry {
        angle_min: -0.5,
        angle_increment: 0.05,
        range_min: 0.05,
        range_max: 10.0,
    };
    let f = features::leg_tracker_features(&pts, &whole(&pts), &g, &ranges).expect("4 points");
    let pi = std::f64::consts::PI;
    let want = [
        4.0,
        (0.05f64 / 3.0).sqrt(),
        0.1,
        0.3,
        0.0,
        0.0,
        0.0,
        0.3,
        0.05,
        0.0,
        pi / 2.0,
        pi / 2.0,
        pi / 3f64.sqrt(),
        1.0,
        0.25,
        1.0,
        0.0,
    ];
    for (k, (a, b)) in f.iter().zip(want).enumerate() {
        assert!(
            (a - b).abs() < 1e-9,
            "{}: {a} vs {b}",
            features::LEG_TRACKER_FEATURE_NAMES[k]
        );
    }
    let two = &pts[..2];
    assert!(features::leg_tracker_features(two, &whole(two), &g, &ranges).is_none());
}

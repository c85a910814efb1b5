use nalgebra::Point2;

use super::*;
use crate::track::pdaf::ModelKind;

/// Beams over ±90° every 0.5° from the origin against circles `(x, y, r)`; no return → no point.
fn scan(circles: &[(f64, f64, f64)]) -> Vec<ScanPoint> {
    let mut out = Vec::new();
    for k in 0..361usize {
        let a = (-90.0 + 0.5 * k as f64).to_radians();
        let (dx, dy) = (a.cos(), a.sin());
        let mut best = f64::INFINITY;
        for &(cx, cy, r) in circles {
            let b = dx * cx + dy * cy;
            let disc = b * b - (cx * cx + cy * cy - r * r);
            if disc >= 0.0 {
                let t = b - disc.sqrt();
                if t > 0.0 {
                    best = best.min(t);
                }
            }
        }
        if best.is_finite() {
            let p = Point2::new(best * dx, best * dy);
            out.push(ScanPoint {
                beam: k,
                range: best,
                angle: a,
                sensor: p,
                fixed: p,
            });
        }
    }
    out
}

fn legs(x: f64, y: f64) -> [(f64, f64, f64); 2] {
    [(x, y - 0.13, 0.06), (x, y + 0.13, 0.06)]
}

fn params(model: ModelKind) -> FollowParams {
    let mut p = FollowParams {
        colour: false,
        ..FollowParams::default()
    };
    p.filter.model = model;
    p
}

#[test]
fn two_legs_are_one_blob_and_a_wall_is_none() {
    let mut world: Vec<(f64, f64, f64)> = legs(3.0, 0.5).to_vec();
    world.push((2.0, -6.0, 5.0)); // a big round object: a wide arc
    let pts = scan(&world);
    let bl = blobs(&pts, &params(ModelKind::Cv));
    assert_eq!(bl.len(), 1, "{bl:?}");
    let b = bl[0];
    assert!(
        (b.centre[1] - 0.5).abs() < 0.05 && (b.centre[0] - 2.95).abs() < 0.05,
        "{b:?}"
    );
    assert!(b.width > 0.2 && b.width < 0.4);
}

/// A person walking at 1.5 m/s across the scan, a still post beside the path: the follower
/// stays on the person (error under 0.15 m), never resets.
#[test]
fn follows_a_walker_past_a_post() {
    for model in [ModelKind::Cv, ModelKind::Ct, ModelKind::Imm] {
        let mut tr = FollowTracker::new(&params(model), [4.0, -2.0]);
        let mut worst: f64 = 0.0;
        for k in 0..40 {
            let t = 0.1 * f64::from(k);
            let y = -2.0 + 1.5 * t;
            let mut world = legs(4.0, y).to_vec();
            world.push((5.5, 0.5, 0.08));
            let pts = scan(&world);
            let out = tr
                .step(&ScanObs {
                    t,
                    points: &pts,
                    omni: None,
                })
                .expect("step");
            assert!(!out.reset, "{model:?} reset at {t}");
            let e = out.estimate.expect("tracked");
            if k > 5 {
                worst = worst.max((e.position[0] - 3.97).hypot(e.position[1] - y));
            }
        }
        assert!(worst < 0.15, "{model:?}: {worst}");
    }
}

/// The person vanishes (no blob): the covariance grows until `rst` fires and the estimate is
/// dropped; when they reappear near the last estimate the track restarts there.
#[test]
fn reset_then_reinitialise_on_the_nearest_blob() {
    let mut tr = FollowTracker::new(&params(ModelKind::Cv), [3.0, 0.0]);
    let mut reset_at = None;
    let mut restarted = false;
    for k in 0..120 {
        let t = 0.1 * f64::from(k);
        let world = if !(10..60).contains(&k) {
            legs(3.0, 0.0).to_vec()
        } else {
            Vec::new()
        };
        let pts = scan(&world);
        let out = tr
            .step(&ScanObs {
                t,
                points: &pts,
                omni: None,
            })
            .expect("step");
        if out.reset && reset_at.is_none() {
            reset_at = Some(k);
            assert!(out.estimate.is_none());
        }
        if k >= 60 && out.initialised {
            restarted = true;
            let e = out.estimate.expect("restarted");
            assert!((e.position[0] - 2.97).abs() < 0.05 && e.position[1].abs() < 0.05);
        }
    }
    let r = reset_at.expect("rst fired while the person was gone");
    assert!((10..60).contains(&r), "rst at {r}");
    assert!(restarted);
}

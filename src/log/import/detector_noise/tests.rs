use nalgebra::{Point2, Point3};

use super::*;
use crate::geometry::camera::{CameraModel, Pinhole};
use crate::geometry::look_at;

/// A 1920×1080 camera (60° field of view) 3 m up at the origin, looking horizontally along +y.
fn level_camera() -> CalibratedView {
    CalibratedView::new(
        CameraModel::Pinhole(Pinhole::from_fov(1920, 1080, 60.0)),
        look_at(Point3::new(0.0, 0.0, 3.0), Point3::new(0.0, 10.0, 3.0)),
    )
}

/// The same kind of camera 6 m up, looking down at the middle of a 10 × 10 m room.
fn room_camera() -> CalibratedView {
    CalibratedView::new(
        CameraModel::Pinhole(Pinhole::from_fov(1920, 1080, 70.0)),
        look_at(Point3::new(5.0, -6.0, 6.0), Point3::new(5.0, 5.0, 0.0)),
    )
}

const ROOM: [f64; 4] = [0.0, 0.0, 10.0, 10.0];

fn frame(view: &CalibratedView, stamp_ns: u64) -> CameraFrame<'_> {
    CameraFrame {
        view,
        camera: 3,
        stamp_ns,
        room_m: ROOM,
    }
}

/// 200 boxes 300 px high in the middle of the image.
fn boxes() -> Vec<[f64; 4]> {
    (0..200)
        .map(|k| {
            let x = 400.0 + 5.0 * f64::from(k);
            [x, 300.0, x + 100.0, 600.0]
        })
        .collect()
}

#[test]
fn levels_parse_validate_and_label() {
    let n = DetectorNoise::parse("drop=0.2, jitter=0.04,false=1").expect("parses");
    assert_eq!(
        n,
        DetectorNoise {
            drop: 0.2,
            jitter: 0.04,
            false_per_frame: 1.0
        }
    );
    assert_eq!(n.label(), "drop 0.2, jitter 0.04, false 1");
    assert_eq!(DetectorNoise::parse("").expect("empty").label(), "none");
    assert_eq!(
        DetectorNoise::parse("jitter=0.02").expect("one").label(),
        "jitter 0.02"
    );
    for bad in [
        "drop=1",
        "drop=-0.1",
        "jitter=x",
        "false=-1",
        "fp=1",
        "drop",
    ] {
        assert!(DetectorNoise::parse(bad).is_err(), "{bad}");
    }
}

#[test]
fn no_noise_passes_the_boxes_unchanged() {
    let v = room_camera();
    let b = boxes();
    assert_eq!(apply(&DetectorNoise::default(), 7, &frame(&v, 1), &b), b);
}

#[test]
fn the_cylinder_box_of_a_level_camera_is_its_closed_form() {
    // a cylinder of radius r, height h (below the camera) at distance d straight ahead: the
    // nearest point of its base (depth d − r) and the farthest of its top (depth d + r) bound
    // it vertically, its side points (depth d, x = ±r) horizontally
    let v = level_camera();
    // 12 m ahead: feet and head inside the 60° image (at 8 m the feet fall below it)
    let (d, r, h) = (12.0, 0.25, 1.8);
    let b = person_box(&v, 0.0, d, h, r).expect("in front");
    let (f, c) = v.focal_and_principal();
    let want = [
        c.x - f * r / d,
        c.y + f * (3.0 - h) / (d + r),
        c.x + f * r / d,
        c.y + f * 3.0 / (d - r),
    ];
    for k in 0..4 {
        assert!((b[k] - want[k]).abs() < 1e-9, "{b:?} {want:?}");
    }
    assert!(whole_in_image(&v, &b));
    // behind the camera: no box
    assert_eq!(person_box(&v, 0.0, -5.0, h, r), None);
}

#[test]
fn poisson_quantiles_are_the_inverse_cdf() {
    // Poisson(1): P(0) = 0.3679, P(≤1) = 0.7358, P(≤2) = 0.9197
    assert_eq!(poisson_quantile(1.0, 0.30), 0);
    assert_eq!(poisson_quantile(1.0, 0.50), 1);
    assert_eq!(poisson_quantile(1.0, 0.90), 2);
    assert_eq!(poisson_quantile(1.0, 0.95), 3);
    assert_eq!(poisson_quantile(0.0, 0.99), 0);
    // a larger mean never gives fewer
    for u in [0.1, 0.4, 0.7, 0.99] {
        assert!(poisson_quantile(2.0, u) >= poisson_quantile(1.0, u));
    }
}

#[test]
fn drops_are_nested_across_levels_and_near_their_rate() {
    let v = room_camera();
    let b = boxes();
    let (mut kept10, mut kept20) = (0, 0);
    for stamp in 0..50 {
        let f = frame(&v, stamp);
        let a = apply(
            &DetectorNoise {
                drop: 0.1,
                ..Default::default()
            },
            1,
            &f,
            &b,
        );
        let c = apply(
            &DetectorNoise {
                drop: 0.2,
                ..Default::default()
            },
            1,
            &f,
            &b,
        );
        // every box kept at 20 % is kept at 10 %
        assert!(c.iter().all(|x| a.contains(x)));
        kept10 += a.len();
        kept20 += c.len();
    }
    // 10,000 boxes: binomial standard deviations 30 and 40
    let n = 50.0 * 200.0;
    assert!((kept10 as f64 - 0.9 * n).abs() < 4.0 * 30.0, "{kept10}");
    assert!((kept20 as f64 - 0.8 * n).abs() < 4.0 * 40.0, "{kept20}");
}

#[test]
fn jitter_moves_each_edge_by_its_fraction_of_the_height() {
    let v = room_camera();
    let b = boxes();
    let noise = DetectorNoise {
        jitter: 0.04,
        ..Default::default()
    };
    let mut dev = [Vec::new(), Vec::new(), Vec::new(), Vec::new()];
    for stamp in 0..25 {
        let out = apply(&noise, 9, &frame(&v, stamp), &b);
        assert_eq!(out.len(), b.len());
        for (o, i) in out.iter().zip(&b) {
            for k in 0..4 {
                dev[k].push(o[k] - i[k]);
            }
        }
    }
    // σ = 0.04 · 300 px = 12 px per edge; 5,000 draws: the sample σ within 5 %
    for d in &dev {
        let n = d.len() as f64;
        let mean = d.iter().sum::<f64>() / n;
        let sd = (d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n).sqrt();
        assert!(mean.abs() < 0.6 && (sd - 12.0).abs() < 0.6, "{mean} {sd}");
    }
    // and twice the level is twice the same deviates
    let twice = DetectorNoise {
        jitter: 0.08,
        ..Default::default()
    };
    let (a, c) = (
        apply(&noise, 9, &frame(&v, 3), &b),
        apply(&twice, 9, &frame(&v, 3), &b),
    );
    for ((x, y), i) in a.iter().zip(&c).zip(&b) {
        assert!((2.0 * (x[0] - i[0]) - (y[0] - i[0])).abs() < 1e-9);
    }
}

#[test]
fn a_jittered_box_is_clipped_to_the_image() {
    let v = room_camera();
    let edge = [[-30.0, 900.0, 40.0, 1079.0]];
    let noise = DetectorNoise {
        jitter: 0.3,
        ..Default::default()
    };
    for stamp in 0..20 {
        for b in apply(&noise, 2, &frame(&v, stamp), &edge) {
            assert!(
                b[0] >= 0.0 && b[2] <= 1920.0 && b[1] >= 0.0 && b[3] <= 1080.0,
                "{b:?}"
            );
            assert!(b[2] - b[0] >= MIN_BOX_PX && b[3] - b[1] >= MIN_BOX_PX);
        }
    }
}

#[test]
fn false_boxes_are_standing_people_in_the_room_at_their_mean_rate() {
    let v = room_camera();
    let noise = DetectorNoise {
        false_per_frame: 1.0,
        ..Default::default()
    };
    let more = DetectorNoise {
        false_per_frame: 2.0,
        ..Default::default()
    };
    let mut count = 0;
    for stamp in 0..400 {
        let f = frame(&v, stamp);
        let one = apply(&noise, 5, &f, &[]);
        let two = apply(&more, 5, &f, &[]);
        // the boxes at mean 1 are the first ones at mean 2
        assert!(two.len() >= one.len() && two[..one.len()] == one[..]);
        count += one.len();
        for b in &one {
            assert!(whole_in_image(&v, b), "{b:?}");
            // the bottom centre is the foot of a cylinder standing in the room: its ground
            // point lies in the room, at most a radius from where the box's own ray meets it
            let (o, d) = v
                .ray_in_world(&Point2::new(0.5 * (b[0] + b[2]), b[3]))
                .expect("ray");
            let g = o + d * (-o.z / d.z);
            assert!(
                g.x > ROOM[0] - 0.5
                    && g.x < ROOM[2] + 0.5
                    && g.y > ROOM[1] - 0.5
                    && g.y < ROOM[3] + 0.5,
                "{g:?}"
            );
        }
    }
    // Poisson(1) over 400 frames: 400 ± 20
    assert!((count as f64 - 400.0).abs() < 4.0 * 20.0, "{count}");
}

#[test]
fn the_same_seed_and_stamp_give_the_same_boxes_and_others_do_not() {
    let v = room_camera();
    let b = boxes();
    let noise = DetectorNoise {
        drop: 0.2,
        jitter: 0.04,
        false_per_frame: 1.0,
    };
    let a = apply(&noise, 11, &frame(&v, 5), &b);
    assert_eq!(a, apply(&noise, 11, &frame(&v, 5), &b));
    assert_ne!(a, apply(&noise, 12, &frame(&v, 5), &b));
    assert_ne!(a, apply(&noise, 11, &frame(&v, 6), &b));
}

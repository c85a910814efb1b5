use nalgebra::Point3;

use super::super::tests::{cylinder_box, objects_for, office_views};
use super::super::{Association, CylinderParams, CylinderTracker, Object2d};
use crate::geometry::camera::{CameraModel, Pinhole};
use crate::geometry::look_at;
use crate::geometry::triangulate::CalibratedView;

/// Seven 1920×1080 cameras (70° field of view) 6 m up on a circle of radius 14 m around a
/// 12 × 12 m square, all looking at its centre.
fn crowd_views() -> Vec<CalibratedView> {
    (0..7)
        .map(|k| {
            let a = std::f64::consts::TAU * f64::from(k) / 7.0;
            let c = Point3::new(6.0 + 14.0 * a.cos(), 6.0 + 14.0 * a.sin(), 6.0);
            CalibratedView::new(
                CameraModel::Pinhole(Pinhole::from_fov(1920, 1080, 70.0)),
                look_at(c, Point3::new(6.0, 6.0, 0.8)),
            )
        })
        .collect()
}

fn crowd_params() -> CylinderParams {
    CylinderParams {
        association: Association::Scalable,
        n_app: 1,
        room_m: [0.0, 0.0, 12.0, 12.0],
        ..Default::default()
    }
}

/// People on a 1.5 m grid (jittered deterministically), heights 1.55–1.95 m.
fn crowd(n: usize) -> Vec<(u32, f64, f64, f64, f64)> {
    (0..n)
        .map(|i| {
            let (gx, gy) = ((i % 7) as f64, (i / 7) as f64);
            let j = (i * 37 % 11) as f64 / 11.0;
            (
                i as u32 + 1,
                1.0 + 1.5 * gx + 0.3 * j,
                1.0 + 1.5 * gy + 0.2 * (1.0 - j),
                1.55 + 0.4 * j,
                0.2,
            )
        })
        .collect()
}

/// Noise-free heads and boxes of every person in every camera whose image holds them; ids
/// `1000·camera + person`.
fn crowd_objects(views: &[CalibratedView], people: &[(u32, f64, f64, f64, f64)]) -> Vec<Object2d> {
    let mut out = Vec::new();
    for (c, v) in views.iter().enumerate() {
        for &(id, x, y, h, r) in people {
            let (Some(head), Some(b)) = (
                v.project(&Point3::new(x, y, h)),
                cylinder_box(v, x, y, h, r),
            ) else {
                continue;
            };
            if !(v.model.in_image(&head) && b[0] >= 0.0 && b[2] < 1920.0 && b[3] < 1080.0) {
                continue;
            }
            out.push(Object2d {
                camera: c,
                id: 1000 * c as u32 + id,
                head_px: [head.x, head.y],
                width_px: b[2] - b[0],
                foot_px: Some([(b[0] + b[2]) / 2.0, b[3]]),
            });
        }
    }
    out
}

#[test]
fn n_people_in_seven_noise_free_cameras_are_recovered_exactly_up_to_40() {
    let views = crowd_views();
    for n in [1, 5, 10, 20, 30, 40] {
        let people = crowd(n);
        let objs = crowd_objects(&views, &people);
        let mut t = CylinderTracker::new(views.clone(), crowd_params()).expect("tracker");
        let (cyl, stats) = t.step(&objs);
        assert_eq!(cyl.len(), n, "n = {n}: {} found", cyl.len());
        assert!(!stats.pruned);
        for &(id, x, y, h, _) in &people {
            let mut want: Vec<(usize, u32)> = objs
                .iter()
                .filter(|o| o.id % 1000 == id)
                .map(|o| (o.camera, o.id))
                .collect();
            want.sort_unstable();
            assert!(
                want.len() >= 3,
                "person {id} is seen by {} cameras",
                want.len()
            );
            let c = cyl
                .iter()
                .find(|c| c.support == want)
                .unwrap_or_else(|| panic!("n = {n}: no object supported by person {id}'s views"));
            let m = c.measured.as_ref().expect("measured");
            assert!(
                (m.head_m.x - x).abs() < 1e-6 && (m.head_m.y - y).abs() < 1e-6,
                "{m:?}"
            );
            assert!((m.head_m.z - h).abs() < 1e-6, "{m:?}");
        }
    }
}

#[test]
fn a_person_seen_by_one_camera_is_placed_by_the_ground_point() {
    let views = office_views(true);
    let (x, y, h) = (2.5, 5.5, 1.7);
    let v = &views[2];
    let head = v.project(&Point3::new(x, y, h)).expect("head");
    let foot = v.project(&Point3::new(x, y, 0.0)).expect("foot");
    let objs = [Object2d {
        camera: 2,
        id: 9,
        head_px: [head.x, head.y],
        width_px: 30.0,
        foot_px: Some([foot.x, foot.y]),
    }];
    let params = CylinderParams {
        association: Association::Scalable,
        n_app: 1,
        ..Default::default()
    };
    let mut t = CylinderTracker::new(views.clone(), params).expect("tracker");
    let (cyl, _) = t.step(&objs);
    assert_eq!(cyl.len(), 1, "{cyl:?}");
    let c = &cyl[0];
    assert_eq!(c.support, vec![(2, 9)]);
    assert!(
        (c.x_m - x).abs() < 1e-6 && (c.y_m - y).abs() < 1e-6,
        "{c:?}"
    );
    assert!((c.height_m - h).abs() < 1e-6, "{c:?}");
    // the next frame keeps it on the same single view
    let (cyl, _) = t.step(&objs);
    assert_eq!(cyl.iter().map(|c| c.id).collect::<Vec<_>>(), vec![1]);
    assert!(cyl[0].measured.is_some());
    // the paper's search needs two cameras: nobody
    let paper = CylinderParams {
        association: Association::Paper,
        ..params
    };
    let mut t = CylinderTracker::new(views, paper).expect("tracker");
    assert!(t.step(&objs).0.is_empty());
}

#[test]
fn a_single_view_of_a_person_already_found_is_not_a_second_person() {
    // person 1 in all four cameras, plus a stray second box of them in camera 0 (a
    // duplicate detection): its ground point lies within ground_separation_m of person 1
    let views = office_views(false);
    let mut objs = objects_for(&views, &[(1, 4.0, 4.0, 1.8, 0.2)]);
    let mut dup = objs[0];
    dup.id = 99;
    dup.head_px[0] += 3.0;
    objs.push(dup);
    let params = CylinderParams {
        association: Association::Scalable,
        n_app: 1,
        ..Default::default()
    };
    let mut t = CylinderTracker::new(views, params).expect("tracker");
    let (cyl, _) = t.step(&objs);
    assert_eq!(cyl.len(), 1, "{cyl:?}");
    assert_eq!(cyl[0].support.len(), 4);
}

#[test]
fn on_the_office_rig_both_associations_agree_frame_by_frame() {
    // four people walking past each other in the paper's four corner cameras, lens
    // distortion on: the same objects, supports and positions every frame
    let views = office_views(true);
    let mut out = Vec::new();
    for association in [Association::Paper, Association::Scalable] {
        let params = CylinderParams {
            association,
            ..Default::default()
        };
        let mut t = CylinderTracker::new(views.clone(), params).expect("tracker");
        let mut frames = Vec::new();
        for k in 0..20 {
            let s = 0.05 * f64::from(k);
            let people = [
                (1, 2.0 + s, 2.0, 1.8, 0.2),
                (2, 6.0 - s, 2.2, 1.7, 0.22),
                (3, 3.0, 6.5 - s, 1.65, 0.2),
                (4, 5.5, 5.0 + 0.5 * s, 1.9, 0.25),
            ];
            frames.push(t.step(&objects_for(&views, &people)).0);
        }
        out.push(frames);
    }
    assert!(
        out[0].iter().any(|f| f.len() == 4),
        "the paper variant finds them"
    );
    assert_eq!(out[0], out[1]);
}

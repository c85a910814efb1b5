use nalgebra::Point3;

use super::super::tests::office_views;
use super::super::{Association, CylinderParams, CylinderTracker, Object2d};
use crate::geometry::camera::{CameraModel, Pinhole};
use crate::geometry::look_at;
use crate::geometry::triangulate::CalibratedView;

/// Seven 1920×1080 cameras (70° field of view) 6 m up on a circle of radius 14 m around a
/// 12 × 12 m square, all looking at its centre.
pub(in crate::track::cylinders) fn crowd_views() -> Vec<CalibratedView> {
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

fn params() -> CylinderParams {
    CylinderParams {
        association: Association::Ground,
        n_app: 1,
        n_dis: 1,
        room_m: [0.0, 0.0, 12.0, 12.0],
        ..Default::default()
    }
}

/// People 0.8 m apart and more (a dense crowd: 40 in 7 × 6 cells of 1.5 m, jittered
/// deterministically), heights 1.55–1.95 m.
pub(in crate::track::cylinders) fn crowd(n: usize) -> Vec<(u32, f64, f64, f64)> {
    (0..n)
        .map(|i| {
            let (gx, gy) = ((i % 7) as f64, (i / 7) as f64);
            let j = (i * 37 % 11) as f64 / 11.0;
            (
                i as u32 + 1,
                1.0 + 1.5 * gx + 0.7 * j,
                1.0 + 1.5 * gy + 0.5 * (1.0 - j),
                1.55 + 0.4 * j,
            )
        })
        .collect()
}

/// Noise-free feet and heads of every person in every camera whose image holds both; ids
/// `1000·camera + person`.
pub(in crate::track::cylinders) fn objects(
    views: &[CalibratedView],
    people: &[(u32, f64, f64, f64)],
) -> Vec<Object2d> {
    let mut out = Vec::new();
    for (c, v) in views.iter().enumerate() {
        for &(id, x, y, h) in people {
            let (Some(head), Some(foot)) = (
                v.project(&Point3::new(x, y, h)),
                v.project(&Point3::new(x, y, 0.0)),
            ) else {
                continue;
            };
            if !(v.model.in_image(&head) && v.model.in_image(&foot)) {
                continue;
            }
            out.push(Object2d {
                camera: c,
                id: 1000 * c as u32 + id,
                head_px: [head.x, head.y],
                width_px: 40.0,
                foot_px: Some([foot.x, foot.y]),
            });
        }
    }
    out
}

#[test]
fn n_people_in_seven_noise_free_cameras_are_recovered_exactly_up_to_40() {
    let views = crowd_views();
    for n in 1..=40 {
        let people = crowd(n);
        let objs = objects(&views, &people);
        let mut t = CylinderTracker::new(views.clone(), params()).expect("tracker");
        let (cyl, _) = t.step(&objs);
        assert_eq!(cyl.len(), n, "n = {n}: {} found", cyl.len());
        for &(id, x, y, h) in &people {
            let mut want: Vec<(usize, u32)> = objs
                .iter()
                .filter(|o| o.id % 1000 == id)
                .map(|o| (o.camera, o.id))
                .collect();
            want.sort_unstable();
            assert!(want.len() >= 3, "person {id}: {} cameras", want.len());
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
            assert!(m.e_m_px < 1e-4, "{m:?}");
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
    let p = CylinderParams {
        association: Association::Ground,
        n_app: 1,
        ..Default::default()
    };
    let mut t = CylinderTracker::new(views, p).expect("tracker");
    let (cyl, _) = t.step(&objs);
    assert_eq!(cyl.len(), 1, "{cyl:?}");
    let c = &cyl[0];
    assert_eq!(c.support, vec![(2, 9)]);
    assert!(
        (c.x_m - x).abs() < 1e-6 && (c.y_m - y).abs() < 1e-6,
        "{c:?}"
    );
    assert!((c.height_m - h).abs() < 1e-6, "{c:?}");
    // without its box bottom there is no ground point: nobody
    let mut t = CylinderTracker::new(office_views(true), p).expect("tracker");
    let no_foot = [Object2d {
        foot_px: None,
        ..objs[0]
    }];
    assert!(t.step(&no_foot).0.is_empty());
}

#[test]
fn a_second_box_of_a_person_already_found_is_not_a_second_person() {
    let views = crowd_views();
    let mut objs = objects(&views, &[(1, 6.0, 6.0, 1.8)]);
    let mut dup = objs[0];
    dup.id = 99;
    dup.head_px[0] += 3.0;
    dup.foot_px = dup.foot_px.map(|f| [f[0] + 3.0, f[1]]);
    objs.push(dup);
    let mut t = CylinderTracker::new(views, params()).expect("tracker");
    let (cyl, _) = t.step(&objs);
    assert_eq!(cyl.len(), 1, "{cyl:?}");
    assert_eq!(cyl[0].support.len(), 7);
}

#[test]
fn people_walking_at_two_frames_per_second_keep_their_ids_with_fresh_2d_ids_every_frame() {
    // 30 people walking 1.4 m/s in alternating directions, 0.5 s apart: the 2-D ids change
    // every frame (no 2-D tracks at all), the 3-D ids do not
    let views = crowd_views();
    let p = CylinderParams {
        dt_s: 0.5,
        n_app: 2,
        n_dis: 2,
        ..params()
    };
    let mut t = CylinderTracker::new(views.clone(), p).expect("tracker");
    let base = crowd(30);
    let mut ids_at = Vec::new();
    for k in 0..8 {
        let s = 1.4 * 0.5 * f64::from(k) - 2.0;
        let people: Vec<(u32, f64, f64, f64)> = base
            .iter()
            .map(|&(id, x, y, h)| {
                let dir = if id % 2 == 0 { 1.0 } else { -1.0 };
                (id, x + 0.2 * dir * s, y, h)
            })
            .collect();
        let mut objs = objects(&views, &people);
        for o in objs.iter_mut() {
            o.id += 100_000 * k;
        }
        let (cyl, _) = t.step(&objs);
        if k == 0 {
            assert!(cyl.is_empty(), "N_app = 2: nobody after one frame");
            continue;
        }
        assert_eq!(cyl.len(), 30, "frame {k}");
        // each object's id, by the person whose views support it
        let mut by_person: Vec<(u32, u32)> =
            cyl.iter().map(|c| (c.support[0].1 % 1000, c.id)).collect();
        by_person.sort_unstable();
        ids_at.push(by_person);
    }
    assert!(ids_at.windows(2).all(|w| w[0] == w[1]), "{ids_at:?}");
}

#[test]
fn an_object_missed_for_n_dis_frames_is_discarded() {
    let views = crowd_views();
    let p = CylinderParams {
        n_dis: 2,
        ..params()
    };
    let mut t = CylinderTracker::new(views.clone(), p).expect("tracker");
    let objs = objects(&views, &[(1, 6.0, 6.0, 1.8)]);
    assert_eq!(t.step(&objs).0.len(), 1);
    let (cyl, _) = t.step(&[]);
    assert_eq!(cyl.len(), 1, "coasting one frame");
    assert!(cyl[0].measured.is_none());
    assert!(t.step(&[]).0.is_empty(), "gone after N_dis = 2");
}

#[test]
fn on_the_office_rig_the_ground_association_finds_the_paper_s_people() {
    // the scalable test's scene (four people walking past each other in the paper's four
    // corner cameras, lens distortion on, boxes of 0.2 m cylinders): from the frame N_app
    // promotes them on, both report the same people on the same views every frame; the
    // ground positions differ by the box bottom lying on the near rim of the base, not the
    // axis (within the 0.25 m radius)
    use super::super::tests::objects_for;
    let views = office_views(true);
    let mut runs = Vec::new();
    for association in [Association::Paper, Association::Ground] {
        let p = CylinderParams {
            association,
            ..Default::default()
        };
        let mut t = CylinderTracker::new(views.clone(), p).expect("tracker");
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
        runs.push(frames);
    }
    for (k, (paper, ground)) in runs[0].iter().zip(&runs[1]).enumerate().skip(4) {
        assert_eq!(paper.len(), 4, "frame {k}: paper {paper:?}");
        assert_eq!(ground.len(), 4, "frame {k}: ground {ground:?}");
        for g in ground {
            let p = paper
                .iter()
                .find(|p| p.support == g.support)
                .unwrap_or_else(|| panic!("frame {k}: {:?} not in the paper's", g.support));
            assert!((p.x_m - g.x_m).hypot(p.y_m - g.y_m) < 0.25, "{p:?} {g:?}");
        }
    }
}

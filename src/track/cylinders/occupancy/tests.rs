use nalgebra::Point3;

use super::super::ground::tests::{crowd, crowd_views, objects};
use super::*;
use crate::geometry::camera::{CameraModel, Pinhole};
use crate::geometry::look_at;

fn occupancy() -> OccupancyParams {
    OccupancyParams {
        p_detect: 0.8,
        false_per_frame: 1.0,
        people_per_m2: 0.1,
        confirm_llr: 5.0,
        max_llr: 20.0,
        max_coast_frames: 3,
        ..OccupancyParams::default()
    }
}

fn params() -> CylinderParams {
    CylinderParams {
        association: Association::Occupancy,
        n_app: 1,
        n_dis: 1,
        room_m: [0.0, 0.0, 12.0, 12.0],
        occupancy: occupancy(),
        ..Default::default()
    }
}

/// A 1000×800 camera (60° across) `height` m above `(x, y)`, looking straight down.
fn nadir(x: f64, y: f64, height: f64) -> CalibratedView {
    CalibratedView::new(
        CameraModel::Pinhole(Pinhole::from_fov(1000, 800, 60.0)),
        look_at(Point3::new(x, y, height), Point3::new(x, y, 0.0)),
    )
}

/// This frame's people and their log-odds, as `step_occupancy` computes them.
fn people_and_odds(t: &CylinderTracker, objs: &[Object2d]) -> Vec<(Hypothesis, f64)> {
    let prepared = t.prepare(objs);
    let people = t.detect_ground(&prepared, &mut StepStats::default());
    let boxes: BTreeMap<(usize, u32), &Prepared> =
        prepared.iter().map(|o| ((o.camera, o.id), o)).collect();
    people
        .into_iter()
        .map(|h| {
            let l = t.log_odds(&h, &boxes);
            (h, l)
        })
        .collect()
}

#[test]
fn a_nadir_camera_sees_the_rectangle_its_field_of_view_gives_at_head_height() {
    // whole = feet and head in the image; looking down, the head (closer) is the tighter:
    // half-widths (H − z) tan(θ) with tan θ_x = 500 / f, tan θ_y = 400 / f, z = 1.65 m
    // (the middle of the head heights)
    let views = vec![nadir(50.0, 50.0, 10.0), nadir(20.0, 20.0, 10.0)];
    let p = CylinderParams {
        room_m: [0.0, 0.0, 100.0, 100.0],
        ..params()
    };
    let t = CylinderTracker::new(views.clone(), p).expect("tracker");
    let (f, _) = views[0].focal_and_principal();
    let z = 0.5 * (p.head_height_m.0 + p.head_height_m.1);
    let want = 4.0 * (10.0 - z) * 500.0 / f * (10.0 - z) * 400.0 / f;
    let got = t.seen_area_m2()[0];
    assert!((got - want).abs() < 0.01 * want, "{got} vs {want}");
    // and nothing of it when the room is elsewhere
    let far = CylinderParams {
        room_m: [80.0, 80.0, 90.0, 90.0],
        ..params()
    };
    let t = CylinderTracker::new(views, far).expect("tracker");
    assert_eq!(t.seen_area_m2()[0], 0.0);
}

#[test]
fn a_one_camera_person_s_log_odds_is_its_closed_form() {
    // ℓ = ln(ρ P_D A_c / λ) + (cameras seeing it whole without a box) · ln(1 − P_D): the
    // localisation cell cancels
    let views = crowd_views();
    let t = CylinderTracker::new(views.clone(), params()).expect("tracker");
    let (x, y, h) = (6.0, 6.0, 1.8);
    let objs: Vec<Object2d> = objects(&views, &[(1, x, y, h)])
        .into_iter()
        .filter(|o| o.camera == 0)
        .collect();
    let got = people_and_odds(&t, &objs);
    assert_eq!(got.len(), 1);
    let q = occupancy();
    let seeing = views
        .iter()
        .skip(1)
        .filter(|v| sees_whole(v, x, y, h))
        .count();
    assert_eq!(seeing, 6, "the crowd rig sees its centre from every camera");
    let want = (q.people_per_m2 * q.p_detect * t.seen_area_m2()[0] / q.false_per_frame).ln()
        + seeing as f64 * (1.0 - q.p_detect).ln();
    assert!((got[0].1 - want).abs() < 1e-9, "{} vs {want}", got[0].1);
    assert!(want < 0.0, "one box of seven: doubtful");
}

/// ℓ of a person seen by two cameras of the crowd rig, by hand: `ln(ρ a₀)` with `a₀` the
/// smaller gate disc, each box `ln(P_D / (μ_c a_c))` with `a_c` its disc stretched by `d_c / z_c`
/// under `ray_gate` (the disc alone without), and the five silent cameras' misses.
#[test]
fn a_two_camera_person_s_log_odds_is_its_closed_form_with_and_without_the_ray_gate() {
    let views = crowd_views();
    let (x, y, h) = (6.0, 6.0, 1.8);
    for ray_gate in [true, false] {
        let p = CylinderParams {
            occupancy: OccupancyParams {
                ray_gate,
                ..occupancy()
            },
            ..params()
        };
        let t = CylinderTracker::new(views.clone(), p).expect("tracker");
        let objs: Vec<Object2d> = objects(&views, &[(1, x, y, h)])
            .into_iter()
            .filter(|o| o.camera < 2)
            .collect();
        let got = people_and_odds(&t, &objs);
        assert_eq!(got.len(), 1, "one person of two boxes");
        let q = p.occupancy;
        let foot = Point3::new(x, y, 0.0);
        let (mut l, mut cell) = (0.0, f64::INFINITY);
        for (c, v) in views.iter().enumerate().take(2) {
            let (f, _) = v.focal_and_principal();
            let d = (v.center() - foot).norm();
            let r = p.p_th_px * d / f;
            let disc = std::f64::consts::PI * r * r;
            let stretch = if ray_gate {
                (d / v.center().z).max(1.0)
            } else {
                1.0
            };
            assert!(
                stretch > 1.5 || !ray_gate,
                "the rig's cameras look at a slant"
            );
            let mu = q.false_per_frame / t.seen_area_m2()[c];
            l += (q.p_detect / (mu * disc * stretch)).ln();
            cell = cell.min(disc);
        }
        let want = (q.people_per_m2 * cell).ln() + l + 5.0 * (1.0 - q.p_detect).ln();
        assert!(
            (got[0].1 - want).abs() < 1e-6,
            "ray_gate {ray_gate}: {} vs {want}",
            got[0].1
        );
    }
}

#[test]
fn with_exact_boxes_everyone_is_found_and_confirmed_in_the_first_frame() {
    let views = crowd_views();
    for n in [1, 10, 25] {
        let people = crowd(n);
        let objs = objects(&views, &people);
        let mut t = CylinderTracker::new(views.clone(), params()).expect("tracker");
        let (cyl, stats) = t.step(&objs);
        assert_eq!((cyl.len(), stats.promoted), (n, n), "n = {n}");
        for &(_, x, y, h) in &people {
            let c = cyl
                .iter()
                .find(|c| (c.x_m - x).hypot(c.y_m - y) < 1e-6)
                .unwrap_or_else(|| panic!("n = {n}: nobody at ({x}, {y})"));
            assert!((c.height_m - h).abs() < 1e-6);
            assert!(c.support.len() >= 3);
        }
    }
}

#[test]
fn a_box_that_one_camera_of_seven_has_is_no_person_but_the_ground_association_reports_it() {
    let views = crowd_views();
    // a false box in camera 3 every frame, somewhere else each time, among two real people
    let real = [(1, 3.0, 4.0, 1.7), (2, 8.0, 7.0, 1.8)];
    let mut reported = [0usize; 2];
    for (k, association) in [Association::Occupancy, Association::Ground]
        .into_iter()
        .enumerate()
    {
        let p = CylinderParams {
            association,
            n_dis: 1,
            ..params()
        };
        let mut t = CylinderTracker::new(views.clone(), p).expect("tracker");
        for f in 0..6 {
            let ghost = (99, 4.0 + 0.7 * f64::from(f), 9.0, 1.75);
            let mut objs = objects(&views, &real);
            objs.extend(
                objects(&views, &[ghost])
                    .into_iter()
                    .filter(|o| o.camera == 3),
            );
            reported[k] = reported[k].max(t.step(&objs).0.len());
        }
    }
    assert_eq!(reported, [2, 3]);
}

#[test]
fn a_person_only_one_camera_can_see_is_confirmed_as_the_scores_add_up() {
    // two cameras looking at disjoint floors: nobody else can see the person, so each frame's
    // ℓ = ln(ρ P_D A_c / λ) > 0 adds up to confirm_llr. The person walks off the camera's
    // nadir, where feet and head would fall on one pixel and no box places anyone.
    let views = vec![nadir(3.0, 6.0, 8.0), nadir(9.0, 6.0, 8.0)];
    let t0 = CylinderTracker::new(views.clone(), params()).expect("tracker");
    let q = occupancy();
    let l1 = (q.people_per_m2 * q.p_detect * t0.seen_area_m2()[0] / q.false_per_frame).ln();
    assert!(l1 > 0.0 && l1 < q.confirm_llr, "{l1}");
    let frames_needed = (q.confirm_llr / l1).ceil() as usize;
    let mut t = t0;
    for k in 0..frames_needed + 2 {
        let objs: Vec<Object2d> = objects(&views, &[(1, 1.5 + 0.1 * k as f64, 6.0, 1.7)])
            .into_iter()
            .filter(|o| o.camera == 0)
            .collect();
        assert_eq!(objs.len(), 1);
        let (cyl, _) = t.step(&objs);
        let tracks: Vec<_> = t
            .occupancy
            .tracks
            .iter()
            .map(|t| (t.id, t.score, t.hits, t.misses, t.kf.x[0]))
            .collect();
        assert_eq!(
            cyl.len(),
            usize::from(k + 1 >= frames_needed),
            "frame {k}: l1 {l1}, tracks {tracks:?}"
        );
    }
}

#[test]
fn a_confirmed_person_keeps_its_id_through_a_missed_frame_and_loses_it_when_the_misses_outweigh_it()
{
    // score capped at 20; a frame without boxes costs 7 ln(1 − 0.8) = −11.3: after one miss
    // 8.7 is left (coasting, not reported, same id when the person is back); after two the
    // score is below 0 and the track is gone (a new id)
    let views = crowd_views();
    let objs = objects(&views, &[(1, 6.0, 6.0, 1.8)]);
    let mut t = CylinderTracker::new(views.clone(), params()).expect("tracker");
    let (cyl, _) = t.step(&objs);
    assert_eq!(cyl.len(), 1);
    let id = cyl[0].id;
    assert!(t.step(&[]).0.is_empty(), "coasting: not reported");
    let (cyl, _) = t.step(&objs);
    assert_eq!(cyl.iter().map(|c| c.id).collect::<Vec<_>>(), [id]);
    assert!(t.step(&[]).0.is_empty());
    let (cyl, stats) = t.step(&[]);
    assert!(cyl.is_empty());
    assert_eq!(stats.discarded, 1);
    let (cyl, _) = t.step(&objs);
    assert_eq!(cyl.len(), 1);
    assert_ne!(cyl[0].id, id);
}

#[test]
fn residual_weights_widen_with_the_jitter() {
    let views = crowd_views();
    let p = CylinderParams {
        p_th_px: 22.5,
        occupancy: OccupancyParams {
            jitter: 0.04,
            ..occupancy()
        },
        ..params()
    };
    let t = CylinderTracker::new(views, p).expect("tracker");
    let o = Object2d {
        camera: 0,
        id: 1,
        head_px: [900.0, 300.0],
        width_px: 100.0,
        foot_px: Some([900.0, 600.0]),
    };
    // σ = 0.04 · 300 px = 12 px down, 12/√2 across; w = p_Th / √(p_Th² + (z₉₀ σ)²)
    let w = |s: f64| 22.5 / (22.5f64.powi(2) + (P90_SIGMAS * s).powi(2)).sqrt();
    let (foot, head) = t.residual_weights(&o);
    let (wx, wy) = (w(12.0 / 2f64.sqrt()), w(12.0));
    assert!((foot[0] - wx).abs() < 1e-12 && (foot[1] - wy).abs() < 1e-12);
    assert_eq!(foot, head);
    // twice the box, a wider gate
    let tall = Object2d {
        head_px: [900.0, 0.0],
        ..o
    };
    assert!(t.residual_weights(&tall).0[1] < wy);
    // no jitter, or another association: all ones
    let exact = CylinderTracker::new(crowd_views(), params()).expect("tracker");
    assert_eq!(exact.residual_weights(&o), ([1.0; 2], [1.0; 2]));
    let g = CylinderTracker::new(
        crowd_views(),
        CylinderParams {
            association: Association::Ground,
            ..p
        },
    )
    .expect("tracker");
    assert_eq!(g.residual_weights(&o), ([1.0; 2], [1.0; 2]));
}

#[test]
fn bad_occupancy_parameters_are_named() {
    for (q, name) in [
        (
            OccupancyParams {
                p_detect: 1.0,
                ..occupancy()
            },
            "p_detect",
        ),
        (
            OccupancyParams {
                false_per_frame: 0.0,
                ..occupancy()
            },
            "false_per_frame",
        ),
        (
            OccupancyParams {
                max_llr: 1.0,
                ..occupancy()
            },
            "confirm_llr/max_llr",
        ),
    ] {
        let p = CylinderParams {
            occupancy: q,
            ..params()
        };
        match p.validate() {
            Err(CylinderError::BadParameter { name: n, .. }) => assert_eq!(n, name),
            other => panic!("{other:?}"),
        }
    }
}

/// The prepared boxes of `objs` keyed as `step_occupancy` keys them.
fn keyed(prepared: &[Prepared]) -> BTreeMap<(usize, u32), &Prepared> {
    prepared.iter().map(|o| ((o.camera, o.id), o)).collect()
}

#[test]
fn a_box_s_chi2_is_zero_on_its_segment_and_grows_as_the_square_of_its_offset() {
    // pinhole without distortion: ideal px = px; jitter 0, so the weights are 1 and
    // χ² = Σ (offset / σ_w)², σ_w = p_Th / z₉₀, over foot and head (x, y)
    let views = crowd_views();
    let t = CylinderTracker::new(views.clone(), params()).expect("tracker");
    let head = Point3::new(5.0, 7.0, 1.75);
    let mut objs: Vec<Object2d> = objects(&views, &[(1, head.x, head.y, head.z)])
        .into_iter()
        .filter(|o| o.camera == 2)
        .collect();
    let prepared = t.prepare(&objs);
    let chi2 = t.box_chi2(&prepared[0], &head).expect("projects");
    assert!(chi2 < 1e-12, "{chi2}");
    let shift = 6.0;
    objs[0].head_px[0] += shift;
    if let Some(f) = objs[0].foot_px.as_mut() {
        f[0] += shift;
    }
    let prepared = t.prepare(&objs);
    let chi2 = t.box_chi2(&prepared[0], &head).expect("projects");
    let sigma = t.params.p_th_px / P90_SIGMAS;
    let want = 2.0 * (shift / sigma).powi(2);
    assert!((chi2 - want).abs() < 1e-6 * want, "{chi2} vs {want}");
}

#[test]
fn a_confirmed_track_s_prediction_raises_a_candidate_s_prior_by_its_density() {
    // ρ → ρ + N(x; prediction, P): on the prediction with P = s² I the log-odds gain
    // ln(1 + 1 / (2π s² ρ)); a tentative track gives nothing
    let views = crowd_views();
    let t = CylinderTracker::new(views.clone(), params()).expect("tracker");
    let objs = objects(&views, &[(1, 6.0, 5.0, 1.8)]);
    let prepared = t.prepare(&objs);
    let boxes = keyed(&prepared);
    let people = t.detect_ground(&prepared, &mut StepStats::default());
    assert_eq!(people.len(), 1);
    let h = &people[0];
    let s: f64 = 0.4;
    let track = |id: Option<u32>, dx: f64| {
        let mut kf = t.new_filter(h);
        kf.x[0] += dx;
        kf.p[(0, 0)] = s * s;
        kf.p[(1, 1)] = s * s;
        kf.p[(0, 1)] = 0.0;
        kf.p[(1, 0)] = 0.0;
        Track {
            id,
            kf,
            support: h.support.clone(),
            score: 10.0,
            hits: 3,
            misses: 0,
            age: 2,
            measured: None,
        }
    };
    let alone = t.fit_log_odds(h, &boxes, &[]);
    let rho = occupancy().people_per_m2;
    let on = t.fit_log_odds(h, &boxes, &[track(Some(1), 0.0)]) - alone;
    let want = (1.0 + 1.0 / (std::f64::consts::TAU * s * s * rho)).ln();
    assert!((on - want).abs() < 1e-9, "{on} vs {want}");
    assert_eq!(t.fit_log_odds(h, &boxes, &[track(None, 0.0)]), alone);
    // one metre off: the density at d = 1 m of N(0, s² I)
    let off = t.fit_log_odds(h, &boxes, &[track(Some(1), 1.0)]) - alone;
    let want = (1.0 + (-0.5 / (s * s)).exp() / (std::f64::consts::TAU * s * s * rho)).ln();
    assert!((off - want).abs() < 1e-9, "{off} vs {want}");
}

#[test]
fn both_selections_find_a_noise_free_crowd_and_e_c_is_the_ground_association_s() {
    let views = crowd_views();
    let people = crowd(25);
    let objs = objects(&views, &people);
    for select in [OccupancySelect::Evidence, OccupancySelect::Ec] {
        let p = CylinderParams {
            occupancy: OccupancyParams {
                select,
                ..occupancy()
            },
            ..params()
        };
        let t = CylinderTracker::new(views.clone(), p).expect("tracker");
        let prepared = t.prepare(&objs);
        let found = match select {
            OccupancySelect::Evidence => {
                t.select_by_evidence(&prepared, &keyed(&prepared), &[], &mut StepStats::default())
            }
            OccupancySelect::Ec => t.detect_ground(&prepared, &mut StepStats::default()),
        };
        assert_eq!(found.len(), people.len(), "{select:?}");
        for &(_, x, y, h) in &people {
            assert!(
                found
                    .iter()
                    .any(|f| (f.head_m - Point3::new(x, y, h)).norm() < 1e-6),
                "{select:?}: nobody at ({x}, {y})"
            );
        }
    }
    let text = |s: &str| toml::from_str::<OccupancyParams>(&format!("select = \"{s}\""));
    assert_eq!(text("e_c").expect("e_c").select, OccupancySelect::Ec);
    assert_eq!(
        text("evidence").expect("ev").select,
        OccupancySelect::Evidence
    );
    assert!(text("ec").is_err());
}

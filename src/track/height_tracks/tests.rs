use super::*;
use crate::track::height_ekf::{Motion, camera_model, laser_model};

fn ekf() -> EkfParams {
    EkfParams {
        motion: Motion::ConstantPosition,
        q_pos: 0.1,
        q_height: 1e-6,
        sigma_range_m: 0.05,
        sigma_bearing_rad: 0.01,
        sigma_cam_bearing_rad: 0.01,
        sigma_cam_elevation_rad: 0.01,
        h0_m: 1.0,
        sigma_h0_m: 10.0,
        sigma_pos0_m: 1.0,
        gate_sigma: 3.0,
    }
}

fn params() -> TrackerParams {
    TrackerParams {
        ekf: ekf(),
        delete_after_s: 1.0,
        birth_clearance_m: 0.6,
        confirm_hits: 3,
        skip_ambiguous_camera: false,
    }
}

const LASER: SensorAt = SensorAt {
    x: 0.15,
    y: 3.0,
    z: 0.3,
    yaw: 0.0,
};
const CAM0: SensorAt = SensorAt {
    x: 7.85,
    y: 3.0,
    z: 2.2,
    yaw: 0.0,
};
const CAM1: SensorAt = SensorAt {
    x: 4.0,
    y: 0.15,
    z: 2.4,
    yaw: 0.0,
};

fn leg_pair(x: f64, y: f64) -> Observation {
    let (z, _) = laser_model(x, y, &LASER);
    Observation::Laser {
        range_m: z[0],
        bearing_rad: z[1],
        laser: LASER,
    }
}

fn head(x: f64, y: f64, h: f64, cam: SensorAt) -> Observation {
    let (z, _) = camera_model(x, y, h, &cam);
    Observation::Camera {
        bearing_rad: z[0],
        elevation_rad: z[1],
        camera: cam,
    }
}

/// Two people at (2, 2) 1.84 m and (5, 4) 1.62 m, learned by 40 noise-free laser + camera
/// events.
fn two_people() -> MultiTracker {
    let mut m = MultiTracker::new(params());
    for k in 0..40 {
        let t = 0.2 * f64::from(k);
        m.step(t, &[leg_pair(2.0, 2.0), leg_pair(5.0, 4.0)], true);
        m.step(
            t + 0.1,
            &[head(2.0, 2.0, 1.84, CAM0), head(5.0, 4.0, 1.62, CAM0)],
            false,
        );
    }
    m
}

#[test]
fn two_people_at_known_positions_are_associated_one_to_one_whatever_the_order() {
    let mut m = two_people();
    let ids: Vec<u64> = m.tracks().iter().map(|t| t.id).collect();
    assert_eq!(ids, vec![1, 2], "one track per person, no duplicate births");
    let (a, b) = (&m.tracks()[0], &m.tracks()[1]);
    assert!((a.ekf.xy()[0] - 2.0).abs() < 1e-3 && (a.ekf.xy()[1] - 2.0).abs() < 1e-3);
    assert!(
        (b.ekf.xy()[0] - 5.0).abs() < 1e-3 && (b.ekf.xy()[1] - 4.0).abs() < 1e-3,
        "{:?} h {}",
        b.ekf.xy(),
        b.ekf.height()
    );
    assert!((a.ekf.height() - 1.84).abs() < 1e-3, "{}", a.ekf.height());
    assert!((b.ekf.height() - 1.62).abs() < 1e-3, "{}", b.ekf.height());
    // observations given in the other order go to the same tracks
    let r = m.step(8.0, &[leg_pair(5.0, 4.0), leg_pair(2.0, 2.0)], true);
    assert_eq!(r.assigned, vec![(1, 1), (2, 0)]);
    assert!(r.born.is_empty() && r.unassigned.is_empty());
    let r = m.step(
        8.1,
        &[head(5.0, 4.0, 1.62, CAM0), head(2.0, 2.0, 1.84, CAM0)],
        false,
    );
    assert_eq!(r.assigned, vec![(1, 1), (2, 0)]);
}

#[test]
fn the_height_tells_apart_two_heads_on_one_camera_bearing() {
    // both people on cam_0's optical axis y = 3: the same bearing from cam_0; 1.84 m at
    // x = 3 and 1.62 m at x = 5. Heights learned with cam_1, which sees them apart; then
    // cam_0's two head tops are told apart by elevation alone, i.e. by the learned heights
    let mut m = MultiTracker::new(params());
    for k in 0..20 {
        let t = 0.2 * f64::from(k);
        m.step(t, &[leg_pair(3.0, 3.0), leg_pair(5.0, 3.0)], true);
        m.step(
            t + 0.1,
            &[head(3.0, 3.0, 1.84, CAM1), head(5.0, 3.0, 1.62, CAM1)],
            false,
        );
    }
    let r = m.step(
        4.1,
        &[head(5.0, 3.0, 1.62, CAM0), head(3.0, 3.0, 1.84, CAM0)],
        false,
    );
    assert_eq!(r.assigned, vec![(1, 1), (2, 0)]);
    // a head top implying a 2.5 m person on that bearing matches nobody
    let r = m.step(4.3, &[head(4.0, 3.0, 2.5, CAM0)], false);
    assert!(r.assigned.is_empty() && r.unassigned == vec![0], "{r:?}");
}

#[test]
fn tracks_are_born_from_free_leg_pairs_confirmed_after_three_and_deleted_after_the_timeout() {
    // A at (2, 2) from 0 to 1.0 s; B at (5, 4) from 0.4 to 3.0 s; one scan every 0.2 s
    let mut m = MultiTracker::new(params());
    let mut born = Vec::new();
    let mut deleted = Vec::new();
    for k in 0..=15 {
        let t = 0.2 * f64::from(k);
        let mut obs = Vec::new();
        if t <= 1.0 + 1e-9 {
            obs.push(leg_pair(2.0, 2.0));
        }
        if t >= 0.4 - 1e-9 {
            obs.push(leg_pair(5.0, 4.0));
        }
        let r = m.step(t, &obs, true);
        born.extend(r.born.iter().map(|&id| (k, id)));
        deleted.extend(r.deleted.iter().map(|&id| (k, id)));
        if k >= 6 && m.tracks().iter().any(|t| t.id == 1) {
            // A's head still seen by the camera 0.1 s after each scan: it updates A's track
            // but does not keep it alive
            let r = m.step(t + 0.1, &[head(2.0, 2.0, 1.84, CAM0)], false);
            assert_eq!(r.assigned, vec![(1, 0)]);
            deleted.extend(r.deleted.iter().map(|&id| (k, id)));
        }
        if k == 1 {
            assert!(!m.confirmed(&m.tracks()[0]), "two hits: not yet reported");
        }
        if k == 2 {
            assert!(m.confirmed(&m.tracks()[0]), "three hits: reported");
            assert!(!m.confirmed(&m.tracks()[1]), "B's first scan");
        }
    }
    assert_eq!(born, vec![(0, 1), (2, 2)]);
    // A's last leg pair at 1.0 s; deleted at the first step more than 1.0 s later: the
    // camera step at 2.1 s (after scan 10)
    assert_eq!(deleted, vec![(10, 1)]);
    assert_eq!(m.tracks().len(), 1);
    assert_eq!(m.tracks()[0].id, 2);
    // a leg pair 0.55 m from a settled track is outside its gate and inside the birth
    // clearance: it starts no new track
    let mut m2 = MultiTracker::new(params());
    for k in 0..10 {
        m2.step(0.2 * f64::from(k), &[leg_pair(5.0, 4.0)], true);
    }
    let r = m2.step(2.0, &[leg_pair(5.55, 4.0)], true);
    assert!(r.assigned.is_empty() && r.born.is_empty(), "{r:?}");
    assert_eq!(m2.tracks().len(), 1);
}

#[test]
fn two_cameras_triangulate_a_head_of_known_height_exactly() {
    for &(x, y, h) in &[(3.0, 2.0, 1.75), (5.5, 4.2, 1.62), (2.2, 3.9, 1.84)] {
        let (za, _) = camera_model(x, y, h, &CAM0);
        let (zb, _) = camera_model(x, y, h, &CAM1);
        let p = triangulate_head((za[0], za[1], CAM0), (zb[0], zb[1], CAM1)).expect("meet");
        assert!(
            (p[0] - x).abs() < 1e-12 && (p[1] - y).abs() < 1e-12 && (p[2] - h).abs() < 1e-12,
            "{p:?} vs ({x}, {y}, {h})"
        );
    }
    // parallel bearings do not meet
    let c2 = SensorAt { y: 5.0, ..CAM0 };
    assert_eq!(triangulate_head((0.0, -0.1, CAM0), (0.0, -0.1, c2)), None);
    // bearings that meet behind a camera
    assert_eq!(
        triangulate_head((0.0, -0.1, CAM0), (std::f64::consts::FRAC_PI_2, -0.1, CAM1)),
        None
    );
}

#[test]
fn two_cameras_alone_learn_position_and_height_where_one_camera_cannot() {
    // a track born from one leg pair 0.4 m off, then only noise-free camera head tops
    let (x, y, h) = (3.0, 2.0, 1.75);
    let run = |cams: &[SensorAt]| {
        // no leg pair after the birth: keep the track alive for the whole run
        let mut m = MultiTracker::new(TrackerParams {
            delete_after_s: 100.0,
            ..params()
        });
        m.step(0.0, &[leg_pair(x + 0.4, y - 0.3)], true);
        for k in 1..=200 {
            let t = 0.05 * f64::from(k);
            let obs: Vec<Observation> = cams.iter().map(|c| head(x, y, h, *c)).collect();
            for o in obs {
                m.step(t, &[o], false);
            }
        }
        let f = &m.tracks()[0].ekf;
        (f.xy(), f.height())
    };
    let (xy, h2) = run(&[CAM0, CAM1]);
    assert!(
        (xy[0] - x).abs() < 1e-3 && (xy[1] - y).abs() < 1e-3 && (h2 - h).abs() < 1e-3,
        "{xy:?} {h2}"
    );
    // one camera: range and height trade along the ray (the paper's §5 ambiguity)
    let (xy1, h1) = run(&[CAM0]);
    let off = (xy1[0] - x).hypot(xy1[1] - y);
    assert!(off > 0.05 || (h1 - h).abs() > 0.02, "{xy1:?} {h1}");
}

#[test]
fn a_head_top_in_two_tracks_gates_updates_neither_when_ambiguity_is_skipped() {
    // two tracks of unknown height on cam_0's axis: any head top on that bearing fits both
    let run = |skip: bool| {
        let mut m = MultiTracker::new(TrackerParams {
            skip_ambiguous_camera: skip,
            ..params()
        });
        m.step(0.0, &[leg_pair(3.0, 3.0), leg_pair(5.0, 3.0)], true);
        m.step(0.1, &[head(3.0, 3.0, 1.84, CAM0)], false)
    };
    let r = run(false);
    assert_eq!(r.assigned.len(), 1, "{r:?}");
    let r = run(true);
    assert!(r.assigned.is_empty() && r.unassigned == vec![0], "{r:?}");
}

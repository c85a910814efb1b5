//! A hand-made scored session for the sub-experiments' tests: one person walking along x for
//! 10 frames (seen by one camera in frames 0–1, by two from frame 2), and runs whose tracks
//! are placed at known offsets from them:
//!
//! - `gt_boxes`, E_c, N_app 5: every frame, 0.1 m off, except frames 3–4 0.7 m off;
//! - `templates`, E_c, N_app 5 (the main run): the same from frame 3 on (none before);
//!   3 supporting cameras, E_m 2 px;
//! - `templates`, E_m, N_app 5: every frame 0.1 m off; 2 cameras, E_m 1 px;
//! - `templates`, E_c, N_app 1: every frame 0.1 m off, and a ghost track far from anybody.

use std::path::PathBuf;

use crate::pipelines::s004_mohedano_multicam::Params;
use crate::pipelines::s004_mohedano_multicam::scored::{Scored, SessionData, score_data};
use crate::pipelines::s004_mohedano_multicam::tables::{GtRow, SessionRow, TrackRow};

const FRAMES: i64 = 10;
const DT_S: f64 = 0.04;

fn truth() -> Vec<GtRow> {
    (0..FRAMES)
        .map(|k| GtRow {
            frame: k,
            stamp_ns: k * 40_000_000,
            t_s: k as f64 * DT_S,
            id: 1,
            x_m: 1.0 + 0.1 * k as f64,
            y_m: 2.0,
            height_m: 1.75,
            radius_m: 0.2,
            cameras_visible: if k < 2 { 1 } else { 2 },
            in_room: true,
        })
        .collect()
}

fn track(run: (&str, &str, i64), k: i64, id: i64, dx: f64, cameras: i64, e_m: f64) -> TrackRow {
    TrackRow {
        detector: run.0.into(),
        selection: run.1.into(),
        n_app: run.2,
        frame: k,
        stamp_ns: k * 40_000_000,
        t_s: k as f64 * DT_S,
        id,
        x_m: 1.0 + 0.1 * k as f64 + dx,
        y_m: 2.0,
        vx_mps: 2.5,
        vy_mps: 0.0,
        height_m: 1.8,
        radius_m: 0.25,
        cameras,
        support: String::new(),
        e_m_px: Some(e_m),
        meas_x_m: None,
        meas_y_m: None,
        meas_height_m: None,
        meas_radius_m: None,
    }
}

fn tracks() -> Vec<TrackRow> {
    let off = |k: i64| if k == 3 || k == 4 { 0.7 } else { 0.1 };
    let mut out = Vec::new();
    for k in 0..FRAMES {
        out.push(track(("gt_boxes", "E_c", 5), k, 1, off(k), 2, 1.0));
        if k >= 3 {
            out.push(track(("templates", "E_c", 5), k, 7, off(k), 3, 2.0));
        }
        out.push(track(("templates", "E_m", 5), k, 7, 0.1, 2, 1.0));
        out.push(track(("templates", "E_c", 1), k, 7, 0.1, 2, 1.0));
        let mut ghost = track(("templates", "E_c", 1), k, 9, 0.0, 2, 1.0);
        ghost.y_m = 6.0;
        out.push(ghost);
    }
    out
}

/// The session's data.
pub(crate) fn session() -> SessionData {
    SessionData {
        dataset: "test".into(),
        name: "s0".into(),
        path: PathBuf::from("s0.mcap"),
        tracks: tracks(),
        truth: truth(),
        head_centroid: Vec::new(),
        cameras: Vec::new(),
        detections_2d: Vec::new(),
        errors_2d: Vec::new(),
        variants: Vec::new(),
        calibration: Vec::new(),
        timing: Vec::new(),
        noise_tracks: Vec::new(),
        noise_boxes: Vec::new(),
        session: SessionRow {
            frames: FRAMES,
            cameras: 2,
            dt_s: DT_S,
            duration_s: (FRAMES - 1) as f64 * DT_S,
            first_stamp_ns: 0,
            decode_failures: 0,
            missing_camera_frames: 0,
            gt_frames: FRAMES,
            gt_bad_frames: 0,
            first_error: String::new(),
        },
        view: None,
    }
}

/// The session scored with the default parameters (thresholds 0.5 and 1 m).
pub(crate) fn scored() -> Scored {
    match score_data(vec![session()], &Params::default()) {
        Ok(s) => s,
        Err(e) => panic!("scoring the test session: {e:#}"),
    }
}

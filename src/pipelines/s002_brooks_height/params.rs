//! `[params]` of `pipelines/s002_brooks_height.toml` and their validation. Seed 002 gives no
//! numbers for the detectors or the filter noise; every default here was chosen on the quick
//! profile of `office_network` (synthetic), as the pipeline file says.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::run::config::Invalid;
use crate::track::height_ekf::{EkfParams, Motion};
use crate::track::height_tracks::TrackerParams;
use crate::vision::jabri::{ColourPlanes, EdgePlanes, JabriParams};
use crate::vision::skin::SkinParams;

/// `skin_training` value naming the last log of each session's folder.
pub const LAST: &str = "last";

/// What the pipeline file runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    /// Seed 002 as published: one person, laser + `camera` (the `office_network` dataset).
    Paper,
    /// Our addition: several people, laser + every camera of `cameras`, one EKF per person
    /// ([`crate::track::height_tracks`]); scored with CLEAR MOT and per-person heights.
    Multi,
    /// The camera's mount: the paper's filters (one person) once per camera of `cameras`, the
    /// same walks seen from cameras at several heights (`office_network_mount`).
    Mount,
}

/// Which session's learned height the camera-only run of a session starts from (the paper's
/// second trial uses the height learned in the first, by the same person).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum HeightFrom {
    /// The previous evaluated session (the first from the last): one person in every session.
    Previous,
    /// Sessions in pairs, (0, 1), (2, 3), ...: each trial starts from its partner's height (the
    /// same person walks both; a last unpaired session falls back to the previous one).
    Pairs,
}

impl HeightFrom {
    /// The name in the pipeline file.
    pub fn name(self) -> &'static str {
        match self {
            HeightFrom::Previous => "previous",
            HeightFrom::Pairs => "pairs",
        }
    }

    /// The session whose learned height session `k` of `n` starts from.
    pub fn source(self, k: usize, n: usize) -> usize {
        match self {
            HeightFrom::Pairs if (k ^ 1) < n => k ^ 1,
            _ => (k + n - 1) % n,
        }
    }
}

/// `[params]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Params {
    pub mode: Mode,
    pub camera: String,
    /// Multi mode: the cameras, in order (the first alone is the one-camera run).
    pub cameras: Vec<String>,
    pub scan_topic: String,
    /// Skin-training logs (globs), or `["last"]`: the last log (by name) in each session's
    /// folder — the dataset's skin-training session, which is then not evaluated. The histogram
    /// is built from their skin masks, never from an evaluated session.
    pub skin_training: Vec<String>,
    /// Every `skin_training_every`-th frame of the training logs is used.
    pub skin_training_every: usize,
    pub skin_bins: usize,
    pub smooth_sigma_px: f32,
    pub skin_low: f32,
    pub skin_high: f32,
    pub canny_low: f32,
    pub canny_high: f32,
    /// Share of skin pixels in a blob's top fifth that makes it a person.
    pub min_skin_fraction: f64,
    /// Planes of the tracking run.
    pub colour: ColourPlanes,
    pub edges: EdgePlanes,
    pub alpha: f32,
    pub k_sigma: f32,
    pub sigma_floor: f32,
    pub sigma_init: f32,
    pub min_blob_px: u64,
    /// Frames at the start of a session that only train the background (no observations, not
    /// scored).
    pub warmup_frames: usize,
    /// Filter noise (see [`crate::track::height_ekf::EkfParams`]).
    pub q_pos: f64,
    pub q_pos_cv: f64,
    /// Our CV variant only: when no observation was accepted for this long (s), the next
    /// leg pair re-initialises the position there (velocity 0, height and its σ kept);
    /// 0 = never. The paper's constant-position filter never re-initialises.
    pub cv_reinit_after_s: f64,
    /// Height process noise, m²/s: 0 = the paper's model (a constant the filter learns).
    pub q_height: f64,
    /// The random-walk variant's height process noise (its own rows), m²/s.
    pub q_height_walk: f64,
    /// Which session's learned height the camera-only run starts from.
    pub height_from: HeightFrom,
    pub sigma_range_m: f64,
    pub sigma_bearing_rad: f64,
    pub sigma_cam_bearing_rad: f64,
    pub sigma_cam_elevation_rad: f64,
    pub h0_m: f64,
    pub sigma_h0_m: f64,
    pub sigma_pos0_m: f64,
    pub gate_sigma: f64,
    /// Ground truth joined to an instant by nearest stamp within this (s).
    pub gt_tolerance_s: f64,
    /// Speed (m/s) above which the lag along the direction of motion is measured.
    pub lag_min_speed: f64,
    pub level: f64,
    /// Room outline for the top view `[x0, y0, x1, y1]` (m, map frame; drawing only).
    pub room_m: [f64; 4],
    /// Multi mode: a track not updated for this long (s) is deleted.
    pub delete_after_s: f64,
    /// Multi mode: a free leg pair nearer than this (m) to a track starts no track.
    pub birth_clearance_m: f64,
    /// Multi mode: laser updates before a track is reported.
    pub confirm_hits: u32,
    /// Multi mode: CLEAR MOT match distance on the floor (m).
    pub mot_max_m: f64,
    /// Multi mode: a head top inside two or more tracks' gates updates none.
    pub skip_ambiguous_camera: bool,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            mode: Mode::Paper,
            camera: "cam_0".into(),
            cameras: Vec::new(),
            scan_topic: "/scan".into(),
            skin_training: vec![LAST.into()],
            skin_training_every: 5,
            skin_bins: 32,
            smooth_sigma_px: 1.0,
            skin_low: 0.05,
            skin_high: 0.25,
            canny_low: 40.0,
            canny_high: 90.0,
            min_skin_fraction: 0.04,
            colour: ColourPlanes::Rgb,
            edges: EdgePlanes::Sobel,
            alpha: 0.05,
            k_sigma: 3.5,
            sigma_floor: 6.0,
            sigma_init: 20.0,
            min_blob_px: 80,
            warmup_frames: 10,
            q_pos: 0.5,
            q_pos_cv: 2.0,
            cv_reinit_after_s: 1.0,
            q_height: 0.0,
            q_height_walk: 1e-4,
            height_from: HeightFrom::Previous,
            sigma_range_m: 0.1,
            sigma_bearing_rad: 0.02,
            sigma_cam_bearing_rad: 0.02,
            sigma_cam_elevation_rad: 0.02,
            h0_m: 1.0,
            sigma_h0_m: 10.0,
            sigma_pos0_m: 1.0,
            gate_sigma: 3.0,
            gt_tolerance_s: 0.05,
            lag_min_speed: 0.3,
            level: 0.95,
            room_m: [0.0, 0.0, 8.0, 6.0],
            delete_after_s: 2.0,
            birth_clearance_m: 0.6,
            confirm_hits: 3,
            mot_max_m: 0.75,
            skip_ambiguous_camera: true,
        }
    }
}

impl Params {
    /// The skin-training logs for a session at `session` (see `skin_training`).
    pub fn training_logs(&self, session: &Path) -> Vec<PathBuf> {
        if self.skin_training.len() == 1 && self.skin_training[0] == LAST {
            return last_in_folder(session).into_iter().collect();
        }
        let mut out: Vec<PathBuf> = self
            .skin_training
            .iter()
            .flat_map(|g| glob::glob(g).into_iter().flatten().flatten())
            .collect();
        out.sort();
        out
    }

    /// Whether `session` is a skin-training log (not evaluated).
    pub fn is_training(&self, session: &Path) -> bool {
        self.training_logs(session)
            .iter()
            .any(|t| same_file(t, session))
    }

    /// These parameters with `camera` set to `name` (multi mode runs the camera stage once
    /// per camera).
    pub fn for_camera(&self, name: &str) -> Params {
        Params {
            camera: name.into(),
            ..self.clone()
        }
    }

    pub fn tracker(&self) -> TrackerParams {
        TrackerParams {
            ekf: self.ekf(Motion::ConstantPosition),
            delete_after_s: self.delete_after_s,
            birth_clearance_m: self.birth_clearance_m,
            confirm_hits: self.confirm_hits,
            skip_ambiguous_camera: self.skip_ambiguous_camera,
        }
    }

    pub fn jabri(&self) -> JabriParams {
        JabriParams {
            alpha: self.alpha,
            k_sigma: self.k_sigma,
            sigma_floor: self.sigma_floor,
            sigma_init: self.sigma_init,
            min_blob_px: self.min_blob_px,
        }
    }

    pub fn skin(&self) -> SkinParams {
        SkinParams {
            smooth_sigma_px: self.smooth_sigma_px,
            low: self.skin_low,
            high: self.skin_high,
            canny_low: self.canny_low,
            canny_high: self.canny_high,
        }
    }

    /// The filter with the random-walk height instead (`q_height_walk`).
    pub fn ekf_walk(&self, motion: Motion) -> EkfParams {
        EkfParams {
            q_height: self.q_height_walk,
            ..self.ekf(motion)
        }
    }

    pub fn ekf(&self, motion: Motion) -> EkfParams {
        EkfParams {
            motion,
            q_pos: match motion {
                Motion::ConstantPosition => self.q_pos,
                Motion::ConstantVelocity => self.q_pos_cv,
            },
            q_height: self.q_height,
            sigma_range_m: self.sigma_range_m,
            sigma_bearing_rad: self.sigma_bearing_rad,
            sigma_cam_bearing_rad: self.sigma_cam_bearing_rad,
            sigma_cam_elevation_rad: self.sigma_cam_elevation_rad,
            h0_m: self.h0_m,
            sigma_h0_m: self.sigma_h0_m,
            sigma_pos0_m: self.sigma_pos0_m,
            gate_sigma: self.gate_sigma,
        }
    }
}

pub(super) fn validate(p: &Params) -> Vec<Invalid> {
    let mut out: Vec<Invalid> = Vec::new();
    let mut pos = |key: &str, v: f64| {
        if !(v.is_finite() && v > 0.0) {
            out.push((key.into(), format!("{v} must be finite and > 0")));
        }
    };
    for (k, v) in [
        ("q_pos", p.q_pos),
        ("q_pos_cv", p.q_pos_cv),
        ("q_height_walk", p.q_height_walk),
        ("sigma_range_m", p.sigma_range_m),
        ("sigma_bearing_rad", p.sigma_bearing_rad),
        ("sigma_cam_bearing_rad", p.sigma_cam_bearing_rad),
        ("sigma_cam_elevation_rad", p.sigma_cam_elevation_rad),
        ("sigma_h0_m", p.sigma_h0_m),
        ("sigma_pos0_m", p.sigma_pos0_m),
        ("gate_sigma", p.gate_sigma),
        ("delete_after_s", p.delete_after_s),
        ("birth_clearance_m", p.birth_clearance_m),
        ("mot_max_m", p.mot_max_m),
        ("k_sigma", f64::from(p.k_sigma)),
        ("sigma_floor", f64::from(p.sigma_floor)),
        ("sigma_init", f64::from(p.sigma_init)),
        ("canny_high", f64::from(p.canny_high)),
    ] {
        pos(k, v);
    }
    if !(p.q_height.is_finite() && p.q_height >= 0.0) {
        out.push((
            "q_height".into(),
            format!("{} must be >= 0 (0 = constant height)", p.q_height),
        ));
    }
    if !(p.alpha > 0.0 && p.alpha <= 1.0) {
        out.push(("alpha".into(), format!("{} is not in (0, 1]", p.alpha)));
    }
    if !(p.cv_reinit_after_s.is_finite() && p.cv_reinit_after_s >= 0.0) {
        out.push((
            "cv_reinit_after_s".into(),
            format!("{} must be >= 0 (0 = never)", p.cv_reinit_after_s),
        ));
    }
    if matches!(p.mode, Mode::Multi | Mode::Mount) && p.cameras.is_empty() {
        out.push((
            "cameras".into(),
            "mode = \"multi\" and mode = \"mount\" need at least one camera".into(),
        ));
    }
    if !(p.level > 0.0 && p.level < 1.0) {
        out.push(("level".into(), format!("{} is not in (0, 1)", p.level)));
    }
    if !(0.0..=1.0).contains(&p.min_skin_fraction) {
        out.push((
            "min_skin_fraction".into(),
            format!("{} is not in [0, 1]", p.min_skin_fraction),
        ));
    }
    if !(p.skin_low >= 0.0 && p.skin_low <= p.skin_high && p.skin_high <= 1.0) {
        out.push((
            "skin_low".into(),
            format!(
                "need 0 <= skin_low ({}) <= skin_high ({}) <= 1",
                p.skin_low, p.skin_high
            ),
        ));
    }
    if p.skin_bins == 0 || p.skin_bins > 256 {
        out.push((
            "skin_bins".into(),
            format!("{} is not in [1, 256]", p.skin_bins),
        ));
    }
    if p.skin_training_every == 0 {
        out.push(("skin_training_every".into(), "must be >= 1".into()));
    }
    if p.skin_training.is_empty() {
        out.push((
            "skin_training".into(),
            "name at least one training log".into(),
        ));
    }
    if !(p.smooth_sigma_px >= 0.0 && p.smooth_sigma_px.is_finite()) {
        out.push((
            "smooth_sigma_px".into(),
            format!("{} must be >= 0", p.smooth_sigma_px),
        ));
    }
    if !(p.gt_tolerance_s >= 0.0 && p.gt_tolerance_s <= 10.0) {
        out.push((
            "gt_tolerance_s".into(),
            format!("{} is not in [0, 10] s", p.gt_tolerance_s),
        ));
    }
    out
}

/// The 1 / 3 colour × 0 / 1 / 2 edge plane configurations of §4's scaling claim.
pub const PLANE_GRID: [(ColourPlanes, EdgePlanes); 6] = [
    (ColourPlanes::Grey, EdgePlanes::None),
    (ColourPlanes::Grey, EdgePlanes::Laplacian),
    (ColourPlanes::Grey, EdgePlanes::Sobel),
    (ColourPlanes::Rgb, EdgePlanes::None),
    (ColourPlanes::Rgb, EdgePlanes::Laplacian),
    (ColourPlanes::Rgb, EdgePlanes::Sobel),
];

/// A configuration's name, e.g. `rgb+sobel`.
pub fn plane_name(c: ColourPlanes, e: EdgePlanes) -> String {
    let c = match c {
        ColourPlanes::Grey => "grey",
        ColourPlanes::Rgb => "rgb",
    };
    let e = match e {
        EdgePlanes::None => "none",
        EdgePlanes::Laplacian => "laplacian",
        EdgePlanes::Sobel => "sobel",
    };
    format!("{c}+{e}")
}

/// The last `.mcap` (by file name) in the folder of `session`.
fn last_in_folder(session: &Path) -> Option<PathBuf> {
    let dir = session.parent()?;
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let mut logs: Vec<PathBuf> = std::fs::read_dir(dir)
        .ok()?
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "mcap"))
        .collect();
    logs.sort();
    logs.pop()
}

fn same_file(a: &Path, b: &Path) -> bool {
    a.file_name() == b.file_name()
        && match (a.canonicalize(), b.canonicalize()) {
            (Ok(x), Ok(y)) => x == y,
            _ => a == b,
        }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_last_log_of_the_folder_is_the_training_session() {
        let dir = tempfile::tempdir().expect("tempdir");
        for n in ["d_00.mcap", "d_01.mcap", "d_02.mcap", "notes.txt"] {
            std::fs::write(dir.path().join(n), b"").expect("write");
        }
        let p = Params::default();
        let s0 = dir.path().join("d_00.mcap");
        assert_eq!(p.training_logs(&s0), vec![dir.path().join("d_02.mcap")]);
        assert!(!p.is_training(&s0));
        assert!(p.is_training(&dir.path().join("d_02.mcap")));
    }

    #[test]
    fn camera_only_height_sources_previous_and_pairs() {
        let all = |h: HeightFrom, n: usize| (0..n).map(|k| h.source(k, n)).collect::<Vec<_>>();
        assert_eq!(all(HeightFrom::Previous, 5), [4, 0, 1, 2, 3]);
        assert_eq!(all(HeightFrom::Pairs, 6), [1, 0, 3, 2, 5, 4]);
        // an odd last session falls back to the previous one; two sessions: the rules agree
        assert_eq!(all(HeightFrom::Pairs, 5), [1, 0, 3, 2, 3]);
        assert_eq!(all(HeightFrom::Pairs, 2), all(HeightFrom::Previous, 2));
        assert_eq!(all(HeightFrom::Pairs, 1), [0]);
    }

    #[test]
    fn a_constant_height_is_valid_and_a_negative_one_is_not() {
        let p = Params::default();
        assert_eq!((p.q_height, p.q_height_walk), (0.0, 1e-4));
        assert!(validate(&p).is_empty());
        let bad = Params {
            q_height: -1e-4,
            q_height_walk: 0.0,
            ..Params::default()
        };
        let keys: Vec<String> = validate(&bad).into_iter().map(|(k, _)| k).collect();
        assert_eq!(keys, ["q_height_walk", "q_height"]);
    }
}

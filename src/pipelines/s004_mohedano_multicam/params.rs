//! `[params]` of `pipelines/s004_mohedano_multicam.toml` and their checks.

use serde::{Deserialize, Serialize};

use crate::log::import::detector_noise::DetectorNoise;
use crate::run::config::Invalid;
use crate::track::cylinders::{Association, OccupancyParams, Selection};

/// Where the 2-D objects of the main run come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Detector {
    /// The paper's chain: Gabor background, templates, graph-matching 2-D tracks.
    Templates,
    /// `vision_msgs/msg/Detection2DArray` per camera from the log, through the same 2-D
    /// tracker (bring your own detector).
    Log,
}

/// How the Gabor background learns (`vision::gabor::Update`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BackgroundUpdate {
    /// Eq. 2 as printed: every pixel with weight α.
    All,
    /// Our addition: foreground pixels (dilated by the Gabor filter radius) learn at
    /// `foreground_alpha` instead of α, so walkers leave no trail.
    Selective,
}

/// How the template detector suppresses overlapping candidates (`vision::template::Suppression`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Nms {
    /// Boxes overlapping a better detection (`nms_iou`, `nms_contained`).
    Boxes,
    /// Local maxima of the combined score image: heads within `nms_head_radius` body widths
    /// of a better detection's head (the paper's non-minimal suppression over Pᵗ).
    Heads,
}

/// `[params]` of `pipelines/s004_mohedano_multicam.toml`; the file says where each default comes
/// from.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Params {
    /// Camera names; topics default to `/<cam>/image_raw/compressed`, `/<cam>/camera_info`,
    /// `/<cam>/detections` (remap with `[topics]` keys `<cam>_image`, `<cam>_info`,
    /// `<cam>_detections`).
    pub cameras: Vec<String>,
    /// World frame of the TF tree (ground plane z = 0).
    pub world_frame: String,
    pub detector: Detector,
    /// Also run the 3-D stage on the ground-truth boxes when the log has them.
    pub gt_boxes: bool,
    // §2 background
    pub alpha: f64,
    pub gabor_sigma_px: f64,
    pub gabor_wavelength_px: f64,
    pub mad_k: f64,
    /// Frames, spread evenly over the log, whose per-pixel median starts the background
    /// (0: the first frame, as eq. 2 alone would).
    pub bootstrap_frames: usize,
    pub background_update: BackgroundUpdate,
    /// Learning rate of foreground pixels under `background_update = "selective"`.
    pub foreground_alpha: f64,
    /// Remove ghosts: a foreground region whose contour has more luminance edge in the
    /// background than in the frame is learnt at once (`vision::gabor::GhostTest`; our addition).
    pub ghost_removal: bool,
    /// Half-width of the contour band of the ghost test (pixels).
    pub ghost_band_px: u32,
    /// Frames running a pixel must lie in ghost regions before it is learnt.
    pub ghost_frames: u32,
    /// The learnt ghost pixels grown by this many pixels (0: the region and its band only).
    pub ghost_grow_px: u32,
    // §3 detection
    pub person_height_m: f64,
    pub template_scales: usize,
    pub template_tilts: usize,
    pub template_threshold: f64,
    /// Fraction of a template window the silhouette fills (a background margin is added
    /// around it; 1 = the silhouette's tight box).
    pub template_fill: f64,
    /// The silhouettes' width relative to the profile's (`Silhouette::widened`).
    pub template_width: f64,
    /// Dilate each silhouette by this many pixels before adding the margin (the Gabor
    /// envelope spreads a person's foreground by about σ; `Silhouette::grown`).
    pub template_grow_px: u32,
    /// Try at each head position only the template the calibration predicts there
    /// (`vision::template::TemplateMap`); false: all templates everywhere.
    pub templates_by_position: bool,
    pub template_stride_px: u32,
    pub nms: Nms,
    pub nms_iou: f64,
    pub nms_contained: f64,
    /// `nms = "heads"`: suppression half-window in body widths (across) and body heights
    /// (along the body).
    pub nms_head_radius: f64,
    /// Head point of a box (log detections, ground-truth boxes): the box's top row on the
    /// image of the person's vertical (`track::cylinders::box_head_px`); false: the top centre.
    pub box_head_on_axis: bool,
    // §4 2-D tracking
    pub match_iou_2d: f64,
    pub max_missed_2d: u32,
    // §5 3-D tracking
    pub p_th_px: f64,
    pub n_app: u32,
    pub n_dis: u32,
    pub selection: Selection,
    pub head_height_m: [f64; 2],
    pub room_m: [f64; 4],
    pub room_margin_m: f64,
    pub gate_m: f64,
    /// σ of the 3-D tracks' white-noise acceleration on the ground (m/s², piecewise constant
    /// over a frame period: `track::kalman::constant_velocity_2d`). 2.0 is the synthetic
    /// office's value (25 fps); at WILDTRACK's 2 fps it is set from the annotated people's own
    /// second differences (`peopletrack import wildtrack` prints it).
    pub accel_sigma_mps2: f64,
    pub max_combinations: usize,
    /// New 3-D objects: `paper` (exhaustive combinations), `scalable` (pairwise ray seeds
    /// grown camera by camera, plus single-camera ground points) or `ground` (per frame on
    /// the ground plane from feet and heads, tracked by assignment; `track::cylinders`).
    pub association: Association,
    /// `scalable`: a single-camera ground point this close to a person already found is a
    /// view of that person (m).
    pub ground_separation_m: f64,
    /// `occupancy`: the detector's model (`P_D`, edge jitter, false boxes per camera frame),
    /// the prior density of people and the track scores (`track::cylinders::OccupancyParams`).
    pub occupancy: OccupancyParams,
    // detector noise (issue 32)
    /// Levels of the detector model of `log::import::detector_noise` applied to the boxes of
    /// the log (`detector = "log"`) or to the ground-truth boxes (otherwise), each run through
    /// the 2-D tracker and the 3-D stage; empty: no `detector_noise` table.
    pub detector_noise: Vec<DetectorNoise>,
    /// Seed of the detector model's draws.
    pub noise_seed: u64,
    /// The associations each noise level is run with.
    pub noise_associations: Vec<Association>,
    // evaluation
    /// Also run the configured association frame by frame without temporal tracking
    /// (detector `<detector>_per_frame`) and write the `ghosts` and `splits` tables.
    pub decompose: bool,
    /// With `decompose`: `splits` scores frames before this one and from it on separately
    /// (a development and a held-out part); 0 = no split.
    pub split_frame: i64,
    /// CLEAR MOT / IDF1 matching thresholds on the ground (m).
    pub match_m: Vec<f64>,
    /// `N_app` values of the latency / false-alarm sweep (`N_dis = N_app`, as the paper).
    pub n_app_sweep: Vec<u32>,
    /// A camera's view of a person counts as statically occluded below this visibility when
    /// no other person's box overlaps it.
    pub occluded_visibility: f64,
    /// Frames of different cameras within this time belong together (s).
    pub sync_tolerance_s: f64,
    /// Desks and other furniture drawn in the bird's-eye view `[x0, y0, x1, y1]` (m): the log
    /// does not carry the room's furniture.
    pub figure_obstacles_m: Vec<[f64; 4]>,
    // outputs
    /// Folder for the logs with tracks as markers (`<dir>/<dataset>/<session>_tracks.mcap`);
    /// empty: do not write them.
    pub write_tracks: String,
    /// Topic of the markers in those logs.
    pub tracks_topic: String,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            cameras: (0..4).map(|k| format!("cam_{k}")).collect(),
            world_frame: "map".into(),
            detector: Detector::Templates,
            gt_boxes: true,
            alpha: 0.02,
            gabor_sigma_px: 2.0,
            gabor_wavelength_px: 8.0,
            mad_k: 3.0,
            bootstrap_frames: 25,
            background_update: BackgroundUpdate::Selective,
            foreground_alpha: 0.0,
            ghost_removal: true,
            ghost_band_px: 4,
            ghost_frames: 5,
            ghost_grow_px: 6,
            person_height_m: 1.75,
            template_scales: 4,
            template_tilts: 4,
            template_threshold: 0.7,
            template_fill: 0.5,
            template_width: 1.5,
            template_grow_px: 2,
            templates_by_position: true,
            template_stride_px: 2,
            nms: Nms::Heads,
            nms_iou: 0.3,
            nms_contained: 0.7,
            nms_head_radius: 0.5,
            box_head_on_axis: true,
            match_iou_2d: 0.1,
            max_missed_2d: 2,
            p_th_px: 10.0,
            n_app: 5,
            n_dis: 5,
            selection: Selection::Corrected,
            head_height_m: [1.0, 2.3],
            room_m: [0.0, 0.0, 8.0, 8.5],
            room_margin_m: 0.5,
            gate_m: 1.0,
            accel_sigma_mps2: 2.0,
            max_combinations: 20_000,
            association: Association::Paper,
            ground_separation_m: 0.5,
            occupancy: OccupancyParams::default(),
            detector_noise: Vec::new(),
            noise_seed: 1,
            noise_associations: vec![Association::Ground, Association::Occupancy],
            decompose: false,
            split_frame: 0,
            match_m: vec![0.5, 1.0],
            n_app_sweep: (1..=10).collect(),
            occluded_visibility: 0.8,
            sync_tolerance_s: 0.015,
            figure_obstacles_m: Vec::new(),
            write_tracks: String::new(),
            tracks_topic: "/tracks/cylinders".into(),
        }
    }
}

/// The template shape and head-suppression checks (issue 32).
fn validate_shapes(p: &Params, bad: &mut impl FnMut(&str, String)) {
    if !(p.template_width >= 0.5 && p.template_width <= 3.0) {
        bad(
            "template_width",
            format!(
                "{} is not in [0.5, 3] × the profile's width",
                p.template_width
            ),
        );
    }
    if p.template_grow_px > 16 {
        bad(
            "template_grow_px",
            format!("{} is not in 0..=16 px", p.template_grow_px),
        );
    }
    if !(p.nms_head_radius > 0.0 && p.nms_head_radius <= 5.0) {
        bad(
            "nms_head_radius",
            format!("{} is not in (0, 5] body sizes", p.nms_head_radius),
        );
    }
}

/// The ghost test's checks (issue 32).
fn validate_ghosts(p: &Params, bad: &mut impl FnMut(&str, String)) {
    if p.ghost_band_px == 0 || p.ghost_band_px > 32 {
        bad(
            "ghost_band_px",
            format!("{} is not in 1..=32 px", p.ghost_band_px),
        );
    }
    if p.ghost_grow_px > 32 {
        bad(
            "ghost_grow_px",
            format!("{} is not in 0..=32 px", p.ghost_grow_px),
        );
    }
    if p.ghost_frames == 0 || p.ghost_frames > 1000 {
        bad(
            "ghost_frames",
            format!("{} is not in 1..=1000 frames", p.ghost_frames),
        );
    }
}

/// The checks of `occupancy`, `detector_noise` and `noise_associations` (issue 32).
fn validate_noise(p: &Params, bad: &mut impl FnMut(&str, String)) {
    if let Err(e) = p.occupancy.validate() {
        bad("occupancy", e.to_string());
    }
    for (k, n) in p.detector_noise.iter().enumerate() {
        if let Err(e) = n.validate() {
            bad("detector_noise", format!("level {}: {e}", k + 1));
        }
    }
    if !p.detector_noise.is_empty() && p.noise_associations.is_empty() {
        bad(
            "noise_associations",
            "needs at least one association to run the noise levels with".into(),
        );
    }
}

/// Parameter checks beyond types: `(key, reason)` for each problem.
pub(crate) fn validate(p: &Params) -> Vec<Invalid> {
    let mut out: Vec<Invalid> = Vec::new();
    let mut bad = |k: &str, r: String| out.push((k.to_string(), r));
    if p.cameras.len() < 2 {
        bad(
            "cameras",
            format!(
                "{} camera(s): triangulation needs at least 2",
                p.cameras.len()
            ),
        );
    }
    if !(p.alpha > 0.0 && p.alpha < 1.0) {
        bad(
            "alpha",
            format!("{} is not in (0, 1) (paper: 0.01–0.1)", p.alpha),
        );
    }
    if !(p.gabor_sigma_px >= 0.5 && p.gabor_sigma_px <= 20.0) {
        bad(
            "gabor_sigma_px",
            format!("{} is not in [0.5, 20] px", p.gabor_sigma_px),
        );
    }
    if !(p.gabor_wavelength_px >= 2.0 && p.gabor_wavelength_px.is_finite()) {
        bad(
            "gabor_wavelength_px",
            format!("{} is below 2 px", p.gabor_wavelength_px),
        );
    }
    if !(p.foreground_alpha >= 0.0 && p.foreground_alpha < 1.0) {
        bad(
            "foreground_alpha",
            format!("{} is not in [0, 1)", p.foreground_alpha),
        );
    }
    validate_ghosts(p, &mut bad);
    if !(p.mad_k >= 0.0 && p.mad_k.is_finite()) {
        bad("mad_k", format!("{} is not a finite number ≥ 0", p.mad_k));
    }
    if !(p.template_threshold > 0.0 && p.template_threshold < 1.0) {
        bad(
            "template_threshold",
            format!(
                "{} is not in (0, 1) (paper: 0.6–0.75)",
                p.template_threshold
            ),
        );
    }
    if !(p.template_fill > 0.0 && p.template_fill <= 1.0) {
        bad(
            "template_fill",
            format!("{} is not a fraction in (0, 1]", p.template_fill),
        );
    }
    for (key, n) in [
        ("template_scales", p.template_scales),
        ("template_tilts", p.template_tilts),
    ] {
        if n == 0 || p.template_scales.saturating_mul(p.template_tilts) > 64 {
            bad(key, "scales × tilts must be between 1 and 64".into());
        }
    }
    validate_shapes(p, &mut bad);
    if p.template_stride_px == 0 || p.template_stride_px > 16 {
        bad(
            "template_stride_px",
            format!("{} is not in 1..=16", p.template_stride_px),
        );
    }
    if !(p.person_height_m > 0.5 && p.person_height_m < 2.5) {
        bad(
            "person_height_m",
            format!("{} is not a person's height in metres", p.person_height_m),
        );
    }
    for (key, v, what) in [
        ("p_th_px", p.p_th_px, "number of pixels"),
        ("gate_m", p.gate_m, "distance in metres"),
        (
            "accel_sigma_mps2",
            p.accel_sigma_mps2,
            "acceleration in m/s²",
        ),
    ] {
        if !(v > 0.0 && v.is_finite()) {
            bad(key, format!("{v} is not a positive {what}"));
        }
    }
    for (key, n) in [("n_app", p.n_app), ("n_dis", p.n_dis)] {
        if n == 0 {
            bad(key, "N_app and N_dis must be at least 1 frame".into());
        }
    }
    for (key, v) in [
        ("match_iou_2d", p.match_iou_2d),
        ("nms_iou", p.nms_iou),
        ("nms_contained", p.nms_contained),
    ] {
        if !(0.0..=1.0).contains(&v) {
            bad(key, format!("{v} is not in [0, 1]"));
        }
    }
    if !(p.room_margin_m >= 0.0 && p.room_margin_m.is_finite()) {
        bad(
            "room_margin_m",
            format!("{} is not a finite distance ≥ 0 m", p.room_margin_m),
        );
    }
    if p.max_combinations == 0 {
        bad("max_combinations", "must be at least 1".into());
    }
    if !(p.ground_separation_m >= 0.0 && p.ground_separation_m.is_finite()) {
        bad(
            "ground_separation_m",
            format!("{} is not a finite distance ≥ 0 m", p.ground_separation_m),
        );
    }
    validate_noise(p, &mut bad);
    if p.n_app_sweep.contains(&0) {
        bad("n_app_sweep", "values must be at least 1".into());
    }
    if p.match_m.is_empty() || p.match_m.iter().any(|&m| !(m > 0.0 && m.is_finite())) {
        bad("match_m", "needs positive distances in metres".into());
    }
    if p.head_height_m[0].partial_cmp(&p.head_height_m[1]) != Some(std::cmp::Ordering::Less) {
        bad("head_height_m", "the range is empty".into());
    }
    if !(p.room_m[0] < p.room_m[2] && p.room_m[1] < p.room_m[3]) {
        bad(
            "room_m",
            "needs [x0, y0, x1, y1] with x0 < x1 and y0 < y1".into(),
        );
    }
    if !(p.sync_tolerance_s > 0.0 && p.sync_tolerance_s < 1.0) {
        bad(
            "sync_tolerance_s",
            format!("{} is not in (0, 1) s", p.sync_tolerance_s),
        );
    }
    if !(0.0..=1.0).contains(&p.occluded_visibility) {
        bad(
            "occluded_visibility",
            format!("{} is not in [0, 1]", p.occluded_visibility),
        );
    }
    out
}

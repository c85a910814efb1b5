//! `[params]` of `pipelines/s003_zivkovic_background.toml`, their validation, the topics read
//! and the names shared by the sub-experiments.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::groundtruth::PEOPLE_TOPIC;
use crate::run::config::Invalid;
use crate::vision::GmmParams;
use crate::vision::colortrack::{ColorSpace, ColorTrackError, EmParams, MeanShiftParams};
use crate::vision::gmm::GmmError;
use crate::vision::local::{LocalError, LocalParams};
use crate::vision::moving::MovingParams;
use crate::vision::sg1999::Sg1999Params;

use super::reid_params::validate_reid;
pub use super::reid_params::{ClipParams, ReidParams};

/// `[params.roc]`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RocParams {
    /// c_thr values (squared Mahalanobis distance, OpenCV's `varThreshold`) swept for the ROC.
    pub var_thresholds: Vec<f32>,
    /// Frames at the start of a session left out of the counts (both models still learning).
    pub skip_frames: usize,
    /// The adaptive model (its `var_threshold` is replaced by each swept value).
    pub adaptive: GmmParams,
    /// The fixed-M baseline.
    pub baseline: GmmParams,
    /// False-positive rates (%) at which the summary reads each curve's true-positive rate.
    pub fp_at_pct: Vec<f64>,
    /// Datasets with exact masks that are *not* ROC / timing / components scenes (e.g. the
    /// static-background walker sequence of the colour-tracker comparison).
    pub exclude_datasets: Vec<String>,
    /// More models scored beside the two (`[[params.roc.extra]]`): rows of `roc`, columns
    /// of `roc_summary` (not timed).
    pub extra: Vec<RocVariant>,
}

/// One more ROC model (`[[params.roc.extra]]`): a `name` (its `roc_summary` column), a
/// `label` (its `model` in `roc` and the figures) and exactly one model table — `gmm`
/// (Zivkovic's model / OpenCV MOG2 with any parameters, `var_threshold` swept) or `sg1999`
/// (Stauffer & Grimson as published, `vision::sg1999`; its Mahalanobis threshold swept).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RocVariant {
    pub name: String,
    pub label: String,
    #[serde(default)]
    pub gmm: Option<GmmParams>,
    #[serde(default)]
    pub sg1999: Option<Sg1999Params>,
}

impl RocVariant {
    /// The two printed models of seed 003's comparison (README, "Which GMM each table uses").
    pub fn printed() -> Vec<Self> {
        vec![
            Self {
                name: "printed".into(),
                label: "adaptive GMM as printed (c_T = 0.01; dropped when negative)".into(),
                gmm: Some(GmmParams::zivkovic_printed()),
                sg1999: None,
            },
            Self {
                name: "sg1999".into(),
                label: "Stauffer-Grimson 1999 as published (omega/sigma ranking; rho = alpha eta)"
                    .into(),
                gmm: None,
                sg1999: Some(Sg1999Params::default()),
            },
        ]
    }
}

/// Columns of `roc_summary` besides the variants' names.
const SUMMARY_COLUMNS: [&str; 4] = ["dataset", "measure", "adaptive", "fixed_m4"];

/// The `[[params.roc.extra]]` entries: a unique column-safe name, a label unlike the two
/// models', exactly one model table, valid model parameters.
fn validate_extra(roc: &RocParams, bad: &mut impl FnMut(&str, String)) {
    let mut seen = std::collections::BTreeSet::new();
    for (i, v) in roc.extra.iter().enumerate() {
        let key = format!("roc.extra[{i}]");
        let safe = !v.name.is_empty()
            && v.name
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_');
        if !safe || SUMMARY_COLUMNS.contains(&v.name.as_str()) {
            bad(
                &format!("{key}.name"),
                format!(
                    "`{}` must be lowercase letters, digits and _ and not one of {SUMMARY_COLUMNS:?}",
                    v.name
                ),
            );
        }
        if !seen.insert(v.name.clone()) {
            bad(
                &format!("{key}.name"),
                format!("`{}` is used twice", v.name),
            );
        }
        if v.label.trim().is_empty()
            || [model_name(true), model_name(false)].contains(&v.label.as_str())
        {
            bad(
                &format!("{key}.label"),
                format!(
                    "`{}` must be non-empty and unlike the two models' labels",
                    v.label
                ),
            );
        }
        let problem = match (&v.gmm, &v.sg1999) {
            (Some(g), None) => g.validate().err().map(|e| gmm_problem(&format!("{key}.gmm"), &e)),
            (None, Some(sg)) => sg
                .validate()
                .err()
                .map(|e| gmm_problem(&format!("{key}.sg1999"), &e)),
            _ => Some((
                key.clone(),
                "needs exactly one model table: [params.roc.extra.gmm] or [params.roc.extra.sg1999]"
                    .into(),
            )),
        };
        if let Some((k, r)) = problem {
            bad(&k, r);
        }
    }
}

impl Default for RocParams {
    fn default() -> Self {
        Self {
            var_thresholds: vec![4.0, 6.0, 9.0, 12.0, 16.0, 25.0, 36.0, 64.0, 100.0, 144.0],
            skip_frames: 45,
            adaptive: GmmParams::default(),
            baseline: GmmParams::stauffer_grimson(),
            fp_at_pct: vec![0.5, 1.0, 2.0],
            exclude_datasets: Vec::new(),
            extra: RocVariant::printed(),
        }
    }
}

/// `[params.colour]`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ColourParams {
    /// Datasets on which the trackers are compared.
    pub datasets: Vec<String>,
    /// Ground-truth id of the person tracked.
    pub person: u32,
    /// If set, only the person with that id *and* this height (m, ±5 mm) is tracked: two
    /// people of one log can share an id (the synthesizer numbers its crowd from 1 again when
    /// a scenario also has scripted people).
    pub person_height_m: Option<f64>,
    /// Frames where the person is less visible than this are not used (initialisation, errors).
    pub min_visibility: f64,
    /// A person whose box comes this close to the image border is truncated: not used (px).
    pub border_px: f64,
    pub spaces: Vec<ColorSpace>,
    pub em: EmParams,
    /// If set, the EM-like tracker runs a second time with this β (e.g. the value consistent
    /// with the 2-D 2.5σ cut-off, 1.168, beside the paper's 1.1), as method "EM-like β=…".
    pub compare_beta: Option<f64>,
    pub mean_shift: MeanShiftParams,
    /// Overlay figure: frames this far apart after initialisation.
    pub overlay_every: usize,
    pub overlay_count: usize,
}

impl Default for ColourParams {
    fn default() -> Self {
        Self {
            datasets: vec!["home_tour_walker".into()],
            person: 1,
            person_height_m: None,
            min_visibility: 0.95,
            border_px: 2.0,
            spaces: vec![ColorSpace::Hs, ColorSpace::Rgb],
            em: EmParams::default(),
            compare_beta: None,
            mean_shift: MeanShiftParams::default(),
            overlay_every: 15,
            overlay_count: 4,
        }
    }
}

/// `[params.local_eval]`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LocalEvalParams {
    /// A track box matches a ground-truth box at this IoU or more (MOTChallenge: 0.5).
    pub min_iou: f64,
    /// Ground-truth people less visible than this are left out.
    pub min_visibility: f64,
    /// The camera moves when odometry reports more than this speed (m/s) ...
    pub moving_speed_mps: f64,
    /// ... or turn rate (rad/s), averaged over the odometry samples of the last
    /// `moving_window_s` seconds before the frame (a single sample's noise is no motion).
    pub moving_turn_rad_s: f64,
    /// Averaging window of the odometry twist (s); 0 = the nearest sample alone.
    pub moving_window_s: f64,
}

impl Default for LocalEvalParams {
    fn default() -> Self {
        Self {
            min_iou: 0.5,
            min_visibility: 0.3,
            moving_speed_mps: 0.02,
            moving_turn_rad_s: 0.02,
            moving_window_s: 0.3,
        }
    }
}

/// `[params.wallflower]`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WallflowerParams {
    /// Folder of the WavingTrees frames (`b00000.bmp` …) and `hand_segmented_00247.BMP`;
    /// skipped with a note when absent.
    pub dir: String,
    pub eval_frame: usize,
}

impl Default for WallflowerParams {
    fn default() -> Self {
        Self {
            dir: "../shared/real/wallflower_waving_trees/WavingTrees".into(),
            eval_frame: 247,
        }
    }
}

/// `[params.moving]`: the moving-camera detection of Zajdel et al. §III-B (KLT corners, a
/// RANSAC fundamental matrix, the outliers as moving people), scored on the frames where the
/// camera moves. See `vision::moving` for what each value means.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MovingDetectParams {
    /// The paper's 100 corner-like points.
    pub corners: usize,
    pub min_distance_px: f32,
    pub ransac_threshold_px: f64,
    pub ransac_iterations: usize,
    pub min_points: usize,
    pub cluster_px: f64,
    pub gate_sigma: f64,
    /// An object's box spans ± this many standard deviations of its points (√3: the extent
    /// of a uniform spread).
    pub box_sigma: f64,
}

impl Default for MovingDetectParams {
    fn default() -> Self {
        let d = MovingParams::default();
        Self {
            corners: d.corners,
            min_distance_px: d.min_distance_px,
            ransac_threshold_px: d.ransac_threshold_px,
            ransac_iterations: d.ransac_iterations,
            min_points: d.min_points,
            cluster_px: d.cluster_px,
            gate_sigma: d.gate_sigma,
            box_sigma: 3f64.sqrt(),
        }
    }
}

impl MovingDetectParams {
    /// The detector's settings.
    pub fn detector(&self) -> MovingParams {
        MovingParams {
            corners: self.corners,
            min_distance_px: self.min_distance_px,
            ransac_threshold_px: self.ransac_threshold_px,
            ransac_iterations: self.ransac_iterations,
            min_points: self.min_points,
            cluster_px: self.cluster_px,
            gate_sigma: self.gate_sigma,
            ..MovingParams::default()
        }
    }
}

/// `[params]` of `pipelines/s003_zivkovic_background.toml`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Params {
    /// Camera whose ground-truth views are read.
    pub camera: String,
    pub roc: RocParams,
    pub colour: ColourParams,
    pub local: LocalParams,
    pub local_eval: LocalEvalParams,
    pub wallflower: WallflowerParams,
    pub reid: ReidParams,
    pub moving: MovingDetectParams,
}

impl Default for Params {
    fn default() -> Self {
        Self {
            camera: "cam_0".into(),
            roc: RocParams::default(),
            colour: ColourParams::default(),
            local: LocalParams::default(),
            local_eval: LocalEvalParams::default(),
            wallflower: WallflowerParams::default(),
            reid: ReidParams::default(),
            moving: MovingDetectParams::default(),
        }
    }
}

fn topic(topics: &BTreeMap<String, String>, logical: &str, default: String) -> String {
    topics.get(logical).cloned().unwrap_or(default)
}

/// The logical topic names `[topics]` may remap.
pub(super) const TOPIC_KEYS: [&str; 5] = ["image", "mask", "ground_truth", "odom", "person_ids"];

/// The topics read, with `[topics]` remaps applied.
pub(super) struct Topics {
    pub image: String,
    pub mask: String,
    pub ground_truth: String,
    pub odom: String,
    /// The per-person id mask (`mono8`, each pixel the id of the person seen there).
    pub person_ids: String,
}

pub(super) fn topics_of(p: &Params, t: &BTreeMap<String, String>) -> Topics {
    Topics {
        image: topic(t, "image", format!("/{}/image_raw/compressed", p.camera)),
        mask: topic(t, "mask", format!("/{}/ground_truth_mask", p.camera)),
        ground_truth: topic(t, "ground_truth", PEOPLE_TOPIC.to_string()),
        odom: topic(t, "odom", "/odom".to_string()),
        person_ids: topic(t, "person_ids", format!("/{}/ground_truth_ids", p.camera)),
    }
}

/// `(key path, reason)` of a GMM parameter error under `prefix` (e.g. `roc.adaptive`).
fn gmm_problem(prefix: &str, e: &GmmError) -> Invalid {
    match e {
        GmmError::BadParam { name, value, why } => {
            (format!("{prefix}.{name}"), format!("{value} {why}"))
        }
        other => (prefix.to_string(), other.to_string()),
    }
}

/// `(key path, reason)` of a colour-tracker parameter error under `prefix`.
fn colour_problem(prefix: &str, e: &ColorTrackError) -> Invalid {
    match e {
        ColorTrackError::BadParam { name, value, why } => {
            (format!("{prefix}.{name}"), format!("{value} {why}"))
        }
        other => (prefix.to_string(), other.to_string()),
    }
}

/// `(key path, reason)` of a local-tracking parameter error (`[params.local]` and its
/// `gmm` / `em` tables).
fn local_problem(e: &LocalError) -> Invalid {
    match e {
        LocalError::BadParam { name, value, why } => {
            (format!("local.{name}"), format!("{value} {why}"))
        }
        LocalError::Gmm(g) => gmm_problem("local.gmm", g),
        LocalError::Colour(c) => colour_problem("local.em", c),
        other => ("local".into(), other.to_string()),
    }
}

fn validate_moving(m: &MovingDetectParams, bad: &mut impl FnMut(&str, String)) {
    for (key, v) in [
        ("moving.min_distance_px", f64::from(m.min_distance_px)),
        ("moving.ransac_threshold_px", m.ransac_threshold_px),
        ("moving.cluster_px", m.cluster_px),
        ("moving.gate_sigma", m.gate_sigma),
        ("moving.box_sigma", m.box_sigma),
    ] {
        if !(v.is_finite() && v > 0.0) {
            bad(key, format!("{v} must be finite and positive"));
        }
    }
    for (key, v) in [
        ("moving.corners", m.corners),
        ("moving.ransac_iterations", m.ransac_iterations),
        ("moving.min_points", m.min_points),
    ] {
        if v == 0 {
            bad(key, "must be at least 1".into());
        }
    }
}

pub(super) fn validate(p: &Params) -> Vec<Invalid> {
    let mut out: Vec<Invalid> = Vec::new();
    let mut bad = |k: &str, r: String| out.push((k.to_string(), r));
    if p.roc.var_thresholds.is_empty()
        || p.roc
            .var_thresholds
            .iter()
            .any(|v| !(v.is_finite() && *v > 0.0))
    {
        bad("roc.var_thresholds", "needs finite values > 0".into());
    }
    for (name, g) in [
        ("roc.adaptive", &p.roc.adaptive),
        ("roc.baseline", &p.roc.baseline),
    ] {
        if let Err(e) = g.validate() {
            let (k, r) = gmm_problem(name, &e);
            bad(&k, r);
        }
    }
    if let Err(e) = p.local.validate() {
        let (k, r) = local_problem(&e);
        bad(&k, r);
    }
    if let Err(e) = p.colour.em.validate() {
        let (k, r) = colour_problem("colour.em", &e);
        bad(&k, r);
    }
    if let Err(e) = p.colour.mean_shift.validate() {
        let (k, r) = colour_problem("colour.mean_shift", &e);
        bad(&k, r);
    }
    if let Some(beta) = p.colour.compare_beta
        && !(beta.is_finite() && beta > 0.0)
    {
        bad(
            "colour.compare_beta",
            format!("{beta} must be finite and positive"),
        );
    }
    if p.colour.spaces.is_empty() {
        bad("colour.spaces", "needs at least one colour space".into());
    }
    if let Some(h) = p.colour.person_height_m
        && !(h.is_finite() && h > 0.0)
    {
        bad(
            "colour.person_height_m",
            format!("{h} must be finite and positive"),
        );
    }
    for (key, v) in [
        ("colour.min_visibility", p.colour.min_visibility),
        ("local_eval.min_iou", p.local_eval.min_iou),
        ("local_eval.min_visibility", p.local_eval.min_visibility),
    ] {
        if !(0.0..=1.0).contains(&v) {
            bad(key, format!("{v} is not in [0, 1]"));
        }
    }
    for (key, v) in [
        ("colour.border_px", p.colour.border_px),
        ("local_eval.moving_speed_mps", p.local_eval.moving_speed_mps),
        (
            "local_eval.moving_turn_rad_s",
            p.local_eval.moving_turn_rad_s,
        ),
        ("local_eval.moving_window_s", p.local_eval.moving_window_s),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            bad(key, format!("{v} must be finite and non-negative"));
        }
    }
    validate_extra(&p.roc, &mut bad);
    validate_reid(&p.reid, &mut bad);
    validate_moving(&p.moving, &mut bad);
    if p.roc.fp_at_pct.iter().any(|v| !(0.0..=100.0).contains(v)) {
        bad(
            "roc.fp_at_pct",
            "values must be percentages in [0, 100]".into(),
        );
    }
    out
}

/// The two background models' names in every table.
pub(super) fn model_name(adaptive: bool) -> &'static str {
    if adaptive {
        "adaptive GMM (Zivkovic)"
    } else {
        "fixed M = 4 (Stauffer-Grimson)"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_bad_values_are_named() {
        assert!(validate(&Params::default()).is_empty());
        let mut p = Params::default();
        p.roc.var_thresholds = vec![16.0, -1.0];
        p.roc.fp_at_pct = vec![101.0];
        p.local_eval.min_iou = 1.5;
        p.colour.compare_beta = Some(f64::NAN);
        p.roc.baseline.history = 0;
        p.local.gmm.n_mixtures = 0;
        p.local.em.beta = -1.0;
        p.local.gate_sigma = f64::NAN;
        let names: Vec<String> = validate(&p).into_iter().map(|(n, _)| n).collect();
        assert_eq!(
            names,
            [
                "roc.var_thresholds",
                "roc.baseline.history",
                "local.gmm.n_mixtures",
                "colour.compare_beta",
                "local_eval.min_iou",
                "roc.fp_at_pct"
            ]
        );
        // the GMM and colour tracker of [params.local] are checked before its own keys
        p.local.gmm.n_mixtures = 5;
        assert!(validate(&p).iter().any(|(n, _)| n == "local.em.beta"));
        p.local.em.beta = 1.1;
        assert!(validate(&p).iter().any(|(n, _)| n == "local.gate_sigma"));
        let mut m = Params::default();
        m.moving.corners = 0;
        m.moving.ransac_threshold_px = f64::INFINITY;
        let names: Vec<String> = validate(&m).into_iter().map(|(n, _)| n).collect();
        assert_eq!(names, ["moving.ransac_threshold_px", "moving.corners"]);
    }

    #[test]
    fn extra_roc_models_are_checked_and_named() {
        let mut p = Params::default();
        assert_eq!(p.roc.extra.len(), 2);
        p.roc.extra[0].name = "fixed_m4".into();
        p.roc.extra[1].name = "Bad Name".into();
        p.roc.extra[1].sg1999 = Some(Sg1999Params {
            k: 0,
            ..Sg1999Params::default()
        });
        let mut both = RocVariant::printed().remove(1);
        both.name = "both".into();
        both.gmm = Some(GmmParams::default());
        let mut twice = RocVariant::printed().remove(0);
        twice.label = model_name(true).into();
        p.roc.extra.push(both);
        p.roc.extra.push(twice);
        let names: Vec<String> = validate(&p).into_iter().map(|(n, _)| n).collect();
        assert_eq!(
            names,
            [
                "roc.extra[0].name",
                "roc.extra[1].name",
                "roc.extra[1].sg1999.k",
                "roc.extra[2]",
                "roc.extra[3].label"
            ]
        );
        // and from TOML: a model table the variant does not know is a clear error
        let ok: RocParams = toml::from_str(
            "[[extra]]\nname = \"p\"\nlabel = \"P\"\n[extra.gmm]\ncomplexity_reduction = 0.01\npruning = \"negative\"\n",
        )
        .expect("parses");
        assert_eq!(
            ok.extra[0].gmm.map(|g| g.pruning),
            Some(crate::vision::Pruning::Negative)
        );
        let err =
            toml::from_str::<RocParams>("[[extra]]\nname = \"p\"\nlabel = \"P\"\n[extra.mog]\n")
                .expect_err("unknown table")
                .to_string();
        assert!(err.contains("unknown field `mog`"), "{err}");
        let err = toml::from_str::<RocParams>(
            "[[extra]]\nname = \"p\"\nlabel = \"P\"\n[extra.gmm]\npruning = \"never\"\n",
        )
        .expect_err("unknown rule")
        .to_string();
        assert!(err.contains("unknown variant `never`"), "{err}");
    }

    #[test]
    fn topics_default_to_the_camera_and_follow_remaps() {
        let p = Params::default();
        let t = topics_of(&p, &BTreeMap::new());
        assert_eq!(t.image, "/cam_0/image_raw/compressed");
        assert_eq!(t.mask, "/cam_0/ground_truth_mask");
        assert_eq!(t.person_ids, "/cam_0/ground_truth_ids");
        let remap = BTreeMap::from([("odom".to_string(), "/robot/odom".to_string())]);
        assert_eq!(topics_of(&p, &remap).odom, "/robot/odom");
    }
}

//! `[params]` of `pipelines/s000_cielniak_omni.toml` and their validation.

use serde::{Deserialize, Serialize};

use crate::learn::mlp::TrainSpec;
use crate::run::config::Invalid;

/// `[params]` of `pipelines/s000_cielniak_omni.toml`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Params {
    /// Webcams of the external measurement system (their topic and TF frame names).
    pub webcams: Vec<String>,
    /// The omnidirectional camera.
    pub omni: String,
    /// Hat colour: hue band (degrees) and minimum saturation and value.
    pub hat_hue_deg: [f64; 2],
    pub hat_min_saturation: f64,
    pub hat_min_value: f64,
    pub hat_min_area: u32,
    /// Panorama size (the paper: 480 × 120).
    pub panorama: [usize; 2],
    /// Inner radius of the unwrapped ring as a fraction of the mirror's image radius.
    pub inner_radius: f64,
    /// Person-free frames at the start of each session that make the background (paper: 5).
    pub background_frames: usize,
    pub train_fraction: f64,
    pub splits: usize,
    pub hidden_units: usize,
    pub learning_rate: f64,
    pub epochs: usize,
    pub sweep_hidden: Vec<usize>,
    pub sweep_learning_rates: Vec<f64>,
    pub sweep_splits: usize,
    pub seed: u64,
    /// Kalman: frames further apart than this (s) start a new track.
    pub max_gap_s: f64,
    /// Use a trained model file instead of training (empty: train).
    pub model: String,
    /// Also save the general model trained on all data here (relative to out/s000_cielniak_omni/).
    pub save_model: String,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            webcams: (0..4).map(|k| format!("cam_{k}")).collect(),
            omni: "omni_camera".into(),
            hat_hue_deg: [90.0, 150.0],
            hat_min_saturation: 0.45,
            hat_min_value: 0.25,
            hat_min_area: 6,
            panorama: [480, 120],
            inner_radius: 0.12,
            background_frames: 5,
            train_fraction: 0.3,
            splits: 10,
            hidden_units: 4,
            learning_rate: 0.3,
            epochs: 2000,
            sweep_hidden: (1..=10).collect(),
            sweep_learning_rates: vec![0.05, 0.1, 0.3, 0.5, 0.8],
            sweep_splits: 3,
            seed: 7,
            max_gap_s: 1.5,
            model: String::new(),
            save_model: "models/omni_appearance.json".into(),
        }
    }
}

impl Params {
    /// The network of the main protocol (3-H-1, learning rate, epochs).
    pub fn spec(&self) -> TrainSpec {
        TrainSpec {
            hidden: self.hidden_units,
            learning_rate: self.learning_rate,
            epochs: self.epochs,
        }
    }
}

/// Largest panorama side (px): the paper's is 480 × 120; beyond this a frame's panorama alone
/// takes hundreds of megabytes.
pub const MAX_PANORAMA_PX: usize = 8192;

/// Every problem with `p`, as (parameter, reason).
pub fn validate(p: &Params) -> Vec<Invalid> {
    let mut out: Vec<Invalid> = Vec::new();
    let mut bad = |k: &str, r: String| out.push((k.to_string(), r));
    if !(p.train_fraction > 0.0 && p.train_fraction < 1.0) {
        bad(
            "train_fraction",
            format!("{} is not in (0, 1)", p.train_fraction),
        );
    }
    if p.webcams.len() == 1 || p.webcams.is_empty() && p.model.is_empty() {
        bad(
            "webcams",
            "the measurement system needs at least two cameras (or none, with `model` set, to only estimate positions)".into(),
        );
    }
    if p.hidden_units == 0 {
        bad(
            "hidden_units",
            "a network needs at least one hidden unit".into(),
        );
    }
    if p.sweep_hidden.contains(&0) {
        bad(
            "sweep_hidden",
            "a network needs at least one hidden unit".into(),
        );
    }
    if !(p.learning_rate > 0.0 && p.learning_rate < 10.0) {
        bad(
            "learning_rate",
            format!("{} is not in (0, 10)", p.learning_rate),
        );
    }
    if let Some(lr) = p
        .sweep_learning_rates
        .iter()
        .find(|lr| !(**lr > 0.0 && **lr < 10.0))
    {
        bad("sweep_learning_rates", format!("{lr} is not in (0, 10)"));
    }
    if !p.sweep_hidden.is_empty() && p.sweep_learning_rates.is_empty() {
        bad(
            "sweep_learning_rates",
            "[] leaves the sweep over `sweep_hidden` empty: give at least one learning rate (or `sweep_hidden = []` for no sweep)".into(),
        );
    }
    for (key, n, what) in [
        ("splits", p.splits, "random splits"),
        (
            "sweep_splits",
            p.sweep_splits,
            "random splits per sweep cell",
        ),
        (
            "epochs",
            p.epochs,
            "epochs (0 leaves the network untrained)",
        ),
    ] {
        if n == 0 {
            bad(key, format!("needs at least 1 of {what}"));
        }
    }
    if p.background_frames < 2 {
        bad(
            "background_frames",
            "the background needs at least 2 frames".into(),
        );
    }
    let [w, h] = p.panorama;
    if !(8..=MAX_PANORAMA_PX).contains(&w) || !(4..=MAX_PANORAMA_PX).contains(&h) {
        bad(
            "panorama",
            format!(
                "[{w}, {h}] is not a panorama size: width 8..={MAX_PANORAMA_PX}, height 4..={MAX_PANORAMA_PX} px (paper: [480, 120])"
            ),
        );
    }
    if !(p.inner_radius > 0.0 && p.inner_radius < 1.0) {
        bad("inner_radius", "must be a fraction in (0, 1)".into());
    }
    let [lo, hi] = p.hat_hue_deg;
    if !(lo.is_finite() && hi.is_finite() && lo < hi && (0.0..=360.0).contains(&lo) && hi <= 360.0)
    {
        bad(
            "hat_hue_deg",
            format!("[{lo}, {hi}] is not a hue band in 0..=360 degrees"),
        );
    }
    for (key, v) in [
        ("hat_min_saturation", p.hat_min_saturation),
        ("hat_min_value", p.hat_min_value),
    ] {
        if !(0.0..=1.0).contains(&v) {
            bad(key, format!("{v} is not in [0, 1]"));
        }
    }
    if !(p.max_gap_s > 0.0 && p.max_gap_s.is_finite()) {
        bad(
            "max_gap_s",
            format!("{} is not a positive number of seconds", p.max_gap_s),
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(p: &Params) -> Vec<String> {
        validate(p).into_iter().map(|(n, _)| n).collect()
    }

    #[test]
    fn the_defaults_are_valid() {
        assert!(validate(&Params::default()).is_empty());
    }

    #[test]
    fn each_bad_value_names_its_parameter() {
        let bad = Params {
            train_fraction: 1.0,
            webcams: vec!["cam_0".into()],
            sweep_hidden: vec![0],
            learning_rate: 0.0,
            background_frames: 1,
            inner_radius: 1.0,
            ..Params::default()
        };
        assert_eq!(
            names(&bad),
            [
                "train_fraction",
                "webcams",
                "sweep_hidden",
                "learning_rate",
                "background_frames",
                "inner_radius"
            ]
        );
        let bad = Params {
            splits: 0,
            sweep_splits: 0,
            epochs: 0,
            panorama: [480, 0],
            hat_hue_deg: [150.0, 90.0],
            max_gap_s: 0.0,
            ..Params::default()
        };
        assert_eq!(
            names(&bad),
            [
                "splits",
                "sweep_splits",
                "epochs",
                "panorama",
                "hat_hue_deg",
                "max_gap_s"
            ]
        );
    }

    #[test]
    fn no_webcams_needs_a_model() {
        let p = Params {
            webcams: Vec::new(),
            ..Params::default()
        };
        assert_eq!(names(&p), ["webcams"]);
        let p = Params {
            model: "m.json".into(),
            ..p
        };
        assert!(names(&p).is_empty());
    }
}

//! `s004_mohedano_multicam`: seed 004 (Mohedano et al.) end to end — Gabor-feature background
//! subtraction with a MAD threshold (§2), silhouette-template detection (§3), 2-D tracking by
//! graph matching (§4) and the multi-camera geometry-based 3-D tracker that models people as
//! cylinders (§5) — on calibrated cameras (`CameraInfo` + TF), with the paper's evaluation
//! extended to numbers: 3-D position, height and radius errors, CLEAR MOT and IDF1 at 0.5 m
//! and 1 m, detection latency and false alarms against `N_app`, head point versus blob
//! centroid under static occlusion (t-test), and `E_c` versus `E_m` as the selection rule.
//!
//! Per session (cached), the images of all cameras are read once, in time order, and grouped
//! into frames by header stamp; each camera runs background, detection and 2-D tracking
//! (cameras in parallel). The 2-D objects of every frame are kept, so the 3-D stage runs
//! several times on the same input: the configured one, `N_app` = 1..10, and `E_m` selection.
//! The same 3-D stage also runs on the ground-truth boxes of synthetic logs (isolating it
//! from detection) and, with `detector = "log"`, on any detector's
//! `vision_msgs/msg/Detection2DArray` per camera ("bring your own detector").
//!
//! Outputs: the tracks (per frame, per person: position, height, radius, supporting cameras,
//! `E_m`), tables and figures under `out/s004_mohedano_multicam/`, and with `write_tracks` the
//! tracks written back into a copy of each log as `visualization_msgs/msg/MarkerArray`
//! (cylinders and labels in the world frame) that Foxglove's 3-D and image panels draw over
//! the cameras.
//!
//! Layout, in the direction data flows: `params` (the pipeline file's `[params]` and their
//! checks); `session` (per session: calibration and camera frames through `crate::frames`, each
//! camera's chain, the ground-truth-box run, the 3-D runs, the per-frame scores and the camera
//! view for the figure) writes the row structs of `tables`, the only thing cached; `scored`
//! reads them back and evaluates every run once; `evaluate` (one file per sub-experiment) and
//! `figures` turn them into tables and figures; `aggregate` orders the products; `markers` is
//! the `--write-tracks` export, the one step of aggregation that reads the logs, run only when
//! asked.

mod aggregate;
mod evaluate;
mod figures;
mod markers;
mod params;
mod scored;
mod session;
mod tables;

use std::collections::BTreeMap;

use crate::progress::Progress;

use crate::groundtruth::PEOPLE_TOPIC;
use crate::run::config::Invalid;
use crate::run::{Aggregate, Experiment, Products, Session, SessionTables, Stage};

pub use params::{BackgroundUpdate, Detector, Nms, Params};

pub struct MulticamCylinders;

/// Per-camera topics after `[topics]` remaps.
#[derive(Debug, Clone)]
pub(crate) struct Topics {
    pub image: Vec<String>,
    pub info: Vec<String>,
    pub detections: Vec<String>,
    pub ground_truth: String,
}

pub(crate) fn topics(p: &Params, remap: &BTreeMap<String, String>) -> Topics {
    let get = |key: String, default: String| remap.get(&key).cloned().unwrap_or(default);
    Topics {
        image: p
            .cameras
            .iter()
            .map(|c| get(format!("{c}_image"), format!("/{c}/image_raw/compressed")))
            .collect(),
        info: p
            .cameras
            .iter()
            .map(|c| get(format!("{c}_info"), format!("/{c}/camera_info")))
            .collect(),
        detections: p
            .cameras
            .iter()
            .map(|c| get(format!("{c}_detections"), format!("/{c}/detections")))
            .collect(),
        ground_truth: get("ground_truth".into(), PEOPLE_TOPIC.into()),
    }
}

impl Experiment for MulticamCylinders {
    const KIND: &'static str = "s004_mohedano_multicam";
    const VERSION: u32 = 4;
    const SESSION_TABLES: &'static [crate::run::schemas::TableDoc] = tables::SESSION_TABLES;
    type Params = Params;

    fn validate(p: &Params) -> Vec<Invalid> {
        params::validate(p)
    }

    fn topic_keys(p: &Params) -> Vec<String> {
        let mut keys: Vec<String> = p
            .cameras
            .iter()
            .flat_map(|c| ["image", "info", "detections"].map(|k| format!("{c}_{k}")))
            .collect();
        keys.push("ground_truth".into());
        keys
    }

    fn plan(p: &Params, remap: &BTreeMap<String, String>) -> Vec<Stage> {
        let t = topics(p, remap);
        let mut stages = vec![Stage {
            name: "calibration (camera_info + TF)".into(),
            requires: t.info.clone(),
            optional: vec!["/tf_static".into(), "/tf".into()],
        }];
        match p.detector {
            Detector::Templates => stages.push(Stage {
                name: "Gabor background, templates, 2-D tracks (§2–4)".into(),
                requires: t.image.clone(),
                optional: vec![],
            }),
            Detector::Log => stages.push(Stage {
                name: "log detections, 2-D tracks (§4)".into(),
                requires: t.detections.clone(),
                optional: t.image.clone(),
            }),
        }
        stages.push(Stage {
            name: "3-D cylinders (§5)".into(),
            requires: vec![],
            optional: vec![],
        });
        stages.push(Stage {
            name: "evaluation, ground-truth boxes".into(),
            requires: vec![],
            optional: vec![t.ground_truth],
        });
        stages
    }

    fn process(
        s: &Session,
        p: &Params,
        remap: &BTreeMap<String, String>,
        bar: &dyn Progress,
    ) -> anyhow::Result<SessionTables> {
        session::process(s, p, &topics(p, remap), bar)
    }

    fn aggregate(ctx: &Aggregate, p: &Params) -> anyhow::Result<Products> {
        aggregate::aggregate(ctx, p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::config;

    #[test]
    fn the_shipped_pipeline_file_states_the_code_defaults_and_bad_values_are_named() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("pipelines/s004_mohedano_multicam.toml");
        let text = std::fs::read_to_string(&path).expect("pipeline file");
        let mut file = config::parse::<Params>(&path, &text).expect("parses");
        assert!(MulticamCylinders::validate(&file.params).is_empty());
        // every default is written out in the file, with where it comes from; the furniture
        // of the figure is the dataset's, not a default
        assert_eq!(file.params.figure_obstacles_m.len(), 5);
        file.params.figure_obstacles_m.clear();
        let json = |p: &Params| serde_json::to_value(p).expect("json");
        assert_eq!(json(&file.params), json(&Params::default()));
        let p = Params {
            cameras: vec!["cam_0".into()],
            alpha: 0.0,
            foreground_alpha: 1.0,
            mad_k: f64::NAN,
            ghost_band_px: 0,
            ghost_frames: 0,
            ghost_grow_px: 33,
            ..Params::default()
        };
        let named: Vec<String> = MulticamCylinders::validate(&p)
            .into_iter()
            .map(|(k, _)| k)
            .collect();
        assert_eq!(
            named,
            [
                "cameras",
                "alpha",
                "foreground_alpha",
                "ghost_band_px",
                "ghost_grow_px",
                "ghost_frames",
                "mad_k"
            ]
        );
    }
}

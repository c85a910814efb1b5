//! `s002_brooks_height` — seed 002 (Brooks & Williams, "Tracking People with Networks of
//! Heterogeneous Sensors"): a laser at shin height and a fixed camera fused in an EKF over
//! (x, y, height) that learns the person's height, and a camera-only trial with the learned
//! height.
//!
//! Per session ([`session`], cached as the rows of [`tables`]): the laser's leg pairs as
//! range–bearing observations (§3, [`crate::laser::legs`]); the camera's person detections as
//! bearing + elevation of the head top (§4, [`camera`]: Jabri background subtraction, skin
//! histogram from the skin-training logs, hysteresis bounded by Canny edges, top-fifth test);
//! §4's plane grid (1 / 3 colour × 0 / 1 / 2 edge planes) timed and scored; the ground truth.
//! The aggregation ([`aggregate`]) runs the filters of [`fusion`] (§5: laser + camera, laser
//! only, camera only from the height learned in the previous session or its pair partner, the
//! height a constant the filter learns — the paper — or a random walk — a variant — and our
//! constant-velocity variant), and writes the height tables with one-sample t-tests
//! ([`height`]), camera only with the constant height against the random walk ([`walk`]),
//! position errors and lag with paired t-tests, the plane-grid table, and the figures
//! ([`figures`]). `mode = "multi"`: several people ([`multi`]); `mode = "mount"`: the same
//! filters once per camera of a mast of cameras at several heights ([`mount`]).

mod aggregate;
mod camera;
mod fig4;
mod figures;
mod fusion;
mod height;
mod mount;
mod multi;
mod multi_report;
mod multi_session;
mod params;
mod session;
mod tables;
mod walk;

use std::collections::BTreeMap;
use std::path::PathBuf;

use crate::progress::Progress;
use crate::run::config::Invalid;
use crate::run::{Aggregate, Experiment, Products, Session, SessionTables, Stage};

pub use params::{Mode, Params};

pub struct BrooksHeight;

impl Experiment for BrooksHeight {
    const KIND: &'static str = "s002_brooks_height";
    const VERSION: u32 = 2;
    const SESSION_TABLES: &'static [crate::run::schemas::TableDoc] = tables::SESSION_TABLES;
    type Params = Params;

    fn validate(p: &Params) -> Vec<Invalid> {
        params::validate(p)
    }

    fn plan(p: &Params, _: &BTreeMap<String, String>) -> Vec<Stage> {
        if matches!(p.mode, Mode::Multi | Mode::Mount) {
            return multi_plan(p);
        }
        let (mask, _) = camera::mask_topics(&p.camera);
        vec![
            Stage {
                name: "laser leg pairs (seed 002 §3)".into(),
                requires: vec![p.scan_topic.clone()],
                optional: vec!["/tf".into(), "/tf_static".into()],
            },
            Stage {
                name: "camera: Jabri background, skin, person test (§4)".into(),
                requires: vec![format!("/{}/camera_info", p.camera)],
                optional: vec![
                    format!("/{}/image_raw/compressed", p.camera),
                    format!("/{}/image_raw", p.camera),
                    mask,
                ],
            },
            Stage {
                name: "ground truth".into(),
                requires: vec![crate::groundtruth::PEOPLE_TOPIC.into()],
                optional: vec![],
            },
        ]
    }

    /// The skin-training logs when named by glob (`last` names one of the sessions).
    fn external_inputs(p: &Params) -> Vec<PathBuf> {
        if p.skin_training.len() == 1 && p.skin_training[0] == params::LAST {
            return Vec::new();
        }
        p.training_logs(std::path::Path::new(""))
    }

    fn process(
        s: &Session,
        p: &Params,
        _: &BTreeMap<String, String>,
        bar: &dyn Progress,
    ) -> anyhow::Result<SessionTables> {
        match p.mode {
            Mode::Paper => session::process(s, p, bar),
            Mode::Multi | Mode::Mount => multi_session::process(s, p, bar),
        }
    }

    fn aggregate(ctx: &Aggregate, p: &Params) -> anyhow::Result<Products> {
        if p.mode == Mode::Multi {
            let r = multi_report::compute(ctx, p)?;
            let mut out = Products::default();
            multi_report::products(&r, p, &mut out)?;
            return Ok(out);
        }
        if p.mode == Mode::Mount {
            let cams = mount::compute(ctx, p)?;
            let mut out = Products::default();
            mount::products(&cams, p, &mut out)?;
            return Ok(out);
        }
        let data = aggregate::load(ctx, p)?;
        let mut out = Products::default();
        height::tables(&data, p, &mut out)?;
        walk::tables(&data, p, &mut out)?;
        aggregate::tables(&data, p, &mut out)?;
        out.figures.extend(figures::all(&data, p));
        out.summary.extend(figures::summary(&data));
        Ok(out)
    }
}

/// Multi mode's stages: the laser, each camera, the truth.
fn multi_plan(p: &Params) -> Vec<Stage> {
    let mut out = vec![Stage {
        name: "laser leg pairs (seed 002 §3), every pair".into(),
        requires: vec![p.scan_topic.clone()],
        optional: vec!["/tf".into(), "/tf_static".into()],
    }];
    for cam in &p.cameras {
        out.push(Stage {
            name: format!("camera {cam}: Jabri background, skin, person test (§4)"),
            requires: vec![format!("/{cam}/camera_info")],
            optional: vec![
                format!("/{cam}/image_raw/compressed"),
                format!("/{cam}/image_raw"),
            ],
        });
    }
    out.push(Stage {
        name: "ground truth, every person".into(),
        requires: vec![crate::groundtruth::PEOPLE_TOPIC.into()],
        optional: vec![],
    });
    out
}

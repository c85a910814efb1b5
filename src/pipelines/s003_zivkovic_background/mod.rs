//! `s003_zivkovic_background` (seed 003): the two COGNIRON vision methods of Zivkovic (ICPR
//! 2004) and Zivkovic & Kröse (CVPR 2004) on the home-tour background scenes, and the local
//! tracks built from them.
//!
//! Per session (one pass over the camera's frames, in time order):
//! - **ROC** (paper fig. 1), when the session has exact person masks and its dataset is not
//!   in `roc.exclude_datasets` (static-background sequences such as the walker): the adaptive GMM
//!   ([`GmmParams::default`], OpenCV MOG2's defaults) and the fixed-M baseline
//!   ([`GmmParams::stauffer_grimson`], M = 4, c_T = 0), and the `roc.extra` variants
//!   (default: Zivkovic as printed, [`GmmParams::zivkovic_printed`], and Stauffer & Grimson
//!   as published, `vision::sg1999`) for every c_thr in `roc.var_thresholds`; true positives (% of person pixels called foreground) and false
//!   positives (% of other pixels called foreground), summed over the frames after
//!   `roc.skip_frames`. Shadow pixels (127) count as background.
//! - **Time per frame** (fig. 2, same sessions as the ROC) of both models at the default c_thr, each on one thread,
//!   alternating which runs first; the mean number of components per pixel every frame; the
//!   components-per-pixel image at the last frame (fig. 2, right).
//! - **EM-like vs mean shift** on the datasets in `colour.datasets`: person `colour.person`
//!   is initialised from its exact mask (eq. 16–17) in the first frame where it is fully in
//!   view, then tracked by the EM-like tracker and by mean shift with the ±10 % scale test,
//!   with HS and RGB histograms; per frame the centre error and the ellipse overlap (IoU of
//!   2σ regions) against the moments of its exact mask, iterations and similarity.
//! - **Local tracks** ([`LocalTracker`]) on every session, the camera taken as moving when
//!   odometry reports a speed or turn rate above the thresholds; scored against the ground
//!   truth boxes with CLEAR MOT and IDF1 (IoU ≥ `local_eval.min_iou`).
//! - **Re-identification** (Zajdel et al., inside seed 003, §IV–V) on `reid.datasets` and
//!   the training split `reid.train_datasets`: the region means of every ground-truth and
//!   local-track box per frame, of the tracker's foreground, the exact per-person mask and
//!   the whole box (`reid`); at aggregation local tracks become observations
//!   (`reid_features`), the methods (`reid_methods`) label them clip by clip, and the runs
//!   are scored per session (`reid_report`) and across sessions (`reid_summary`), with
//!   figs. 4b, 5 and 6 (`reid_figures`, `reid_snapshots`).
//!
//! Aggregation writes the ROC table, figures and summary (TP at fixed FP), the timing table
//! (measured, so *not* byte-identical between runs: kept apart), the components images, the
//! tracker comparison with per-frame samples and paired t-tests, the local-track table, and
//! the Wallflower WavingTrees F-measure (real data, read from `wallflower.dir` when present,
//! declared as an external input).
//!
//! Layout: `params` (parameters, validation, topics), `session` (the frame loop over
//! [`crate::frames`] camera frames joined to ground truth and odometry, which hands each
//! [`shared::Frame`] to one state struct per sub-experiment, and the `sessions` table),
//! `shared` (the frame, the `session` row, grouping by dataset), one file per sub-experiment holding
//! its per-frame state, cached tables, result tables and figures (`roc` + `roc_report`, `timing`,
//! `components`, `colour` + `colour_report`, `local_tracks`, `moving`, `reid` with
//! `reid_params`, `reid_features`, `reid_methods`, `reid_report`, `reid_summary`,
//! `reid_figures` and `reid_snapshots` (+ `snapshots`), `wallflower`).

mod colour;
mod colour_report;
mod components;
mod local_tracks;
mod moving;
mod params;
mod reid;
mod reid_features;
mod reid_figures;
mod reid_methods;
mod reid_params;
mod reid_report;
mod reid_snapshots;
mod reid_summary;
mod roc;
mod roc_report;
mod session;
mod shared;
mod snapshots;
mod timing;
mod wallflower;

use std::collections::BTreeMap;
use std::path::PathBuf;

pub use params::{
    ClipParams, ColourParams, LocalEvalParams, Params, ReidParams, RocParams, WallflowerParams,
};

use crate::progress::Progress;
use crate::run::config::Invalid;
use crate::run::schemas::{TableDoc, table};
use crate::run::{Aggregate, Experiment, Products, Session, SessionTables, Stage};

/// Every per-session table and what a row of it is (`docs/schemas.md`).
const SESSION_TABLES: &[TableDoc] = &[
    table(
        shared::SESSION_TABLE,
        "What was read, and each stage's counters (one row).",
    ),
    table(
        local_tracks::TRACKS_TABLE,
        "One local track's observation in one frame.",
    ),
    table(
        local_tracks::GT_TABLE,
        "A ground-truth person's box in one frame (right and bottom exclusive); people less \
         visible than `local_eval.min_visibility` left out.",
    ),
    table(
        local_tracks::HAS_GT_TABLE,
        "Whether the log has ground truth (one row, `value`).",
    ),
    table(
        moving::TABLE,
        "The session's moving-camera detection counts (one row).",
    ),
    table(
        reid::FRAMES_TABLE,
        "The region means of one box's pixel set in one frame (re-identification).",
    ),
    table(
        snapshots::BOXES_TABLE,
        "One box of a kept re-identification snapshot frame.",
    ),
    table(
        "reid_snapshot_{n}",
        "The `{n}`-th kept re-identification snapshot: the image as PNG bytes and its frame (one row).",
    ),
    table(
        components::SAMPLES_TABLE,
        "One frame: mean components per pixel of both models.",
    ),
    table(
        components::IMAGE_TABLE,
        "The adaptive model's components at the last frame, one row per pixel in row-major order.",
    ),
    table(
        components::LAST_FRAME_TABLE,
        "The last frame as PNG bytes (one row).",
    ),
    table(
        roc::COUNTS_TABLE,
        "One model at one c_thr: mask counts summed over the scored frames.",
    ),
    table(
        roc::PEOPLE_TABLE,
        "Person pixels (exact mask inside a person's box) of standing or walking people, and how \
         the adaptive model at c_thr = 16 labelled them.",
    ),
    table(
        roc::COMPONENTS_TABLE,
        "A variant's mean components per pixel summed over the frames with masks.",
    ),
    table(
        timing::SAMPLES_TABLE,
        "One frame: the fastest of repeated updates of each timed model (ms).",
    ),
    table(
        colour::SAMPLES_TABLE,
        "One colour tracker's estimate in one frame, with the ground-truth ellipse where the \
         person is fully in view.",
    ),
    table(
        "colour_overlay_{n}",
        "The `{n}`-th overlay frame of the colour trackers as PNG bytes and its frame (one row).",
    ),
];

pub struct BackgroundTracking;

impl Experiment for BackgroundTracking {
    const KIND: &'static str = "s003_zivkovic_background";
    // 2: EM-like stop rule (settled boundary), ROC datasets can be excluded
    // 3: timing = fastest of 3 runs per frame; standing/walking person pixels; cached tables
    //    from row structs, images as PNG
    // 5: re-identification features (`reid_frames`) for `reid.datasets`
    // 6: `reid_frames` per box and pixel set (tracker foreground, exact id mask, box), raw
    //    region means and frame means; `reid.train_datasets` too
    // 7: `reid_frames` also for the filled foreground (`person_filled`)
    const VERSION: u32 = 7;
    const SESSION_TABLES: &'static [TableDoc] = SESSION_TABLES;
    type Params = Params;

    fn validate(p: &Params) -> Vec<Invalid> {
        params::validate(p)
    }

    fn topic_keys(_: &Params) -> Vec<String> {
        params::TOPIC_KEYS.iter().map(|k| k.to_string()).collect()
    }

    fn plan(p: &Params, t: &BTreeMap<String, String>) -> Vec<Stage> {
        let tp = params::topics_of(p, t);
        vec![
            Stage {
                name: "ROC and timing: adaptive vs fixed-M GMM".into(),
                requires: vec![tp.image.clone()],
                optional: vec![tp.mask.clone()],
            },
            Stage {
                name: "EM-like vs mean shift".into(),
                requires: vec![tp.image.clone()],
                optional: vec![tp.mask.clone(), tp.ground_truth.clone()],
            },
            Stage {
                name: "local tracks".into(),
                requires: vec![tp.image.clone()],
                optional: vec![tp.ground_truth.clone(), tp.odom.clone()],
            },
            Stage {
                name: "re-identification features".into(),
                requires: vec![tp.image.clone()],
                optional: vec![tp.ground_truth.clone(), tp.person_ids.clone()],
            },
        ]
    }

    fn external_inputs(p: &Params) -> Vec<PathBuf> {
        wallflower::inputs(&p.wallflower)
    }

    fn process(
        s: &Session,
        p: &Params,
        topics: &BTreeMap<String, String>,
        bar: &dyn Progress,
    ) -> anyhow::Result<SessionTables> {
        session::process(s, p, topics, bar)
    }

    fn aggregate(ctx: &Aggregate, p: &Params) -> anyhow::Result<Products> {
        let mut products = Products::default();
        session::products(ctx, &mut products)?;
        roc_report::products(ctx, p, &mut products)?;
        timing::products(ctx, &mut products)?;
        components::products(ctx, &mut products)?;
        colour_report::products(ctx, p, &mut products)?;
        local_tracks::products(ctx, p, &mut products)?;
        moving::products(ctx, p, &mut products)?;
        if let Some((runs, training)) = reid_report::products(ctx, p, &mut products)? {
            reid_summary::products(&runs, &training, &p.reid, &mut products)?;
        }
        reid_figures::products(ctx, &p.reid, &mut products)?;
        reid_snapshots::products(ctx, &p.reid, &mut products)?;
        wallflower::products(p, &mut products)?;
        Ok(products)
    }
}

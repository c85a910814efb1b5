//! `s000_cielniak_omni` — appearance-based tracking with an omnidirectional camera (seed 000, Cielniak et al.
//! 2003), every step on the logged images:
//!
//! 1. **External measurement system** (section 3): webcams find the green hat, turn its column
//!    into a bearing, triangulate every pair that sees the whole hat; calibration of each
//!    camera's (α, X, Y, Δα) on the calibration segment by minimising d̄ (Nelder–Mead).
//! 2. **Omni pre-processing** (4.2): polar unwrap, background from person-free frames,
//!    histograms, person localisation, angle from the horizontal histogram.
//! 3. **Features** (4.3): width, apparent distance, foreground pixels; Pearson r with distance.
//! 4. **ANN** (4.4): 3-H-1 network, back-propagation, 30/70 splits repeated 10 times; a sweep
//!    over hidden units and learning rates.
//! 5. **Person-specific models** (6.1): 2×2 table and an unpaired t-test at 99 %.
//! 6. **Kalman filter** (5): Q and R from the training data; appearance model vs Kalman with an
//!    unpaired t-test; a fragment of the tracked path.
//!
//! As in the paper, the "true" distance for training and error measurement is the external
//! measurement system's; the simulator's own truth, when the log has it, is used only for extra
//! rows that measure the measurement system itself. Person identity (for person-specific models)
//! comes from the ground-truth ids when present, otherwise from the halves of the session.

use std::collections::BTreeMap;

use crate::progress::Progress;
use anyhow::Context;
use image::RgbImage;
use nalgebra::{Matrix2, Vector2};
use polars::prelude::*;
use rand::seq::SliceRandom;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::calib::external::{self, BearingCamera, Sample};
use crate::eval::stats::{self, DEFAULT_LEVEL};
use crate::geometry::camera::CameraModel;
use crate::groundtruth::{PEOPLE_TOPIC, PeopleFrame, TARGETS_TOPIC, TargetsFrame};
use crate::learn::mlp::{Regressor, TrainSpec};
use crate::log::msgs::{CameraInfo, CompressedImage, Image};
use crate::log::{SessionLog, TfBuffer, read_topic};
use crate::report::columns::{bools, concat, f64s, i64s, strs};
use crate::report::figure::{
    Circle, FigureKind, LinePlot, Mark, ScatterPlot, Sensor, Series, TopView,
};
use crate::report::{Figure, Table};
use crate::rng;
use crate::run::config::Invalid;
use crate::run::{Aggregate, Experiment, Products, Session, SessionTables, Stage};
use crate::track::position::{PositionKf, covariance};
use crate::vision::omni::{Background, Unwrapper, features};

pub struct OmniAppearance;

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

/// A saved appearance model: the network, its scaling, and where it came from.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct AppearanceModel {
    pub kind: String,
    pub version: u32,
    pub features: Vec<String>,
    pub regressor: Regressor,
    pub train: TrainSpec,
    pub samples: usize,
    pub sessions: Vec<String>,
    pub tool_version: String,
    pub git_commit: String,
}

fn image_topic(log: &SessionLog, name: &str) -> Option<(String, bool)> {
    let compressed = format!("/{name}/image_raw/compressed");
    let raw = format!("/{name}/image_raw");
    if log.summary().channel(&compressed).is_some() {
        Some((compressed, true))
    } else if log.summary().channel(&raw).is_some() {
        Some((raw, false))
    } else {
        None
    }
}

/// Every frame of a camera as `(header stamp ns, RGB image)`.
fn for_each_frame(
    log: &SessionLog,
    name: &str,
    mut f: impl FnMut(i64, RgbImage) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    let (topic, compressed) =
        image_topic(log, name).with_context(|| format!("no image topic for camera `{name}`"))?;
    if compressed {
        for item in read_topic::<CompressedImage>(log, &topic)? {
            let (_, m) = item?;
            let stamp = m.header.stamp.nanos().map_or(0, |n| n.0 as i64);
            let img = crate::log::image::decode_compressed(&m)
                .with_context(|| format!("{topic} at {stamp} ns"))?;
            f(stamp, img.to_rgb8())?;
        }
    } else {
        for item in read_topic::<Image>(log, &topic)? {
            let (_, m) = item?;
            let stamp = m.header.stamp.nanos().map_or(0, |n| n.0 as i64);
            let img = crate::log::image::decode_raw(&m)
                .with_context(|| format!("{topic} at {stamp} ns"))?;
            f(stamp, img.to_rgb8())?;
        }
    }
    Ok(())
}

fn first_info(log: &SessionLog, name: &str) -> anyhow::Result<CameraInfo> {
    let topic = format!("/{name}/camera_info");
    let (_, info) = read_topic::<CameraInfo>(log, &topic)?
        .next()
        .with_context(|| format!("{topic} has no messages"))??;
    Ok(info)
}

impl Experiment for OmniAppearance {
    const KIND: &'static str = "s000_cielniak_omni";
    const VERSION: u32 = 1;
    type Params = Params;

    fn validate(p: &Params) -> Vec<Invalid> {
        let mut out = Vec::new();
        if !(p.train_fraction > 0.0 && p.train_fraction < 1.0) {
            out.push((
                "train_fraction".into(),
                format!("{} is not in (0, 1)", p.train_fraction),
            ));
        }
        if p.webcams.len() == 1 || p.webcams.is_empty() && p.model.is_empty() {
            out.push((
                "webcams".into(),
                "the measurement system needs at least two cameras (or none, with `model` set, to only estimate positions)".into(),
            ));
        }
        if p.hidden_units == 0 || p.sweep_hidden.contains(&0) {
            out.push((
                "hidden_units".into(),
                "a network needs at least one hidden unit".into(),
            ));
        }
        if !(p.learning_rate > 0.0 && p.learning_rate < 10.0) {
            out.push((
                "learning_rate".into(),
                format!("{} is not in (0, 10)", p.learning_rate),
            ));
        }
        if p.background_frames < 2 {
            out.push((
                "background_frames".into(),
                "the background needs at least 2 frames".into(),
            ));
        }
        if !(p.inner_radius > 0.0 && p.inner_radius < 1.0) {
            out.push(("inner_radius".into(), "must be a fraction in (0, 1)".into()));
        }
        out
    }

    fn plan(p: &Params, _: &BTreeMap<String, String>) -> Vec<Stage> {
        vec![
            Stage {
                name: "hat detection (webcams)".into(),
                requires: p
                    .webcams
                    .iter()
                    .map(|c| format!("/{c}/camera_info"))
                    .collect(),
                optional: vec![TARGETS_TOPIC.into()],
            },
            Stage {
                name: "omni features".into(),
                requires: vec![format!("/{}/camera_info", p.omni), "/tf_static".into()],
                optional: vec![PEOPLE_TOPIC.into()],
            },
        ]
    }

    fn process(
        s: &Session,
        p: &Params,
        _: &BTreeMap<String, String>,
        bar: &dyn Progress,
    ) -> anyhow::Result<SessionTables> {
        let log = &s.log;
        let tf = TfBuffer::from_log(log, 1e6)?;
        let t0 = log
            .summary()
            .statistics
            .as_ref()
            .map_or(crate::Nanos(0), |st| st.start);
        bar.set_length((p.webcams.len() + 1) as u64);
        // webcams: nominal parameters from TF and camera_info, then hat detections
        let (mut cam_rows, mut hats) = (
            Vec::new(),
            (
                Vec::new(),
                Vec::new(),
                Vec::new(),
                Vec::new(),
                Vec::new(),
                Vec::new(),
            ),
        );
        for (k, name) in p.webcams.iter().enumerate() {
            bar.set_message(&format!("hats in {name}"));
            let info = first_info(log, name)?;
            let pose = tf
                .lookup("map", name, t0)
                .with_context(|| format!("no transform map <- {name}"))?;
            let z = pose.rotation * nalgebra::Vector3::z();
            cam_rows.push((
                name.clone(),
                pose.translation.x,
                pose.translation.y,
                z.y.atan2(z.x),
                2.0 * (f64::from(info.width) / 2.0 / info.k[0]).atan(),
                f64::from(info.width),
            ));
            for_each_frame(log, name, |stamp, img| {
                if let Some(b) = external::find_hue_blob(
                    &img,
                    (p.hat_hue_deg[0], p.hat_hue_deg[1]),
                    p.hat_min_saturation,
                    p.hat_min_value,
                    p.hat_min_area,
                ) {
                    hats.0.push(stamp);
                    hats.1.push(k as i64);
                    hats.2.push(b.u);
                    hats.3.push(b.v);
                    hats.4.push(i64::from(b.area));
                    hats.5.push(!b.touches_border);
                }
                Ok(())
            })?;
            bar.inc(1);
        }
        let cameras = df! {
            "camera" => cam_rows.iter().map(|c| c.0.clone()).collect::<Vec<_>>(),
            "x" => cam_rows.iter().map(|c| c.1).collect::<Vec<_>>(),
            "y" => cam_rows.iter().map(|c| c.2).collect::<Vec<_>>(),
            "heading" => cam_rows.iter().map(|c| c.3).collect::<Vec<_>>(),
            "range" => cam_rows.iter().map(|c| c.4).collect::<Vec<_>>(),
            "width" => cam_rows.iter().map(|c| c.5).collect::<Vec<_>>(),
        }?;
        let hats = df! { "stamp" => hats.0, "camera" => hats.1, "u" => hats.2, "v" => hats.3, "area" => hats.4, "whole" => hats.5 }?;

        // calibration targets and (when present) the simulator's truth
        let (mut tg_t, mut tg_x, mut tg_y) = (Vec::new(), Vec::new(), Vec::new());
        if log.summary().channel(TARGETS_TOPIC).is_some() {
            for m in log.messages_on(&[TARGETS_TOPIC])? {
                let m = m?;
                let f: TargetsFrame = serde_json::from_slice(&m.data)
                    .with_context(|| format!("{TARGETS_TOPIC} at {} s", m.log_time))?;
                for t in f.targets {
                    tg_t.push(f.stamp_ns as i64);
                    tg_x.push(t.x);
                    tg_y.push(t.y);
                }
            }
        }
        let targets = df! { "stamp" => tg_t, "x" => tg_x, "y" => tg_y }?;
        let (mut tr_t, mut tr_id, mut tr_x, mut tr_y) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        if log.summary().channel(PEOPLE_TOPIC).is_some() {
            for m in log.messages_on(&[PEOPLE_TOPIC])? {
                let m = m?;
                let f: PeopleFrame = serde_json::from_slice(&m.data)
                    .with_context(|| format!("{PEOPLE_TOPIC} at {} s", m.log_time))?;
                for q in f.people {
                    tr_t.push(f.stamp_ns as i64);
                    tr_id.push(i64::from(q.id));
                    tr_x.push(q.x);
                    tr_y.push(q.y);
                }
            }
        }
        let truth = df! { "stamp" => tr_t, "id" => tr_id, "x" => tr_x, "y" => tr_y }?;
        let camera_truth = {
            let meta = log
                .summary()
                .metadata
                .iter()
                .find(|m| m.name == "peopletrack.truth");
            let list: Vec<serde_json::Value> = meta
                .and_then(|m| m.entries.get("cameras"))
                .and_then(|c| serde_json::from_str(c).ok())
                .unwrap_or_default();
            let get =
                |v: &serde_json::Value, k: &str, i: usize| v[k][i].as_f64().unwrap_or(f64::NAN);
            df! {
                "camera" => list.iter().map(|v| v["name"].as_str().unwrap_or_default().to_string()).collect::<Vec<_>>(),
                "true_x" => list.iter().map(|v| get(v, "true_xyz", 0)).collect::<Vec<_>>(),
                "true_y" => list.iter().map(|v| get(v, "true_xyz", 1)).collect::<Vec<_>>(),
                "true_yaw_deg" => list.iter().map(|v| v["true_yaw_deg"].as_f64().unwrap_or(f64::NAN)).collect::<Vec<_>>(),
            }?
        };

        // omni: unwrap, background, features
        bar.set_message("omni features");
        let info = first_info(log, &p.omni)?;
        let model = info
            .model()
            .with_context(|| format!("/{}/camera_info", p.omni))?;
        let (xc, yc, rim) = match &model {
            CameraModel::ConicalMirror(c) => (c.xc, c.yc, c.r_rim()),
            CameraModel::Paracatadioptric(c) => (c.xc, c.yc, c.r_max),
            CameraModel::Pinhole(_) => anyhow::bail!(
                "camera `{}` is a pinhole, not an omnidirectional camera",
                p.omni
            ),
        };
        let unwrap = Unwrapper::new(
            xc,
            yc,
            p.inner_radius * rim,
            rim,
            p.panorama[0],
            p.panorama[1],
        );
        let omni_pose = tf
            .lookup("map", &p.omni, t0)
            .with_context(|| format!("no transform map <- {}", p.omni))?;
        let ox = omni_pose.rotation * nalgebra::Vector3::x();
        let mut bg_frames: Vec<Vec<f32>> = Vec::new();
        let mut background: Option<Background> = None;
        let mut om = (
            Vec::new(),
            Vec::new(),
            Vec::new(),
            Vec::new(),
            Vec::new(),
            Vec::new(),
        );
        for_each_frame(log, &p.omni, |stamp, img| {
            let pano = unwrap.unwrap_grey(&img);
            if background.is_none() {
                bg_frames.push(pano);
                if bg_frames.len() == p.background_frames {
                    background = Some(Background::learn(&bg_frames, p.panorama[0], p.panorama[1])?);
                }
                return Ok(());
            }
            let Some(bg) = &background else { return Ok(()) };
            let f = features(bg, &pano)?;
            om.0.push(stamp);
            om.1.push(f.is_some());
            om.2.push(f.map_or(f64::NAN, |f| f.width));
            om.3.push(f.map_or(f64::NAN, |f| f.apparent_distance));
            om.4.push(f.map_or(f64::NAN, |f| f.pixels));
            om.5.push(f.map_or(f64::NAN, |f| unwrap.angle(f.mean_column)));
            Ok(())
        })?;
        bar.inc(1);
        let omni = df! {
            "stamp" => om.0, "valid" => om.1, "width" => om.2, "apparent_distance" => om.3, "pixels" => om.4, "angle" => om.5,
        }?;
        let pose = df! {
            "x" => [omni_pose.translation.x], "y" => [omni_pose.translation.y], "yaw" => [ox.y.atan2(ox.x)],
        }?;
        Ok(SessionTables::from([
            ("cameras".to_string(), cameras),
            ("camera_truth".to_string(), camera_truth),
            ("hats".to_string(), hats),
            ("targets".to_string(), targets),
            ("truth".to_string(), truth),
            ("omni".to_string(), omni),
            ("omni_pose".to_string(), pose),
        ]))
    }

    fn aggregate(ctx: &Aggregate, p: &Params) -> anyhow::Result<Products> {
        analyse(ctx, p)
    }
}

/// One frame usable for the appearance model.
#[derive(Debug, Clone, Copy)]
struct Row {
    session: usize,
    stamp: i64,
    features: [f64; 3],
    /// Distance and bearing from the measurement system.
    distance: f64,
    bearing: f64,
    /// Bearing measured in the panorama (map frame).
    omni_bearing: f64,
    ext: (f64, f64),
    cam: (f64, f64),
    person: i64,
    truth: Option<(f64, f64)>,
}

/// Run the position Kalman filter (eq. 1–9) over appearance-model positions `z`; `starts[i]`
/// restarts it (a new session or a gap). With `velocity`, u_k is the difference of the last two
/// estimates (the paper's "estimated velocity of the person"); without, u_k = 0.
fn kalman_track(
    z: &[Vector2<f64>],
    starts: &[bool],
    q: Matrix2<f64>,
    r: Matrix2<f64>,
    velocity: bool,
) -> Vec<Vector2<f64>> {
    let mut est = vec![Vector2::zeros(); z.len()];
    let mut kf: Option<PositionKf> = None;
    for i in 0..z.len() {
        match kf.as_mut() {
            Some(k) if !starts[i] => {
                let u = if velocity && i >= 2 && !starts[i - 1] {
                    est[i - 1] - est[i - 2]
                } else {
                    Vector2::zeros()
                };
                k.predict(u);
                k.correct(z[i]);
            }
            _ => kf = Some(PositionKf::new(z[i], q, r)),
        }
        est[i] = kf.as_ref().map_or(z[i], |k| k.x);
    }
    est
}

/// Per-frame estimates of the appearance model on every omni frame with a person: session,
/// stamp, bearing (deg, map frame), distance (m) and position (m, map frame), as CSV.
#[allow(clippy::type_complexity)]
fn estimates_csv(ctx: &Aggregate, omni: &DataFrame, model: &Regressor) -> anyhow::Result<Vec<u8>> {
    let mut cols: (
        Vec<String>,
        Vec<i64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
    ) = Default::default();
    if omni.height() > 0 {
        let (ss, st, valid) = (
            i64s(omni, "session")?,
            i64s(omni, "stamp")?,
            bools(omni, "valid")?,
        );
        let (w, a, px, ang) = (
            f64s(omni, "width")?,
            f64s(omni, "apparent_distance")?,
            f64s(omni, "pixels")?,
            f64s(omni, "angle")?,
        );
        for i in 0..ss.len() {
            if !valid[i] {
                continue;
            }
            let (session, frames) = &ctx.sessions[ss[i] as usize];
            let pose = frames.get("omni_pose").context("no omni pose")?;
            let (cx, cy, yaw) = (
                f64s(pose, "x")?[0],
                f64s(pose, "y")?[0],
                f64s(pose, "yaw")?[0],
            );
            let d = model.predict(&[w[i], a[i], px[i]]);
            let b = external::wrap(yaw + ang[i]);
            cols.0.push(session.path.display().to_string());
            cols.1.push(st[i]);
            cols.2.push(b.to_degrees());
            cols.3.push(d);
            cols.4.push(cx + d * b.cos());
            cols.5.push(cy + d * b.sin());
        }
    }
    let df = df! { "session" => cols.0, "stamp_ns" => cols.1, "bearing_deg" => cols.2, "distance_m" => cols.3, "x_m" => cols.4, "y_m" => cols.5 }?;
    Ok(Table::new("estimates", "", df).to_csv()?)
}

fn fmt_ms(m: f64, s: f64) -> String {
    format!("{m:.3} ± {s:.3}")
}

fn mean_std(v: &[f64]) -> (f64, f64) {
    match stats::describe(v) {
        Ok(s) => (s.mean, s.std),
        Err(_) => (v.first().copied().unwrap_or(f64::NAN), f64::NAN),
    }
}

#[allow(clippy::too_many_lines, clippy::type_complexity)]
fn analyse(ctx: &Aggregate, p: &Params) -> anyhow::Result<Products> {
    let mut out = Products::default();
    let loaded: Option<AppearanceModel> = if p.model.is_empty() {
        None
    } else {
        let text = std::fs::read_to_string(&p.model)
            .with_context(|| format!("reading model {}", p.model))?;
        let m: AppearanceModel = serde_json::from_str(&text)
            .with_context(|| format!("model {} is not an appearance model", p.model))?;
        anyhow::ensure!(
            m.kind == OmniAppearance::KIND,
            "model {} is a `{}` model, not `{}`",
            p.model,
            m.kind,
            OmniAppearance::KIND
        );
        Some(m)
    };
    let get = |name: &str| -> anyhow::Result<DataFrame> {
        concat(
            ctx.sessions
                .iter()
                .enumerate()
                .map(|(i, (_, f))| {
                    let mut df = f.get(name).cloned().unwrap_or_default();
                    if df.width() > 0 {
                        df.with_column(Column::new("session".into(), vec![i as i64; df.height()]))?;
                    }
                    Ok(df)
                })
                .collect::<anyhow::Result<Vec<_>>>()?,
        )
        .map_err(Into::into)
    };
    if p.webcams.is_empty() {
        // no measurement system: only estimate positions with the loaded model
        let model = loaded
            .as_ref()
            .context("no webcams and no model: nothing to do")?;
        out.artifacts.push((
            "estimates.csv".into(),
            estimates_csv(ctx, &get("omni")?, &model.regressor)?,
        ));
        out.summary.push(format!(
            "Positions estimated with {} written to out/s000_cielniak_omni/estimates.csv.",
            p.model
        ));
        return Ok(out);
    }
    let cameras = ctx
        .sessions
        .first()
        .and_then(|(_, f)| f.get("cameras"))
        .context("no camera table")?;
    let names = strs(cameras, "camera")?;
    let nominal: Vec<BearingCamera> = {
        let (x, y, h, r, w) = (
            f64s(cameras, "x")?,
            f64s(cameras, "y")?,
            f64s(cameras, "heading")?,
            f64s(cameras, "range")?,
            f64s(cameras, "width")?,
        );
        (0..names.len())
            .map(|i| BearingCamera {
                alpha: h[i],
                x: x[i],
                y: y[i],
                range: r[i],
                width: w[i],
            })
            .collect()
    };
    let hats = get("hats")?;
    let targets = get("targets")?;
    // hat detections per (session, stamp): cameras that see the whole hat
    let mut seen: BTreeMap<(i64, i64), Vec<(usize, f64)>> = BTreeMap::new();
    if hats.height() > 0 {
        let (ss, st, sc, su, sw) = (
            i64s(&hats, "session")?,
            i64s(&hats, "stamp")?,
            i64s(&hats, "camera")?,
            f64s(&hats, "u")?,
            bools(&hats, "whole")?,
        );
        for i in 0..ss.len() {
            if sw[i] {
                seen.entry((ss[i], st[i]))
                    .or_default()
                    .push((sc[i] as usize, su[i]));
            }
        }
    }

    // 1. calibration of the measurement system
    let mut samples = Vec::new();
    if targets.height() > 0 {
        let (ss, st, tx, ty) = (
            i64s(&targets, "session")?,
            i64s(&targets, "stamp")?,
            f64s(&targets, "x")?,
            f64s(&targets, "y")?,
        );
        for i in 0..ss.len() {
            if let Some(v) = seen.get(&(ss[i], st[i]))
                && v.len() >= 2
            {
                samples.push(Sample {
                    seen: v.clone(),
                    known: (tx[i], ty[i]),
                });
            }
        }
    }
    let d_before = external::mean_distance(&nominal, &samples);
    let (cams, d_after) = if samples.len() >= 4 {
        external::calibrate(&nominal, &samples)
            .map_err(|e| anyhow::anyhow!("calibration failed: {e}"))?
    } else {
        out.summary.push(format!(
            "Only {} calibration samples: the nominal camera parameters are used uncalibrated.",
            samples.len()
        ));
        (nominal.clone(), d_before)
    };
    {
        let truth = ctx
            .sessions
            .first()
            .and_then(|(_, f)| f.get("camera_truth"))
            .cloned()
            .unwrap_or_default();
        let tnames = if truth.height() > 0 {
            strs(&truth, "camera")?
        } else {
            Vec::new()
        };
        let (tx, ty, tyaw) = if truth.height() > 0 {
            (
                f64s(&truth, "true_x")?,
                f64s(&truth, "true_y")?,
                f64s(&truth, "true_yaw_deg")?,
            )
        } else {
            (Vec::new(), Vec::new(), Vec::new())
        };
        let mut rows: (
            Vec<String>,
            Vec<String>,
            Vec<f64>,
            Vec<f64>,
            Vec<Option<f64>>,
        ) = Default::default();
        for (i, n) in names.iter().enumerate() {
            let t = tnames.iter().position(|x| x == n);
            for (param, nom, est, tru) in [
                (
                    "alpha (deg)",
                    nominal[i].alpha.to_degrees(),
                    cams[i].alpha.to_degrees(),
                    t.map(|k| tyaw[k]),
                ),
                ("X (m)", nominal[i].x, cams[i].x, t.map(|k| tx[k])),
                ("Y (m)", nominal[i].y, cams[i].y, t.map(|k| ty[k])),
                (
                    "delta alpha (deg)",
                    nominal[i].range.to_degrees(),
                    cams[i].range.to_degrees(),
                    None,
                ),
            ] {
                rows.0.push(n.clone());
                rows.1.push(param.to_string());
                rows.2.push(nom);
                rows.3.push(est);
                rows.4.push(tru);
            }
        }
        rows.0.push("all".into());
        rows.1.push("d̄ (m) over calibration samples".into());
        rows.2.push(d_before);
        rows.3.push(d_after);
        rows.4.push(None);
        let df = df! { "camera" => rows.0, "parameter" => rows.1, "nominal" => rows.2, "estimated" => rows.3, "true" => rows.4 }?;
        out.tables.push(
            Table::new("calibration", "External measurement system: camera parameters before and after calibration", df)
                .with_note(format!(
                    "Paper (section 3): d̄ ≈ 1 cm after calibration. {} calibration samples (hat at a known mark seen whole by ≥ 2 cameras). \
                     `true` is the simulator's pose; the true Δα is not defined for a distorted lens (the linear column model approximates it).",
                    samples.len()
                )),
        );
        out.summary.push(format!(
            "Calibration: d̄ {:.3} m → {:.3} m over {} samples (paper ≈ 0.01 m).",
            d_before,
            d_after,
            samples.len()
        ));
    }

    // 2. external positions and the dataset
    let omni = get("omni")?;
    let pose = ctx
        .sessions
        .first()
        .and_then(|(_, f)| f.get("omni_pose"))
        .context("no omni pose")?;
    let cam_xy = (f64s(pose, "x")?[0], f64s(pose, "y")?[0]);
    let cam_yaw = f64s(pose, "yaw")?[0];
    let truth = get("truth")?;
    let mut truth_at: BTreeMap<(i64, i64), (i64, f64, f64)> = BTreeMap::new();
    if truth.height() > 0 {
        let (ss, st, id, x, y) = (
            i64s(&truth, "session")?,
            i64s(&truth, "stamp")?,
            i64s(&truth, "id")?,
            f64s(&truth, "x")?,
            f64s(&truth, "y")?,
        );
        for i in 0..ss.len() {
            truth_at
                .entry((ss[i], st[i]))
                .or_insert((id[i], x[i], y[i]));
        }
    }
    let mut rows: Vec<Row> = Vec::new();
    let mut ext_err_truth = Vec::new();
    {
        let (ss, st, valid) = (
            i64s(&omni, "session")?,
            i64s(&omni, "stamp")?,
            bools(&omni, "valid")?,
        );
        let (w, a, px, ang) = (
            f64s(&omni, "width")?,
            f64s(&omni, "apparent_distance")?,
            f64s(&omni, "pixels")?,
            f64s(&omni, "angle")?,
        );
        let n_sessions = ctx.sessions.len();
        let mut first_stamp = vec![i64::MAX; n_sessions];
        let mut last_stamp = vec![i64::MIN; n_sessions];
        for i in 0..ss.len() {
            first_stamp[ss[i] as usize] = first_stamp[ss[i] as usize].min(st[i]);
            last_stamp[ss[i] as usize] = last_stamp[ss[i] as usize].max(st[i]);
        }
        for i in 0..ss.len() {
            let Some(ext) = seen
                .get(&(ss[i], st[i]))
                .filter(|v| v.len() >= 2)
                .and_then(|v| external::locate(&cams, v))
            else {
                continue;
            };
            let tr = truth_at.get(&(ss[i], st[i]));
            if let Some((_, x, y)) = tr {
                ext_err_truth.push((ext.0 - x).hypot(ext.1 - y));
            }
            if !valid[i] {
                continue;
            }
            let (dx, dy) = (ext.0 - cam_xy.0, ext.1 - cam_xy.1);
            let person = match tr {
                Some((id, _, _)) => *id,
                None => {
                    let mid = (first_stamp[ss[i] as usize] + last_stamp[ss[i] as usize]) / 2;
                    if st[i] < mid { 1 } else { 2 }
                }
            };
            rows.push(Row {
                session: ss[i] as usize,
                stamp: st[i],
                features: [w[i], a[i], px[i]],
                distance: dx.hypot(dy),
                bearing: dy.atan2(dx),
                omni_bearing: external::wrap(cam_yaw + ang[i]),
                ext,
                cam: cam_xy,
                person,
                truth: tr.map(|(_, x, y)| (*x, *y)),
            });
        }
    }
    if rows.len() < 20 {
        let with_person = bools(&omni, "valid")?.iter().filter(|v| **v).count();
        let measured = seen.values().filter(|v| v.len() >= 2).count();
        anyhow::bail!(
            "only {} frames have both omni features and a measured position; need at least 20 \
             ({with_person} of {} omni frames show a person, {measured} webcam frames see the hat in ≥ 2 cameras; \
             no person in any omni frame usually means one stood in the first {} frames, which are taken as the empty background)",
            rows.len(),
            omni.height(),
            p.background_frames
        );
    }
    rows.sort_by_key(|r| (r.session, r.stamp));
    let (ext_m, ext_s) = mean_std(&ext_err_truth);
    if !ext_err_truth.is_empty() {
        out.summary.push(format!(
            "Measurement system vs simulator truth: {} over {} frames (the paper's ground truth has its own error; this is it).",
            fmt_ms(ext_m, ext_s),
            ext_err_truth.len()
        ));
    }

    // angle error
    let angle_err: Vec<f64> = rows
        .iter()
        .map(|r| {
            external::wrap(r.omni_bearing - r.bearing)
                .abs()
                .to_degrees()
        })
        .collect();
    let (am, asd) = mean_std(&angle_err);
    out.tables.push(
        Table::new(
            "angle_error",
            "Angle to the person from the horizontal histogram mean",
            df! {
                "quantity" => ["absolute angle error (deg)"],
                "ours" => [fmt_ms(am, asd)],
                "paper" => ["2.01 ± 1.60"],
                "frames" => [angle_err.len() as i64],
            }?,
        )
        .with_note("Paper section 4.2. Error against the bearing from the external measurement system.")
        .with_samples(df! { "session" => rows.iter().map(|r| r.session as i64).collect::<Vec<_>>(), "stamp" => rows.iter().map(|r| r.stamp).collect::<Vec<_>>(), "angle_error_deg" => angle_err.clone() }?),
    );

    // 3. correlations
    let dist: Vec<f64> = rows.iter().map(|r| r.distance).collect();
    let names3 = ["width", "apparent_distance", "pixels"];
    let mut corr_rows: (Vec<String>, Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) = Default::default();
    for (k, n) in names3.iter().enumerate() {
        let x: Vec<f64> = rows.iter().map(|r| r.features[k]).collect();
        let c = stats::pearson(&x, &dist, 0.95)?;
        corr_rows.0.push((*n).to_string());
        corr_rows.1.push(c.r);
        corr_rows.2.push(c.ci_low);
        corr_rows.3.push(c.ci_high);
        corr_rows.4.push(c.p_two_sided);
        out.figures.push(Figure::new(
            format!("fig5_{n}"),
            format!("{n} vs distance (r = {:.3})", c.r),
            FigureKind::Scatter(ScatterPlot {
                x_label: "distance from the measurement system (m)".into(),
                y_label: (*n).into(),
                series: vec![Series::points(
                    "",
                    dist.iter().copied().zip(x.iter().copied()).collect(),
                    5,
                )],
                annotation: format!("r = {:.3}", c.r),
                fit_line: true,
            }),
        ));
    }

    // 4. ANN protocol
    let xs: Vec<Vec<f64>> = rows.iter().map(|r| r.features.to_vec()).collect();
    let spec = TrainSpec {
        hidden: p.hidden_units,
        learning_rate: p.learning_rate,
        epochs: p.epochs,
    };
    let split = |s: usize, idx: &[usize]| -> (Vec<usize>, Vec<usize>) {
        let mut r = rng::stream(p.seed, "split", s as u64);
        let mut v = idx.to_vec();
        v.shuffle(&mut r);
        let n_train = ((v.len() as f64) * p.train_fraction).round() as usize;
        let test = v.split_off(n_train);
        (v, test)
    };
    let all: Vec<usize> = (0..rows.len()).collect();
    let fit = |train: &[usize], seed_label: u64, spec: TrainSpec| {
        let tx: Vec<Vec<f64>> = train.iter().map(|i| xs[*i].clone()).collect();
        let ty: Vec<f64> = train.iter().map(|i| dist[*i]).collect();
        Regressor::fit(&tx, &ty, spec, &mut rng::stream(p.seed, "net", seed_label))
    };
    let per_split: Vec<(usize, Vec<(usize, f64)>)> = (0..p.splits)
        .into_par_iter()
        .map(|s| {
            let (train, test) = split(s, &all);
            let model = match &loaded {
                Some(m) => m.regressor.clone(),
                None => fit(&train, s as u64, spec),
            };
            (
                s,
                test.iter()
                    .map(|i| (*i, (model.predict(&xs[*i]) - dist[*i]).abs()))
                    .collect(),
            )
        })
        .collect();
    let split_stats: Vec<(f64, f64)> = per_split
        .iter()
        .map(|(_, e)| mean_std(&e.iter().map(|x| x.1).collect::<Vec<_>>()))
        .collect();
    let pooled: Vec<f64> = per_split
        .iter()
        .flat_map(|(_, e)| e.iter().map(|x| x.1))
        .collect();
    let (pm, ps) = mean_std(&pooled);
    let best = (0..split_stats.len())
        .min_by(|a, b| split_stats[*a].0.total_cmp(&split_stats[*b].0))
        .unwrap_or(0);
    let worst = (0..split_stats.len())
        .max_by(|a, b| split_stats[*a].0.total_cmp(&split_stats[*b].0))
        .unwrap_or(0);
    out.tables.push(
        Table::new(
            "ann_error",
            format!(
                "Appearance model (ANN 3-{}-1, learning rate {}) distance error over {} random {:.0}/{:.0} splits",
                p.hidden_units,
                p.learning_rate,
                p.splits,
                100.0 * p.train_fraction,
                100.0 * (1.0 - p.train_fraction)
            ),
            df! {
                "results" => ["Average", "Best", "Worst"],
                "ours_m" => [fmt_ms(pm, ps), fmt_ms(split_stats[best].0, split_stats[best].1), fmt_ms(split_stats[worst].0, split_stats[worst].1)],
                "paper_m" => ["0.126 ± 0.167", "0.110 ± 0.099", "0.163 ± 0.325"],
                "frames" => [pooled.len() as i64, per_split[best].1.len() as i64, per_split[worst].1.len() as i64],
            }?,
        )
        .with_note(if loaded.is_some() { format!("Model loaded from {} (not retrained).", p.model) } else { "Paper section 6.1 (684 frames at 3 Hz, two people). Error against the external measurement system.".into() })
        .with_samples(df! {
            "split" => per_split.iter().flat_map(|(s, e)| std::iter::repeat_n(*s as i64, e.len())).collect::<Vec<_>>(),
            "stamp" => per_split.iter().flat_map(|(_, e)| e.iter().map(|x| rows[x.0].stamp)).collect::<Vec<_>>(),
            "abs_error_m" => pooled.clone(),
        }?),
    );
    out.summary.push(format!(
        "ANN distance error {} m over {} splits (paper 0.126 ± 0.167).",
        fmt_ms(pm, ps),
        p.splits
    ));
    // ANN output vs distance (fig 5, bottom right): split 0's test predictions
    {
        let (train0, test0) = split(0, &all);
        let m0 = loaded
            .as_ref()
            .map_or_else(|| fit(&train0, 0, spec), |m| m.regressor.clone());
        let pred: Vec<f64> = test0.iter().map(|i| m0.predict(&xs[*i])).collect();
        let truth0: Vec<f64> = test0.iter().map(|i| dist[*i]).collect();
        let c = stats::pearson(&pred, &truth0, 0.95)?;
        corr_rows.0.push("appearance model output".into());
        corr_rows.1.push(c.r);
        corr_rows.2.push(c.ci_low);
        corr_rows.3.push(c.ci_high);
        corr_rows.4.push(c.p_two_sided);
        out.figures.push(Figure::new(
            "fig5_ann",
            format!("Appearance model output vs distance (r = {:.3})", c.r),
            FigureKind::Scatter(ScatterPlot {
                x_label: "distance from the measurement system (m)".into(),
                y_label: "appearance model output (m)".into(),
                series: vec![Series::points(
                    "",
                    truth0.iter().copied().zip(pred.iter().copied()).collect(),
                    5,
                )],
                annotation: format!("r = {:.3}", c.r),
                fit_line: true,
            }),
        ));
    }
    out.tables.push(
        Table::new(
            "correlations",
            "Linear correlation of each feature and of the appearance model with the true distance (fig. 5)",
            df! { "quantity" => corr_rows.0, "r" => corr_rows.1, "ci95_low" => corr_rows.2, "ci95_high" => corr_rows.3, "p" => corr_rows.4 }?,
        )
        .with_precision("p", 6)
        .with_note("The paper shows these r values inside fig. 5 but not in its text, so no paper column. Fisher 95 % intervals."),
    );

    // sweep
    if loaded.is_none() && !p.sweep_hidden.is_empty() {
        let configs: Vec<(usize, f64)> = p
            .sweep_hidden
            .iter()
            .flat_map(|h| p.sweep_learning_rates.iter().map(move |lr| (*h, *lr)))
            .collect();
        let results: Vec<(usize, f64, f64)> = configs
            .par_iter()
            .map(|&(h, lr)| {
                let errs: Vec<f64> = (0..p.sweep_splits)
                    .flat_map(|s| {
                        let (train, test) = split(s, &all);
                        let m = fit(
                            &train,
                            1000 + s as u64,
                            TrainSpec {
                                hidden: h,
                                learning_rate: lr,
                                epochs: p.epochs,
                            },
                        );
                        test.iter()
                            .map(|i| (m.predict(&xs[*i]) - dist[*i]).abs())
                            .collect::<Vec<_>>()
                    })
                    .collect();
                (h, lr, mean_std(&errs).0)
            })
            .collect();
        let series = p
            .sweep_learning_rates
            .iter()
            .enumerate()
            .map(|(k, lr)| {
                Series::line(
                    format!("learning rate {lr}"),
                    results
                        .iter()
                        .filter(|r| r.1 == *lr)
                        .map(|r| (r.0 as f64, r.2))
                        .collect(),
                    k + 1,
                )
                .with_mark(Mark::LinePoints)
            })
            .collect();
        out.figures.push(Figure::new(
            "ann_sweep",
            "Mean test error by hidden units and learning rate",
            FigureKind::Lines(LinePlot {
                x_label: "hidden units".into(),
                y_label: "mean distance error (m)".into(),
                series,
                ..Default::default()
            }),
        ));
        let best_cfg = results.iter().min_by(|a, b| a.2.total_cmp(&b.2)).copied();
        if let Some((h, lr, e)) = best_cfg {
            out.summary.push(format!("Sweep: lowest mean error {e:.3} m with {h} hidden units and learning rate {lr} (paper's best: 4 units, 0.3)."));
        }
        out.tables.push(Table::new(
            "ann_sweep",
            "Mean test error (m) by hidden units and learning rate",
            df! {
                "hidden_units" => results.iter().map(|r| r.0 as i64).collect::<Vec<_>>(),
                "learning_rate" => results.iter().map(|r| r.1).collect::<Vec<_>>(),
                "mean_error_m" => results.iter().map(|r| r.2).collect::<Vec<_>>(),
            }?,
        ));
    }

    // 5. person-specific models
    let persons: Vec<i64> = {
        let mut v: Vec<i64> = rows.iter().map(|r| r.person).collect();
        v.sort_unstable();
        v.dedup();
        v
    };
    if persons.len() >= 2 && loaded.is_none() {
        let pa: Vec<i64> = persons[..2].to_vec();
        let mut train_by = BTreeMap::new();
        let mut test_by = BTreeMap::new();
        for (k, pid) in pa.iter().enumerate() {
            let idx: Vec<usize> = (0..rows.len())
                .filter(|i| rows[*i].person == *pid)
                .collect();
            let (tr, te) = split(100 + k, &idx);
            train_by.insert(*pid, tr);
            test_by.insert(*pid, te);
        }
        let models: BTreeMap<i64, Regressor> = pa
            .iter()
            .map(|pid| (*pid, fit(&train_by[pid], 200 + *pid as u64, spec)))
            .collect();
        let union: Vec<usize> = pa.iter().flat_map(|pid| train_by[pid].clone()).collect();
        let general = fit(&union, 300, spec);
        let err = |m: &Regressor, idx: &[usize]| {
            idx.iter()
                .map(|i| (m.predict(&xs[*i]) - dist[*i]).abs())
                .collect::<Vec<_>>()
        };
        let paper = [
            ["0.096 ± 0.074", "0.133 ± 0.126"],
            ["0.231 ± 0.276", "0.117 ± 0.111"],
        ];
        let mut t: (
            Vec<String>,
            Vec<String>,
            Vec<String>,
            Vec<String>,
            Vec<String>,
        ) = Default::default();
        let (mut specific, mut generic) = (Vec::new(), Vec::new());
        for (a, subject) in pa.iter().enumerate() {
            t.0.push(format!("person {subject}"));
            for (b, model_for) in pa.iter().enumerate() {
                let e = err(&models[model_for], &test_by[subject]);
                let (m, s) = mean_std(&e);
                if b == 0 {
                    t.1.push(fmt_ms(m, s))
                } else {
                    t.2.push(fmt_ms(m, s))
                }
                if a == b {
                    specific.extend(e);
                }
            }
            t.3.push(paper[a][0].into());
            t.4.push(paper[a][1].into());
            generic.extend(err(&general, &test_by[subject]));
        }
        let tt = stats::student_t(&specific, &generic, DEFAULT_LEVEL)?;
        let (sm, ss) = mean_std(&specific);
        let (gm, gs) = mean_std(&generic);
        out.tables.push(
            Table::new(
                "person_specific",
                "Person-specific appearance models: distance error (m), test subject × model trained for",
                df! {
                    "test subject" => t.0,
                    format!("model person {}", pa[0]).as_str() => t.1,
                    format!("model person {}", pa[1]).as_str() => t.2,
                    "paper model 1" => t.3,
                    "paper model 2" => t.4,
                }?,
            )
            .with_note(format!(
                "Specific models on their own person {} vs the general model (trained on the same frames) {}: Student t = {:.3}, df = {:.0}, p = {:.4}, 99 % CI of the difference [{:.3}, {:.3}] m; {} at the 99 % level (paper: specific significantly better).",
                fmt_ms(sm, ss),
                fmt_ms(gm, gs),
                tt.t,
                tt.df,
                tt.p_two_sided,
                tt.ci_low,
                tt.ci_high,
                if tt.significant(0.01) { "significant" } else { "not significant" }
            ))
            .with_samples(df! {
                "model" => std::iter::repeat_n("specific", specific.len()).chain(std::iter::repeat_n("general", generic.len())).collect::<Vec<_>>(),
                "abs_error_m" => specific.iter().chain(&generic).copied().collect::<Vec<_>>(),
            }?),
        );
        out.summary.push(format!(
            "Person-specific {} vs general {} m: p = {:.4} ({} at 99 %).",
            fmt_ms(sm, ss),
            fmt_ms(gm, gs),
            tt.p_two_sided,
            if tt.significant(0.01) {
                "significant"
            } else {
                "not significant"
            }
        ));
    }

    // 6. Kalman filter
    {
        let (train, test) = split(0, &all);
        let model = loaded
            .as_ref()
            .map_or_else(|| fit(&train, 0, spec), |m| m.regressor.clone());
        let in_train: Vec<bool> = {
            let mut v = vec![false; rows.len()];
            for i in &train {
                v[*i] = true;
            }
            v
        };
        let z: Vec<Vector2<f64>> = rows
            .iter()
            .zip(&xs)
            .map(|(r, x)| {
                let d = model.predict(x);
                Vector2::new(
                    r.cam.0 + d * r.omni_bearing.cos(),
                    r.cam.1 + d * r.omni_bearing.sin(),
                )
            })
            .collect();
        let ext: Vec<Vector2<f64>> = rows
            .iter()
            .map(|r| Vector2::new(r.ext.0, r.ext.1))
            .collect();
        // R: measurement errors on training frames; Q: deviations from constant velocity
        let r_samples: Vec<Vector2<f64>> = (0..rows.len())
            .filter(|i| in_train[*i])
            .map(|i| z[i] - ext[i])
            .collect();
        let gap = (p.max_gap_s * 1e9) as i64;
        let consecutive = |i: usize| {
            i >= 2
                && rows[i].session == rows[i - 2].session
                && rows[i].stamp - rows[i - 2].stamp <= 2 * gap
        };
        let q_samples: Vec<Vector2<f64>> = (2..rows.len())
            .filter(|i| in_train[*i] && consecutive(*i))
            .map(|i| ext[i] - ext[i - 1] - (ext[i - 1] - ext[i - 2]))
            .collect();
        let (q, r) = (covariance(&q_samples), covariance(&r_samples));
        let starts: Vec<bool> = (0..rows.len())
            .map(|i| {
                i == 0
                    || rows[i].session != rows[i - 1].session
                    || rows[i].stamp - rows[i - 1].stamp > gap
            })
            .collect();
        let est = kalman_track(&z, &starts, q, r, true);
        // extra: the same filter with u = 0 (a random walk), Q from per-step displacements
        let q_rw = covariance(
            &(1..rows.len())
                .filter(|i| in_train[*i] && !starts[*i])
                .map(|i| ext[i] - ext[i - 1])
                .collect::<Vec<_>>(),
        );
        let est_rw = kalman_track(&z, &starts, q_rw, r, false);
        let rw_err: Vec<f64> = test.iter().map(|i| (est_rw[*i] - ext[*i]).norm()).collect();
        let app_err: Vec<f64> = test.iter().map(|i| (z[*i] - ext[*i]).norm()).collect();
        let kf_err: Vec<f64> = test.iter().map(|i| (est[*i] - ext[*i]).norm()).collect();
        let tt = stats::student_t(&kf_err, &app_err, DEFAULT_LEVEL)?;
        let ((am, asd), (km, ksd), (rm, rsd)) =
            (mean_std(&app_err), mean_std(&kf_err), mean_std(&rw_err));
        let tt_rw = stats::student_t(&rw_err, &app_err, DEFAULT_LEVEL)?;
        out.tables.push(
            Table::new(
                "kalman",
                "Position error: appearance model alone vs with the Kalman filter",
                df! {
                    "tracking method" => ["Appearance model", "With Kalman filter", "Extra: Kalman filter with u = 0"],
                    "ours_m" => [fmt_ms(am, asd), fmt_ms(km, ksd), fmt_ms(rm, rsd)],
                    "paper_m" => ["0.154 ± 0.094", "0.145 ± 0.092", "—"],
                    "frames" => [app_err.len() as i64, kf_err.len() as i64, rw_err.len() as i64],
                }?,
            )
            .with_note(format!(
                "Unpaired Student t-test (Kalman − appearance): t = {:.3}, df = {:.0}, p = {:.4}, 99 % CI [{:.3}, {:.3}] m; {} at the 99 % level, the filter's error is {} (paper: significantly better). Errors on test frames against the measurement system. The filter is eq. 1–9 as written: u_k, the person's velocity, is the difference of the last two estimates, and P ignores its uncertainty, so the prediction overshoots where the person turns or stops. Extra row: the same filter with u = 0 and Q from per-step displacements, t-test against the appearance model: t = {:.3}, p = {:.4} ({}).",
                tt.t,
                tt.df,
                tt.p_two_sided,
                tt.ci_low,
                tt.ci_high,
                if tt.significant(0.01) { "significant" } else { "not significant" },
                if km < am { "lower" } else { "higher" },
                tt_rw.t,
                tt_rw.p_two_sided,
                if tt_rw.significant(0.01) { "significant" } else { "not significant" }
            ))
            .with_samples(df! {
                "stamp" => test.iter().map(|i| rows[*i].stamp).collect::<Vec<_>>(),
                "appearance_error_m" => app_err.clone(),
                "kalman_error_m" => kf_err.clone(),
                "kalman_u0_error_m" => rw_err.clone(),
            }?),
        );
        out.tables.push(
            Table::new(
                "kalman_noise",
                "Kalman noise covariances estimated from the training data (eq. 10)",
                df! {
                    "matrix" => ["Q", "Q", "R", "R"],
                    "row" => [1i64, 2, 1, 2],
                    "ours_col1" => [q[(0, 0)], q[(1, 0)], r[(0, 0)], r[(1, 0)]],
                    "ours_col2" => [q[(0, 1)], q[(1, 1)], r[(0, 1)], r[(1, 1)]],
                    "paper_col1" => [0.024, -0.001, 0.011, -0.004],
                    "paper_col2" => [-0.001, 0.043, -0.004, 0.020],
                }?,
            )
            .with_precision("ours_col1", 4)
            .with_precision("ours_col2", 4)
            .with_note("Q from deviations of the measured path from constant velocity, R from appearance-model position errors, both on training frames (m²)."),
        );
        out.summary.push(format!(
            "Kalman: {} → {} m, p = {:.4} (paper 0.154 → 0.145, significant).",
            fmt_ms(am, asd),
            fmt_ms(km, ksd),
            tt.p_two_sided
        ));
        // fig 6: a fragment of the tracked path (first 60 consecutive frames of session 0)
        let frag: Vec<usize> = (0..rows.len())
            .filter(|i| rows[*i].session == 0)
            .skip(rows.len() / 4)
            .take(60)
            .collect();
        let pts = |v: &[Vector2<f64>]| frag.iter().map(|i| (v[*i].x, v[*i].y)).collect::<Vec<_>>();
        let mut traj = vec![
            Series::line("measurement system", pts(&ext), 0),
            Series::points("appearance model", pts(&z), 5),
            Series::line("Kalman filter", pts(&est), 6).with_mark(Mark::Dashed),
        ];
        let truth_pts: Vec<(f64, f64)> = frag.iter().filter_map(|i| rows[*i].truth).collect();
        if truth_pts.len() == frag.len() {
            traj.push(Series::line("simulator truth", truth_pts, 3).with_mark(Mark::Dashed));
        }
        out.figures.push(Figure::new(
            "fig6_path",
            "Fragment of the tracked path in room coordinates (fig. 6)",
            FigureKind::TopView(TopView {
                outline: Vec::new(),
                obstacles: Vec::new(),
                sensors: vec![Sensor {
                    x: cam_xy.0,
                    y: cam_xy.1,
                    heading: Some(cam_yaw),
                    label: "omnicam".into(),
                }],
                trajectories: traj,
                circles: Vec::<Circle>::new(),
            }),
        ));
        if !rows.iter().all(|r| r.truth.is_none()) {
            let app_truth: Vec<f64> = test
                .iter()
                .filter_map(|i| {
                    rows[*i]
                        .truth
                        .map(|(x, y)| (z[*i] - Vector2::new(x, y)).norm())
                })
                .collect();
            let kf_truth: Vec<f64> = test
                .iter()
                .filter_map(|i| {
                    rows[*i]
                        .truth
                        .map(|(x, y)| (est[*i] - Vector2::new(x, y)).norm())
                })
                .collect();
            let ((a1, a2), (k1, k2)) = (mean_std(&app_truth), mean_std(&kf_truth));
            out.tables.push(
                Table::new(
                    "truth_check",
                    "Extra (not in the paper): errors against the simulator's truth instead of the measurement system",
                    df! {
                        "quantity" => ["measurement system position", "appearance model position", "with Kalman filter"],
                        "error_m" => [fmt_ms(ext_m, ext_s), fmt_ms(a1, a2), fmt_ms(k1, k2)],
                        "frames" => [ext_err_truth.len() as i64, app_truth.len() as i64, kf_truth.len() as i64],
                    }?,
                )
                .with_note("The paper could only compare with its webcam system; a synthetic log also knows where the person really was."),
            );
        }
    }

    // the general model on all data (or the loaded one): per-frame estimates, and the artefact
    let general = loaded
        .as_ref()
        .map_or_else(|| fit(&all, 400, spec), |m| m.regressor.clone());
    out.artifacts
        .push(("estimates.csv".into(), estimates_csv(ctx, &omni, &general)?));
    if loaded.is_none() && !p.save_model.is_empty() {
        let model = AppearanceModel {
            kind: "s000_cielniak_omni".into(),
            version: 1,
            features: names3.iter().map(|s| (*s).to_string()).collect(),
            regressor: general,
            train: spec,
            samples: rows.len(),
            sessions: ctx
                .sessions
                .iter()
                .map(|(s, _)| s.path.display().to_string())
                .collect(),
            tool_version: ctx.provenance.tool_version.clone(),
            git_commit: ctx.provenance.git_commit.clone(),
        };
        out.artifacts.push((
            p.save_model.clone().into(),
            serde_json::to_vec_pretty(&model)?,
        ));
        out.summary.push(format!(
            "General model trained on all {} frames saved to out/s000_cielniak_omni/{}.",
            rows.len(),
            p.save_model
        ));
    }
    Ok(out)
}

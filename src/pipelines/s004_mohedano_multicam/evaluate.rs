//! Aggregation: every session's tracks and ground truth into the experiment's tables.
//!
//! Sessions are scored together as one sequence (frame numbers and identities offset per
//! session, so nothing can match across sessions): CLEAR MOT counts are then the sums over
//! sessions, as motmetrics' `OVERALL` row.

// Tables are built column by column in tuples of vectors, one per column.
#![allow(clippy::type_complexity)]

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use anyhow::Context;
use polars::prelude::*;

use super::Params;
use super::session::{DETECTION_HEAD_TOL, GT_BOXES, main_detector, selection_label};
use crate::eval::mot::{
    Evaluation, EventKind, Geometry, GroundPoint, MatchRule, Observation, evaluate,
};
use crate::eval::stats::{DEFAULT_LEVEL, describe, student_t};
use crate::report::Table;
use crate::run::{Aggregate, Products};

/// Frame numbers and identities of session `s` are offset by `s · STRIDE`.
const STRIDE: i64 = 1_000_000_000;

pub(super) use crate::report::columns::{bools, f64s, i64s, opt_f64s, strs};

/// The tracks table of one session, by column.
#[derive(Debug, Clone, Default)]
pub(super) struct Tracks {
    pub detector: Vec<String>,
    pub selection: Vec<String>,
    pub n_app: Vec<i64>,
    pub frame: Vec<i64>,
    pub stamp_ns: Vec<i64>,
    pub t_s: Vec<f64>,
    pub id: Vec<i64>,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub h: Vec<f64>,
    pub r: Vec<f64>,
    pub cameras: Vec<i64>,
    pub support: Vec<String>,
    pub e_m: Vec<Option<f64>>,
}

impl Tracks {
    fn read(df: &DataFrame) -> anyhow::Result<Tracks> {
        Ok(Tracks {
            detector: strs(df, "detector")?,
            selection: strs(df, "selection")?,
            n_app: i64s(df, "n_app")?,
            frame: i64s(df, "frame")?,
            stamp_ns: i64s(df, "stamp_ns")?,
            t_s: f64s(df, "t_s")?,
            id: i64s(df, "id")?,
            x: f64s(df, "x_m")?,
            y: f64s(df, "y_m")?,
            h: f64s(df, "height_m")?,
            r: f64s(df, "radius_m")?,
            cameras: i64s(df, "cameras")?,
            support: strs(df, "support")?,
            e_m: opt_f64s(df, "e_m_px")?,
        })
    }

    /// Row indices of one variant.
    pub fn rows(&self, key: &Key) -> Vec<usize> {
        (0..self.id.len())
            .filter(|&i| {
                self.detector[i] == key.0 && self.selection[i] == key.1 && self.n_app[i] == key.2
            })
            .collect()
    }
}

/// The ground-truth table of one session.
#[derive(Debug, Clone, Default)]
pub(super) struct Truth {
    pub frame: Vec<i64>,
    pub t_s: Vec<f64>,
    pub id: Vec<i64>,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub h: Vec<f64>,
    pub r: Vec<f64>,
    pub cams: Vec<i64>,
    pub in_room: Vec<bool>,
}

impl Truth {
    fn read(df: &DataFrame) -> anyhow::Result<Truth> {
        Ok(Truth {
            frame: i64s(df, "frame")?,
            t_s: f64s(df, "t_s")?,
            id: i64s(df, "id")?,
            x: f64s(df, "x_m")?,
            y: f64s(df, "y_m")?,
            h: f64s(df, "height_m")?,
            r: f64s(df, "radius_m")?,
            cams: i64s(df, "cameras_visible")?,
            in_room: bools(df, "in_room")?,
        })
    }
}

/// One session's cached results.
pub(super) struct SessionData {
    pub dataset: String,
    pub name: String,
    pub path: PathBuf,
    pub tracks: Tracks,
    pub truth: Truth,
    pub head_centroid: DataFrame,
    pub cameras: DataFrame,
    pub detections_2d: DataFrame,
    pub variants: DataFrame,
    pub calibration: DataFrame,
    pub dt_s: f64,
    pub duration_s: f64,
    pub frames: i64,
    pub decode_failures: i64,
    pub first_error: String,
}

/// `(detector, selection, n_app)`.
pub(super) type Key = (String, String, i64);

fn load(ctx: &Aggregate) -> anyhow::Result<Vec<SessionData>> {
    let mut out = Vec::new();
    for (info, frames) in ctx.sessions {
        let get = |n: &str| {
            frames.get(n).with_context(|| {
                format!(
                    "{}/{}: cached result lacks the {n} table",
                    info.dataset, info.name
                )
            })
        };
        let session = get("session")?;
        out.push(SessionData {
            dataset: info.dataset.clone(),
            name: info.name.clone(),
            path: info.path.clone(),
            tracks: Tracks::read(get("tracks")?)?,
            truth: Truth::read(get("gt")?)?,
            head_centroid: get("head_centroid")?.clone(),
            cameras: get("cameras")?.clone(),
            detections_2d: get("detections_2d")?.clone(),
            variants: get("variants")?.clone(),
            calibration: get("calibration")?.clone(),
            dt_s: f64s(session, "dt_s")?.first().copied().unwrap_or(0.04),
            duration_s: f64s(session, "duration_s")?.first().copied().unwrap_or(0.0),
            frames: i64s(session, "frames")?.first().copied().unwrap_or(0),
            decode_failures: i64s(session, "decode_failures")?
                .first()
                .copied()
                .unwrap_or(0),
            first_error: strs(session, "first_error")?
                .first()
                .cloned()
                .unwrap_or_default(),
        });
    }
    Ok(out)
}

fn point(frame: i64, id: i64, x: f64, y: f64) -> Observation {
    Observation {
        frame,
        id,
        geometry: Geometry::Point(GroundPoint { x_m: x, y_m: y }),
        confidence: 1.0,
    }
}

/// Ground truth of every session (people inside the room), offset per session.
fn truth_observations(data: &[SessionData]) -> Vec<Observation> {
    let mut out = Vec::new();
    for (s, d) in data.iter().enumerate() {
        let o = s as i64 * STRIDE;
        let g = &d.truth;
        for i in 0..g.id.len() {
            if g.in_room[i] {
                out.push(point(o + g.frame[i], o + g.id[i], g.x[i], g.y[i]));
            }
        }
    }
    out
}

fn hypothesis_observations(data: &[SessionData], key: &Key) -> Vec<Observation> {
    let mut out = Vec::new();
    for (s, d) in data.iter().enumerate() {
        let o = s as i64 * STRIDE;
        let t = &d.tracks;
        for i in t.rows(key) {
            out.push(point(o + t.frame[i], o + t.id[i], t.x[i], t.y[i]));
        }
    }
    out
}

/// Per-person detection latency and false-alarm tracks of one evaluation.
struct Latency {
    /// Seconds from the first frame a person is seen by ≥ 2 cameras to the first match.
    latencies_s: Vec<f64>,
    latencies_frames: Vec<f64>,
    trackable: usize,
    false_alarm_tracks: usize,
    tracks: usize,
}

fn latency(data: &[SessionData], key: &Key, ev: &Evaluation) -> Latency {
    let mut first_match: HashMap<i64, i64> = HashMap::new();
    let mut matched_frames: HashMap<i64, u64> = HashMap::new();
    for e in &ev.events {
        if matches!(e.kind, EventKind::Match | EventKind::Switch)
            && let (Some(g), Some(h)) = (e.gt_id, e.hyp_id)
        {
            first_match.entry(g).or_insert(e.frame);
            *matched_frames.entry(h).or_default() += 1;
        }
    }
    // first match at or after the start frame: events are in frame order
    let mut matches_by_gt: HashMap<i64, Vec<i64>> = HashMap::new();
    for e in &ev.events {
        if matches!(e.kind, EventKind::Match | EventKind::Switch)
            && let Some(g) = e.gt_id
        {
            matches_by_gt.entry(g).or_default().push(e.frame);
        }
    }
    let mut out = Latency {
        latencies_s: Vec::new(),
        latencies_frames: Vec::new(),
        trackable: 0,
        false_alarm_tracks: 0,
        tracks: 0,
    };
    for (s, d) in data.iter().enumerate() {
        let o = s as i64 * STRIDE;
        let g = &d.truth;
        let mut start: BTreeMap<i64, i64> = BTreeMap::new();
        for i in 0..g.id.len() {
            if g.in_room[i] && g.cams[i] >= 2 {
                start.entry(g.id[i]).or_insert(g.frame[i]);
            }
        }
        for (id, f0) in start {
            out.trackable += 1;
            let gid = o + id;
            if let Some(f) = matches_by_gt
                .get(&gid)
                .and_then(|v| v.iter().copied().find(|&f| f >= o + f0))
            {
                let frames = (f - (o + f0)) as f64;
                out.latencies_frames.push(frames);
                out.latencies_s.push(frames * d.dt_s);
            }
        }
        let t = &d.tracks;
        let mut total: BTreeMap<i64, u64> = BTreeMap::new();
        for i in t.rows(key) {
            *total.entry(o + t.id[i]).or_default() += 1;
        }
        for (h, n) in total {
            out.tracks += 1;
            let m = matched_frames.get(&h).copied().unwrap_or(0);
            if (m as f64) < 0.5 * n as f64 {
                out.false_alarm_tracks += 1;
            }
        }
    }
    let _ = first_match;
    out
}

fn mean(v: &[f64]) -> Option<f64> {
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

fn std(v: &[f64]) -> Option<f64> {
    describe(v).ok().map(|s| s.std)
}

fn median(v: &[f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    Some(if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    })
}

fn percentile(v: &[f64], q: f64) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let pos = q * (s.len() - 1) as f64;
    let (i, f) = (pos.floor() as usize, pos.fract());
    Some(s[i] * (1.0 - f) + s[(i + 1).min(s.len() - 1)] * f)
}

/// Everything aggregation computes once and the tables and figures share.
pub(super) struct Scored {
    pub data: Vec<SessionData>,
    pub keys: Vec<Key>,
    pub main: Key,
    /// `(key, threshold) → evaluation`.
    pub evals: BTreeMap<(Key, u64), Evaluation>,
    pub thresholds: Vec<f64>,
}

fn tkey(t: f64) -> u64 {
    (t * 1e6).round() as u64
}

impl Scored {
    pub fn eval(&self, key: &Key, t: f64) -> Option<&Evaluation> {
        self.evals.get(&(key.clone(), tkey(t)))
    }
}

pub(crate) fn aggregate(ctx: &Aggregate, p: &Params) -> anyhow::Result<Products> {
    let data = load(ctx)?;
    let mut keys: Vec<Key> = Vec::new();
    for d in &data {
        for i in 0..d.tracks.id.len() {
            let k = (
                d.tracks.detector[i].clone(),
                d.tracks.selection[i].clone(),
                d.tracks.n_app[i],
            );
            if !keys.contains(&k) {
                keys.push(k);
            }
        }
    }
    keys.sort();
    let main: Key = (
        main_detector(p).to_string(),
        selection_label(p.selection).to_string(),
        i64::from(p.n_app),
    );
    let mut thresholds = p.match_m.clone();
    thresholds.sort_by(f64::total_cmp);
    thresholds.dedup();
    let gt = truth_observations(&data);
    let has_truth = !gt.is_empty();
    let mut evals = BTreeMap::new();
    if has_truth {
        use rayon::prelude::*;
        let jobs: Vec<(Key, f64)> = keys
            .iter()
            .flat_map(|k| thresholds.iter().map(move |&t| (k.clone(), t)))
            .collect();
        let results: Vec<anyhow::Result<((Key, u64), Evaluation)>> = jobs
            .par_iter()
            .map(|(k, t)| {
                let hyp = hypothesis_observations(&data, k);
                let ev = evaluate(&gt, &hyp, MatchRule::Euclidean { max_m: *t })
                    .with_context(|| format!("scoring {k:?} at {t} m"))?;
                Ok(((k.clone(), tkey(*t)), ev))
            })
            .collect();
        for r in results {
            let (k, v) = r?;
            evals.insert(k, v);
        }
    }
    let scored = Scored {
        data,
        keys,
        main,
        evals,
        thresholds,
    };
    let mut products = Products::default();
    let sessions = scored.data.len();
    let failures: i64 = scored.data.iter().map(|d| d.decode_failures).sum();
    products.summary.push(format!(
        "{sessions} session(s), {} frames in all; {failures} camera frames failed to decode{}.",
        scored.data.iter().map(|d| d.frames).sum::<i64>(),
        scored
            .data
            .iter()
            .find(|d| !d.first_error.is_empty())
            .map(|d| format!(" (first: {})", d.first_error))
            .unwrap_or_default()
    ));
    products.tables.push(tracks_table(&scored));
    if has_truth {
        products.tables.push(clear_mot_table(&scored, p));
        if let Some(t) = gt_boxes_table(&scored, p, &mut products.summary) {
            products.tables.push(t);
        }
        products
            .tables
            .push(position_table(&scored, p, &mut products.summary)?);
        let (sweep, curve) = sweep_table(&scored, p);
        products.tables.push(sweep);
        products.figures.push(curve);
        let (hc, bars) = head_centroid_table(&scored, p, &mut products.summary)?;
        products.tables.push(hc);
        products.figures.extend(bars);
        products
            .tables
            .push(selection_table(&scored, p, &mut products.summary));
    } else {
        products
            .summary
            .push("No ground truth in these logs: tracks only, no accuracy tables.".to_string());
    }
    products.tables.push(stages_table(&scored)?);
    if let Some(t) = detections_2d_table(&scored, &mut products.summary)? {
        products.tables.push(t);
    }
    products.tables.push(search_table(&scored)?);
    products
        .figures
        .extend(super::figures::birdseye(&scored, p));
    match super::figures::camera_views(&scored, p) {
        Ok(Some(f)) => products.figures.push(f),
        Ok(None) => {}
        Err(e) => products
            .summary
            .push(format!("Camera-view figure not drawn: {e:#}")),
    }
    let tracks_dir = ctx
        .write_tracks
        .map(Path::to_path_buf)
        .or_else(|| (!p.write_tracks.is_empty()).then(|| PathBuf::from(&p.write_tracks)));
    if let Some(dir) = tracks_dir {
        for line in super::markers::write_all(&scored, p, &dir)? {
            products.summary.push(line);
        }
    }
    if let Some(e) = scored.eval(&scored.main, scored.thresholds[scored.thresholds.len() - 1]) {
        let m = &e.metrics;
        products.summary.insert(
            0,
            format!(
                "Main run ({}, {}, N_app = {}): MOTA {:.3} and IDF1 {:.3} at {} m.",
                scored.main.0,
                scored.main.1,
                scored.main.2,
                m.clear.mota,
                m.identity.idf1,
                scored.thresholds[scored.thresholds.len() - 1]
            ),
        );
    }
    Ok(products)
}

fn tracks_table(s: &Scored) -> Table {
    let (mut sess, mut id, mut t0, mut t1, mut frames, mut supported) = (
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
    );
    let (mut mx, mut my, mut mh, mut mr, mut mc, mut me) = (
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
    );
    // per-frame samples
    let (
        mut s_sess,
        mut s_frame,
        mut s_t,
        mut s_id,
        mut s_x,
        mut s_y,
        mut s_h,
        mut s_r,
        mut s_c,
        mut s_sup,
        mut s_e,
    ) = (
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
    );
    for d in &s.data {
        let t = &d.tracks;
        let rows = t.rows(&s.main);
        let mut by_id: BTreeMap<i64, Vec<usize>> = BTreeMap::new();
        for &i in &rows {
            by_id.entry(t.id[i]).or_default().push(i);
            s_sess.push(d.name.clone());
            s_frame.push(t.frame[i]);
            s_t.push(t.t_s[i]);
            s_id.push(t.id[i]);
            s_x.push(t.x[i]);
            s_y.push(t.y[i]);
            s_h.push(t.h[i]);
            s_r.push(t.r[i]);
            s_c.push(t.cameras[i]);
            s_sup.push(t.support[i].clone());
            s_e.push(t.e_m[i]);
        }
        for (k, ix) in by_id {
            let avg = |v: &[f64]| ix.iter().map(|&i| v[i]).sum::<f64>() / ix.len() as f64;
            sess.push(d.name.clone());
            id.push(k);
            t0.push(t.t_s[ix[0]]);
            t1.push(t.t_s[ix[ix.len() - 1]]);
            frames.push(ix.len() as i64);
            let sup: Vec<usize> = ix.iter().copied().filter(|&i| t.cameras[i] > 0).collect();
            supported.push(sup.len() as i64);
            mx.push(avg(&t.x));
            my.push(avg(&t.y));
            mh.push(avg(&t.h));
            mr.push(avg(&t.r));
            mc.push(if sup.is_empty() {
                f64::NAN
            } else {
                sup.iter().map(|&i| t.cameras[i] as f64).sum::<f64>() / sup.len() as f64
            });
            let es: Vec<f64> = ix.iter().filter_map(|&i| t.e_m[i]).collect();
            me.push(mean(&es));
        }
    }
    let df = df! {
        "session" => sess, "id" => id, "first_s" => t0, "last_s" => t1, "frames" => frames,
        "supported_frames" => supported, "mean_x_m" => mx, "mean_y_m" => my,
        "mean_height_m" => mh, "mean_radius_m" => mr, "mean_cameras" => mc, "mean_E_m_px" => me,
    };
    let samples = df! {
        "session" => s_sess, "frame" => s_frame, "t_s" => s_t, "id" => s_id, "x_m" => s_x,
        "y_m" => s_y, "height_m" => s_h, "radius_m" => s_r, "cameras" => s_c,
        "support" => s_sup, "E_m_px" => s_e,
    };
    let mut t = Table::new(
        "tracks",
        format!(
            "3-D tracks ({} detector, {} selection, N_app = {}): one row per track; per frame and person in the samples",
            s.main.0, s.main.1, s.main.2
        ),
        df.unwrap_or_default(),
    )
    .with_precision("first_s", 2)
    .with_precision("last_s", 2)
    .with_precision("mean_cameras", 2)
    .with_precision("mean_E_m_px", 2)
    .with_note("Per frame: ground position, height and radius (Kalman-smoothed), supporting cameras as `camera:2-D id`, E_m of the supporting combination (empty while the track coasts) — in tracks.samples.parquet and in each session's tracks.parquet (all runs).");
    if let Ok(samples) = samples {
        t = t.with_samples(samples);
    }
    t
}

fn clear_mot_table(s: &Scored, p: &Params) -> Table {
    let mut cols: (
        Vec<String>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
    ) = Default::default();
    let mut counts: (
        Vec<i64>,
        Vec<i64>,
        Vec<i64>,
        Vec<i64>,
        Vec<i64>,
        Vec<i64>,
        Vec<i64>,
        Vec<i64>,
    ) = Default::default();
    let mut paper = Vec::new();
    let detectors: Vec<String> = {
        let mut v: Vec<String> = s.keys.iter().map(|k| k.0.clone()).collect();
        v.dedup();
        v
    };
    for det in &detectors {
        let key: Key = (det.clone(), s.main.1.clone(), s.main.2);
        for &t in &s.thresholds {
            let Some(e) = s.eval(&key, t) else { continue };
            let (c, i, h) = (&e.metrics.clear, &e.metrics.identity, &e.metrics.hota);
            cols.0.push(det.clone());
            cols.1.push(t);
            cols.2.push(c.mota);
            cols.3.push(c.motp);
            cols.4.push(i.idf1);
            cols.5.push(h.hota);
            cols.6.push(c.recall);
            cols.7.push(c.precision);
            cols.8.push(i.idp);
            counts.0.push(c.num_objects as i64);
            counts.1.push(c.num_false_positives as i64);
            counts.2.push(c.num_misses as i64);
            counts.3.push(c.num_switches as i64);
            counts.4.push(c.num_fragmentations as i64);
            counts.5.push(c.mostly_tracked as i64);
            counts.6.push(c.mostly_lost as i64);
            counts.7.push(c.num_unique_objects as i64);
            paper.push("—".to_string());
        }
    }
    let df = df! {
        "detector" => cols.0, "match_m" => cols.1, "MOTA" => cols.2, "MOTP_m" => cols.3,
        "IDF1" => cols.4, "HOTA" => cols.5, "recall" => cols.6, "precision" => cols.7,
        "IDP" => cols.8, "GT" => counts.0, "FP" => counts.1, "FN" => counts.2, "IDSW" => counts.3,
        "frag" => counts.4, "MT" => counts.5, "ML" => counts.6, "people" => counts.7,
        "paper" => paper,
    };
    Table::new(
        "clear_mot",
        format!(
            "CLEAR MOT, IDF1 and HOTA on the ground plane ({} selection, N_app = {}, N_dis = {})",
            s.main.1, p.n_app, p.n_dis
        ),
        df.unwrap_or_default(),
    )
    .with_precision("match_m", 1)
    .with_note("Ground truth: every person inside the room at every frame (also those seen by fewer than two cameras, which no triangulation can place). A hypothesis matches a person within match_m on the ground (motmetrics 'euc' rule); MOTP is the mean matched distance in metres.")
    .with_note("Paper: no CLEAR MOT, IDF1 or error numbers are given (§6 reports figures 5–6 and qualitative statements only), hence '—'.")
    .with_note(format!("Detectors: `{}` = the paper's chain (Gabor background, templates, graph-matching 2-D tracks); `{GT_BOXES}` = the ground-truth visible boxes of the log through the same 2-D and 3-D stages (head: the box's top row on the image of the person's vertical, from the calibration; the top centre with box_head_on_axis = false); `log` = Detection2DArray topics.", super::session::TEMPLATES))
}

fn gt_boxes_table(s: &Scored, _p: &Params, summary: &mut Vec<String>) -> Option<Table> {
    let key: Key = (GT_BOXES.to_string(), s.main.1.clone(), s.main.2);
    let mut rows: (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>, Vec<bool>) = Default::default();
    for &t in &s.thresholds {
        let e = s.eval(&key, t)?;
        rows.0.push(t);
        rows.1.push(e.metrics.clear.mota);
        rows.2.push(e.metrics.identity.idf1);
        rows.3.push(0.95);
        rows.4.push(e.metrics.clear.mota >= 0.95);
    }
    let last = rows.1.last().copied().unwrap_or(f64::NAN);
    summary.push(format!(
        "3-D stage alone on ground-truth boxes: MOTA {last:.3} at {} m (target ≥ 0.95).",
        rows.0.last().copied().unwrap_or(f64::NAN)
    ));
    let df = df! {
        "match_m" => rows.0, "MOTA" => rows.1, "IDF1" => rows.2, "target_MOTA" => rows.3,
        "reached" => rows.4,
    }
    .ok()?;
    Some(
        Table::new(
            "gt_boxes_3d",
            "The 3-D stage isolated from detection: ground-truth 2-D boxes from the log as the detector",
            df,
        )
        .with_precision("match_m", 1)
        .with_precision("target_MOTA", 2)
        .with_note("Boxes are the visible extent of each person in each camera; the head is the point of the box's top row on the image of the person's vertical line, from the calibration (box_head_on_axis; in the corner cameras people lean and the top centre is off the head), as for any box detector. Misses here come from people seen by fewer than two cameras, from heads hidden by furniture or people, and from the N_app promotion delay.")
        .with_note("Paper: no number (the target 0.95 is this project's acceptance bar, not the paper's)."),
    )
}

fn position_table(s: &Scored, p: &Params, summary: &mut Vec<String>) -> anyhow::Result<Table> {
    let t_match = s.thresholds[s.thresholds.len() - 1];
    let mut det_col = Vec::new();
    let mut sess_col = Vec::new();
    let mut id_col = Vec::new();
    let (
        mut n_col,
        mut ge_mean,
        mut ge_std,
        mut ge_p95,
        mut he_mean,
        mut he_abs,
        mut r_est,
        mut r_true,
        mut h_true,
    ) = (
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
    );
    let mut smp: (
        Vec<String>,
        Vec<String>,
        Vec<i64>,
        Vec<i64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
    ) = Default::default();
    let mut detectors: Vec<String> = s.keys.iter().map(|k| k.0.clone()).collect();
    detectors.dedup();
    for det in &detectors {
        let key: Key = (det.clone(), s.main.1.clone(), s.main.2);
        let Some(ev) = s.eval(&key, t_match) else {
            continue;
        };
        // lookups: (global frame, global id) → row
        let mut hyp: HashMap<(i64, i64), (usize, usize)> = HashMap::new();
        let mut gt: HashMap<(i64, i64), (usize, usize)> = HashMap::new();
        for (si, d) in s.data.iter().enumerate() {
            let o = si as i64 * STRIDE;
            for i in d.tracks.rows(&key) {
                hyp.insert((o + d.tracks.frame[i], o + d.tracks.id[i]), (si, i));
            }
            for i in 0..d.truth.id.len() {
                gt.insert((o + d.truth.frame[i], o + d.truth.id[i]), (si, i));
            }
        }
        // per person: (ground error, height error, radius estimate)
        let mut per: BTreeMap<(usize, i64), Vec<(f64, f64, f64, f64, f64)>> = BTreeMap::new();
        for e in &ev.events {
            if !matches!(e.kind, EventKind::Match | EventKind::Switch) {
                continue;
            }
            let (Some(g), Some(h)) = (e.gt_id, e.hyp_id) else {
                continue;
            };
            let (Some(&(si, gi)), Some(&(_, hi))) = (gt.get(&(e.frame, g)), hyp.get(&(e.frame, h)))
            else {
                continue;
            };
            let (d, tr) = (&s.data[si].truth, &s.data[si].tracks);
            let ground = (tr.x[hi] - d.x[gi]).hypot(tr.y[hi] - d.y[gi]);
            per.entry((si, d.id[gi])).or_default().push((
                ground,
                tr.h[hi] - d.h[gi],
                tr.r[hi],
                d.r[gi],
                d.h[gi],
            ));
            smp.0.push(det.clone());
            smp.1.push(s.data[si].name.clone());
            smp.2.push(d.frame[gi]);
            smp.3.push(d.id[gi]);
            smp.4.push(ground);
            smp.5.push(tr.h[hi] - d.h[gi]);
            smp.6.push(tr.r[hi]);
            smp.7.push(d.r[gi]);
            smp.8.push(d.t_s[gi]);
        }
        let mut all: Vec<(f64, f64, f64, f64, f64)> = Vec::new();
        let mut push = |sess: String, id: String, v: &[(f64, f64, f64, f64, f64)]| {
            let g: Vec<f64> = v.iter().map(|x| x.0).collect();
            let h: Vec<f64> = v.iter().map(|x| x.1).collect();
            det_col.push(det.clone());
            sess_col.push(sess);
            id_col.push(id);
            n_col.push(v.len() as i64);
            ge_mean.push(mean(&g));
            ge_std.push(std(&g));
            ge_p95.push(percentile(&g, 0.95));
            he_mean.push(mean(&h));
            he_abs.push(mean(&h.iter().map(|x| x.abs()).collect::<Vec<_>>()));
            r_est.push(mean(&v.iter().map(|x| x.2).collect::<Vec<_>>()));
            r_true.push(mean(&v.iter().map(|x| x.3).collect::<Vec<_>>()));
            h_true.push(mean(&v.iter().map(|x| x.4).collect::<Vec<_>>()));
        };
        for ((si, id), v) in &per {
            push(s.data[*si].name.clone(), id.to_string(), v);
            all.extend_from_slice(v);
        }
        push("all".into(), "all".into(), &all);
        if det == &s.main.0 {
            let g: Vec<f64> = all.iter().map(|x| x.0).collect();
            let h: Vec<f64> = all.iter().map(|x| x.1.abs()).collect();
            summary.push(format!(
                "Ground-position error {:.3} m (median {:.3}), |height error| {:.3} m over {} matched person-frames ({}).",
                mean(&g).unwrap_or(f64::NAN),
                median(&g).unwrap_or(f64::NAN),
                mean(&h).unwrap_or(f64::NAN),
                g.len(),
                det
            ));
        }
    }
    let n_rows = n_col.len();
    let df = df! {
        "detector" => det_col, "session" => sess_col, "person" => id_col, "frames" => n_col,
        "ground_error_m" => ge_mean, "ground_error_std_m" => ge_std, "ground_error_p95_m" => ge_p95,
        "height_error_m" => he_mean, "abs_height_error_m" => he_abs, "true_height_m" => h_true,
        "radius_m" => r_est, "true_radius_m" => r_true,
        "paper" => vec!["—"; n_rows],
    }?;
    let samples = df! {
        "detector" => smp.0, "session" => smp.1, "frame" => smp.2, "person" => smp.3,
        "ground_error_m" => smp.4, "height_error_m" => smp.5, "radius_m" => smp.6,
        "true_radius_m" => smp.7, "t_s" => smp.8,
    }?;
    let _ = p;
    Ok(Table::new(
        "position_error",
        format!("3-D ground-position error, height error and cylinder radius per person (frames matched within {t_match} m)"),
        df,
    )
    .with_note("Errors are of the Kalman-smoothed cylinder against the ground truth: ground position = body centre on the floor; height = top of the head; radius = body (shoulder) radius. Height error is signed (estimate − truth).")
    .with_note("Paper: no numbers; §6 says the system locates a person 'accurately' and estimates the height 'with great precision' (fig. 5c).")
    .with_samples(samples))
}

fn sweep_table(s: &Scored, p: &Params) -> (Table, crate::report::Figure) {
    use crate::report::figure::{Event, FigureKind, LinePlot, Mark, Series};
    let t_match = s.thresholds[s.thresholds.len() - 1];
    let mut c: (
        Vec<String>,
        Vec<i64>,
        Vec<Option<f64>>,
        Vec<Option<f64>>,
        Vec<Option<f64>>,
        Vec<i64>,
        Vec<i64>,
        Vec<i64>,
        Vec<i64>,
        Vec<f64>,
        Vec<f64>,
    ) = Default::default();
    let mut paper = Vec::new();
    let mut detectors: Vec<String> = s.keys.iter().map(|k| k.0.clone()).collect();
    detectors.dedup();
    let minutes: f64 = s.data.iter().map(|d| d.duration_s).sum::<f64>() / 60.0;
    let mut series = Vec::new();
    for (di, det) in detectors.iter().enumerate() {
        let mut lat_pts = Vec::new();
        let mut fa_pts = Vec::new();
        let mut ns: Vec<i64> = s
            .keys
            .iter()
            .filter(|k| &k.0 == det && k.1 == s.main.1)
            .map(|k| k.2)
            .collect();
        ns.sort_unstable();
        for n in ns {
            if !p.n_app_sweep.contains(&(n as u32)) {
                continue;
            }
            let key: Key = (det.clone(), s.main.1.clone(), n);
            let Some(ev) = s.eval(&key, t_match) else {
                continue;
            };
            let l = latency(&s.data, &key, ev);
            c.0.push(det.clone());
            c.1.push(n);
            c.2.push(mean(&l.latencies_frames));
            c.3.push(mean(&l.latencies_s));
            c.4.push(median(&l.latencies_s));
            c.5.push(l.latencies_s.len() as i64);
            c.6.push(l.trackable as i64);
            c.7.push(l.false_alarm_tracks as i64);
            c.8.push(l.tracks as i64);
            c.9.push(if minutes > 0.0 {
                ev.metrics.clear.num_false_positives as f64 / minutes
            } else {
                f64::NAN
            });
            c.10.push(ev.metrics.clear.mota);
            paper.push(if n == 5 { "chosen (5)" } else { "" }.to_string());
            if let Some(m) = mean(&l.latencies_frames) {
                lat_pts.push((n as f64, m));
            }
            fa_pts.push((n as f64, l.false_alarm_tracks as f64));
        }
        series.push(
            Series::line(format!("{det}: mean latency (frames)"), lat_pts, 2 * di + 1).with_mark(
                if di == 0 {
                    Mark::LinePoints
                } else {
                    Mark::Dashed
                },
            ),
        );
        series.push(
            Series::line(format!("{det}: false-alarm tracks"), fa_pts, 2 * di + 5).with_mark(
                if di == 0 {
                    Mark::LinePoints
                } else {
                    Mark::Dashed
                },
            ),
        );
    }
    let df = df! {
        "detector" => c.0, "N_app" => c.1, "latency_frames" => c.2, "latency_s" => c.3,
        "median_latency_s" => c.4, "people_detected" => c.5, "people_trackable" => c.6,
        "false_alarm_tracks" => c.7, "tracks" => c.8, "FP_per_min" => c.9,
        format!("MOTA_{t_match}m") => c.10, "paper" => paper,
    };
    let table = Table::new(
        "n_app_sweep",
        format!("Detection latency and false alarms against N_app (N_dis = N_app; matches within {t_match} m)"),
        df.unwrap_or_default(),
    )
    .with_precision("latency_frames", 1)
    .with_precision("latency_s", 2)
    .with_precision("median_latency_s", 2)
    .with_precision("FP_per_min", 1)
    .with_note("Latency: per person, from the first frame in which at least two cameras see them to the first frame a 3-D track is matched to them. A false-alarm track is matched to a person in fewer than half of its frames; FP_per_min counts unmatched track-frames per minute of data.")
    .with_note("Paper: N_app = 5 'is a good trade-off between 3D object detection latency and false alarm rate' (§5); no latency or false-alarm numbers are given.");
    let fig = crate::report::Figure::new(
        "n_app_latency_false_alarms",
        "Latency and false alarms against N_app",
        FigureKind::Lines(LinePlot {
            x_label: "N_app (frames; N_dis = N_app)".into(),
            y_label: "frames / tracks".into(),
            series,
            events: vec![Event {
                x: 5.0,
                label: "paper: N_app = 5".into(),
                color: 0,
            }],
            ..Default::default()
        }),
    );
    (table, fig)
}

fn head_centroid_table(
    s: &Scored,
    p: &Params,
    summary: &mut Vec<String>,
) -> anyhow::Result<(Table, Vec<crate::report::Figure>)> {
    use crate::report::figure::{Bar, BarPlot, FigureKind, Significance};
    let mut c: (
        Vec<String>,
        Vec<String>,
        Vec<i64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        Vec<bool>,
    ) = Default::default();
    let mut smp: (
        Vec<String>,
        Vec<String>,
        Vec<i64>,
        Vec<i64>,
        Vec<String>,
        Vec<f64>,
        Vec<f64>,
    ) = Default::default();
    let mut figures = Vec::new();
    let mut detectors: Vec<String> = Vec::new();
    let mut rows: BTreeMap<(String, String), (Vec<f64>, Vec<f64>)> = BTreeMap::new();
    for d in &s.data {
        let hc = &d.head_centroid;
        let det = strs(hc, "detector")?;
        let occ = bools(hc, "occluded")?;
        let clear = bools(hc, "clear")?;
        let he = f64s(hc, "head_error_m")?;
        let ce = f64s(hc, "centroid_error_m")?;
        let fr = i64s(hc, "frame")?;
        let id = i64s(hc, "id")?;
        for i in 0..det.len() {
            if !detectors.contains(&det[i]) {
                detectors.push(det[i].clone());
            }
            let set = if occ[i] {
                "static occlusion"
            } else if clear[i] {
                "unoccluded"
            } else {
                continue;
            };
            let e = rows.entry((det[i].clone(), set.to_string())).or_default();
            e.0.push(he[i]);
            e.1.push(ce[i]);
            smp.0.push(det[i].clone());
            smp.1.push(d.name.clone());
            smp.2.push(fr[i]);
            smp.3.push(id[i]);
            smp.4.push(set.to_string());
            smp.5.push(he[i]);
            smp.6.push(ce[i]);
        }
    }
    for det in &detectors {
        let mut bars = Vec::new();
        let mut sig = Vec::new();
        for set in ["static occlusion", "unoccluded"] {
            let Some((h, m)) = rows.get(&(det.clone(), set.to_string())) else {
                continue;
            };
            let test = student_t(h, m, DEFAULT_LEVEL).ok();
            c.0.push(det.clone());
            c.1.push(set.to_string());
            c.2.push(h.len() as i64);
            c.3.push(mean(h).unwrap_or(f64::NAN));
            c.4.push(std(h).unwrap_or(f64::NAN));
            c.5.push(mean(m).unwrap_or(f64::NAN));
            c.6.push(std(m).unwrap_or(f64::NAN));
            c.7.push(test.as_ref().map_or(f64::NAN, |t| t.t));
            c.8.push(test.as_ref().map_or(f64::NAN, |t| t.df));
            c.9.push(test.as_ref().map_or(f64::NAN, |t| t.p_two_sided));
            c.10.push(test.as_ref().map_or(f64::NAN, |t| t.cohens_d));
            c.11.push(
                test.as_ref()
                    .is_some_and(|t| t.significant(1.0 - DEFAULT_LEVEL)),
            );
            let i0 = bars.len();
            bars.push(Bar {
                label: format!("head, {set}"),
                value: mean(h).unwrap_or(f64::NAN),
                error: std(h).unwrap_or(0.0),
            });
            bars.push(Bar {
                label: format!("centroid, {set}"),
                value: mean(m).unwrap_or(f64::NAN),
                error: std(m).unwrap_or(0.0),
            });
            if let Some(t) = &test {
                sig.push(Significance {
                    i: i0,
                    j: i0 + 1,
                    label: format!("p = {:.2e}", t.p_two_sided),
                });
                if set == "static occlusion" && det == &s.main.0 {
                    summary.push(format!(
                        "Under static occlusion ({det}), head-point triangulation errs {:.3} m on the ground vs {:.3} m for blob centroids (n = {} each, Student t = {:.2}, p = {:.2e}).",
                        mean(h).unwrap_or(f64::NAN),
                        mean(m).unwrap_or(f64::NAN),
                        h.len(),
                        t.t,
                        t.p_two_sided
                    ));
                }
            }
        }
        if !bars.is_empty() {
            figures.push(crate::report::Figure::new(
                format!("head_vs_centroid_{det}"),
                format!("Ground error of triangulated head points vs blob centroids ({det})"),
                FigureKind::Bars(BarPlot {
                    y_label: "ground-position error (m), mean ± std".into(),
                    bars,
                    significance: sig,
                }),
            ));
        }
    }
    let df = df! {
        "detector" => c.0, "set" => c.1, "n" => c.2, "head_error_m" => c.3, "head_std_m" => c.4,
        "centroid_error_m" => c.5, "centroid_std_m" => c.6, "t" => c.7, "df" => c.8, "p" => c.9,
        "cohens_d" => c.10, "significant_99" => c.11,
    }?;
    let samples = df! {
        "detector" => smp.0, "session" => smp.1, "frame" => smp.2, "person" => smp.3,
        "set" => smp.4, "head_error_m" => smp.5, "centroid_error_m" => smp.6,
    }?;
    Ok((
        Table::new(
            "head_vs_centroid",
            "Triangulating head points vs blob centroids: ground-position error under static (desk) occlusion, unpaired Student t-test at 99 %",
            df,
        )
        .with_precision("t", 2)
        .with_precision("df", 0)
        .with_precision("p", 4)
        .with_precision("cohens_d", 2)
        .with_note(format!("Per person and frame, each camera's detection is associated with the person by box overlap (IoU ≥ 0.25 with the visible ground-truth box); the head points (template top, or the box head of the 3-D run) and the blob centroids (foreground pixels in the template box, or box centre) of the associated cameras (≥ 2) are triangulated by DLT and the ground (x, y) compared with the truth. 'static occlusion': at least one camera sees the person with visibility < {} and no other person's box overlaps theirs there (so furniture hides them); 'unoccluded': visibility ≥ 0.95 in every camera used.", p.occluded_visibility))
        .with_note("Consecutive frames of one person are correlated, so the t-test's n overstates the independent evidence; the effect size (Cohen's d) does not depend on n.")
        .with_note("Paper: argues (§5) that head points are more robust than centroids to static occlusion, without numbers.")
        .with_samples(samples),
        figures,
    ))
}

fn selection_table(s: &Scored, _p: &Params, summary: &mut Vec<String>) -> Table {
    let mut c: (
        Vec<String>,
        Vec<String>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        Vec<i64>,
        Vec<i64>,
        Vec<i64>,
        Vec<f64>,
        Vec<f64>,
    ) = Default::default();
    let mut detectors: Vec<String> = s.keys.iter().map(|k| k.0.clone()).collect();
    detectors.dedup();
    let (lo, hi) = (s.thresholds[0], s.thresholds[s.thresholds.len() - 1]);
    for det in &detectors {
        for sel in ["E_c", "E_m"] {
            let key: Key = (det.clone(), sel.to_string(), s.main.2);
            let (Some(a), Some(b)) = (s.eval(&key, lo), s.eval(&key, hi)) else {
                continue;
            };
            let mut cams = Vec::new();
            let mut ems = Vec::new();
            for d in &s.data {
                for i in d.tracks.rows(&key) {
                    if d.tracks.cameras[i] > 0 {
                        cams.push(d.tracks.cameras[i] as f64);
                    }
                    if let Some(e) = d.tracks.e_m[i] {
                        ems.push(e);
                    }
                }
            }
            c.0.push(det.clone());
            c.1.push(sel.to_string());
            c.2.push(a.metrics.clear.mota);
            c.3.push(b.metrics.clear.mota);
            c.4.push(b.metrics.identity.idf1);
            c.5.push(b.metrics.clear.num_false_positives as i64);
            c.6.push(b.metrics.clear.num_misses as i64);
            c.7.push(b.metrics.clear.num_switches as i64);
            c.8.push(mean(&cams).unwrap_or(f64::NAN));
            c.9.push(mean(&ems).unwrap_or(f64::NAN));
        }
    }
    for det in &detectors {
        let find = |sel: &str| {
            (0..c.0.len())
                .find(|&i| &c.0[i] == det && c.1[i] == sel)
                .map(|i| (c.3[i], c.8[i]))
        };
        if let (Some(ec), Some(em)) = (find("E_c"), find("E_m")) {
            summary.push(format!(
                "Selection by E_c vs E_m ({det}): MOTA {:.3} vs {:.3} at {hi} m, {:.2} vs {:.2} supporting cameras on average.",
                ec.0, em.0, ec.1, em.1
            ));
        }
    }
    let df = df! {
        "detector" => c.0, "selection" => c.1, format!("MOTA_{lo}m") => c.2,
        format!("MOTA_{hi}m") => c.3, format!("IDF1_{hi}m") => c.4, "FP" => c.5, "FN" => c.6,
        "IDSW" => c.7, "mean_cameras" => c.8, "mean_E_m_px" => c.9,
    };
    Table::new(
        "selection_rule",
        format!("Choosing combinations by the corrected error E_c = E_m / 10^N_c (eq. 5) or by E_m (eq. 4), N_app = {}", s.main.2),
        df.unwrap_or_default(),
    )
    .with_precision("mean_cameras", 2)
    .with_precision("mean_E_m_px", 2)
    .with_note("Both rules see the same 2-D objects and thresholds; only the choice among valid combinations (new objects and updates) differs. FP/FN/IDSW at the larger threshold.")
    .with_note("Paper: E_c 'has proved a good trade-off between different numbers of cameras' (§5); no numbers.")
}

fn stages_table(s: &Scored) -> anyhow::Result<Table> {
    let mut acc: BTreeMap<String, (f64, f64, f64, f64, usize)> = BTreeMap::new();
    for d in &s.data {
        let cams = strs(&d.cameras, "camera")?;
        let fg = f64s(&d.cameras, "foreground_frac")?;
        let th = f64s(&d.cameras, "threshold")?;
        let dets = i64s(&d.cameras, "detections")?;
        let objs = i64s(&d.cameras, "objects_2d")?;
        for i in 0..cams.len() {
            let e = acc.entry(cams[i].clone()).or_default();
            e.0 += fg[i];
            e.1 += th[i];
            e.2 += dets[i] as f64;
            e.3 += objs[i] as f64;
            e.4 += 1;
        }
    }
    let (mut cam, mut fg, mut th, mut de, mut ob, mut n) = (
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
    );
    for (k, v) in acc {
        let m = v.4.max(1) as f64;
        cam.push(k);
        fg.push(v.0 / m);
        th.push(v.1 / m);
        de.push(v.2 / m);
        ob.push(v.3 / m);
        n.push(v.4 as i64);
    }
    let df = df! {
        "camera" => cam, "frames" => n, "foreground_fraction" => fg, "mad_threshold" => th,
        "detections_per_frame" => de, "objects_2d_per_frame" => ob,
    }?;
    Ok(Table::new(
        "stages",
        "Per-camera image stages (templates detector): segmented fraction, MAD threshold, detections and 2-D objects per frame",
        df,
    )
    .with_precision("foreground_fraction", 4)
    .with_precision("mad_threshold", 4)
    .with_precision("detections_per_frame", 2)
    .with_precision("objects_2d_per_frame", 2)
    .with_note("Means over all frames of all sessions. The MAD threshold is in Gabor-feature distance units (median + k · 1.4826 · MAD of the frame's distance image). Empty when the detector is `log`."))
}

/// The paper's detector (§2–3) alone: template detections against the log's visible
/// ground-truth boxes.
fn detections_2d_table(s: &Scored, summary: &mut Vec<String>) -> anyhow::Result<Option<Table>> {
    // per camera: frames, truth, detections, matched, Σ|dx|, Σdy, Σ height ratio
    let mut acc: BTreeMap<String, (i64, i64, i64, i64, f64, f64, f64)> = BTreeMap::new();
    for d in &s.data {
        let t = &d.detections_2d;
        if t.height() == 0 {
            continue;
        }
        let cams = strs(t, "camera")?;
        let (tr, de, ma) = (
            i64s(t, "truth")?,
            i64s(t, "detections")?,
            i64s(t, "matched")?,
        );
        let (dx, dy, hr) = (
            f64s(t, "head_dx_abs_px")?,
            f64s(t, "head_dy_px")?,
            f64s(t, "height_ratio")?,
        );
        for i in 0..cams.len() {
            for key in [cams[i].clone(), "all".to_string()] {
                let e = acc.entry(key).or_default();
                e.0 += 1;
                e.1 += tr[i];
                e.2 += de[i];
                e.3 += ma[i];
                e.4 += dx[i];
                e.5 += dy[i];
                e.6 += hr[i];
            }
        }
    }
    if acc.is_empty() {
        return Ok(None);
    }
    let mut cols: (
        Vec<String>,
        Vec<i64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
    ) = Default::default();
    let (mut dxs, mut dys, mut hrs) = (Vec::new(), Vec::new(), Vec::new());
    // cameras first, "all" last
    let mut keys: Vec<String> = acc.keys().filter(|k| *k != "all").cloned().collect();
    keys.push("all".into());
    for k in keys {
        let v = acc[&k];
        let frames = v.0.max(1) as f64;
        let ratio = |a: i64, b: i64| if b > 0 { a as f64 / b as f64 } else { f64::NAN };
        let per_match = |x: f64| if v.3 > 0 { x / v.3 as f64 } else { f64::NAN };
        let (precision, recall) = (ratio(v.3, v.2), ratio(v.3, v.1));
        let f1 = 2.0 * precision * recall / (precision + recall);
        if k == "all" {
            summary.push(format!(
                "template detector alone (head within {DETECTION_HEAD_TOL} box widths of the true head): precision {precision:.3}, recall {recall:.3}, {:.1} detections for {:.1} people per camera and frame",
                v.2 as f64 / frames,
                v.1 as f64 / frames
            ));
        }
        cols.0.push(k);
        cols.1.push(v.0);
        cols.2.push(v.1 as f64 / frames);
        cols.3.push(v.2 as f64 / frames);
        cols.4.push(precision);
        cols.5.push(recall);
        cols.6.push(f1);
        dxs.push(per_match(v.4));
        dys.push(per_match(v.5));
        hrs.push(per_match(v.6));
    }
    let df = df! {
        "camera" => cols.0, "frames" => cols.1, "people_per_frame" => cols.2,
        "detections_per_frame" => cols.3, "precision" => cols.4, "recall" => cols.5,
        "f1" => cols.6, "head_dx_abs_px" => dxs, "head_dy_px" => dys, "height_ratio" => hrs,
    }?;
    Ok(Some(
        Table::new(
            "detections_2d",
            "The template detector alone (§2–3): detections against the visible ground-truth boxes per camera",
            df,
        )
        .with_precision("people_per_frame", 2)
        .with_precision("detections_per_frame", 2)
        .with_precision("head_dx_abs_px", 1)
        .with_precision("head_dy_px", 1)
        .with_precision("height_ratio", 2)
        .with_note(format!("A detection matches a ground-truth person (the visible box, at least 8 px tall) when its head point lies within {DETECTION_HEAD_TOL} × the visible box width of the person's projected head top (from the log's ground truth; the box's top centre when the log has none) — the point the 3-D stage triangulates; IoU would punish the full-body template box of a person whose legs a desk hides — one to one, nearest first. Head offsets and height ratios are means over matched pairs: head_dy_px < 0 puts the detected head above the projected head top; height_ratio is the template's silhouette height over the visible box height (a desk hides the legs, so > 1 is expected there)."))
        .with_note("Paper: no detection numbers (fig. 3 shows the process on one frame)."),
    ))
}

fn search_table(s: &Scored) -> anyhow::Result<Table> {
    let mut acc: BTreeMap<(String, String, i64), (i64, i64, i64, i64, i64)> = BTreeMap::new();
    for d in &s.data {
        let v = &d.variants;
        let (det, sel, n) = (
            strs(v, "detector")?,
            strs(v, "selection")?,
            i64s(v, "n_app")?,
        );
        let (c, pr, po, di) = (
            i64s(v, "combinations")?,
            i64s(v, "pruned_frames")?,
            i64s(v, "promoted")?,
            i64s(v, "discarded")?,
        );
        for i in 0..det.len() {
            let e = acc
                .entry((det[i].clone(), sel[i].clone(), n[i]))
                .or_default();
            e.0 += c[i];
            e.1 += pr[i];
            e.2 += po[i];
            e.3 += di[i];
            e.4 += d.frames;
        }
    }
    let mut c: (
        Vec<String>,
        Vec<String>,
        Vec<i64>,
        Vec<f64>,
        Vec<i64>,
        Vec<i64>,
        Vec<i64>,
    ) = Default::default();
    for ((det, sel, n), v) in acc {
        c.0.push(det);
        c.1.push(sel);
        c.2.push(n);
        c.3.push(v.0 as f64 / v.4.max(1) as f64);
        c.4.push(v.1);
        c.5.push(v.2);
        c.6.push(v.3);
    }
    let df = df! {
        "detector" => c.0, "selection" => c.1, "N_app" => c.2, "combinations_per_frame" => c.3,
        "pruned_frames" => c.4, "promoted" => c.5, "discarded" => c.6,
    }?;
    Ok(Table::new(
        "search",
        "The 3-D search: combinations triangulated per frame, frames where the exhaustive search was pruned, objects promoted and discarded",
        df,
    )
    .with_precision("combinations_per_frame", 1)
    .with_note("pruned_frames counts frames in which the exhaustive search over new combinations would have exceeded max_combinations and only pairwise-coherent combinations were tried."))
}

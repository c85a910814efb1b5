//! What the aggregation shares: every session's cached tables read back as rows, and the
//! CLEAR MOT evaluations of every run at every matching threshold, computed once.
//!
//! Sessions are scored together as one sequence (frame numbers and identities offset per
//! session, so nothing can match across sessions): CLEAR MOT counts are then the sums over
//! sessions, as motmetrics' `OVERALL` row.

use std::collections::BTreeMap;
use std::path::PathBuf;

use anyhow::Context;
use polars::prelude::DataFrame;
use rayon::prelude::*;

use super::Params;
use super::session::{main_detector, selection_label};
use super::tables::{
    self, CalibRow, CameraRow, Det2dRow, Error2dRow, GtRow, HeadCentroidRow, NoiseBoxRow,
    SessionRow, TrackRow, VariantRow,
};
use crate::eval::mot::{Evaluation, Geometry, GroundPoint, MatchRule, Observation, evaluate};
use crate::report::rows::Rows;
use crate::run::{Aggregate, SessionTables};

/// Frame numbers and identities of session `s` are offset by `s · STRIDE`.
pub(crate) const STRIDE: i64 = 1_000_000_000;

/// `(detector, selection, n_app)`: one 3-D run.
pub(crate) type Key = (String, String, i64);

/// Whether a track row belongs to run `key`.
pub(crate) fn of(r: &TrackRow, key: &Key) -> bool {
    r.detector == key.0 && r.selection == key.1 && r.n_app == key.2
}

/// The camera view cached for the figure (absent when the session had no supported track).
pub(crate) struct CachedView {
    pub frame: tables::ViewFrameRow,
    /// `view_image` and `view_shapes` (absent when the view failed).
    pub tables: Option<(DataFrame, DataFrame)>,
}

/// One session's cached results.
pub(crate) struct SessionData {
    pub dataset: String,
    pub name: String,
    /// The log (only the `--write-tracks` export reads it).
    pub path: PathBuf,
    pub tracks: Vec<TrackRow>,
    pub truth: Vec<GtRow>,
    pub head_centroid: Vec<HeadCentroidRow>,
    pub cameras: Vec<CameraRow>,
    pub detections_2d: Vec<Det2dRow>,
    /// The template chain's misses and false detections with their causes.
    pub errors_2d: Vec<Error2dRow>,
    pub variants: Vec<VariantRow>,
    pub calibration: Vec<CalibRow>,
    pub session: SessionRow,
    pub view: Option<CachedView>,
    /// MEASURED: the main run's 3-D stage per frame.
    pub timing: Vec<tables::Timing3dRow>,
    /// The detector-noise runs (empty without `detector_noise`).
    pub noise_tracks: Vec<TrackRow>,
    pub noise_boxes: Vec<NoiseBoxRow>,
}

impl SessionData {
    /// The rows of one run, in table order.
    pub fn rows(&self, key: &Key) -> Vec<&TrackRow> {
        self.tracks.iter().filter(|r| of(r, key)).collect()
    }
}

/// A table only some configurations write: none when absent.
fn read_optional<R: Rows>(
    tables: &SessionTables,
    name: &str,
    session: &str,
) -> anyhow::Result<Vec<R>> {
    if tables.contains_key(name) {
        read(tables, name, session)
    } else {
        Ok(Vec::new())
    }
}

fn read<R: Rows>(tables: &SessionTables, name: &str, session: &str) -> anyhow::Result<Vec<R>> {
    let df = tables
        .get(name)
        .with_context(|| format!("{session}: cached result lacks the {name} table"))?;
    R::read(df).with_context(|| format!("{session}: reading the cached {name} table"))
}

fn session_data(
    info: &crate::run::config::SessionRef,
    t: &SessionTables,
) -> anyhow::Result<SessionData> {
    let label = format!("{}/{}", info.dataset, info.name);
    let session = read::<SessionRow>(t, tables::SESSION, &label)?
        .into_iter()
        .next()
        .with_context(|| format!("{label}: the cached session table is empty"))?;
    let view = match t.get(tables::VIEW_FRAME) {
        None => None,
        Some(df) => {
            let frame = tables::ViewFrameRow::read(df)?
                .into_iter()
                .next()
                .with_context(|| format!("{label}: the cached view_frame table is empty"))?;
            let tables = t
                .get(tables::VIEW_IMAGE)
                .cloned()
                .zip(t.get(tables::VIEW_SHAPES).cloned());
            Some(CachedView { frame, tables })
        }
    };
    Ok(SessionData {
        dataset: info.dataset.clone(),
        name: info.name.clone(),
        path: info.path.clone(),
        tracks: read(t, tables::TRACKS, &label)?,
        truth: read(t, tables::GT, &label)?,
        head_centroid: read(t, tables::HEAD_CENTROID, &label)?,
        cameras: read(t, tables::CAMERAS, &label)?,
        detections_2d: read(t, tables::DETECTIONS_2D, &label)?,
        errors_2d: read(t, tables::ERRORS_2D, &label)?,
        variants: read(t, tables::VARIANTS, &label)?,
        calibration: read(t, tables::CALIBRATION, &label)?,
        session,
        view,
        timing: read(t, tables::TIMING_3D, &label)?,
        noise_tracks: read_optional(t, tables::NOISE_TRACKS, &label)?,
        noise_boxes: read_optional(t, tables::NOISE_BOXES, &label)?,
    })
}

/// Everything aggregation computes once and the tables and figures share.
pub(crate) struct Scored {
    pub data: Vec<SessionData>,
    /// Every run, sorted.
    pub keys: Vec<Key>,
    pub main: Key,
    /// `(key, threshold) → evaluation`.
    pub evals: BTreeMap<(Key, u64), Evaluation>,
    /// The matching thresholds (m), ascending, at least one.
    pub thresholds: Vec<f64>,
}

fn tkey(t: f64) -> u64 {
    (t * 1e6).round() as u64
}

impl Scored {
    pub fn eval(&self, key: &Key, t: f64) -> Option<&Evaluation> {
        self.evals.get(&(key.clone(), tkey(t)))
    }

    /// The largest matching threshold.
    pub fn t_max(&self) -> f64 {
        self.thresholds.last().copied().unwrap_or(f64::NAN)
    }

    /// The detectors of the runs, in key order.
    pub fn detectors(&self) -> Vec<String> {
        let mut v: Vec<String> = self.keys.iter().map(|k| k.0.clone()).collect();
        v.dedup();
        v
    }

    /// Whether the logs had ground truth (else nothing was evaluated).
    pub fn has_truth(&self) -> bool {
        self.data.iter().any(|d| d.truth.iter().any(|g| g.in_room))
    }
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
pub(crate) fn truth_observations(data: &[SessionData]) -> Vec<Observation> {
    let mut out = Vec::new();
    for (s, d) in data.iter().enumerate() {
        let o = s as i64 * STRIDE;
        for g in d.truth.iter().filter(|g| g.in_room) {
            out.push(point(o + g.frame, o + g.id, g.x_m, g.y_m));
        }
    }
    out
}

/// The tracks of run `key` of every session, offset per session.
pub(crate) fn hypothesis_observations(data: &[SessionData], key: &Key) -> Vec<Observation> {
    let mut out = Vec::new();
    for (s, d) in data.iter().enumerate() {
        let o = s as i64 * STRIDE;
        for t in d.rows(key) {
            out.push(point(o + t.frame, o + t.id, t.x_m, t.y_m));
        }
    }
    out
}

/// Read every session's tables and evaluate every run at every threshold (in parallel).
pub(crate) fn score(ctx: &Aggregate, p: &Params) -> anyhow::Result<Scored> {
    let data = ctx
        .sessions
        .iter()
        .map(|(info, t)| session_data(info, t))
        .collect::<anyhow::Result<Vec<_>>>()?;
    score_data(data, p)
}

/// Evaluate every run of these sessions at every threshold (in parallel).
pub(crate) fn score_data(data: Vec<SessionData>, p: &Params) -> anyhow::Result<Scored> {
    let mut keys: Vec<Key> = Vec::new();
    for r in data.iter().flat_map(|d| &d.tracks) {
        let k = (r.detector.clone(), r.selection.clone(), r.n_app);
        if !keys.contains(&k) {
            keys.push(k);
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
    let mut evals = BTreeMap::new();
    if !gt.is_empty() {
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
    Ok(Scored {
        data,
        keys,
        main,
        evals,
        thresholds,
    })
}

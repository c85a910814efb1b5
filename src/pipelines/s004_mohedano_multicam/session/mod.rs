//! One session: calibration, the per-camera chains over every frame (`pass`, `chain`), the
//! ground-truth-box run (`gt_boxes`), the 3-D runs (`runs`), the per-frame scores against the
//! ground truth (`truth`, `head_centroid`) and the camera view for the figure (`view`), as the
//! per-session tables of `tables` that the aggregation reads.

mod boxes;
mod calibration;
mod chain;
mod errors;
mod gt_boxes;
mod head_centroid;
mod input;
mod noise;
mod pass;
mod runs;
mod truth;
mod view;

pub(crate) use boxes::MIN_BOX_HEIGHT_PX;
pub(crate) use errors::{FALSE, MISS, STANDING_MPS};
pub(crate) use head_centroid::{ASSOCIATION_IOU, CLEAR_VISIBILITY};
pub(crate) use noise::{association_label, told};
pub(crate) use truth::DETECTION_HEAD_TOL;
pub(crate) use view::shapes_from_rows;

use polars::prelude::DataFrame;

use super::tables::{self, GtRow, HeadCentroidRow, SessionRow, TrackRow};
use super::{Detector, Params, Topics};
use crate::groundtruth::PeopleFrame;
use crate::progress::Progress;
use crate::report::rows::Rows;
use crate::run::{Session, SessionTables};
use crate::time::Nanos;
use crate::track::cylinders::{Object2d, Selection};
use calibration::{calibration_rows, read_calibration};
use chain::{CameraChain, ChainSetup};
use pass::{Chains, FrameRec, Pass, run_pass};

/// Label of each source of 2-D objects in the tables.
pub(crate) const TEMPLATES: &str = "templates";
pub(crate) const GT_BOXES: &str = "gt_boxes";
pub(crate) const LOG: &str = "log";

pub(crate) fn selection_label(s: Selection) -> &'static str {
    match s {
        Selection::Corrected => "E_c",
        Selection::Mean => "E_m",
    }
}

pub(crate) fn main_detector(p: &Params) -> &'static str {
    match p.detector {
        Detector::Templates => TEMPLATES,
        Detector::Log => LOG,
    }
}

/// Whether the 3-D stage takes each box's own head point rather than the 2-D track's smoothed
/// one: under the `occupancy` association, which smooths on the ground. The 2-D tracker's head
/// filter was made for 25 fps templates; at WILDTRACK's 2 fps, after a missed box its
/// prediction is a frame behind and drags the head point off the box (measured on the
/// development frames: see docs/s004_wildtrack.md).
pub(crate) fn box_head_for_3d(p: &Params) -> bool {
    p.association == crate::track::cylinders::Association::Occupancy
}

/// Frame period from the stamps (median of the positive steps; 0.04 s for a single frame).
fn frame_period(frames: &[FrameRec]) -> f64 {
    let mut periods: Vec<f64> = frames
        .windows(2)
        .map(|w| (w[1].stamp.0.saturating_sub(w[0].stamp.0)) as f64 * 1e-9)
        .filter(|d| *d > 0.0)
        .collect();
    periods.sort_by(f64::total_cmp);
    periods.get(periods.len() / 2).copied().unwrap_or(0.04)
}

/// Background bootstrap, calibrated templates and the 2-D trackers of every camera.
fn camera_chains(
    s: &Session,
    p: &Params,
    t: &Topics,
    views: &[crate::geometry::triangulate::CalibratedView],
    setup: &ChainSetup,
    bar: &dyn Progress,
) -> anyhow::Result<Vec<CameraChain>> {
    let file = s.log.path().display().to_string();
    let boot = if setup.use_images {
        bar.set_message("background bootstrap");
        crate::frames::camera::spread(&s.log, &t.image, p.bootstrap_frames)?
    } else {
        Vec::new()
    };
    views
        .iter()
        .enumerate()
        .map(|(c, view)| CameraChain::new(c, view, p, setup, boot.get(c).map(Vec::as_slice), &file))
        .collect()
}

pub(crate) fn process(
    s: &Session,
    p: &Params,
    t: &Topics,
    bar: &dyn Progress,
) -> anyhow::Result<SessionTables> {
    let log = &s.log;
    let views = read_calibration(log, p, t)?;
    let use_images = p.detector == Detector::Templates;
    let setup = ChainSetup::new(p, use_images)?;
    let mut chains = Chains {
        chains: camera_chains(s, p, t, &views, &setup, bar)?,
        views: &views,
        setup: &setup,
    };
    let pass = run_pass(log, p, t, &mut chains, bar)?;
    let frames = &pass.frames;
    let dt_s = frame_period(frames);
    let frame_tol = (p.sync_tolerance_s * 1e9) as u64;
    let tol_ns = frame_tol.max(1);
    let gt_for_frame: Vec<Option<&PeopleFrame>> = frames
        .iter()
        .map(|f| pass.truth.nearest(f.stamp, tol_ns))
        .collect();

    // sources of 2-D objects for the 3-D stage
    let mut sources: Vec<(&'static str, Vec<Vec<Object2d>>)> = vec![(
        main_detector(p),
        frames.iter().map(|f| f.objects.clone()).collect(),
    )];
    let mut gt_box = gt_boxes::GtBoxRun::default();
    if p.gt_boxes && !pass.truth.is_empty() {
        gt_box = gt_boxes::gt_box_run(p, &views, dt_s, &gt_for_frame);
        sources.push((GT_BOXES, std::mem::take(&mut gt_box.objects)));
    }
    bar.set_message("3-D");
    let runs = runs::run_all(p, &views, dt_s, &sources, frames)?;
    if !p.detector_noise.is_empty() {
        bar.set_message("3-D under detector noise");
    }
    let noisy = noise::noise_runs(log, p, t, &views, frames, &gt_for_frame, dt_s)?;
    bar.set_message("3-D timing");
    let timing = runs::time_run(
        &views,
        runs::cylinder_params(p, dt_s, p.selection, p.n_app),
        &sources[0].1,
    )?;
    bar.inc(1);

    let scores = Scores {
        p,
        hc: head_centroid::HeadCentroid {
            cameras: &p.cameras,
            views: &views,
            occluded_visibility: p.occluded_visibility,
        },
        use_images,
    };
    let mut out = SessionTables::new();
    let mut put = |name: &str, df: DataFrame| out.insert(name.to_string(), df);
    put(
        tables::CALIBRATION,
        tables::CalibRow::frame(&calibration_rows(&p.cameras, &views))?,
    );
    put(tables::TRACKS, TrackRow::frame(&runs.tracks)?);
    put(tables::GT, GtRow::frame(&scores.gt(frames, &gt_for_frame))?);
    put(
        tables::HEAD_CENTROID,
        HeadCentroidRow::frame(&scores.head_centroid(frames, &gt_for_frame, &gt_box.boxes))?,
    );
    put(
        tables::CAMERAS,
        tables::CameraRow::frame(&pass.camera_rows)?,
    );
    put(
        tables::DETECTIONS_2D,
        tables::Det2dRow::frame(&scores.detections_2d(frames, &gt_for_frame))?,
    );
    put(tables::ERRORS_2D, tables::Error2dRow::frame(&pass.errors)?);
    put(tables::VARIANTS, tables::VariantRow::frame(&runs.variants)?);
    if !p.detector_noise.is_empty() {
        put(tables::NOISE_TRACKS, TrackRow::frame(&noisy.tracks)?);
        put(
            tables::NOISE_BOXES,
            tables::NoiseBoxRow::frame(&noisy.boxes)?,
        );
    }
    let timing_rows: Vec<tables::Timing3dRow> = timing
        .iter()
        .enumerate()
        .map(|(k, &(n, s))| tables::Timing3dRow {
            detector: main_detector(p).to_string(),
            association: format!("{:?}", p.association).to_lowercase(),
            cameras: views.len() as i64,
            frame: k as i64,
            objects_2d: n as i64,
            seconds: s,
        })
        .collect();
    put(tables::TIMING_3D, tables::Timing3dRow::frame(&timing_rows)?);
    put(
        tables::SESSION,
        SessionRow::frame(&[session_row(&pass, dt_s, p)])?,
    );
    let main: Vec<&TrackRow> = runs
        .tracks
        .iter()
        .filter(|r| {
            r.detector == main_detector(p)
                && r.selection == selection_label(p.selection)
                && r.n_app == i64::from(p.n_app)
        })
        .collect();
    // a view that cannot be made is reported by the aggregation, not fatal
    let view = view::camera_view(log, &t.image, &views, &main, frames.len() as i64, frame_tol);
    match view {
        Ok(Some(v)) => {
            let [frame, image, shapes] = view::view_tables(&v)?;
            put(tables::VIEW_FRAME, frame);
            put(tables::VIEW_IMAGE, image);
            put(tables::VIEW_SHAPES, shapes);
        }
        Ok(None) => {}
        Err(e) => {
            let row = tables::ViewFrameRow {
                frame: -1,
                t_s: f64::NAN,
                error: format!("{e:#}"),
            };
            put(tables::VIEW_FRAME, tables::ViewFrameRow::frame(&[row])?);
        }
    }
    Ok(out)
}

/// The session as a whole.
fn session_row(pass: &Pass, dt_s: f64, p: &Params) -> SessionRow {
    let (t0, t1) = (
        pass.frames.first().map_or(Nanos(0), |f| f.stamp),
        pass.frames.last().map_or(Nanos(0), |f| f.stamp),
    );
    SessionRow {
        frames: pass.frames.len() as i64,
        cameras: p.cameras.len() as i64,
        dt_s,
        duration_s: (t1.0.saturating_sub(t0.0)) as f64 * 1e-9,
        first_stamp_ns: t0.0 as i64,
        decode_failures: pass.decode_failures as i64,
        missing_camera_frames: pass.missing_camera_frames as i64,
        gt_frames: pass.truth.len() as i64,
        gt_bad_frames: pass.bad_truth as i64,
        first_error: pass.first_error.clone().unwrap_or_default(),
    }
}

/// The per-frame scores against the ground truth.
struct Scores<'a> {
    p: &'a Params,
    hc: head_centroid::HeadCentroid<'a>,
    use_images: bool,
}

impl Scores<'_> {
    /// The people of every frame with ground truth.
    fn gt(&self, frames: &[FrameRec], gt_for_frame: &[Option<&PeopleFrame>]) -> Vec<GtRow> {
        let t0 = frames.first().map_or(Nanos(0), |f| f.stamp);
        let mut rows = Vec::new();
        for (k, (f, gt)) in frames.iter().zip(gt_for_frame).enumerate() {
            if let Some(gt) = gt {
                rows.extend(truth::gt_rows(
                    k,
                    f.stamp,
                    t0,
                    gt,
                    &self.p.cameras,
                    self.p.room_m,
                ));
            }
        }
        rows
    }

    /// Head point vs blob centroid, per detector with per-camera detections.
    fn head_centroid(
        &self,
        frames: &[FrameRec],
        gt_for_frame: &[Option<&PeopleFrame>],
        gt_boxes: &[Vec<Vec<gt_boxes::BoxPoints>>],
    ) -> Vec<HeadCentroidRow> {
        let mut rows = Vec::new();
        for (k, gt) in gt_for_frame.iter().enumerate() {
            let Some(gt) = gt else { continue };
            if self.use_images {
                let per_cam: Vec<Vec<gt_boxes::BoxPoints>> = frames[k]
                    .detections
                    .iter()
                    .map(|ds| {
                        ds.iter()
                            .map(|d| (d.bbox, d.head_px, d.centroid_px))
                            .collect()
                    })
                    .collect();
                rows.extend(self.hc.rows(TEMPLATES, k, gt, &per_cam));
            }
            if let Some(per_cam) = gt_boxes.get(k) {
                rows.extend(self.hc.rows(GT_BOXES, k, gt, per_cam));
            }
        }
        rows
    }

    /// The template detections against the visible ground-truth boxes, per frame and camera.
    fn detections_2d(
        &self,
        frames: &[FrameRec],
        gt_for_frame: &[Option<&PeopleFrame>],
    ) -> Vec<tables::Det2dRow> {
        if !self.use_images {
            return Vec::new();
        }
        let mut rows = Vec::new();
        for (k, gt) in gt_for_frame.iter().enumerate() {
            if let Some(gt) = gt {
                rows.extend(truth::det2d_rows(
                    k,
                    gt,
                    &self.p.cameras,
                    &frames[k].detections,
                ));
            }
        }
        rows
    }
}

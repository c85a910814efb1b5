//! WILDTRACK (Chavdarova et al., CVPR 2018) → one session log.
//!
//! **Input** (the layout the dataset and OpenTraj ship): `calibrations/extrinsic/extr_<C>.xml`
//! (OpenCV FileStorage: `rvec`, Rodrigues, and `tvec`, world → camera, centimetres),
//! `calibrations/intrinsic_zero/intr_<C>.xml` (camera matrix + 5 distortion coefficients, all
//! zero: the undistorted 1920×1080 images the boxes were annotated on) or `intrinsic_original`
//! (same matrix, the raw lens distortion), and `annotations_positions/<frame>.json` (a list of
//! `{personID, positionID, views: [{viewNum, xmin, ymin, xmax, ymax}]}`, a box of −1 = not
//! visible). Cameras in `viewNum` order: CVLab1–4, IDIAP1–3. Ground position from the
//! 480 × 1440 grid of 2.5 cm: `X = −3.0 + 0.025·(id mod 480)`, `Y = −9.0 + 0.025·⌊id/480⌋` (m).
//!
//! Which intrinsics the boxes belong to is measured, not assumed: [`projection_check`]
//! projects each annotated ground point and the point [`NOMINAL_HEIGHT_M`] above it and
//! compares them with the box's bottom and top centre; `import` prints it for both sets, and
//! the real-data test asserts that `intrinsic_zero` fits better (it does, over all 42,721
//! boxes: median 6.7 px at the feet and 6.7 px at the head (top centre), against 19 px and
//! 19 px with `intrinsic_original`'s distortion).
//!
//! **Output**: world frame `map` = WILDTRACK's world in metres (z up, ground z = 0); one TF
//! frame and one `sensor_msgs/CameraInfo` (`plumb_bob`) per camera, named `cvlab1` …
//! `idiap3` (topics `/<cam>/camera_info`, `/<cam>/detections`), the camera poses on
//! `/tf_static`; per annotated frame, a `vision_msgs/Detection2DArray` per camera (every
//! annotated box, class `person`, score 1, no id: the boxes carry no identity) and
//! `/ground_truth/people` (id = `personID`, position from `positionID`). Frame `N` is stamped
//! `T0 + N · 0.1 s` (the 10 fps extraction; annotated every 5th frame = 2 fps). With
//! [`write_noisy`] the detections are the annotated boxes through the seeded detector model of
//! [`super::detector_noise`] (false boxes stand on the annotation's grid, [`ROOM_M`]); the
//! ground truth stays the annotation.
//!
//! What the annotations do not give is filled in and said so: the person's height is the
//! median over its views of where the ray through the box's top centre passes the person's
//! vertical ([`NOMINAL_HEIGHT_M`] when no view), the radius the median of half the box width
//! at the person's depth ([`NOMINAL_RADIUS_M`] when no view), velocity a finite difference to
//! the person's next (or previous) annotated position, visibility 1 in every annotated view,
//! legs at the centre.
//!
//! Hand-written: the two-tag subset of OpenCV's FileStorage XML (a dependency for ten lines of
//! text would be more code to review than the parser); Rodrigues is nalgebra's
//! `Rotation3::from_scaled_axis`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use nalgebra::{Isometry3, Point2, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};

use super::detector_noise::{self, DetectorNoise};
use super::{ImportError, read_text};
use crate::geometry::camera::{CameraModel, Pinhole};
use crate::geometry::triangulate::CalibratedView;
use crate::groundtruth::{self, CameraView, PeopleFrame, PersonTruth};
use crate::log::msgs::{
    CameraInfo, Detection2D, Detection2DArray, Header, TfMessage, Time, Transform, TransformStamped,
};
use crate::log::{SessionWriter, WriterOptions};
use crate::time::Nanos;

/// Dataset camera names in `viewNum` order.
pub const CAMERAS: [&str; 7] = [
    "CVLab1", "CVLab2", "CVLab3", "CVLab4", "IDIAP1", "IDIAP2", "IDIAP3",
];
pub const WIDTH: u32 = 1920;
pub const HEIGHT: u32 = 1080;
/// The world frame of the log.
pub const WORLD_FRAME: &str = "map";
/// Height of WILDTRACK's annotation cylinder (m): used only where a person has no box.
pub const NOMINAL_HEIGHT_M: f64 = 1.8;
/// Radius used only where a person has no box (m).
pub const NOMINAL_RADIUS_M: f64 = 0.25;
/// Source frame rate: file `N` is frame `N` at 10 fps.
pub const FRAME_PERIOD_NS: u64 = 100_000_000;
/// Stamp of frame 0 (2017-07-14T02:40:00Z; the dataset was recorded in 2017).
pub const T0: Nanos = Nanos(1_500_000_000 * Nanos::NANOS_PER_SEC);

/// Which intrinsic calibration to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Intrinsics {
    /// `intrinsic_zero`: the undistorted images (the annotations' images).
    Zero,
    /// `intrinsic_original`: the raw video, with lens distortion.
    Original,
}

impl Intrinsics {
    pub fn folder(self) -> &'static str {
        match self {
            Intrinsics::Zero => "intrinsic_zero",
            Intrinsics::Original => "intrinsic_original",
        }
    }
}

/// The topic-safe name of camera `k` (`cvlab1` …).
pub fn camera_name(k: usize) -> String {
    CAMERAS
        .get(k)
        .map_or_else(|| format!("cam_{k}"), |c| c.to_lowercase())
}

/// Ground position (m) of a `positionID`.
pub fn ground_position(position_id: u64) -> (f64, f64) {
    (
        -3.0 + 0.025 * (position_id % 480) as f64,
        -9.0 + 0.025 * (position_id / 480) as f64,
    )
}

/// The annotated frames design values may be chosen on: the first 200 (frames 0–199, the
/// development part of `pipelines/real/s004_wildtrack.toml`'s `split_frame`).
pub const DEVELOPMENT_FRAMES: usize = 200;

/// Last valid `positionID` (480 × 1440 grid).
pub const POSITIONS: u64 = 480 * 1440;

/// One person in one annotated frame: ground position and boxes `(camera, [x0, y0, x1, y1])`.
#[derive(Debug, Clone, PartialEq)]
pub struct Annotation {
    pub person: u32,
    pub x_m: f64,
    pub y_m: f64,
    pub boxes: Vec<(usize, [f64; 4])>,
}

/// One annotation file.
#[derive(Debug, Clone, PartialEq)]
pub struct AnnotatedFrame {
    /// The file's frame number (10 fps).
    pub frame: u32,
    pub people: Vec<Annotation>,
}

/// The dataset as read.
#[derive(Debug, Clone)]
pub struct Dataset {
    pub views: Vec<CalibratedView>,
    pub frames: Vec<AnnotatedFrame>,
    /// Views with a box of −1 (not visible): dropped, as the format says.
    pub invisible_views: usize,
    /// People skipped with the first reason (bad `positionID`, unknown `viewNum`, bad box).
    pub skipped: usize,
    pub first_skip: Option<String>,
}

#[derive(serde::Deserialize)]
struct JsonPerson {
    #[serde(rename = "personID")]
    person_id: i64,
    #[serde(rename = "positionID")]
    position_id: i64,
    views: Vec<JsonView>,
}

#[derive(serde::Deserialize)]
struct JsonView {
    #[serde(rename = "viewNum")]
    view: i64,
    xmin: f64,
    ymin: f64,
    xmax: f64,
    ymax: f64,
}

/// The numbers inside `<tag>…</tag>` (or inside its `<data>` for an `opencv-matrix`).
fn xml_numbers(text: &str, tag: &str) -> Option<Vec<f64>> {
    let open = text.find(&format!("<{tag}"))?;
    let body_start = open + text[open..].find('>')? + 1;
    let body_end = body_start + text[body_start..].find(&format!("</{tag}>"))?;
    let mut body = &text[body_start..body_end];
    if let Some(d) = body.find("<data>") {
        let end = body.find("</data>")?;
        body = body.get(d + 6..end)?;
    }
    body.split_whitespace()
        .map(|s| s.parse::<f64>().ok().filter(|v| v.is_finite()))
        .collect()
}

fn numbers(path: &Path, text: &str, tag: &str, n: usize) -> Result<Vec<f64>, ImportError> {
    match xml_numbers(text, tag) {
        Some(v) if v.len() == n => Ok(v),
        Some(v) => Err(ImportError::parse(
            path,
            format!("<{tag}> has {} numbers, expected {n}", v.len()),
        )),
        None => Err(ImportError::parse(
            path,
            format!("no <{tag}> with finite numbers"),
        )),
    }
}

/// Camera `name`'s calibration: its pinhole model and `world_from_camera` (metres).
pub fn read_camera(
    dir: &Path,
    name: &str,
    intr: Intrinsics,
) -> Result<CalibratedView, ImportError> {
    let cal = dir.join("calibrations");
    let ipath = cal.join(intr.folder()).join(format!("intr_{name}.xml"));
    let itext = read_text(&ipath)?;
    let k = numbers(&ipath, &itext, "camera_matrix", 9)?;
    let d = numbers(&ipath, &itext, "distortion_coefficients", 5)?;
    if !(k[0] > 0.0 && k[4] > 0.0) {
        return Err(ImportError::parse(
            &ipath,
            "camera_matrix has a non-positive focal length",
        ));
    }
    let epath = cal.join("extrinsic").join(format!("extr_{name}.xml"));
    let etext = read_text(&epath)?;
    let r = numbers(&epath, &etext, "rvec", 3)?;
    let t = numbers(&epath, &etext, "tvec", 3)?;
    let rot = Rotation3::from_scaled_axis(Vector3::new(r[0], r[1], r[2]));
    let camera_from_world = Isometry3::from_parts(
        Translation3::new(t[0] / 100.0, t[1] / 100.0, t[2] / 100.0),
        UnitQuaternion::from_rotation_matrix(&rot),
    );
    let model = CameraModel::Pinhole(Pinhole {
        width: WIDTH,
        height: HEIGHT,
        fx: k[0],
        fy: k[4],
        cx: k[2],
        cy: k[5],
        dist: [d[0], d[1], d[2], d[3], d[4]],
    });
    Ok(CalibratedView::new(model, camera_from_world.inverse()))
}

/// Parse one annotation file; bad people are counted in `skips`, not fatal.
fn read_frame(
    path: &Path,
    frame: u32,
    n_cams: usize,
    ds: &mut Dataset,
) -> Result<AnnotatedFrame, ImportError> {
    let text = read_text(path)?;
    let people: Vec<JsonPerson> = serde_json::from_str(&text)
        .map_err(|e| ImportError::parse(path, format!("not WILDTRACK annotations: {e}")))?;
    let mut out = Vec::with_capacity(people.len());
    let skip = |ds: &mut Dataset, why: String| {
        ds.skipped += 1;
        ds.first_skip
            .get_or_insert_with(|| format!("{}: {why}", path.display()));
    };
    'people: for p in people {
        let (Ok(person), Ok(pos)) = (u32::try_from(p.person_id), u64::try_from(p.position_id))
        else {
            skip(
                ds,
                format!(
                    "person {} at position {}: negative id",
                    p.person_id, p.position_id
                ),
            );
            continue;
        };
        if pos >= POSITIONS {
            skip(
                ds,
                format!("person {person}: positionID {pos} outside the grid"),
            );
            continue;
        }
        let mut boxes = Vec::new();
        for v in &p.views {
            let b = [v.xmin, v.ymin, v.xmax, v.ymax];
            if b.iter().all(|&c| c == -1.0) {
                ds.invisible_views += 1;
                continue;
            }
            let cam = usize::try_from(v.view).ok().filter(|&c| c < n_cams);
            let ok = b.iter().all(|c| c.is_finite()) && b[2] > b[0] && b[3] > b[1];
            match cam {
                Some(c) if ok => boxes.push((c, b)),
                _ => {
                    skip(
                        ds,
                        format!("person {person}: bad view {} box {b:?}", v.view),
                    );
                    continue 'people;
                }
            }
        }
        boxes.sort_by_key(|b| b.0);
        let (x_m, y_m) = ground_position(pos);
        out.push(Annotation {
            person,
            x_m,
            y_m,
            boxes,
        });
    }
    out.sort_by_key(|a| a.person);
    Ok(AnnotatedFrame { frame, people: out })
}

/// Read the calibrations of the 7 cameras and every annotation file of `dir`.
pub fn read(dir: &Path, intr: Intrinsics) -> Result<Dataset, ImportError> {
    let views = CAMERAS
        .iter()
        .map(|c| read_camera(dir, c, intr))
        .collect::<Result<Vec<_>, _>>()?;
    let adir = dir.join("annotations_positions");
    let entries = std::fs::read_dir(&adir).map_err(|error| ImportError::Io {
        path: adir.display().to_string(),
        error,
    })?;
    let mut files: Vec<(u32, PathBuf)> = Vec::new();
    for e in entries {
        let path = e
            .map_err(|error| ImportError::Io {
                path: adir.display().to_string(),
                error,
            })?
            .path();
        if path.extension().is_none_or(|x| x != "json") {
            continue;
        }
        let frame = path
            .file_stem()
            .and_then(|s| s.to_str())
            .and_then(|s| s.parse::<u32>().ok())
            .ok_or_else(|| ImportError::parse(&path, "file name is not a frame number"))?;
        files.push((frame, path));
    }
    files.sort();
    if files.is_empty() {
        return Err(ImportError::parse(&adir, "no annotation files (*.json)"));
    }
    let mut ds = Dataset {
        views,
        frames: Vec::new(),
        invisible_views: 0,
        skipped: 0,
        first_skip: None,
    };
    for (frame, path) in &files {
        let f = read_frame(path, *frame, CAMERAS.len(), &mut ds)?;
        ds.frames.push(f);
    }
    Ok(ds)
}

/// Stamp of frame `n`.
pub fn stamp(frame: u32) -> Nanos {
    Nanos(T0.0 + u64::from(frame) * FRAME_PERIOD_NS)
}

fn median(mut v: Vec<f64>) -> Option<f64> {
    v.retain(|x| x.is_finite());
    v.sort_by(f64::total_cmp);
    let n = v.len();
    (n > 0).then(|| {
        if n % 2 == 1 {
            v[n / 2]
        } else {
            0.5 * (v[n / 2 - 1] + v[n / 2])
        }
    })
}

/// Height (top of the head) and radius of an annotated person from its boxes.
pub fn person_size(views: &[CalibratedView], a: &Annotation) -> (f64, f64) {
    let mut heights = Vec::new();
    for &(c, b) in &a.boxes {
        let top = Point2::new(0.5 * (b[0] + b[2]), b[1]);
        let Some((o, d)) = views[c].ray_in_world(&top) else {
            continue;
        };
        let dxy = d.x * d.x + d.y * d.y;
        if dxy > 1e-12 {
            let s = ((a.x_m - o.x) * d.x + (a.y_m - o.y) * d.y) / dxy;
            if s > 0.0 {
                heights.push(o.z + s * d.z);
            }
        }
    }
    let height = median(heights).unwrap_or(NOMINAL_HEIGHT_M);
    let mid = Point3::new(a.x_m, a.y_m, 0.5 * height);
    let radii = a
        .boxes
        .iter()
        .filter_map(|&(c, b)| {
            let v = &views[c];
            let depth = (v.world_from_camera.inverse() * mid).z;
            let (f, _) = v.focal_and_principal();
            (depth > 0.0).then(|| 0.5 * (b[2] - b[0]) * depth / f)
        })
        .collect();
    (height, median(radii).unwrap_or(NOMINAL_RADIUS_M))
}

/// The ground truth of frame `k` of `ds` (velocities from the neighbouring annotated frames).
pub fn people_frame(ds: &Dataset, k: usize) -> PeopleFrame {
    let f = &ds.frames[k];
    let find = |j: usize, id: u32| {
        ds.frames.get(j).and_then(|g| {
            g.people
                .iter()
                .find(|p| p.person == id)
                .map(|p| (p.x_m, p.y_m, g.frame))
        })
    };
    let people = f
        .people
        .iter()
        .map(|a| {
            let other =
                find(k + 1, a.person).or_else(|| k.checked_sub(1).and_then(|j| find(j, a.person)));
            let (vx, vy) = match other {
                Some((x, y, n)) if n != f.frame => {
                    let dt = (f64::from(n) - f64::from(f.frame)) * FRAME_PERIOD_NS as f64 * 1e-9;
                    ((x - a.x_m) / dt, (y - a.y_m) / dt)
                }
                _ => (0.0, 0.0),
            };
            let (height, radius) = person_size(&ds.views, a);
            let cameras = a
                .boxes
                .iter()
                .map(|&(c, b)| CameraView {
                    camera: camera_name(c),
                    bbox: Some(b),
                    head_px: ds.views[c]
                        .project(&Point3::new(a.x_m, a.y_m, height))
                        .map(|p| [p.x, p.y]),
                    visibility: 1.0,
                })
                .collect();
            PersonTruth {
                id: a.person,
                x: a.x_m,
                y: a.y_m,
                vx,
                vy,
                height,
                head_z: height - 0.1,
                radius,
                legs: [[a.x_m, a.y_m], [a.x_m, a.y_m]],
                leg_radius: 0.0,
                cameras,
            }
        })
        .collect();
    PeopleFrame {
        stamp_ns: stamp(f.frame).0,
        people,
    }
}

/// The annotation's ground grid `[x0, y0, x1, y1]` (m): where the false boxes of
/// [`detector_noise`] stand.
pub const ROOM_M: [f64; 4] = [-3.0, -9.0, 9.0, 27.0];

/// The detections of camera `c` in frame `k` (every annotated box).
pub fn detections(ds: &Dataset, k: usize, c: usize) -> Detection2DArray {
    noisy_detections(ds, k, c, None)
}

/// [`detections`] through the detector model `(levels, seed)` of [`detector_noise`]
/// (`None`: the annotated boxes as they are).
pub fn noisy_detections(
    ds: &Dataset,
    k: usize,
    c: usize,
    noise: Option<(&DetectorNoise, u64)>,
) -> Detection2DArray {
    let f = &ds.frames[k];
    let header = Header {
        stamp: Time::from_nanos(stamp(f.frame)),
        frame_id: camera_name(c),
    };
    let annotated: Vec<[f64; 4]> = f
        .people
        .iter()
        .flat_map(|a| a.boxes.iter().filter(|b| b.0 == c))
        .map(|&(_, b)| b)
        .collect();
    let boxes = match noise {
        Some((n, seed)) => detector_noise::apply(
            n,
            seed,
            &detector_noise::CameraFrame {
                view: &ds.views[c],
                camera: c,
                stamp_ns: stamp(f.frame).0,
                room_m: ROOM_M,
            },
            &annotated,
        ),
        None => annotated,
    };
    let detections = boxes
        .into_iter()
        .map(|b| Detection2D {
            header: header.clone(),
            results: vec![("person".to_string(), 1.0)],
            center_x: 0.5 * (b[0] + b[2]),
            center_y: 0.5 * (b[1] + b[3]),
            theta: 0.0,
            size_x: b[2] - b[0],
            size_y: b[3] - b[1],
            id: String::new(),
        })
        .collect();
    Detection2DArray { header, detections }
}

/// How well the ground points and nominal heads project onto the boxes (pixels).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProjectionCheck {
    pub boxes: usize,
    /// `|P(X, Y, 0) − bottom centre|`.
    pub median_foot_px: f64,
    pub p90_foot_px: f64,
    /// `|P(X, Y, NOMINAL_HEIGHT_M) − top centre|`.
    pub median_head_px: f64,
}

/// Compare every annotated box with the projection of its person's ground point and of the
/// point [`NOMINAL_HEIGHT_M`] above it.
pub fn projection_check(ds: &Dataset) -> ProjectionCheck {
    let (mut foot, mut head) = (Vec::new(), Vec::new());
    for a in ds.frames.iter().flat_map(|f| &f.people) {
        for &(c, b) in &a.boxes {
            let v = &ds.views[c];
            let cx = 0.5 * (b[0] + b[2]);
            if let Some(p) = v.project(&Point3::new(a.x_m, a.y_m, 0.0)) {
                foot.push((p.x - cx).hypot(p.y - b[3]));
            }
            if let Some(p) = v.project(&Point3::new(a.x_m, a.y_m, NOMINAL_HEIGHT_M)) {
                head.push((p.x - cx).hypot(p.y - b[1]));
            }
        }
    }
    let boxes = foot.len();
    foot.sort_by(f64::total_cmp);
    let p90 = foot
        .get((boxes * 9 / 10).min(boxes.saturating_sub(1)))
        .copied()
        .unwrap_or(f64::NAN);
    ProjectionCheck {
        boxes,
        median_foot_px: median(foot).unwrap_or(f64::NAN),
        p90_foot_px: p90,
        median_head_px: median(head).unwrap_or(f64::NAN),
    }
}

/// What [`write`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportSummary {
    pub path: PathBuf,
    pub frames: usize,
    pub people_frames: usize,
    pub boxes: usize,
}

/// Write `ds` as one session log at `out` (atomically).
pub fn write(
    ds: &Dataset,
    source: &Path,
    intr: Intrinsics,
    out: &Path,
) -> Result<ImportSummary, ImportError> {
    write_noisy(ds, source, intr, None, out)
}

/// [`write`] with the detections through the detector model `(levels, seed)` (the ground
/// truth stays the annotation); the levels and the seed go into the log's metadata.
pub fn write_noisy(
    ds: &Dataset,
    source: &Path,
    intr: Intrinsics,
    noise: Option<(&DetectorNoise, u64)>,
    out: &Path,
) -> Result<ImportSummary, ImportError> {
    let mut w = SessionWriter::create(out, &WriterOptions::default())?;
    let mut meta = BTreeMap::new();
    if let Some((n, seed)) = noise {
        meta.insert("detector_noise".to_string(), n.label());
        meta.insert("detector_noise_seed".to_string(), seed.to_string());
    }
    meta.insert("dataset".to_string(), "wildtrack".to_string());
    meta.insert("source".to_string(), source.display().to_string());
    meta.insert("intrinsics".to_string(), intr.folder().to_string());
    meta.insert(
        "generator".to_string(),
        format!("peopletrack {}", env!("CARGO_PKG_VERSION")),
    );
    w.metadata("peopletrack.import", meta)?;
    let tf_static = w.add_ros2::<TfMessage>("/tf_static")?;
    let people = w.add_json(
        groundtruth::PEOPLE_TOPIC,
        groundtruth::PEOPLE_SCHEMA,
        groundtruth::PEOPLE_JSON_SCHEMA,
    )?;
    let mut infos = Vec::new();
    let mut dets = Vec::new();
    for c in 0..ds.views.len() {
        let name = camera_name(c);
        infos.push(w.add_ros2::<CameraInfo>(&format!("/{name}/camera_info"))?);
        dets.push(w.add_ros2::<Detection2DArray>(&format!("/{name}/detections"))?);
    }
    let t0 = ds.frames.first().map_or(T0, |f| stamp(f.frame));
    let transforms = ds
        .views
        .iter()
        .enumerate()
        .map(|(c, v)| TransformStamped {
            header: Header {
                stamp: Time::from_nanos(t0),
                frame_id: WORLD_FRAME.to_string(),
            },
            child_frame_id: camera_name(c),
            transform: Transform {
                translation: v.world_from_camera.translation.vector,
                rotation: v.world_from_camera.rotation.into_inner(),
            },
        })
        .collect();
    w.write(tf_static, t0, &TfMessage { transforms })?;
    for (c, v) in ds.views.iter().enumerate() {
        let header = Header {
            stamp: Time::from_nanos(t0),
            frame_id: camera_name(c),
        };
        w.write(infos[c], t0, &CameraInfo::from_model(&v.model, header))?;
    }
    let (mut people_frames, mut boxes) = (0, 0);
    for k in 0..ds.frames.len() {
        let t = stamp(ds.frames[k].frame);
        let gt = people_frame(ds, k);
        people_frames += gt.people.len();
        w.write_json(people, t, &gt)?;
        for (c, ch) in dets.iter().enumerate() {
            let d = noisy_detections(ds, k, c, noise);
            boxes += d.detections.len();
            w.write(*ch, t, &d)?;
        }
    }
    let path = w.finish()?;
    Ok(ImportSummary {
        path,
        frames: ds.frames.len(),
        people_frames,
        boxes,
    })
}

mod motion;
#[cfg(test)]
mod tests;

pub use motion::{MotionCheck, motion_check};

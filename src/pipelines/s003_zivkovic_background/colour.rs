//! EM-like vs mean shift (Zivkovic & Kröse 2004): on the datasets in `colour.datasets`,
//! person `colour.person` is initialised from its exact mask (eq. 16–17) in the first frame
//! where it is fully in view, then tracked by the EM-like tracker (and, with
//! `compare_beta`, a second β) and by mean shift with the ±10 % scale test, with each
//! histogram space; per frame the estimate against the moments of the exact mask. The
//! session tables are cached here; `colour_report` writes the tables and figures.

use image::RgbImage;
use polars::prelude::*;

use super::params::{ColourParams, Params};
use super::shared::Frame;
use crate::groundtruth::CameraView;
use crate::report::columns::{i64s, image_table, read_image_table};
use crate::report::rows::Rows;
use crate::run::SessionTables;
use crate::table_row;
use crate::vision::blobs::{self, Connectivity};
use crate::vision::colortrack::{BinImage, ColorSpace, ColorTracker, EmParams, Method};
use crate::vision::ellipse::Ellipse;
use crate::vision::gmm::FOREGROUND;

pub(super) const SAMPLES_TABLE: &str = "colour";
const OVERLAY_PREFIX: &str = "colour_overlay_";

table_row! {
    /// Cached per session: one tracker's estimate in one frame, with the ground-truth ellipse
    /// where the person is fully in view.
    #[derive(Debug, Clone, PartialEq)]
    pub(super) struct ColourSample {
        pub frame: i64,
        pub t_s: f64,
        pub space: String,
        pub method: String,
        pub cx: f64,
        pub cy: f64,
        pub vxx: f64,
        pub vxy: f64,
        pub vyy: f64,
        pub iterations: i64,
        pub total_iterations: i64,
        pub similarity: f64,
        pub converged: bool,
        pub lost: bool,
        pub gt_cx: Option<f64>,
        pub gt_cy: Option<f64>,
        pub gt_vxx: Option<f64>,
        pub gt_vxy: Option<f64>,
        pub gt_vyy: Option<f64>,
        pub centre_error_px: Option<f64>,
        pub overlap: Option<f64>,
    }
}

impl ColourSample {
    pub fn estimate(&self) -> Ellipse {
        Ellipse::from_parts(self.cx, self.cy, self.vxx, self.vxy, self.vyy)
    }

    pub fn truth(&self) -> Option<Ellipse> {
        Some(Ellipse::from_parts(
            self.gt_cx?,
            self.gt_cy?,
            self.gt_vxx?,
            self.gt_vxy?,
            self.gt_vyy?,
        ))
    }
}

/// The ground-truth ellipse of a person: the moments (eq. 16) of the largest connected part
/// of the exact mask inside its box. `bbox` is `[x0, y0, x1, y1]` inclusive.
pub(super) fn mask_ellipse(
    mask: &[u8],
    width: usize,
    height: usize,
    bbox: [f64; 4],
) -> Option<Ellipse> {
    let x0 = bbox[0].max(0.0) as usize;
    let y0 = bbox[1].max(0.0) as usize;
    // the logged box is right and bottom exclusive: its last pixel is x1 - 1
    let x1 = ((bbox[2] - 1.0).max(0.0) as usize).min(width.checked_sub(1)?);
    let y1 = ((bbox[3] - 1.0).max(0.0) as usize).min(height.checked_sub(1)?);
    if x1 < x0 || y1 < y0 {
        return None;
    }
    let (w, h) = (x1 - x0 + 1, y1 - y0 + 1);
    let mut sub = vec![0u8; w * h];
    for y in 0..h {
        sub[y * w..(y + 1) * w]
            .copy_from_slice(&mask[(y0 + y) * width + x0..(y0 + y) * width + x0 + w]);
    }
    let mut labels = vec![0u32; w * h];
    let found = blobs::label(&sub, w, h, Connectivity::Eight, FOREGROUND, &mut labels).ok()?;
    let best = found
        .iter()
        .max_by(|a, b| a.area().cmp(&b.area()).then(b.label.cmp(&a.label)))?;
    let e = best.ellipse();
    Some(Ellipse::new(
        nalgebra::Point2::new(e.center.x + x0 as f64, e.center.y + y0 as f64),
        e.cov,
    ))
}

/// The tracked person's view in this frame: `None` when absent or ambiguous (two people
/// match the id and height).
fn person_view<'a>(f: &Frame<'a>, p: &ColourParams, camera: &str) -> Option<&'a CameraView> {
    let fr = f.truth?;
    let mut who = fr.people.iter().filter(|q| {
        q.id == p.person
            && p.person_height_m
                .is_none_or(|h| (q.height - h).abs() <= 0.005)
    });
    match (who.next(), who.next()) {
        (Some(q), None) => q.cameras.iter().find(|v| v.camera == camera),
        _ => None,
    }
}

/// The ground-truth ellipse when the person is fully in view: away from the border and
/// visible enough.
fn usable_truth(v: &CameraView, p: &ColourParams, mask: &[u8], w: u32, h: u32) -> Option<Ellipse> {
    let b = v.bbox?;
    let m = p.border_px;
    let inside =
        b[0] >= m && b[1] >= m && b[2] <= f64::from(w) - 1.0 - m && b[3] <= f64::from(h) - 1.0 - m;
    (inside && v.visibility >= p.min_visibility)
        .then(|| mask_ellipse(mask, w as usize, h as usize, b))
        .flatten()
}

/// The trackers compared, by name: EM-like, EM-like with `compare_beta`, mean shift.
fn methods(p: &ColourParams) -> Vec<(String, Method)> {
    let mut out = vec![("EM-like".to_string(), Method::EmLike(p.em))];
    if let Some(beta) = p.compare_beta {
        let em = EmParams { beta, ..p.em };
        out.push((format!("EM-like β={beta}"), Method::EmLike(em)));
    }
    out.push(("mean shift".to_string(), Method::MeanShift(p.mean_shift)));
    out
}

/// The colour-tracker comparison of one session.
pub(super) struct ColourRun {
    params: ColourParams,
    camera: String,
    trackers: Vec<(ColorSpace, String, ColorTracker)>,
    started: bool,
    finished: bool,
    frame0: i64,
    samples: Vec<ColourSample>,
    overlays: Vec<(i64, RgbImage)>,
}

impl ColourRun {
    /// A run that does nothing unless `wanted`.
    pub fn new(p: &Params, wanted: bool) -> Self {
        Self {
            params: p.colour.clone(),
            camera: p.camera.clone(),
            trackers: Vec::new(),
            started: false,
            finished: !wanted,
            frame0: 0,
            samples: Vec::new(),
            overlays: Vec::new(),
        }
    }

    /// The frame the trackers started from, if they did.
    pub fn frame0(&self) -> Option<i64> {
        self.started.then_some(self.frame0)
    }

    pub fn step(&mut self, f: &Frame) -> anyhow::Result<()> {
        if self.finished {
            return Ok(());
        }
        let Some(mask) = f.mask else { return Ok(()) };
        let p = &self.params;
        let view_of = person_view(f, p, &self.camera);
        let (w, h) = (f.rgb.width(), f.rgb.height());
        let usable = view_of.and_then(|v| usable_truth(v, p, mask, w, h));
        if !self.started {
            if let Some(e) = usable {
                self.start(f, e)?;
            }
        } else if f.truth.is_some() && view_of.is_none_or(|v| v.bbox.is_none()) {
            self.finished = true; // the person left the view
        } else {
            self.track(f, usable)?;
        }
        Ok(())
    }

    fn start(&mut self, f: &Frame, e: Ellipse) -> anyhow::Result<()> {
        for &space in &self.params.spaces {
            let bins = BinImage::new(f.view, space)?;
            for (name, method) in methods(&self.params) {
                self.trackers
                    .push((space, name, ColorTracker::new(&bins, e, method)?));
            }
        }
        self.started = true;
        self.frame0 = f.index;
        self.overlays.push((f.index, f.rgb.clone()));
        Ok(())
    }

    fn track(&mut self, f: &Frame, usable: Option<Ellipse>) -> anyhow::Result<()> {
        let p = &self.params;
        let since = (f.index - self.frame0) as usize;
        if p.overlay_every > 0
            && since.is_multiple_of(p.overlay_every)
            && self.overlays.len() < p.overlay_count
        {
            self.overlays.push((f.index, f.rgb.clone()));
        }
        let mut bins_of: Vec<(ColorSpace, BinImage)> = Vec::new();
        for &space in &p.spaces {
            bins_of.push((space, BinImage::new(f.view, space)?));
        }
        for (space, name, tr) in &mut self.trackers {
            let Some((_, bins)) = bins_of.iter().find(|(s2, _)| s2 == space) else {
                continue;
            };
            let r = tr.track(bins)?;
            let e = r.region;
            self.samples.push(ColourSample {
                frame: f.index,
                t_s: f.t_s,
                space: space.name().to_string(),
                method: name.clone(),
                cx: e.center.x,
                cy: e.center.y,
                vxx: e.cov[(0, 0)],
                vxy: e.cov[(0, 1)],
                vyy: e.cov[(1, 1)],
                iterations: i64::from(r.iterations),
                total_iterations: i64::from(r.total_iterations),
                similarity: r.similarity,
                converged: r.converged,
                lost: r.lost,
                gt_cx: usable.map(|g| g.center.x),
                gt_cy: usable.map(|g| g.center.y),
                gt_vxx: usable.map(|g| g.cov[(0, 0)]),
                gt_vxy: usable.map(|g| g.cov[(0, 1)]),
                gt_vyy: usable.map(|g| g.cov[(1, 1)]),
                centre_error_px: usable.map(|g| (g.center - e.center).norm()),
                overlap: usable.map(|g| g.overlap(&e)),
            });
        }
        Ok(())
    }

    /// The cached `colour` table and the overlay frames (when the trackers started).
    pub fn finish(self, out: &mut SessionTables) -> anyhow::Result<()> {
        if !self.started {
            return Ok(());
        }
        out.insert(SAMPLES_TABLE.into(), ColourSample::frame(&self.samples)?);
        for (k, (fi, img)) in self.overlays.iter().enumerate() {
            let mut df = image_table(img)?;
            df.with_column(Column::new("frame".into(), [*fi]))?;
            out.insert(format!("{OVERLAY_PREFIX}{k}"), df);
        }
        Ok(())
    }
}

/// A session's cached overlay frames, in order: `(frame index, image)`.
pub(super) fn overlays(tables: &SessionTables) -> anyhow::Result<Vec<(i64, RgbImage)>> {
    let mut tiles = Vec::new();
    for k in 0.. {
        let Some(o) = tables.get(&format!("{OVERLAY_PREFIX}{k}")) else {
            break;
        };
        let f = i64s(o, "frame")?.first().copied().unwrap_or(0);
        tiles.push((f, read_image_table(o)?));
    }
    Ok(tiles)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::groundtruth::{PeopleFrame, PersonTruth};
    use crate::vision::ImageView;

    /// A filled axis-aligned rectangle of person pixels in a `w`x`h` mask.
    fn rect_mask(w: usize, h: usize, x0: usize, y0: usize, x1: usize, y1: usize) -> Vec<u8> {
        let mut m = vec![0u8; w * h];
        for y in y0..=y1 {
            for x in x0..=x1 {
                m[y * w + x] = 255;
            }
        }
        m
    }

    #[test]
    fn the_truth_ellipse_is_the_moments_of_the_largest_part_in_the_box() {
        // a 5x9 block (x 4..=8, y 2..=10) and a stray pixel inside the (exclusive) box
        let mut mask = rect_mask(20, 16, 4, 2, 8, 10);
        mask[14 * 20 + 2] = 255;
        let e = mask_ellipse(&mask, 20, 16, [0.0, 0.0, 12.0, 15.0]).expect("ellipse");
        assert!((e.center.x - 6.0).abs() < 1e-9 && (e.center.y - 6.0).abs() < 1e-9);
        // a run of n unit-square pixels has variance n² / 12
        assert!((e.cov[(0, 0)] - 25.0 / 12.0).abs() < 1e-9, "{}", e.cov);
        assert!((e.cov[(1, 1)] - 81.0 / 12.0).abs() < 1e-9, "{}", e.cov);
        assert!(e.cov[(0, 1)].abs() < 1e-9);
        assert!(mask_ellipse(&mask, 20, 16, [30.0, 0.0, 12.0, 3.0]).is_none());
    }

    fn person(id: u32, height: f64, bbox: [f64; 4], visibility: f64) -> PersonTruth {
        serde_json::from_value(serde_json::json!({
            "id": id, "x": 0.0, "y": 0.0, "vx": 0.0, "vy": 0.0, "height": height,
            "head_z": height, "radius": 0.2, "legs": [[0.0, 0.0], [0.0, 0.0]], "leg_radius": 0.05,
            "cameras": [{ "camera": "cam_0", "bbox": bbox, "visibility": visibility }],
        }))
        .expect("person")
    }

    #[test]
    fn a_known_ellipse_is_scored_against_the_mask() {
        // the person is a 5x9 block; the trackers start on its exact ellipse and the next
        // frame is the same image: every tracker's error is measured against that ellipse
        let (w, h) = (24u32, 20u32);
        let mask = rect_mask(w as usize, h as usize, 8, 5, 12, 13);
        let rgb = RgbImage::from_fn(w, h, |x, y| {
            if mask[(y * w + x) as usize] == 255 {
                image::Rgb([200, 30, 40])
            } else {
                image::Rgb([40, 90, 200])
            }
        });
        let truth = PeopleFrame {
            stamp_ns: 0,
            // the logged box is right / bottom exclusive
            people: vec![person(1, 1.7, [8.0, 5.0, 13.0, 14.0], 1.0)],
        };
        let mut p = Params::default();
        p.colour.spaces = vec![ColorSpace::Rgb];
        let mut run = ColourRun::new(&p, true);
        for index in 0..2 {
            let f = Frame {
                index,
                t_s: 0.0,
                rgb: &rgb,
                view: ImageView::rgb(&rgb).expect("view"),
                mask: Some(&mask),
                person_ids: None,
                truth: Some(&truth),
                moving: false,
            };
            run.step(&f).expect("step");
        }
        assert_eq!(run.frame0(), Some(0));
        assert_eq!(run.samples.len(), 2, "EM-like and mean shift, one frame");
        for s in &run.samples {
            let g = s.truth().expect("fully in view");
            assert!((g.center.x - 10.0).abs() < 1e-9 && (g.center.y - 9.0).abs() < 1e-9);
            let err = s.centre_error_px.expect("scored");
            assert!((err - (s.estimate().center - g.center).norm()).abs() < 1e-12);
            assert!(err < 1.0, "{} drifted {err} px on a still image", s.method);
            assert!(s.overlap.expect("scored") > 0.8, "{}", s.method);
        }
        // a second person with the same id: ambiguous, not used, and the run has ended
        let twins = PeopleFrame {
            stamp_ns: 0,
            people: vec![
                person(1, 1.7, [8.0, 5.0, 12.0, 13.0], 1.0),
                person(1, 1.6, [1.0, 1.0, 4.0, 6.0], 1.0),
            ],
        };
        let f = Frame {
            index: 2,
            t_s: 0.0,
            rgb: &rgb,
            view: ImageView::rgb(&rgb).expect("view"),
            mask: Some(&mask),
            person_ids: None,
            truth: Some(&twins),
            moving: false,
        };
        run.step(&f).expect("step");
        assert!(run.finished);
    }
}

//! People detection by correlating human-silhouette templates with a foreground mask
//! (seed 004 §3, eq. 3).
//!
//! **Templates.** A silhouette is a binary shape built from a fixed human profile (head,
//! neck, shoulders, torso, legs; half-widths as fractions of the body height) at a pixel
//! height and a tilt (the angle of the feet → head direction from the image vertical). The
//! set is constrained by the calibration and the room size, as the paper says: a person of
//! the nominal height is placed on a grid over the room floor, projected into the camera, and
//! the image heights and tilts seen there give `n_scales` heights (geometric steps between the
//! 5th and 95th percentiles) × `n_tilts` tilts (evenly spaced percentiles) — 4 × 4 = 16
//! templates by default, the paper's count.
//!
//! **Correlation.** For a template `T` (its bounding window, 1 inside the silhouette, 0
//! outside) placed with its top-left corner at `(x, y)` over the mask `S`, the matching error
//! is the mean squared difference over the window (eq. 3, normalised by the window area so
//! that templates of different sizes compare):
//! `MSE = (|T| − 2 Σ T·S + Σ S) / A`, evaluated in O(rows) with per-row prefix sums (each
//! silhouette row is one run of pixels). The detector reports the **matching score**
//! `1 − MSE` ∈ [0, 1]; an empty window scores `1 − |T|/A`, a completely filled one `|T|/A`
//! and a perfect match 1.
//!
//! **Window margin.** In the silhouette's tight bounding box the profile fills
//! `|T|/A ≈ 0.71` of the window, so *any* region of foreground larger than a person (a trail
//! left by the running-average background, a group) scores ≈ 0.71 everywhere inside it — above
//! every threshold in the paper's range — and the detector tiles it with detections (measured:
//! 67–115 per camera and frame on `multicam_office`). [`Silhouette::padded`] grows the window
//! by a background margin until the silhouette fills a chosen fraction of it; at 0.5 (the
//! default of the pipeline) an empty and a filled window both score 0.5, as far below the
//! threshold as they can both be. The paper calls its templates "normalized human silhouettes"
//! and does not give the window's proportions. Detections report the silhouette's own box. The
//! paper thresholds its combined matching image in (0.6, 0.75) with "a high threshold value"
//! rejecting shadows: that reads as a threshold on this similarity, which is how it is used
//! here. The minimum error over templates at each position is the maximum score; its local
//! extrema are kept by greedy non-maximum suppression in the image (a candidate survives if
//! its box overlaps no better one by more than `nms_iou` and lies no more than
//! `nms_contained` inside one — a smaller template nested in a larger one has a small IoU,
//! [`Suppression::Boxes`]), or as local maxima of the score image around a better detection's
//! head ([`Suppression::Heads`]): the paper's non-minimal suppression. Placements may hang over the image border (at least `min_inside` of the
//! window inside, the head row inside); only the inside part is compared. A placement whose
//! score cannot reach the threshold (bound `1 − |Σ T − Σ S| / A` from the window sum) is
//! skipped without correlating.
//!
//! Each detection gives its box, the head point (the top of the silhouette, "vertically
//! translating the correspondence coordinates according to the dimensions of the related
//! human template", §4), the template's body width and height, and the centroid of the
//! foreground pixels inside the box (the blob centroid the paper compares against, §5).
//!
//! [`Probe`] (in `probe`) measures what the detector could have found near a known head point
//! (the chain's error analysis).
//!
//! What it does not do: no learned shapes, no sub-pixel positions (the search stride is a
//! parameter).

mod probe;

pub use probe::{Fill, Fit, Probe};

use crate::geometry::rect::{contained, iou};
use nalgebra::Point3;

use super::gabor::Mask;
use crate::geometry::triangulate::CalibratedView;

/// Paper's range for the detection threshold on the matching score: (0.6, 0.75).
pub const THRESHOLD_RANGE: (f64, f64) = (0.6, 0.75);

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TemplateError {
    #[error("no floor point of the room is seen by the camera: cannot size templates")]
    NotVisible,
    #[error("bad parameter `{name}`: {reason}")]
    BadParameter { name: &'static str, reason: String },
}

/// Half-width of the human profile (fraction of the body height) at `v` ∈ [0, 1] from the
/// top of the head.
pub fn profile_half_width(v: f64) -> f64 {
    const HEAD: f64 = 0.13;
    if v < HEAD {
        let c = HEAD / 2.0;
        let t = ((v - c) / c).clamp(-1.0, 1.0);
        0.052 * (1.0 - t * t).max(0.0).sqrt()
    } else if v < 0.15 {
        0.035
    } else if v < 0.20 {
        0.035 + (0.12 - 0.035) * (v - 0.15) / 0.05
    } else if v < 0.5 {
        0.12 - 0.015 * (v - 0.2) / 0.3
    } else {
        0.105 - 0.03 * (v - 0.5) / 0.5
    }
}

/// One binary silhouette: a run `[start, end)` of template columns per row.
#[derive(Debug, Clone, PartialEq)]
pub struct Silhouette {
    pub width: u32,
    pub height: u32,
    pub spans: Vec<(u32, u32)>,
    /// Pixels inside the silhouette.
    pub area: u32,
    /// Top of the head in template coordinates (x, y).
    pub head: (f64, f64),
    /// Widest run (shoulders): the body width in pixels.
    pub body_width_px: f64,
    pub tilt_rad: f64,
    /// The silhouette's own bounding box `[x0, y0, x1, y1)` in template coordinates: the
    /// whole window unless [`Silhouette::padded`] added a background margin.
    pub body: [u32; 4],
}

impl Silhouette {
    /// The silhouette of a person `height_px` tall whose head leans `tilt_rad` from the feet
    /// (positive: head to the right of the feet).
    pub fn new(height_px: f64, tilt_rad: f64) -> Silhouette {
        let rows = height_px.round().max(8.0) as i64;
        let hgt = rows as f64;
        let lean = tilt_rad.tan();
        let mut raw = Vec::with_capacity(rows as usize);
        for r in 0..rows {
            let v = (r as f64 + 0.5) / hgt;
            let center = (1.0 - v) * hgt * lean;
            let hw = (profile_half_width(v) * hgt).max(0.5);
            raw.push(((center - hw).round() as i64, (center + hw).round() as i64));
        }
        let min_a = raw.iter().map(|s| s.0).min().unwrap_or(0);
        let max_b = raw.iter().map(|s| s.1).max().unwrap_or(1);
        let spans: Vec<(u32, u32)> = raw
            .iter()
            .map(|&(a, b)| ((a - min_a) as u32, ((b - min_a).max(a - min_a + 1)) as u32))
            .collect();
        let area = spans.iter().map(|(a, b)| b - a).sum();
        let body_width_px = spans.iter().map(|(a, b)| b - a).max().unwrap_or(1) as f64;
        let width = (max_b - min_a).max(1) as u32;
        Silhouette {
            width,
            height: rows as u32,
            area,
            head: (hgt * lean - min_a as f64, 0.0),
            spans,
            body_width_px,
            tilt_rad,
            body: [0, 0, width, rows as u32],
        }
    }

    /// Fraction of the window inside the silhouette, `|T| / A`.
    pub fn fill(&self) -> f64 {
        f64::from(self.area) / (f64::from(self.width) * f64::from(self.height))
    }

    /// The same silhouette in a window grown evenly on all four sides (background margin) until
    /// the silhouette fills at most `fill` of it. Unchanged when it already does.
    pub fn padded(self, fill: f64) -> Silhouette {
        if !(fill > 0.0 && fill < self.fill()) {
            return self;
        }
        let (w, h) = (f64::from(self.width), f64::from(self.height));
        let s = (self.fill() / fill).sqrt();
        let pad_x = ((w * s - w) / 2.0).ceil() as u32;
        let pad_y = ((h * s - h) / 2.0).ceil() as u32;
        let mut spans = Vec::with_capacity(self.spans.len() + 2 * pad_y as usize);
        spans.extend(std::iter::repeat_n((0, 0), pad_y as usize));
        spans.extend(self.spans.iter().map(|&(a, b)| (a + pad_x, b + pad_x)));
        spans.extend(std::iter::repeat_n((0, 0), pad_y as usize));
        Silhouette {
            width: self.width + 2 * pad_x,
            height: self.height + 2 * pad_y,
            spans,
            area: self.area,
            head: (
                self.head.0 + f64::from(pad_x),
                self.head.1 + f64::from(pad_y),
            ),
            body_width_px: self.body_width_px,
            tilt_rad: self.tilt_rad,
            body: [
                self.body[0] + pad_x,
                self.body[1] + pad_y,
                self.body[2] + pad_x,
                self.body[3] + pad_y,
            ],
        }
    }

    /// The same profile `factor` times as wide: every row's run scaled about its centre (the
    /// lean line stays where it was), for people whose arms and clothes make them wider than
    /// the profile's torso. Apply before [`Silhouette::grown`] and [`Silhouette::padded`].
    pub fn widened(self, factor: f64) -> Silhouette {
        if factor.is_nan() || factor <= 0.0 || factor == 1.0 || self.spans.is_empty() {
            return self;
        }
        let raw: Vec<(i64, i64)> = self
            .spans
            .iter()
            .map(|&(a, b)| {
                let c = 0.5 * f64::from(a + b);
                let half = 0.5 * f64::from(b - a) * factor;
                let (na, nb) = ((c - half).round() as i64, (c + half).round() as i64);
                (na, nb.max(na + 1))
            })
            .collect();
        let min_a = raw.iter().map(|s| s.0).min().unwrap_or(0);
        let max_b = raw.iter().map(|s| s.1).max().unwrap_or(1);
        let spans: Vec<(u32, u32)> = raw
            .iter()
            .map(|&(a, b)| ((a - min_a) as u32, (b - min_a) as u32))
            .collect();
        let width = (max_b - min_a).max(1) as u32;
        Silhouette {
            width,
            height: self.height,
            area: spans.iter().map(|(a, b)| b - a).sum(),
            head: (self.head.0 - min_a as f64, self.head.1),
            body_width_px: spans.iter().map(|(a, b)| b - a).max().unwrap_or(1) as f64,
            spans,
            tilt_rad: self.tilt_rad,
            body: [0, 0, width, self.height],
        }
    }

    /// The silhouette as the segmentation shows it: dilated by a `(2 px + 1)²` square (each
    /// row's run becomes the union of the runs within `px` rows, widened by `px` each side),
    /// since a filter bank of envelope σ spreads the foreground of an edge by about σ. The
    /// person's own box ([`Silhouette::body`]), head point and body width stay those of the
    /// undilated silhouette, `px` inside the grown shape, so detections report the person.
    /// Apply before [`Silhouette::padded`].
    pub fn grown(self, px: u32) -> Silhouette {
        if px == 0 || self.spans.is_empty() {
            return self;
        }
        let g = px as usize;
        let n = self.spans.len();
        let spans: Vec<(u32, u32)> = (0..n + 2 * g)
            .map(|r| {
                // old rows r − 2g ..= r (in old coordinates: the new row r is old row r − g)
                let lo = r.saturating_sub(2 * g);
                let hi = r.min(n - 1);
                let (a, b) = self.spans[lo..=hi]
                    .iter()
                    .filter(|s| s.1 > s.0)
                    .fold((u32::MAX, 0), |(a, b), s| (a.min(s.0), b.max(s.1)));
                if a >= b { (0, 0) } else { (a, b + 2 * px) }
            })
            .collect();
        let area = spans.iter().map(|(a, b)| b - a).sum();
        Silhouette {
            width: self.width + 2 * px,
            height: self.height + 2 * px,
            spans,
            area,
            head: (self.head.0 + f64::from(px), self.head.1 + f64::from(px)),
            body_width_px: self.body_width_px,
            tilt_rad: self.tilt_rad,
            body: self.body.map(|v| v + px),
        }
    }

    /// Height of the silhouette itself (pixels), without margins.
    pub fn body_height_px(&self) -> f64 {
        f64::from(self.body[3] - self.body[1])
    }
}

/// How a calibrated camera sees a person standing on the room floor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Appearance {
    pub height_px: f64,
    pub tilt_rad: f64,
}

/// Image heights and tilts of a person `person_height_m` tall standing on a grid (`step_m`)
/// over the room floor `[x0, y0, x1, y1]` whose head the camera sees.
pub fn appearances(
    view: &CalibratedView,
    room_m: [f64; 4],
    person_height_m: f64,
    step_m: f64,
) -> Vec<Appearance> {
    let mut out = Vec::new();
    let nx = ((room_m[2] - room_m[0]) / step_m).floor().max(0.0) as usize;
    let ny = ((room_m[3] - room_m[1]) / step_m).floor().max(0.0) as usize;
    for i in 0..=nx {
        for j in 0..=ny {
            let (x, y) = (room_m[0] + i as f64 * step_m, room_m[1] + j as f64 * step_m);
            let (Some(foot), Some(head)) = (
                view.project(&Point3::new(x, y, 0.0)),
                view.project(&Point3::new(x, y, person_height_m)),
            ) else {
                continue;
            };
            if !view.model.in_image(&head) {
                continue;
            }
            let (dx, dy) = (head.x - foot.x, foot.y - head.y);
            let height_px = dx.hypot(dy);
            if height_px < 4.0 || dy <= 0.0 {
                continue;
            }
            out.push(Appearance {
                height_px,
                tilt_rad: dx.atan2(dy),
            });
        }
    }
    out
}

fn percentile(sorted: &[f64], q: f64) -> f64 {
    let pos = q.clamp(0.0, 1.0) * (sorted.len() - 1) as f64;
    let (i, f) = (pos.floor() as usize, pos.fract());
    let j = (i + 1).min(sorted.len() - 1);
    sorted[i] * (1.0 - f) + sorted[j] * f
}

/// The calibration-constrained template set of one camera: `n_scales` heights × `n_tilts`
/// tilts (see the module documentation).
pub fn calibrated_templates(
    view: &CalibratedView,
    room_m: [f64; 4],
    person_height_m: f64,
    n_scales: usize,
    n_tilts: usize,
) -> Result<Vec<Silhouette>, TemplateError> {
    if n_scales == 0 || n_tilts == 0 {
        return Err(TemplateError::BadParameter {
            name: "n_scales × n_tilts",
            reason: "needs at least one template".into(),
        });
    }
    let seen = appearances(view, room_m, person_height_m, 0.2);
    if seen.is_empty() {
        return Err(TemplateError::NotVisible);
    }
    let mut heights: Vec<f64> = seen.iter().map(|a| a.height_px).collect();
    let mut tilts: Vec<f64> = seen.iter().map(|a| a.tilt_rad).collect();
    heights.sort_by(f64::total_cmp);
    tilts.sort_by(f64::total_cmp);
    let (lo, hi) = (percentile(&heights, 0.05), percentile(&heights, 0.95));
    let scales: Vec<f64> = (0..n_scales)
        .map(|i| {
            if n_scales == 1 {
                (lo * hi).sqrt()
            } else {
                lo * (hi / lo).powf(i as f64 / (n_scales - 1) as f64)
            }
        })
        .collect();
    let tilt_set: Vec<f64> = (0..n_tilts)
        .map(|i| percentile(&tilts, (i as f64 + 0.5) / n_tilts as f64))
        .collect();
    let mut out = Vec::with_capacity(n_scales * n_tilts);
    for &s in &scales {
        for &t in &tilt_set {
            out.push(Silhouette::new(s, t));
        }
    }
    Ok(out)
}

/// The template tried at each head pixel of one camera: the calibration predicts the image
/// height and tilt of a person `person_height_m` tall whose head is at that pixel (the ray
/// through it meets the plane at head height over the room floor; the feet below project back
/// into the image), and the template nearest in height (log ratio), then in tilt, is the one
/// correlated there. Pixels whose head point falls outside the room (± margin) or that the
/// camera cannot place get none. This is the paper's "the range of the scale and the 3D
/// orientation of the human silhouettes can be restricted according to the camera position
/// and size of the room" applied per position instead of per image.
#[derive(Debug, Clone, PartialEq)]
pub struct TemplateMap {
    width: u32,
    height: u32,
    choice: Vec<u16>,
}

impl TemplateMap {
    const NONE: u16 = u16::MAX;

    pub fn new(
        view: &CalibratedView,
        templates: &[Silhouette],
        person_height_m: f64,
        room_m: [f64; 4],
        margin_m: f64,
    ) -> TemplateMap {
        let (width, height) = view.model.size();
        let mut choice = vec![Self::NONE; width as usize * height as usize];
        for y in 0..height {
            for x in 0..width {
                let px = nalgebra::Point2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
                let Some(a) = expected_appearance(view, &px, person_height_m, room_m, margin_m)
                else {
                    continue;
                };
                let best = templates
                    .iter()
                    .enumerate()
                    .map(|(i, t)| {
                        (
                            (t.body_height_px() / a.height_px).ln().abs(),
                            (t.tilt_rad - a.tilt_rad).abs(),
                            i,
                        )
                    })
                    .min_by(|p, q| {
                        // heights equal to a micro-pixel are one scale: the tilt decides
                        let dh = p.0 - q.0;
                        if dh.abs() > 1e-9 {
                            dh.total_cmp(&0.0)
                        } else {
                            p.1.total_cmp(&q.1).then(p.2.cmp(&q.2))
                        }
                    });
                if let Some((_, _, i)) = best {
                    choice[(y * width + x) as usize] = i as u16;
                }
            }
        }
        TemplateMap {
            width,
            height,
            choice,
        }
    }

    /// The template index to try with the head at pixel `(x, y)`, if any.
    pub fn at(&self, x: i64, y: i64) -> Option<usize> {
        if x < 0 || y < 0 || x >= i64::from(self.width) || y >= i64::from(self.height) {
            return None;
        }
        let c = self.choice[(y as u32 * self.width + x as u32) as usize];
        (c != Self::NONE).then_some(usize::from(c))
    }
}

/// Image height and tilt of a person `person_height_m` tall whose head is seen at `head_px`,
/// or `None` when that head would stand outside the room (± `margin_m`) or is not in front of
/// the camera.
pub fn expected_appearance(
    view: &CalibratedView,
    head_px: &nalgebra::Point2<f64>,
    person_height_m: f64,
    room_m: [f64; 4],
    margin_m: f64,
) -> Option<Appearance> {
    let (o, d) = view.ray_in_world(head_px)?;
    if d.z.abs() < 1e-9 {
        return None;
    }
    let t = (person_height_m - o.z) / d.z;
    if t <= 0.0 {
        return None;
    }
    let head = o + d * t;
    if head.x < room_m[0] - margin_m
        || head.x > room_m[2] + margin_m
        || head.y < room_m[1] - margin_m
        || head.y > room_m[3] + margin_m
    {
        return None;
    }
    let foot = view.project(&Point3::new(head.x, head.y, 0.0))?;
    let (dx, dy) = (head_px.x - foot.x, foot.y - head_px.y);
    (dy > 0.0).then(|| Appearance {
        height_px: dx.hypot(dy),
        tilt_rad: dx.atan2(dy),
    })
}

/// How overlapping candidates are suppressed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Suppression {
    /// Greedy box suppression: a candidate is dropped when its box overlaps a better
    /// detection by more than `nms_iou` or lies more than `nms_contained` inside one.
    Boxes,
    /// Local maxima of the combined score image (the paper's non-minimal suppression over
    /// the combined matching error `Pᵗ`): a candidate is dropped when a better detection's
    /// head lies within `radius` × the larger body width horizontally and `radius` × the
    /// larger body height vertically of its head (the score image's peaks stretch along the
    /// body: a silhouette moved down its own axis by a tenth of its height still scores ~0.8).
    Heads { radius: f64 },
}

/// Detector settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DetectorParams {
    /// Minimum matching score `1 − MSE` (paper: in (0.6, 0.75)).
    pub threshold: f64,
    /// Search stride (pixels).
    pub stride_px: u32,
    /// Greedy non-maximum suppression: a candidate whose box overlaps a better detection by
    /// more than this IoU is dropped.
    pub nms_iou: f64,
    /// A candidate whose box lies more than this fraction inside a better detection's box is
    /// dropped too (a smaller template nested in a larger one has a small IoU with it).
    pub nms_contained: f64,
    /// Fraction of a template window that must lie inside the image.
    pub min_inside: f64,
    pub suppression: Suppression,
}

impl Default for DetectorParams {
    fn default() -> Self {
        DetectorParams {
            threshold: 0.7,
            stride_px: 2,
            nms_iou: 0.3,
            nms_contained: 0.7,
            min_inside: 0.5,
            suppression: Suppression::Boxes,
        }
    }
}

/// One detected person.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Detection {
    /// `[x0, y0, x1, y1]` of the silhouette (the template window without its margin; may reach
    /// outside the image).
    pub bbox: [f64; 4],
    /// Top of the head (pixels).
    pub head_px: [f64; 2],
    /// Centroid of the foreground pixels inside the box (pixels); the head if there are none.
    pub centroid_px: [f64; 2],
    /// Body width and height of the template (pixels).
    pub width_px: f64,
    pub height_px: f64,
    /// Matching score `1 − MSE`.
    pub score: f64,
    /// Index of the template.
    pub template: usize,
}

/// Prefix sums of a mask: per row (`w + 1` per row) and 2-D (`(w + 1) × (h + 1)`).
struct Sums {
    w: usize,
    h: usize,
    rows: Vec<u32>,
    integral: Vec<u32>,
}

impl Sums {
    fn new(mask: &Mask) -> Sums {
        let (w, h) = (mask.width as usize, mask.height as usize);
        let mut rows = vec![0u32; (w + 1) * h];
        let mut integral = vec![0u32; (w + 1) * (h + 1)];
        for y in 0..h {
            let mut acc = 0u32;
            for x in 0..w {
                acc += u32::from(mask.data[y * w + x]);
                rows[y * (w + 1) + x + 1] = acc;
                integral[(y + 1) * (w + 1) + x + 1] = integral[y * (w + 1) + x + 1] + acc;
            }
        }
        Sums {
            w,
            h,
            rows,
            integral,
        }
    }

    /// Foreground pixels in `[x0, x1) × [y0, y1)` (already clipped).
    fn window(&self, x0: usize, y0: usize, x1: usize, y1: usize) -> u32 {
        let s = self.w + 1;
        self.integral[y1 * s + x1] + self.integral[y0 * s + x0]
            - self.integral[y0 * s + x1]
            - self.integral[y1 * s + x0]
    }

    fn row(&self, y: usize, x0: usize, x1: usize) -> u32 {
        let s = self.w + 1;
        self.rows[y * s + x1] - self.rows[y * s + x0]
    }
}

/// Matching score of `t` with its top-left corner at `(x, y)`, or `None` when the placement
/// is not allowed or cannot reach `threshold`.
fn score_at(
    sums: &Sums,
    t: &Silhouette,
    x: i64,
    y: i64,
    threshold: f64,
    min_inside: f64,
) -> Option<f64> {
    let (w, h) = (sums.w as i64, sums.h as i64);
    let (x0, y0) = (x.max(0), y.max(0));
    let (x1, y1) = (
        (x + i64::from(t.width)).min(w),
        (y + i64::from(t.height)).min(h),
    );
    let head_row = y + t.head.1 as i64;
    if x1 <= x0 || y1 <= y0 || head_row < 0 || head_row >= h {
        return None;
    }
    let area = ((x1 - x0) * (y1 - y0)) as f64;
    let full = f64::from(t.width) * f64::from(t.height);
    if area < min_inside * full {
        return None;
    }
    let sw = f64::from(sums.window(x0 as usize, y0 as usize, x1 as usize, y1 as usize));
    let inside =
        x0 == x && y0 == y && x1 == x + i64::from(t.width) && y1 == y + i64::from(t.height);
    if inside && 1.0 - (f64::from(t.area) - sw).abs() / area < threshold {
        return None; // cannot reach the threshold whatever the overlap
    }
    let (mut t1, mut c) = (0u32, 0u32);
    for (r, &(a, b)) in t.spans.iter().enumerate() {
        let yy = y + r as i64;
        if yy < 0 {
            continue;
        }
        if yy >= h {
            break;
        }
        let (a, b) = (
            (x + i64::from(a)).clamp(0, w),
            (x + i64::from(b)).clamp(0, w),
        );
        if b > a {
            t1 += (b - a) as u32;
            c += sums.row(yy as usize, a as usize, b as usize);
        }
    }
    let mse = (f64::from(t1) - 2.0 * f64::from(c) + sw) / area;
    Some(1.0 - mse)
}

/// Detect people in a foreground mask with a template set, every template at every position.
pub fn detect(mask: &Mask, templates: &[Silhouette], p: &DetectorParams) -> Vec<Detection> {
    detect_with(mask, templates, None, p)
}

/// Detect people, trying at each head position only the template `map` chooses there (all
/// of them without a map).
pub fn detect_with(
    mask: &Mask,
    templates: &[Silhouette],
    map: Option<&TemplateMap>,
    p: &DetectorParams,
) -> Vec<Detection> {
    if mask.width == 0 || mask.height == 0 || templates.is_empty() {
        return Vec::new();
    }
    let sums = Sums::new(mask);
    let (w, h) = (i64::from(mask.width), i64::from(mask.height));
    let stride = i64::from(p.stride_px.max(1));
    // best score per head position over templates (the paper's minimum of the MSE images);
    // positions are anchored at the head so that every template shares one grid
    let mut best: std::collections::BTreeMap<(i64, i64), (f64, usize)> = Default::default();
    for (ti, t) in templates.iter().enumerate() {
        let tw = i64::from(t.width);
        let (hx, hy) = (t.head.0.round() as i64, t.head.1.round() as i64);
        let mut yh = 0;
        while yh < h {
            let y = yh - hy;
            let mut xh = -tw / 2 + hx;
            while xh < w + tw / 2 {
                let x = xh - hx;
                let allowed = map.is_none_or(|m| m.at(xh, yh) == Some(ti));
                if allowed
                    && x + tw > 0
                    && let Some(s) = score_at(&sums, t, x, y, p.threshold, p.min_inside)
                    && s >= p.threshold
                {
                    let e = best.entry((xh, yh)).or_insert((f64::NEG_INFINITY, 0));
                    if s > e.0 {
                        *e = (s, ti);
                    }
                }
                xh += stride;
            }
            yh += stride;
        }
    }
    let mut cands: Vec<(f64, i64, i64, usize)> = best
        .into_iter()
        .map(|((x, y), (s, t))| (s, y, x, t))
        .collect();
    // best first; ties broken by position and template for determinism
    cands.sort_by(|a, b| {
        b.0.total_cmp(&a.0)
            .then(a.1.cmp(&b.1))
            .then(a.2.cmp(&b.2))
            .then(a.3.cmp(&b.3))
    });
    let mut out: Vec<Detection> = Vec::new();
    for (score, yh, xh, ti) in cands {
        let t = &templates[ti];
        let x = (xh - t.head.0.round() as i64) as f64;
        let y = (yh - t.head.1.round() as i64) as f64;
        let b = t.body.map(f64::from);
        let bbox = [x + b[0], y + b[1], x + b[2], y + b[3]];
        let head_px = [x + t.head.0, y + t.head.1];
        if out.iter().any(|d| suppresses(d, &bbox, head_px, t, p)) {
            continue;
        }
        out.push(Detection {
            bbox,
            head_px,
            centroid_px: centroid(mask, &bbox).unwrap_or(head_px),
            width_px: t.body_width_px,
            height_px: t.body_height_px(),
            score,
            template: ti,
        });
    }
    out
}

/// Whether detection `d` suppresses a worse candidate of template `t` with box `bbox` and head
/// `head_px`.
pub fn suppresses(
    d: &Detection,
    bbox: &[f64; 4],
    head_px: [f64; 2],
    t: &Silhouette,
    p: &DetectorParams,
) -> bool {
    match p.suppression {
        Suppression::Boxes => {
            iou(&d.bbox, bbox) > p.nms_iou || contained(bbox, &d.bbox) > p.nms_contained
        }
        Suppression::Heads { radius } => {
            (d.head_px[0] - head_px[0]).abs() < radius * d.width_px.max(t.body_width_px)
                && (d.head_px[1] - head_px[1]).abs() < radius * d.height_px.max(t.body_height_px())
        }
    }
}

/// Centroid of the foreground pixels of `mask` inside `bbox` (pixel centres at `i + 0.5`).
pub fn centroid(mask: &Mask, bbox: &[f64; 4]) -> Option<[f64; 2]> {
    let (w, h) = (i64::from(mask.width), i64::from(mask.height));
    let x0 = (bbox[0].floor() as i64).clamp(0, w);
    let x1 = (bbox[2].ceil() as i64).clamp(0, w);
    let y0 = (bbox[1].floor() as i64).clamp(0, h);
    let y1 = (bbox[3].ceil() as i64).clamp(0, h);
    let (mut n, mut sx, mut sy) = (0u64, 0.0, 0.0);
    for y in y0..y1 {
        let row = &mask.data[(y * w) as usize..((y + 1) * w) as usize];
        for x in x0..x1 {
            if row[x as usize] != 0 {
                n += 1;
                sx += x as f64 + 0.5;
                sy += y as f64 + 0.5;
            }
        }
    }
    (n > 0).then(|| [sx / n as f64, sy / n as f64])
}

#[cfg(test)]
mod tests;

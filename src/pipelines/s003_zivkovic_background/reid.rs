//! Re-identification, the session stage (seed 003 §IV–V, Zajdel et al.): the mean colours of
//! the three regions of fig. 4a for every person box in every frame — the ground-truth boxes
//! (local tracks given, which isolates re-identification) and the system's own local tracks
//! (the whole chain) — cached per frame as the `reid_frames` table, one row per box and pixel
//! set. `reid_report` turns them into the paper's colour space, groups them into local tracks
//! and runs the filter.
//!
//! **Whose pixels.** §III: "We need to know which pixels belong to a person in order to give
//! an accurate description on its appearance." Three pixel sets per box:
//! - `person` (the default): the local tracker's own foreground (`LocalTracker::foreground`:
//!   the GMM mask without shadows, majority-filtered) inside the box — what a robot has. None
//!   while the camera moves or the model warms up after a restart.
//! - `exact` (the ceiling): the synthesizer's per-person id mask (`/cam_0/ground_truth_ids`,
//!   when the log has it) — the box's person's own pixels; for a system track, those of the
//!   person it overlaps most.
//! - `box`: every pixel of the box, background included (the feature before issue 31, kept
//!   to measure what the person's pixels change).
//! - `person_filled` (issue 31, round 6): the tracker's foreground with every row of the box
//!   filled from its first to its last foreground pixel — the silhouette with the holes closed
//!   where the person's colour is too like the background behind for the mask.
//!
//! **The regions** (fig. 4a): three horizontal regions of 25 % of "the blob's height" with
//! "skip areas" of 12.5 %. For the mask sets the blob is the set's pixels inside the box and
//! its height their extent from the first to the last row holding one; for `box` it is the
//! box. The text does not say where the two skip areas lie; here they are the top (head) and
//! the bottom (feet) — the parts with the least discriminative power — so the regions cover
//! 12.5–37.5 %, 37.5–62.5 % and 62.5–87.5 % of the height. A mask region with fewer than
//! [`MIN_REGION_PX`] pixels gives no row for that frame (counted at the report).
//!
//! The row keeps the raw means (0–255) and the frame's channel means, so that the report can
//! form any colour space: the paper's colour-channel-normalised one ([8], Drew, Wei & Li: each
//! channel divided by its mean over the image), its logarithm, raw RGB.

use image::RgbImage;

use super::local_tracks::TrackRow;
use super::params::Params;
use super::shared::Frame;
use super::snapshots::Snapshots;
use crate::geometry::rect;
use crate::report::rows::Rows;
use crate::run::SessionTables;
use crate::table_row;
use crate::vision::gmm::FOREGROUND;

/// Name of the cached per-frame feature table.
pub(super) const FRAMES_TABLE: &str = "reid_frames";

/// The region bounds as fractions of the blob's height, top to bottom.
pub(super) const REGIONS: [(f64, f64); 3] = [(0.125, 0.375), (0.375, 0.625), (0.625, 0.875)];

/// A region of a mask pixel set needs this many pixels for its mean colour (a priori: the
/// mean of 10 pixels carries the camera noise of σ ≈ 2.5 grey levels as < 1 level; fewer is
/// a sliver of a person or a few stray foreground pixels).
pub(super) const MIN_REGION_PX: u64 = 10;

/// The pixel sets (`pixels` column): the tracker's foreground, the exact person mask, the box.
pub(super) const PERSON: &str = "person";
pub(super) const EXACT: &str = "exact";
pub(super) const BOX: &str = "box";
pub(super) const FILLED: &str = "person_filled";

table_row! {
    /// Cached per session: the region means of one box's pixel set in one frame.
    #[derive(Debug, Clone, PartialEq)]
    pub(super) struct ReidFrameRow {
        pub frame: i64,
        pub t_s: f64,
        /// `truth` (a ground-truth box) or `system` (a local track's box).
        pub source: String,
        /// The person id (truth) or the track id (system).
        pub id: i64,
        /// The ground-truth person a system box overlaps most (IoU ≥ `local_eval.min_iou`).
        pub truth_id: Option<i64>,
        /// `person`, `person_filled`, `exact` or `box` (the module doc).
        pub pixels: String,
        /// Pixels of the set inside the box.
        pub px: i64,
        /// The frame's mean of each channel (0–255, never below 1).
        pub mean_r: f64, pub mean_g: f64, pub mean_b: f64,
        /// Region means, raw 0–255: region 1 r, g, b, region 2 r, g, b, region 3 r, g, b.
        pub m1: f64, pub m2: f64, pub m3: f64, pub m4: f64, pub m5: f64,
        pub m6: f64, pub m7: f64, pub m8: f64, pub m9: f64,
    }
}

/// Who a box is and what it shows: `(frame, t_s, source, id, truth_id)`.
pub(super) type Head<'a> = (i64, f64, &'a str, i64, Option<i64>);

impl ReidFrameRow {
    pub(super) fn new(head: Head, pixels: &str, px: u64, means: [f64; 3], m: [f64; 9]) -> Self {
        let (frame, t_s, source, id, truth_id) = head;
        ReidFrameRow {
            frame,
            t_s,
            source: source.to_string(),
            id,
            truth_id,
            pixels: pixels.to_string(),
            px: px as i64,
            mean_r: means[0],
            mean_g: means[1],
            mean_b: means[2],
            m1: m[0],
            m2: m[1],
            m3: m[2],
            m4: m[3],
            m5: m[4],
            m6: m[5],
            m7: m[6],
            m8: m[7],
            m9: m[8],
        }
    }

    /// The raw region means (0–255).
    pub fn means(&self) -> [f64; 9] {
        [
            self.m1, self.m2, self.m3, self.m4, self.m5, self.m6, self.m7, self.m8, self.m9,
        ]
    }

    /// The frame's channel means.
    pub fn frame_means(&self) -> [f64; 3] {
        [self.mean_r, self.mean_g, self.mean_b]
    }
}

/// Mean of each channel over the frame, never below 1 grey level.
pub(super) fn channel_means(rgb: &RgbImage) -> [f64; 3] {
    let mut sum = [0u64; 3];
    for p in rgb.pixels() {
        for (acc, v) in sum.iter_mut().zip(p.0) {
            *acc += u64::from(v);
        }
    }
    let n = (u64::from(rgb.width()) * u64::from(rgb.height())).max(1) as f64;
    sum.map(|s| (s as f64 / n).max(1.0))
}

/// Which pixels of a box count.
#[derive(Clone, Copy)]
pub(super) enum Pixels<'a> {
    /// Every pixel; the regions split the box's height.
    All,
    /// Pixels where the row-major `mask` (the image's size) equals `value`; the regions split
    /// the height of those pixels' extent.
    Where { mask: &'a [u8], value: u8 },
    /// As `Where`, each row of the box filled from its first to its last such pixel: the
    /// blob's silhouette with its holes closed (the parts of a person too like the background
    /// behind them for the mask).
    Spans { mask: &'a [u8], value: u8 },
}

/// Rows `[y0, y1)` of the three regions of a blob spanning rows `top..bottom` (fractional for
/// a box), clipped to `height`.
fn region_rows(top: f64, bottom: f64, height: f64) -> [(u32, u32); 3] {
    REGIONS.map(|(a, b)| {
        let y0 = (top + a * (bottom - top)).max(0.0).round() as u32;
        let y1 = (top + b * (bottom - top)).min(height).round() as u32;
        (y0, y1)
    })
}

/// The three regions' mean RGB (raw 0..255) of the `pixels` inside box `[x0, y0, x1, y1)`
/// (clipped to the image), with the number of pixels of the set in the box; `None` when a
/// region holds no pixel (`All`) or fewer than [`MIN_REGION_PX`] (a mask).
pub(super) fn region_means(rgb: &RgbImage, b: [f64; 4], pixels: Pixels) -> Option<([f64; 9], u64)> {
    let (w, h) = (rgb.width(), rgb.height());
    if !(b.iter().all(|v| v.is_finite())) || b[3] <= b[1] {
        return None;
    }
    let x0 = b[0].max(0.0).floor() as u32;
    let x1 = b[2].min(f64::from(w)).ceil() as u32;
    if x1 <= x0 {
        return None;
    }
    let ys = (b[1].max(0.0).floor() as u32)..(b[3].min(f64::from(h)).ceil() as u32);
    let is = |mask: &[u8], value: u8, x: u32, y: u32| {
        mask.get(y as usize * w as usize + x as usize) == Some(&value)
    };
    // per row of the box, the first and last column of the mask's value (Spans only)
    let spans: Vec<Option<(u32, u32)>> = match pixels {
        Pixels::Spans { mask, value } => ys
            .clone()
            .map(|y| {
                let first = (x0..x1).find(|&x| is(mask, value, x, y))?;
                let last = (x0..x1).rev().find(|&x| is(mask, value, x, y))?;
                Some((first, last))
            })
            .collect(),
        _ => Vec::new(),
    };
    let selected = |x: u32, y: u32| match pixels {
        Pixels::All => true,
        Pixels::Where { mask, value } => is(mask, value, x, y),
        Pixels::Spans { .. } => spans
            .get(y.wrapping_sub(ys.start) as usize)
            .copied()
            .flatten()
            .is_some_and(|(a, z)| (a..=z).contains(&x)),
    };
    let (rows, least, in_box) = match pixels {
        Pixels::All => (region_rows(b[1], b[3], f64::from(h)), 1, 0),
        Pixels::Where { .. } | Pixels::Spans { .. } => {
            let (mut top, mut bottom, mut n) = (u32::MAX, 0u32, 0u64);
            for y in ys.clone() {
                let k = (x0..x1).filter(|&x| selected(x, y)).count() as u64;
                if k > 0 {
                    top = top.min(y);
                    bottom = y + 1;
                    n += k;
                }
            }
            if n == 0 {
                return None;
            }
            let rows = region_rows(f64::from(top), f64::from(bottom), f64::from(h));
            (rows, MIN_REGION_PX, n)
        }
    };
    let mut out = [0.0; 9];
    let mut total = 0u64;
    for (r, (y0, y1)) in rows.iter().enumerate() {
        let mut sum = [0u64; 3];
        let mut n = 0u64;
        for y in *y0..*y1 {
            for x in (x0..x1).filter(|&x| selected(x, y)) {
                let p = rgb.get_pixel(x, y).0;
                for c in 0..3 {
                    sum[c] += u64::from(p[c]);
                }
                n += 1;
            }
        }
        if n < least {
            return None;
        }
        total += n;
        for c in 0..3 {
            out[3 * r + c] = sum[c] as f64 / n as f64;
        }
    }
    Some((out, if in_box > 0 { in_box } else { total }))
}

/// The re-identification features of one session.
pub(super) struct ReidRun {
    wanted: bool,
    /// Figs. 5–6 frames are kept (scored datasets only, not the training split).
    keep_snapshots: bool,
    camera: String,
    min_visibility: f64,
    min_iou: f64,
    rows: Vec<ReidFrameRow>,
    snapshots: Snapshots,
}

impl ReidRun {
    /// Features are computed for the datasets `reid.datasets` and `reid.train_datasets` name.
    pub fn new(p: &Params, dataset: &str) -> Self {
        let scored = p.reid.datasets.iter().any(|d| d == dataset);
        Self {
            wanted: scored || p.reid.train_datasets.iter().any(|d| d == dataset),
            keep_snapshots: scored,
            camera: p.camera.clone(),
            min_visibility: p.reid.min_visibility,
            min_iou: p.local_eval.min_iou,
            rows: Vec::new(),
            snapshots: Snapshots::new(p.reid.snapshot_window_s),
        }
    }

    /// Whether this session is re-identified (its frames need the person-id mask, if any).
    pub fn wanted(&self) -> bool {
        self.wanted
    }

    /// Features of the frame's ground-truth boxes and of the local tracks' boxes `tracks`,
    /// with the tracker's `foreground` of this frame (`None`: no blobs were taken).
    pub fn step(&mut self, f: &Frame, tracks: &[TrackRow], foreground: Option<&[u8]>) {
        if !self.wanted {
            return;
        }
        let means = channel_means(f.rgb);
        let mut truth_boxes = Vec::new();
        for person in f.truth.iter().flat_map(|fr| &fr.people) {
            for v in person.cameras.iter().filter(|v| v.camera == self.camera) {
                if let Some(b) = v.bbox
                    && v.visibility >= self.min_visibility
                {
                    // the logged box is already right and bottom exclusive
                    truth_boxes.push((i64::from(person.id), b));
                }
            }
        }
        let mut shown: Vec<(&str, i64, [f64; 4])> = Vec::new();
        for &(id, b) in &truth_boxes {
            self.push(f, (f.index, f.t_s, "truth", id, None), b, means, foreground);
            shown.push(("truth", id, b));
        }
        for t in tracks {
            let b = [t.x0, t.y0, t.x1, t.y1];
            let truth_id = truth_boxes
                .iter()
                .map(|(id, g)| (*id, rect::iou(&b, g)))
                .filter(|(_, o)| *o >= self.min_iou)
                .max_by(|a, b| a.1.total_cmp(&b.1))
                .map(|(id, _)| id);
            let head = (f.index, f.t_s, "system", t.track, truth_id);
            self.push(f, head, b, means, foreground);
            shown.push(("system", t.track, b));
        }
        if self.keep_snapshots {
            self.snapshots.offer(f.index, f.t_s, f.rgb, &shown);
        }
    }

    /// One box's rows: every pixel set that gives a feature in this frame.
    fn push(
        &mut self,
        f: &Frame,
        head: Head,
        b: [f64; 4],
        means: [f64; 3],
        foreground: Option<&[u8]>,
    ) {
        // the person whose exact pixels count: the box's own, or the one a track overlaps
        let person = if head.2 == "truth" {
            Some(head.3)
        } else {
            head.4
        };
        let exact = f.person_ids.zip(person).map(|(mask, id)| Pixels::Where {
            mask,
            value: u8::try_from(id).unwrap_or(u8::MAX),
        });
        let person_px = foreground.map(|mask| Pixels::Where {
            mask,
            value: FOREGROUND,
        });
        let filled_px = foreground.map(|mask| Pixels::Spans {
            mask,
            value: FOREGROUND,
        });
        for (name, pixels) in [
            (BOX, Some(Pixels::All)),
            (PERSON, person_px),
            (FILLED, filled_px),
            (EXACT, exact),
        ] {
            if let Some((m, px)) = pixels.and_then(|p| region_means(f.rgb, b, p)) {
                self.rows.push(ReidFrameRow::new(head, name, px, means, m));
            }
        }
    }

    /// The cached `reid_frames` table (only for the wanted datasets), and figs. 5–6 frames.
    pub fn finish(self, out: &mut SessionTables) -> anyhow::Result<()> {
        if self.wanted {
            out.insert(FRAMES_TABLE.into(), ReidFrameRow::frame(&self.rows)?);
        }
        if self.keep_snapshots {
            self.snapshots.finish(out)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regions_skip_the_head_and_feet_and_average_each_band() {
        // an 8 × 16 image: rows 0..8 red, 8..16 blue; a box over all of it
        let img = RgbImage::from_fn(8, 16, |_, y| {
            if y < 8 {
                image::Rgb([200, 0, 0])
            } else {
                image::Rgb([0, 0, 100])
            }
        });
        let (m, px) = region_means(&img, [0.0, 0.0, 8.0, 16.0], Pixels::All).expect("regions");
        // region 1: rows 2..6 (red); region 2: rows 6..10 (half red, half blue); region 3:
        // rows 10..14 (blue)
        assert_eq!(m, [200.0, 0.0, 0.0, 100.0, 0.0, 50.0, 0.0, 0.0, 100.0]);
        assert_eq!(px, 96, "the regions' pixels");
        // the channel normalisation's means: red 100, blue 50, green 0 → 1
        assert_eq!(channel_means(&img), [100.0, 1.0, 50.0]);
        let all = Pixels::All;
        assert_eq!(
            region_means(&img, [4.0, 4.0, 4.0, 10.0], all),
            None,
            "empty box"
        );
        assert_eq!(region_means(&img, [0.0, f64::NAN, 8.0, 16.0], all), None);
    }

    #[test]
    fn a_masks_regions_split_the_blobs_own_height_and_average_only_its_pixels() {
        // a 10 × 20 grey background; the "person" (mask 7) covers columns 2..6, rows 4..20:
        // green rows 4..12, blue rows 12..20. The box is wider and taller than the person.
        let person = |x: u32, y: u32| (2..6).contains(&x) && y >= 4;
        let img = RgbImage::from_fn(10, 20, |x, y| match (person(x, y), y < 12) {
            (false, _) => image::Rgb([120, 120, 120]),
            (true, true) => image::Rgb([0, 200, 0]),
            (true, false) => image::Rgb([0, 0, 220]),
        });
        let mask: Vec<u8> = (0..200u32)
            .map(|i| if person(i % 10, i / 10) { 7 } else { 0 })
            .collect();
        let pixels = Pixels::Where {
            mask: &mask,
            value: 7,
        };
        let b = [0.0, 0.0, 10.0, 20.0];
        let (m, px) = region_means(&img, b, pixels).expect("regions");
        // the blob spans rows 4..20 (16 rows): regions rows 6..10 (green), 10..14 (half and
        // half), 14..18 (blue); no background pixel counts
        assert_eq!(m, [0.0, 200.0, 0.0, 0.0, 100.0, 110.0, 0.0, 0.0, 220.0]);
        assert_eq!(px, 64, "the person's pixels in the box");
        // the whole box instead: regions on rows 2.5..7.5 etc., background included
        let (all, _) = region_means(&img, b, Pixels::All).expect("box");
        assert!(
            all[1] < 200.0 && all[0] > 0.0,
            "background dilutes: {all:?}"
        );
        // a region with fewer than MIN_REGION_PX pixels gives nothing: a 2-column person
        let thin: Vec<u8> = (0..200u32)
            .map(|i| {
                if (2..4).contains(&(i % 10)) && i / 10 >= 16 {
                    7
                } else {
                    0
                }
            })
            .collect();
        let thin = Pixels::Where {
            mask: &thin,
            value: 7,
        };
        assert_eq!(region_means(&img, b, thin), None);
        // the filled set closes a hole: rows 6..8, columns 3..5 of the person are dark red and
        // missed by the mask; `Where` keeps columns 2 and 5 there (green), `Spans` all four
        let img2 = RgbImage::from_fn(10, 20, |x, y| {
            if person(x, y) && (6..8).contains(&y) && (3..5).contains(&x) {
                image::Rgb([100, 0, 0])
            } else {
                *img.get_pixel(x, y)
            }
        });
        let holed: Vec<u8> = (0..200u32)
            .map(|i| {
                let (x, y) = (i % 10, i / 10);
                u8::from(person(x, y) && !((6..8).contains(&y) && (3..5).contains(&x))) * 7
            })
            .collect();
        let (w, _) = region_means(
            &img2,
            b,
            Pixels::Where {
                mask: &holed,
                value: 7,
            },
        )
        .expect("w");
        assert_eq!(w[..3], [0.0, 200.0, 0.0], "the mask alone misses the red");
        let spans = Pixels::Spans {
            mask: &holed,
            value: 7,
        };
        let (f, px) = region_means(&img2, b, spans).expect("spans");
        // region 1 (rows 6..10, 16 pixels): 4 red, 12 green
        assert_eq!(f[..3], [25.0, 150.0, 0.0], "a quarter red");
        assert_eq!(f[3..], m[3..], "rows without a hole are as before");
        assert_eq!(px, 64, "the filled silhouette is the whole person");
        // another value of the mask is nobody here
        let other = Pixels::Where {
            mask: &mask,
            value: 3,
        };
        assert_eq!(region_means(&img, b, other), None);
    }
}

//! Re-identification, the session stage (seed 003 §IV–V, Zajdel et al.): the paper's 9-D
//! appearance feature of every person box in every frame, for the ground-truth boxes (local
//! tracks given, which isolates re-identification) and for the system's own local tracks
//! (the whole chain), cached per frame as the `reid_frames` table. `reid_report` groups them
//! into local tracks and runs the filter.
//!
//! The feature (paper fig. 4a): three horizontal regions of 25 % of the box height, with
//! "skip areas" of 12.5 %; the mean colour of each region. The text does not say where the
//! two skip areas lie; here they are the top (head) and the bottom (feet) of the box — the
//! parts with the least discriminative power — so the regions cover 12.5–37.5 %, 37.5–62.5 %
//! and 62.5–87.5 % of the height. The colour-channel-normalised space of the paper's [8] is
//! read as grey-world normalisation: each channel divided by its mean over the frame, which
//! cancels a change of illuminant per channel. The log of that ratio is the feature: the
//! paper's prior centres the kernels' means at a₀ = 0 with a spread of about 0.1 (κ₀ = 100,
//! C₀ = 10⁻³·I), which fits a space where the frame's average colour is 0 and a change of
//! light a shift, not ratios around 1. The raw variant (RGB / 255) is kept for the "without
//! colour normalisation" baseline.

use image::RgbImage;

use super::local_tracks::TrackRow;
use super::params::Params;
use super::shared::Frame;
use super::snapshots::Snapshots;
use crate::geometry::rect;
use crate::report::rows::Rows;
use crate::run::SessionTables;
use crate::table_row;

/// Name of the cached per-frame feature table.
pub(super) const FRAMES_TABLE: &str = "reid_frames";

/// The region bounds as fractions of the box height, top to bottom.
pub(super) const REGIONS: [(f64, f64); 3] = [(0.125, 0.375), (0.375, 0.625), (0.625, 0.875)];

table_row! {
    /// Cached per session: one box's features in one frame.
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
        /// The 9-D feature, ln of the grey-world ratio: region 1 r, g, b, region 2 r, g, b, …
        pub f1: f64, pub f2: f64, pub f3: f64, pub f4: f64, pub f5: f64,
        pub f6: f64, pub f7: f64, pub f8: f64, pub f9: f64,
        /// The same regions, raw RGB / 255.
        pub r1: f64, pub r2: f64, pub r3: f64, pub r4: f64, pub r5: f64,
        pub r6: f64, pub r7: f64, pub r8: f64, pub r9: f64,
    }
}

impl ReidFrameRow {
    pub(super) fn new(head: (i64, f64, &str, i64, Option<i64>), f: [f64; 9], r: [f64; 9]) -> Self {
        let (frame, t_s, source, id, truth_id) = head;
        ReidFrameRow {
            frame,
            t_s,
            source: source.to_string(),
            id,
            truth_id,
            f1: f[0],
            f2: f[1],
            f3: f[2],
            f4: f[3],
            f5: f[4],
            f6: f[5],
            f7: f[6],
            f8: f[7],
            f9: f[8],
            r1: r[0],
            r2: r[1],
            r3: r[2],
            r4: r[3],
            r5: r[4],
            r6: r[5],
            r7: r[6],
            r8: r[7],
            r9: r[8],
        }
    }

    /// The normalised (`raw = false`) or raw feature.
    pub fn feature(&self, raw: bool) -> [f64; 9] {
        if raw {
            [
                self.r1, self.r2, self.r3, self.r4, self.r5, self.r6, self.r7, self.r8, self.r9,
            ]
        } else {
            [
                self.f1, self.f2, self.f3, self.f4, self.f5, self.f6, self.f7, self.f8, self.f9,
            ]
        }
    }
}

/// Mean of each channel over the frame (grey world), never below 1 grey level.
fn channel_means(rgb: &RgbImage) -> [f64; 3] {
    let mut sum = [0u64; 3];
    for p in rgb.pixels() {
        for (acc, v) in sum.iter_mut().zip(p.0) {
            *acc += u64::from(v);
        }
    }
    let n = (u64::from(rgb.width()) * u64::from(rgb.height())).max(1) as f64;
    sum.map(|s| (s as f64 / n).max(1.0))
}

/// The three regions' mean RGB inside box `[x0, y0, x1, y1)` (pixels, clipped to the image),
/// raw 0..255; `None` when a region holds no pixel.
pub(super) fn region_means(rgb: &RgbImage, b: [f64; 4]) -> Option<[f64; 9]> {
    let (w, h) = (f64::from(rgb.width()), f64::from(rgb.height()));
    let x0 = b[0].max(0.0).floor() as u32;
    let x1 = b[2].min(w).ceil() as u32;
    if !(b.iter().all(|v| v.is_finite())) || x1 <= x0 || b[3] <= b[1] {
        return None;
    }
    let mut out = [0.0; 9];
    for (r, (top, bottom)) in REGIONS.iter().enumerate() {
        let y0 = (b[1] + top * (b[3] - b[1])).max(0.0).round() as u32;
        let y1 = (b[1] + bottom * (b[3] - b[1])).min(h).round() as u32;
        let mut sum = [0u64; 3];
        let mut n = 0u64;
        for y in y0..y1 {
            for x in x0..x1 {
                let p = rgb.get_pixel(x, y).0;
                for c in 0..3 {
                    sum[c] += u64::from(p[c]);
                }
                n += 1;
            }
        }
        if n == 0 {
            return None;
        }
        for c in 0..3 {
            out[3 * r + c] = sum[c] as f64 / n as f64;
        }
    }
    Some(out)
}

/// The re-identification features of one session.
pub(super) struct ReidRun {
    wanted: bool,
    camera: String,
    min_visibility: f64,
    min_iou: f64,
    rows: Vec<ReidFrameRow>,
    snapshots: Snapshots,
}

impl ReidRun {
    /// Features are computed only for the datasets `reid.datasets` names.
    pub fn new(p: &Params, dataset: &str) -> Self {
        Self {
            wanted: p.reid.datasets.iter().any(|d| d == dataset),
            camera: p.camera.clone(),
            min_visibility: p.reid.min_visibility,
            min_iou: p.local_eval.min_iou,
            rows: Vec::new(),
            snapshots: Snapshots::new(p.reid.snapshot_window_s),
        }
    }

    /// Features of the frame's ground-truth boxes and of the local tracks' boxes `tracks`.
    pub fn step(&mut self, f: &Frame, tracks: &[TrackRow]) {
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
            self.push(f, "truth", id, None, b, means);
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
            self.push(f, "system", t.track, truth_id, b, means);
            shown.push(("system", t.track, b));
        }
        self.snapshots.offer(f.index, f.t_s, f.rgb, &shown);
    }

    fn push(
        &mut self,
        f: &Frame,
        source: &str,
        id: i64,
        truth_id: Option<i64>,
        b: [f64; 4],
        means: [f64; 3],
    ) {
        if let Some(raw) = region_means(f.rgb, b) {
            self.rows.push(ReidFrameRow::new(
                (f.index, f.t_s, source, id, truth_id),
                std::array::from_fn(|i| (raw[i].max(1.0) / means[i % 3]).ln()),
                raw.map(|v| v / 255.0),
            ));
        }
    }

    /// The cached `reid_frames` table (only for the wanted datasets).
    pub fn finish(self, out: &mut SessionTables) -> anyhow::Result<()> {
        if self.wanted {
            out.insert(FRAMES_TABLE.into(), ReidFrameRow::frame(&self.rows)?);
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
        let m = region_means(&img, [0.0, 0.0, 8.0, 16.0]).expect("regions");
        // region 1: rows 2..6 (red); region 2: rows 6..10 (half red, half blue); region 3:
        // rows 10..14 (blue)
        assert_eq!(m, [200.0, 0.0, 0.0, 100.0, 0.0, 50.0, 0.0, 0.0, 100.0]);
        // grey world: the red channel's frame mean is 100, blue's 50 (green 0 → 1)
        assert_eq!(channel_means(&img), [100.0, 1.0, 50.0]);
        assert_eq!(region_means(&img, [4.0, 4.0, 4.0, 10.0]), None, "empty box");
        assert_eq!(region_means(&img, [0.0, f64::NAN, 8.0, 16.0]), None);
    }
}

//! Re-identification, the paper's figs. 5–6 (seed 003 §V): "selected frames … each frame shows
//! the estimated bounding box and estimated label of every detected person".
//!
//! The session stage keeps a few frames so that aggregation never re-opens the log: in every
//! window of `snapshot_window_s` seconds, the frame with the most ground-truth person boxes
//! (the earliest on a tie; windows without a person keep nothing), with the boxes of that
//! frame — ground-truth local tracks and the system's own. The report then picks four of them
//! per clip, evenly spread over the clip's snapshots that show a person of the clip, and draws
//! each box with the label the paper's model (ADF) gave its local track in that clip: the top
//! row on ground-truth local tracks (`#label (person p)`: the estimate beside the truth), the
//! bottom row on the system's local tracks (`#label`, or `–` for a track that is no
//! observation of the clip: too short, or ended after it). Fig. 5 is the first clip, fig. 6
//! the second, as in the paper (clip 1: places lit alike; clip 2: across light).

use image::RgbImage;
use polars::prelude::Column;

use super::params::{ClipParams, ReidParams};
use super::reid::{FRAMES_TABLE, ReidFrameRow};
use super::reid_report::{Method, Observation, in_clip, labels, observations};
use crate::report::Figure;
use crate::report::columns::{i64s, image_table, read_image_table};
use crate::report::figure::{FigureKind, ImageOverlay, Overlay};
use crate::report::rows::Rows;
use crate::run::{Aggregate, Products, SessionTables};
use crate::table_row;

/// Name of the cached table of every kept frame's boxes.
const BOXES_TABLE: &str = "reid_snapshot_boxes";
/// Prefix of the cached snapshot images, `reid_snapshot_0`, `_1`, ….
const IMAGE_PREFIX: &str = "reid_snapshot_";
/// Frames drawn per clip (the paper shows four).
const PER_CLIP: usize = 4;

table_row! {
    /// One box of a kept frame.
    #[derive(Debug, Clone, PartialEq)]
    pub(super) struct SnapshotBox {
        pub frame: i64,
        pub t_s: f64,
        /// `truth` or `system`, as in `reid_frames`.
        pub source: String,
        /// The person id (truth) or the track id (system).
        pub id: i64,
        pub x0: f64,
        pub y0: f64,
        pub x1: f64,
        pub y1: f64,
    }
}

/// A frame offered for keeping.
struct Candidate {
    window: i64,
    frame: i64,
    people: usize,
    image: RgbImage,
    boxes: Vec<SnapshotBox>,
}

/// The session side: the best frame of each window.
pub(super) struct Snapshots {
    window_s: f64,
    best: Option<Candidate>,
    kept: Vec<Candidate>,
}

impl Snapshots {
    pub fn new(window_s: f64) -> Self {
        Self {
            window_s,
            best: None,
            kept: Vec::new(),
        }
    }

    /// Offers frame `frame` at `t_s` with its boxes `(source, id, [x0, y0, x1, y1])`; the image
    /// is copied only when the frame becomes its window's best.
    pub fn offer(&mut self, frame: i64, t_s: f64, rgb: &RgbImage, boxes: &[(&str, i64, [f64; 4])]) {
        let people = boxes.iter().filter(|b| b.0 == "truth").count();
        if people == 0 || !t_s.is_finite() || self.window_s <= 0.0 {
            return;
        }
        let window = (t_s / self.window_s).floor() as i64;
        if self.best.as_ref().is_some_and(|b| b.window != window) {
            self.kept.extend(self.best.take());
        }
        if self.best.as_ref().is_some_and(|b| b.people >= people) {
            return;
        }
        let boxes = boxes
            .iter()
            .map(|&(source, id, b)| SnapshotBox {
                frame,
                t_s,
                source: source.to_string(),
                id,
                x0: b[0],
                y0: b[1],
                x1: b[2],
                y1: b[3],
            })
            .collect();
        self.best = Some(Candidate {
            window,
            frame,
            people,
            image: rgb.clone(),
            boxes,
        });
    }

    /// The frames kept, in order.
    fn frames(mut self) -> Vec<Candidate> {
        self.kept.extend(self.best.take());
        self.kept
    }

    /// The cached tables: every kept frame's boxes and images.
    pub fn finish(self, out: &mut SessionTables) -> anyhow::Result<()> {
        let kept = self.frames();
        let boxes: Vec<SnapshotBox> = kept.iter().flat_map(|c| c.boxes.clone()).collect();
        out.insert(BOXES_TABLE.into(), SnapshotBox::frame(&boxes)?);
        for (k, c) in kept.iter().enumerate() {
            let mut df = image_table(&c.image)?;
            df.with_column(Column::new("frame".into(), [c.frame]))?;
            out.insert(format!("{IMAGE_PREFIX}{k}"), df);
        }
        Ok(())
    }
}

/// `n` of `len` indices spread evenly, first and last included (all of them when `len ≤ n`).
pub(super) fn spread(len: usize, n: usize) -> Vec<usize> {
    if len <= n {
        return (0..len).collect();
    }
    if n == 1 {
        return vec![0];
    }
    (0..n)
        .map(|i| (i * (len - 1) + (n - 1) / 2) / (n - 1))
        .collect()
}

/// The observation of `source` (in the clip's list `obs`) that holds box `b`, and its label
/// (1-based, as `track::reid` numbers people).
fn label_of<'a>(
    obs: &'a [&Observation],
    est: &[usize],
    b: &SnapshotBox,
) -> Option<(&'a Observation, usize)> {
    obs.iter()
        .zip(est)
        .find(|(o, _)| o.id == b.id && o.span.enter <= b.t_s && b.t_s <= o.span.leave)
        .map(|(o, l)| (*o, *l))
}

/// The shapes of one tile: the boxes of `source` at offset `(dx, dy)`, labelled.
fn tile_shapes(
    boxes: &[&SnapshotBox],
    source: &str,
    obs: &[&Observation],
    est: &[usize],
    (dx, dy): (f64, f64),
) -> Vec<Overlay> {
    boxes
        .iter()
        .filter(|b| b.source == source)
        .map(|b| {
            let (label, color) = match label_of(obs, est, b) {
                Some((o, l)) if source == "truth" => {
                    (format!("#{l} (person {})", o.truth.unwrap_or(b.id)), l)
                }
                Some((_, l)) => (format!("#{l}"), l),
                None => ("–".to_string(), 7),
            };
            Overlay::Box {
                x0: b.x0 + dx,
                y0: b.y0 + dy,
                x1: b.x1 + dx,
                y1: b.y1 + dy,
                label,
                color,
            }
        })
        .collect()
}

/// One clip's figure: `PER_CLIP` kept frames side by side, ground-truth local tracks on top,
/// the system's below; `None` when no kept frame shows a person of the clip.
fn clip_figure(
    tiles: &[(i64, RgbImage)],
    boxes: &[SnapshotBox],
    rows: &[ReidFrameRow],
    (clip, number): (&ClipParams, usize),
    p: &ReidParams,
) -> anyhow::Result<Option<Figure>> {
    let mut per_source = Vec::new();
    for source in ["truth", "system"] {
        let all = observations(rows, source, p);
        let obs: Vec<&Observation> = all.iter().filter(|o| in_clip(o, clip)).collect();
        let est = labels(&obs, Method::Paper, p)?;
        per_source.push((source, obs.into_iter().cloned().collect::<Vec<_>>(), est));
    }
    let (_, truth_obs, truth_est) = &per_source[0];
    let truth_refs: Vec<&Observation> = truth_obs.iter().collect();
    // frames showing a ground-truth local track of the clip
    let usable: Vec<&(i64, RgbImage)> = tiles
        .iter()
        .filter(|(f, _)| {
            boxes.iter().any(|b| {
                b.frame == *f
                    && b.source == "truth"
                    && label_of(&truth_refs, truth_est, b).is_some()
            })
        })
        .collect();
    let chosen: Vec<&(i64, RgbImage)> = spread(usable.len(), PER_CLIP)
        .into_iter()
        .map(|i| usable[i])
        .collect();
    let Some((_, first)) = chosen.first() else {
        return Ok(None);
    };
    let (w, h) = first.dimensions();
    if chosen.iter().any(|(_, t)| t.dimensions() != (w, h)) {
        anyhow::bail!("re-identification snapshots differ in size");
    }
    let mut img = RgbImage::new(w * chosen.len() as u32, 2 * h);
    let mut shapes = Vec::new();
    for (k, (f, tile)) in chosen.iter().enumerate() {
        let frame_boxes: Vec<&SnapshotBox> = boxes.iter().filter(|b| b.frame == *f).collect();
        for (row, (source, obs, est)) in per_source.iter().enumerate() {
            image::imageops::replace(
                &mut img,
                tile,
                i64::from(w) * k as i64,
                i64::from(h) * row as i64,
            );
            let refs: Vec<&Observation> = obs.iter().collect();
            let offset = (f64::from(w) * k as f64, f64::from(h) * row as f64);
            shapes.extend(tile_shapes(&frame_boxes, source, &refs, est, offset));
        }
    }
    let frames: Vec<String> = chosen.iter().map(|(f, _)| f.to_string()).collect();
    Ok(Some(Figure::new(
        format!("reid_fig{number}_frames"),
        format!(
            "Fig. {number} ({}), frames {}: the model's labels; top: true tracks (#label (person)), bottom: own tracks",
            clip.name,
            frames.join(", ")
        ),
        FigureKind::Overlay(ImageOverlay { image: img, shapes }),
    )))
}

/// Figs. 5 and 6 for the first re-identified session (the paper's two clips: the first two
/// clips of `[params.reid]`).
pub(super) fn products(
    ctx: &Aggregate,
    p: &ReidParams,
    products: &mut Products,
) -> anyhow::Result<()> {
    let Some(tables) = ctx
        .sessions
        .iter()
        .find_map(|(_, t)| t.get(FRAMES_TABLE).map(|_| t))
    else {
        return Ok(());
    };
    let (Some(frames), Some(boxes)) = (tables.get(FRAMES_TABLE), tables.get(BOXES_TABLE)) else {
        return Ok(());
    };
    let rows = ReidFrameRow::read(frames)?;
    let boxes = SnapshotBox::read(boxes)?;
    let mut tiles = Vec::new();
    for k in 0.. {
        let Some(t) = tables.get(&format!("{IMAGE_PREFIX}{k}")) else {
            break;
        };
        let f = i64s(t, "frame")?.first().copied().unwrap_or(-1);
        tiles.push((f, read_image_table(t)?));
    }
    for (i, clip) in p.clips.iter().take(2).enumerate() {
        if let Some(fig) = clip_figure(&tiles, &boxes, &rows, (clip, 5 + i), p)? {
            products.figures.push(fig);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spread_takes_first_last_and_evenly_between() {
        assert_eq!(spread(3, 4), [0, 1, 2]);
        assert_eq!(spread(4, 4), [0, 1, 2, 3]);
        assert_eq!(spread(7, 4), [0, 2, 4, 6]);
        assert_eq!(spread(10, 4), [0, 3, 6, 9]);
        assert_eq!(spread(5, 1), [0]);
        assert_eq!(spread(0, 4), Vec::<usize>::new());
    }

    #[test]
    fn each_window_keeps_its_frame_with_the_most_people() {
        let img = RgbImage::new(2, 2);
        let one = [("truth", 1, [0.0, 0.0, 1.0, 1.0])];
        let two = [
            ("truth", 1, [0.0, 0.0, 1.0, 1.0]),
            ("truth", 2, [0.0, 0.0, 1.0, 1.0]),
            ("system", 9, [0.0, 0.0, 1.0, 1.0]),
        ];
        let none = [("system", 9, [0.0, 0.0, 1.0, 1.0])];
        let mut s = Snapshots::new(10.0);
        s.offer(0, 1.0, &img, &one);
        s.offer(1, 2.0, &img, &two);
        s.offer(2, 3.0, &img, &two); // a tie: the earlier frame stays
        s.offer(3, 12.0, &img, &none); // no person: nothing kept
        s.offer(4, 25.0, &img, &one);
        s.offer(5, f64::NAN, &img, &two);
        let kept: Vec<(i64, usize, usize)> = s
            .frames()
            .iter()
            .map(|c| (c.frame, c.people, c.boxes.len()))
            .collect();
        assert_eq!(kept, [(1, 2, 3), (4, 1, 1)]);
    }
}

//! Re-identification, the paper's figs. 5–6 (seed 003 §V): "selected frames … each frame shows
//! the estimated bounding box and estimated label of every detected person".
//!
//! The session stage keeps a few frames with their boxes (`snapshots`: per window of
//! `snapshot_window_s` seconds, the frame with the most people). The report picks four of them
//! per clip, evenly spread over the clip's snapshots that show a person of the clip, and draws
//! each box with the label the paper's model (ADF) gave its local track in that clip: the top
//! row on ground-truth local tracks (`#label (person p)`: the estimate beside the truth), the
//! bottom row on the system's local tracks (`#label`, or `–` for a track that is no
//! observation of the clip: too short, ended after it, or no frame gave its person's pixels).
//! Fig. 5 is the first clip, fig. 6 the second, as in the paper (clip 1: places lit alike;
//! clip 2: across light).

use image::RgbImage;

use super::params::{ClipParams, ReidParams};
use super::reid::{FRAMES_TABLE, ReidFrameRow};
use super::reid_features::{Observation, observations};
use super::reid_methods::{PAPER, Training, labels};
use super::reid_report::in_clip;
use super::snapshots::{BOXES_TABLE, IMAGE_PREFIX, SnapshotBox};
use crate::report::Figure;
use crate::report::columns::{i64s, read_image_table};
use crate::report::figure::{FigureKind, ImageOverlay, Overlay};
use crate::report::rows::Rows;
use crate::run::{Aggregate, Products};

/// Frames drawn per clip (the paper shows four).
const PER_CLIP: usize = 4;

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
        let obs: Vec<&Observation> = all
            .iter()
            .filter(|o| in_clip(o, clip) && o.feature(PAPER.feature).is_some())
            .collect();
        let est = labels(&obs, &PAPER, p.nn_threshold, &Training::default())?.unwrap_or_default();
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

/// Figs. 5 and 6 for the first scored session (the paper's two clips: the first two
/// clips of `[params.reid]`).
pub(super) fn products(
    ctx: &Aggregate,
    p: &ReidParams,
    products: &mut Products,
) -> anyhow::Result<()> {
    let Some(tables) = ctx
        .sessions
        .iter()
        .filter(|(info, _)| p.datasets.contains(&info.dataset))
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
}

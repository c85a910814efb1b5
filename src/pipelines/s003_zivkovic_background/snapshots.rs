//! The frames figs. 5–6 draw, kept by the session stage so that aggregation never re-opens the
//! log: in every window of `snapshot_window_s` seconds, the frame with the most ground-truth
//! person boxes (the earliest on a tie; windows without a person keep nothing), with that
//! frame's boxes — ground-truth local tracks and the system's own. `reid_snapshots` draws them.

use image::RgbImage;
use polars::prelude::Column;

use crate::report::columns::image_table;
use crate::report::rows::Rows;
use crate::run::SessionTables;
use crate::table_row;

/// Name of the cached table of every kept frame's boxes.
pub(super) const BOXES_TABLE: &str = "reid_snapshot_boxes";
/// Prefix of the cached snapshot images, `reid_snapshot_0`, `_1`, ….
pub(super) const IMAGE_PREFIX: &str = "reid_snapshot_";
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

#[cfg(test)]
mod tests {
    use super::*;

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

//! Moving-camera detection (seed 003, Zajdel et al. §III-B), scored: on every frame where the
//! camera rides a moving robot, `vision::moving` tracks corners, fits a RANSAC fundamental
//! matrix and turns the outliers into objects; the detector forgets everything when the robot
//! stops. Per session one row: how many corners were tracked and found moving, how many of the
//! moving points lie on a person (inside a ground-truth box), how many visible people got at
//! least one, and the objects' boxes (± `box_sigma` standard deviations of their points)
//! matched one-to-one to the ground-truth boxes at IoU ≥ `local_eval.min_iou`. Table
//! `moving_detection`. It measures the paper's detector alone; the local tracker does not use
//! it (it hands tracks to the colour tracker while the camera moves).

use image::imageops::grayscale;

use super::params::{MovingDetectParams, Params};
use super::shared::Frame;
use crate::assign::max_score_pairs;
use crate::geometry::rect;
use crate::report::Table;
use crate::report::rows::Rows;
use crate::run::{Aggregate, Products, SessionTables};
use crate::table_row;
use crate::vision::moving::{MovingDetector, MovingFrame};

pub(super) const TABLE: &str = "moving_detection";

table_row! {
    /// One session's moving-camera detection counts.
    #[derive(Debug, Clone, Default, PartialEq)]
    pub(super) struct MovingRow {
        pub dataset: String,
        pub session: String,
        /// Frames with the camera moving (the first after a stop has no pairs yet).
        pub moving_frames: i64,
        /// Frames with a fundamental matrix (≥ 8 tracked pairs, non-degenerate).
        pub fitted_frames: i64,
        pub pairs: i64,
        pub moving_points: i64,
        /// Moving points inside a ground-truth person box.
        pub moving_on_person: i64,
        /// Tracked pairs inside a ground-truth person box (moving or not).
        pub pairs_on_person: i64,
        /// Visible ground-truth people over the moving frames, and those holding a moving point.
        pub people: i64,
        pub people_with_moving_point: i64,
        pub objects: i64,
        pub objects_matched: i64,
    }
}

/// The session side.
pub(super) struct MovingRun {
    detector: MovingDetector,
    camera: String,
    min_visibility: f64,
    min_iou: f64,
    box_sigma: f64,
    active: bool,
    row: MovingRow,
}

impl MovingRun {
    /// Runs only where the camera rides the robot (`rides`).
    pub fn new(p: &Params, m: &MovingDetectParams, rides: bool) -> Self {
        Self {
            detector: MovingDetector::new(m.detector()),
            camera: p.camera.clone(),
            min_visibility: p.reid.min_visibility,
            min_iou: p.local_eval.min_iou,
            box_sigma: m.box_sigma,
            active: rides,
            row: MovingRow::default(),
        }
    }

    pub fn step(&mut self, f: &Frame) {
        if !self.active {
            return;
        }
        if !f.moving {
            self.detector.reset();
            return;
        }
        let out = self.detector.step(&grayscale(f.rgb));
        let truth: Vec<[f64; 4]> = f
            .truth
            .iter()
            .flat_map(|fr| &fr.people)
            .flat_map(|person| &person.cameras)
            .filter(|v| v.camera == self.camera && v.visibility >= self.min_visibility)
            .filter_map(|v| v.bbox) // right and bottom exclusive, as logged
            .collect();
        self.count(&out, &truth);
    }

    fn count(&mut self, out: &MovingFrame, truth: &[[f64; 4]]) {
        let inside = |b: &[f64; 4], x: f64, y: f64| b[0] <= x && x < b[2] && b[1] <= y && y < b[3];
        let on_person = |x: f64, y: f64| truth.iter().any(|b| inside(b, x, y));
        let r = &mut self.row;
        r.moving_frames += 1;
        r.fitted_frames += i64::from(out.fitted);
        r.pairs += out.pairs.len() as i64;
        for (pair, m) in out.pairs.iter().zip(&out.moving) {
            let on = on_person(pair.1[0], pair.1[1]);
            r.pairs_on_person += i64::from(on);
            r.moving_points += i64::from(*m);
            r.moving_on_person += i64::from(*m && on);
        }
        let moving = out.moving_points();
        r.people += truth.len() as i64;
        r.people_with_moving_point += truth
            .iter()
            .filter(|b| moving.iter().any(|p| inside(b, p.x, p.y)))
            .count() as i64;
        let boxes: Vec<[f64; 4]> = out
            .objects
            .iter()
            .map(|o| o.ellipse.bbox(self.box_sigma))
            .collect();
        r.objects += boxes.len() as i64;
        let pairs = max_score_pairs(boxes.len(), truth.len(), |i, j| {
            let o = rect::iou(&boxes[i], &truth[j]);
            if o >= self.min_iou { o } else { 0.0 }
        });
        r.objects_matched += pairs.len() as i64;
    }

    /// The cached one-row table (sessions whose camera rides the robot only).
    pub fn finish(
        mut self,
        dataset: &str,
        session: &str,
        out: &mut SessionTables,
    ) -> anyhow::Result<()> {
        if self.active {
            self.row.dataset = dataset.to_string();
            self.row.session = session.to_string();
            out.insert(TABLE.into(), MovingRow::frame(&[self.row])?);
        }
        Ok(())
    }
}

fn ratio(a: i64, b: i64) -> Option<f64> {
    (b > 0).then(|| a as f64 / b as f64)
}

table_row! {
    /// The report's row: the counts and their ratios.
    #[derive(Debug, Clone, PartialEq)]
    struct MovingReportRow {
        dataset: String,
        session: String,
        moving_frames: i64,
        fitted_frames: i64,
        pairs_per_frame: Option<f64>,
        moving_per_frame: Option<f64>,
        /// Moving points on a person / moving points.
        point_precision: Option<f64>,
        /// Share of all tracked pairs on a person (what chance would give).
        pairs_on_person_share: Option<f64>,
        /// Visible people holding a moving point / visible people.
        people_hit: Option<f64>,
        /// Matched objects / objects, and / visible people.
        detection_precision: Option<f64>,
        detection_recall: Option<f64>,
    }
}

pub(super) fn products(ctx: &Aggregate, p: &Params, products: &mut Products) -> anyhow::Result<()> {
    let mut rows = Vec::new();
    for (_, tables) in ctx.sessions {
        let Some(df) = tables.get(TABLE) else {
            continue;
        };
        for r in MovingRow::read(df)? {
            rows.push(MovingReportRow {
                pairs_per_frame: ratio(r.pairs, r.moving_frames),
                moving_per_frame: ratio(r.moving_points, r.moving_frames),
                point_precision: ratio(r.moving_on_person, r.moving_points),
                pairs_on_person_share: ratio(r.pairs_on_person, r.pairs),
                people_hit: ratio(r.people_with_moving_point, r.people),
                detection_precision: ratio(r.objects_matched, r.objects),
                detection_recall: ratio(r.objects_matched, r.people),
                dataset: r.dataset,
                session: r.session,
                moving_frames: r.moving_frames,
                fitted_frames: r.fitted_frames,
            });
        }
    }
    if rows.is_empty() {
        return Ok(());
    }
    let m = &p.moving;
    let mut table = Table::new(
        TABLE,
        "Moving-camera detection (Zajdel et al. §III-B): KLT corners, RANSAC fundamental matrix, the outliers as moving people",
        MovingReportRow::frame(&rows)?,
    )
    .with_note(format!(
        "Frames where odometry says the robot moves, camera on the robot. {} corners, min distance {} px, Sampson threshold {} px, {} RANSAC draws; objects: mean shift with the previous covariance, ≥ {} moving points within {}σ, new ones from single-link groups within {} px; boxes ±{:.3}σ, matched at IoU ≥ {}. point_precision = moving points inside a ground-truth box / moving points (pairs_on_person_share is that share among all tracked corners: chance); people_hit = visible people (visibility ≥ {}) holding a moving point. The detector is measured alone: local tracks do not use it.",
        m.corners, m.min_distance_px, m.ransac_threshold_px, m.ransac_iterations, m.min_points, m.gate_sigma, m.cluster_px, m.box_sigma, p.local_eval.min_iou, p.reid.min_visibility
    ));
    for c in [
        "pairs_per_frame",
        "moving_per_frame",
        "point_precision",
        "pairs_on_person_share",
        "people_hit",
        "detection_precision",
        "detection_recall",
    ] {
        table = table.with_precision(c, 3);
    }
    products.tables.push(table);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vision::ellipse::Ellipse;
    use crate::vision::moving::MovingObject;

    #[test]
    fn counts_points_people_and_matched_objects() {
        let p = Params::default();
        let mut run = MovingRun::new(&p, &MovingDetectParams::default(), true);
        let frame = MovingFrame {
            pairs: vec![
                ([0.0, 0.0], [12.0, 12.0]), // on person A, moving
                ([0.0, 0.0], [14.0, 30.0]), // on person A, still
                ([0.0, 0.0], [80.0, 80.0]), // on nobody, moving
            ],
            moving: vec![true, false, true],
            fitted: true,
            objects: vec![
                MovingObject {
                    id: 0,
                    // ±√3σ box = [10, 10, 30, 50]: person A's box exactly
                    ellipse: Ellipse::from_parts(20.0, 30.0, 100.0 / 3.0, 0.0, 400.0 / 3.0),
                    points: 3,
                },
                MovingObject {
                    id: 1,
                    ellipse: Ellipse::from_parts(80.0, 80.0, 4.0, 0.0, 4.0),
                    points: 3,
                },
            ],
        };
        let truth = [[10.0, 10.0, 30.0, 50.0], [100.0, 10.0, 120.0, 50.0]];
        run.count(&frame, &truth);
        let r = &run.row;
        assert_eq!(
            (r.moving_frames, r.fitted_frames, r.pairs, r.moving_points),
            (1, 1, 3, 2)
        );
        assert_eq!((r.moving_on_person, r.pairs_on_person), (1, 2));
        assert_eq!((r.people, r.people_with_moving_point), (2, 1));
        assert_eq!((r.objects, r.objects_matched), (2, 1));
    }
}

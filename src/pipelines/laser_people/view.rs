//! What the top views and the marker export need beyond the scores, collected by the session
//! stage and cached with its tables (so the aggregation reads only cached tables):
//!
//! - `poses`: per scan, the laser's frame id (as the scan's header names it, without a leading
//!   `/`) and its pose in the fixed frame (none when TF could not place the scan);
//! - `points`: the returns of a sample of the scored scans in the fixed frame, rounded to 1 cm
//!   — at most [`MAX_POINT_SCANS`] scans, evenly spaced: every scored scan is kept at first,
//!   and whenever more than the budget are kept the spacing doubles and every other kept scan
//!   is dropped (so the sample does not depend on knowing the scan count in advance, and is
//!   the same for the same log).

use super::tables::{self};
use crate::frames::laser::LaserFrame;
use crate::laser::points::ScanPoint;
use crate::report::rows::Rows;
use crate::run::SessionTables;
use crate::table_row;

pub const POSES: &str = "poses";
pub const POINTS: &str = "points";

/// At most this many scans' returns are cached for the top view (between half and all of it
/// is used, see the module doc).
pub const MAX_POINT_SCANS: usize = 40;

table_row! {
    /// The laser on one scan: `poses`. `x`, `y` (m) and `yaw` (rad) in the fixed frame.
    #[derive(Debug, Clone, PartialEq)]
    pub struct PoseRow {
        pub scan_idx: i64,
        pub frame_id: String,
        pub x: Option<f64>,
        pub y: Option<f64>,
        pub yaw: Option<f64>,
    }
}

table_row! {
    /// One return of a sampled scan in the fixed frame (m, rounded to 1 cm): `points`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct PointRow {
        pub scan_idx: i64,
        pub x: f64,
        pub y: f64,
    }
}

/// Collects the two tables over a session's scans.
#[derive(Debug, Default)]
pub struct Collector {
    /// The scored scans (`None`: all).
    window: Option<[i64; 2]>,
    /// Scored scans seen so far.
    seen: usize,
    /// Keep scored scan number `k` when `k % stride == 0`.
    stride: usize,
    poses: Vec<PoseRow>,
    /// `(k, its points)` of the kept scans.
    kept: Vec<(usize, Vec<PointRow>)>,
}

fn cm(v: f64) -> f64 {
    (v * 100.0).round() / 100.0
}

impl Collector {
    /// Over the scored scans `window` (`None`: all; [`super::params::Sequence::scans`]).
    pub fn new(window: Option<[i64; 2]>) -> Collector {
        Collector {
            window,
            stride: 1,
            ..Collector::default()
        }
    }

    /// Scan `idx` and its returns.
    pub fn observe(&mut self, idx: i64, f: &LaserFrame, points: &[ScanPoint]) {
        let pose = f.pose.as_ref();
        self.poses.push(PoseRow {
            scan_idx: idx,
            frame_id: f.frame.clone(),
            x: pose.map(|p| p.translation.x),
            y: pose.map(|p| p.translation.y),
            yaw: pose.map(|p| p.rotation.euler_angles().2),
        });
        if !self.window.is_none_or(|[a, b]| idx >= a && idx <= b) {
            return;
        }
        let k = self.seen;
        self.seen += 1;
        if !k.is_multiple_of(self.stride.max(1)) {
            return;
        }
        let rows = points
            .iter()
            .filter(|q| q.fixed.x.is_finite() && q.fixed.y.is_finite())
            .map(|q| PointRow {
                scan_idx: idx,
                x: cm(q.fixed.x),
                y: cm(q.fixed.y),
            })
            .collect();
        self.kept.push((k, rows));
        while self.kept.len() > MAX_POINT_SCANS {
            self.stride = self.stride.max(1) * 2;
            let stride = self.stride;
            self.kept.retain(|(k, _)| k % stride == 0);
        }
    }

    /// The scan indices whose returns are kept, in order.
    #[cfg(test)]
    fn kept_scans(&self) -> Vec<i64> {
        self.kept
            .iter()
            .filter_map(|(_, r)| r.first().map(|p| p.scan_idx))
            .collect()
    }

    /// Add the `poses` and `points` tables.
    pub fn into_tables(self, t: &mut SessionTables) -> anyhow::Result<()> {
        let points: Vec<PointRow> = self.kept.into_iter().flat_map(|(_, r)| r).collect();
        t.insert(POSES.into(), PoseRow::frame(&self.poses)?);
        t.insert(POINTS.into(), PointRow::frame(&points)?);
        Ok(())
    }
}

/// The cached `poses` and `points` of one session.
pub fn read(t: &SessionTables, label: &str) -> anyhow::Result<(Vec<PoseRow>, Vec<PointRow>)> {
    Ok((
        tables::read(t, POSES, label)?,
        tables::read(t, POINTS, label)?,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::log::msgs::LaserScan;
    use crate::time::Nanos;
    use nalgebra::Point2;

    fn frame() -> LaserFrame {
        LaserFrame {
            stamp: Nanos(0),
            log_time: Nanos(0),
            frame: "laser".into(),
            scan: LaserScan::default(),
            no_return: vec![],
            pose: None,
        }
    }

    fn point(x: f64) -> ScanPoint {
        ScanPoint {
            beam: 0,
            range: x,
            angle: 0.0,
            sensor: Point2::new(x, 0.0),
            fixed: Point2::new(x, 0.0),
        }
    }

    /// 100 scored scans (10..=109 of 0..120): the budget of 40 is crossed at the 41st, 81st
    /// scan …, so the stride ends at 4 and the kept scans are 10, 14, …, 106 (25 of them); every
    /// scan has a pose row; returns are rounded to 1 cm.
    #[test]
    fn the_sample_halves_evenly_and_stays_within_its_budget() {
        let mut c = Collector::new(Some([10, 109]));
        let f = frame();
        for idx in 0..120 {
            c.observe(idx, &f, &[point(1.234_56)]);
        }
        let want: Vec<i64> = (0..25).map(|i| 10 + 4 * i).collect();
        assert_eq!(c.kept_scans(), want);
        assert_eq!(c.poses.len(), 120);
        assert_eq!(c.poses[3].x, None);
        assert_eq!(c.kept[0].1[0].x, 1.23);
    }
}

//! The per-session stage: every scan of the sequence's laser topic through the leg model of
//! [`crate::laser`] and every method, the ground truth placed on its scans, all in the laser
//! frame; the rows of [`super::tables`].
//!
//! - **Scans** come from [`frames::laser::scans`] with the sensor pose at the scan stamp in the
//!   fixed frame (`odom` when TF has it; the synthetic logs' `map`, their ground truth's frame;
//!   the sensor frame without TF). Scan indices count the decoded scans in log order.
//! - **Methods** ([`super::methods`], the pipeline's `methods` in order): each turns the scan
//!   into fixed-frame hypotheses, put back into the laser frame through the inverse pose.
//! - **Ground truth**: `leg_tracker/msg/Person` messages (real logs) are already in the laser
//!   frame and belong to the last scan logged before them (the README's and `clear_mot.py`'s
//!   rule); synthetic `/ground_truth/people` frames (map frame) are joined to a scan by nearest
//!   stamp and put into the laser frame through the inverse of the scan's `map` pose.

use nalgebra::{Isometry3, Point2};

use super::methods::{Method, Runner, ScanView, to_laser};
use super::params::{Params, Sequence};
use super::tables::{self, ScanRow, SessionRow, TrackRow, TruthRow};
use super::view;
use crate::frames::laser::{self as laser_frames, LaserFrame, LaserOptions};
use crate::frames::{Skips, truth};
use crate::laser::scan_match::{MAX_FAILED_SHARE, MatchParams, Pose2, ScanOdometry, static_mask};
use crate::log::SessionLog;
use crate::log::decode::carries;
use crate::progress::Progress;
use crate::report::rows::Rows;
use crate::run::{Session, SessionTables};
use crate::time::Nanos;

/// The ROS 2 type of the real logs' annotations.
pub const PERSON_TYPE: &str = "leg_tracker/msg/Person";

/// Where a session's ground truth comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum GtKind {
    LegTracker,
    Synthetic,
    None,
}

impl GtKind {
    fn of(log: &SessionLog, topic: &str) -> GtKind {
        match log.summary().channel(topic) {
            None => GtKind::None,
            Some(ch) if carries(ch, PERSON_TYPE) => GtKind::LegTracker,
            Some(_) => GtKind::Synthetic,
        }
    }

    fn name(self) -> &'static str {
        match self {
            GtKind::LegTracker => "leg_tracker",
            GtKind::Synthetic => "synthetic",
            GtKind::None => "none",
        }
    }
}

/// Everything the scan loop collects.
#[derive(Default)]
struct Collected {
    scans: Vec<ScanRow>,
    truth: Vec<TruthRow>,
    tracks: Vec<TrackRow>,
    gt_dropped: i64,
    /// Poses and sampled returns for the figures and markers.
    view: view::Collector,
}

/// The free-space methods' pose source for a session: the log's TF where the sequence lets
/// the methods see it, the scan has a pose and that pose is motion (the fixed frame is not the
/// scan's own frame), else scan matching (only when a free-space method runs); with, for the
/// sessions whose TF was withheld, the true and matched poses by time for the relative pose
/// error.
struct Odometry {
    matcher: Option<ScanOdometry>,
    withhold: bool,
    /// The fixed frame is the scan's own frame (a log without `odom`/`map`): every TF pose is
    /// the identity, which says nothing about motion, so the free-space methods scan-match.
    sensor_frame: bool,
    /// (time s, true pose, matched pose).
    trace: Vec<(f64, Pose2, Pose2)>,
}

impl Odometry {
    fn pose(&mut self, f: &LaserFrame, view: &ScanView, time_s: f64) -> Option<Isometry3<f64>> {
        if let (false, false, Some(p)) = (self.withhold, self.sensor_frame, f.pose) {
            return Some(p);
        }
        let Some(m) = self.matcher.as_mut() else {
            return f.pose.filter(|_| !self.withhold);
        };
        let keep = static_mask(&view.points, &view.segments, &view.geometric, &m.params);
        let est = m.step(&view.points, &keep);
        if let Some(truth) = f.pose.filter(|_| !self.sensor_frame) {
            self.trace
                .push((time_s, Pose2::of(&truth), Pose2::of(&est)));
        }
        Some(est)
    }

    /// The mean relative pose error over 1 s windows (m, degrees); NaN without a trace.
    fn rpe(&self) -> (f64, f64) {
        let mut sum = (0.0, 0.0, 0usize);
        let mut j = 0;
        for (i, (t, truth, est)) in self.trace.iter().enumerate() {
            while j < i && self.trace[j + 1].0 <= t - RPE_WINDOW_S {
                j += 1;
            }
            let (t0, truth0, est0) = &self.trace[j];
            if t - t0 < RPE_WINDOW_S {
                continue;
            }
            let a = truth0.inverse().compose(truth);
            let b = est0.inverse().compose(est);
            let e = a.inverse().compose(&b);
            sum.0 += e.x.hypot(e.y);
            sum.1 += e.theta.abs().to_degrees();
            sum.2 += 1;
        }
        if sum.2 == 0 {
            (f64::NAN, f64::NAN)
        } else {
            (sum.0 / sum.2 as f64, sum.1 / sum.2 as f64)
        }
    }
}

/// For a log whose fixed frame is the scan's own frame (no odometry): whether scan matching
/// is fit to give the free-space methods their odometry — a first pass over the scans, failing
/// on at most [`MAX_FAILED_SHARE`] of them — with the failures and scans counted. `None` when
/// the log has a fixed frame of its own (its TF is the odometry).
fn scan_match_fit(
    log: &SessionLog,
    topic: &str,
    options: &LaserOptions,
) -> anyhow::Result<Option<(bool, u64, u64)>> {
    let mut frames = laser_frames::scans(log, topic, options)?;
    let mut matcher = ScanOdometry::new(MatchParams::default());
    let mut scans = 0u64;
    while let Some(f) = frames.next() {
        let f = f?;
        if frames.fixed_frame() != Some(f.frame.as_str()) {
            return Ok(None);
        }
        let view = ScanView::new(&f, None);
        let keep = static_mask(
            &view.points,
            &view.segments,
            &view.geometric,
            &matcher.params,
        );
        matcher.step(&view.points, &keep);
        scans += 1;
    }
    let failed = matcher.failures();
    let fit = scans > 0 && failed as f64 <= MAX_FAILED_SHARE * scans as f64;
    Ok(Some((fit, failed, scans)))
}

/// Window of the relative pose error (s).
const RPE_WINDOW_S: f64 = 1.0;

fn track_row(
    detector: &str,
    idx: i64,
    id: i64,
    laser: Point2<f64>,
    world: Point2<f64>,
) -> TrackRow {
    TrackRow {
        detector: detector.into(),
        scan_idx: idx,
        id,
        x: laser.x,
        y: laser.y,
        world_x: world.x,
        world_y: world.y,
    }
}

/// One scan through every method (and the synthetic ground truth, when given).
fn scan_step(
    f: &LaserFrame,
    (idx, time_s): (i64, f64),
    runners: &mut [(Method, Runner)],
    odometry: &mut Odometry,
    gt: Option<&crate::groundtruth::PeopleFrame>,
    out: &mut Collected,
) {
    let mut view = ScanView::new(f, f.pose.filter(|_| !odometry.withhold));
    let odom = odometry.pose(f, &view, time_s);
    view.set_odometry(odom);
    let d = &view.geometric;
    out.view.observe(idx, f, &view.points);
    for (method, runner) in runners.iter_mut() {
        for h in runner.step(&view, time_s) {
            let laser = h
                .laser
                .unwrap_or_else(|| to_laser(view.pose.as_ref(), h.world));
            out.tracks
                .push(track_row(method.name(), idx, h.id, laser, h.world));
        }
    }
    let pose = f.pose.as_ref();
    if let Some(frame) = gt {
        for person in &frame.people {
            match pose {
                Some(_) => {
                    let p = to_laser(pose, Point2::new(person.x, person.y));
                    out.truth.push(TruthRow {
                        scan_idx: idx,
                        id: i64::from(person.id),
                        x: p.x,
                        y: p.y,
                    });
                }
                None => out.gt_dropped += 1,
            }
        }
    }
    out.scans.push(ScanRow {
        scan_idx: idx,
        stamp_ns: i64::try_from(f.stamp.0).unwrap_or(i64::MAX),
        log_time_ns: i64::try_from(f.log_time.0).unwrap_or(i64::MAX),
        posed: f.pose.is_some(),
        legs: d.legs.len() as i64,
        people: d.people.len() as i64,
    });
}

/// Real annotations onto their scans: each belongs to the last scan logged before it.
fn place_leg_tracker(rows: &[truth::PersonPosition], out: &mut Collected) {
    let times: Vec<i64> = out.scans.iter().map(|s| s.log_time_ns).collect();
    let mut seen = std::collections::BTreeSet::new();
    for r in rows {
        let t = i64::try_from(r.log_time.0).unwrap_or(i64::MAX);
        let after = times.partition_point(|&s| s < t);
        let Some(k) = after.checked_sub(1) else {
            out.gt_dropped += 1;
            continue;
        };
        let idx = out.scans[k].scan_idx;
        if !seen.insert((idx, r.id)) {
            out.gt_dropped += 1;
            continue;
        }
        out.truth.push(TruthRow {
            scan_idx: idx,
            id: r.id,
            x: r.x,
            y: r.y,
        });
    }
    out.truth.sort_by_key(|r| r.scan_idx); // stable: annotation order within a scan
}

/// Process one session (see the module doc).
pub(super) fn process(
    s: &Session,
    p: &Params,
    bar: &dyn Progress,
) -> anyhow::Result<SessionTables> {
    let seq: &Sequence = p.sequence(&s.info.name);
    let log = &s.log;
    if log.summary().channel(&seq.scan_topic).is_none() {
        anyhow::bail!(
            "{}: missing laser topic {}",
            log.path().display(),
            seq.scan_topic
        );
    }
    let kind = GtKind::of(log, &seq.gt_topic);
    let mut skips = Skips::new();
    let (synthetic, gt_skips) = match kind {
        GtKind::Synthetic => truth::people(log, &seq.gt_topic)?,
        _ => (crate::frames::Stamped::default(), Skips::new()),
    };
    skips.merge(gt_skips);
    let options = LaserOptions {
        fixed_frame: (kind == GtKind::Synthetic).then(|| "map".to_string()),
        ..LaserOptions::default()
    };
    let tolerance_ns = (p.gt_tolerance_s * 1e9).round() as u64;
    let mut frames = laser_frames::scans(log, &seq.scan_topic, &options)?;
    let summary = log.summary();
    let expected = summary
        .channel(&seq.scan_topic)
        .zip(summary.statistics.as_ref())
        .and_then(|(c, st)| st.channel_message_counts.get(&c.id).copied());
    bar.set_length(expected.unwrap_or(0));
    let mut runners: Vec<(Method, Runner)> = Vec::new();
    for &m in &p.methods {
        if let Some(r) = Runner::new(
            m,
            p.learned_for(m),
            (&p.synthetic.scan_topic, &p.synthetic.gt_topic),
            seq.publish_occluded,
        )? {
            runners.push((m, r));
        }
    }
    let free_space = p.methods.iter().any(|m| m.free_space());
    let fit = if free_space && !seq.withhold_odometry {
        scan_match_fit(log, &seq.scan_topic, &options)?
    } else {
        None
    };
    let mut odometry = Odometry {
        matcher: free_space.then(|| ScanOdometry::new(MatchParams::default())),
        withhold: seq.withhold_odometry,
        sensor_frame: false,
        trace: Vec::new(),
    };
    let mut out = Collected {
        view: view::Collector::new(seq.scans),
        ..Collected::default()
    };
    let mut first: Option<Nanos> = None;
    let mut idx = 0usize;
    while let Some(f) = frames.next() {
        let f = f?;
        odometry.sensor_frame =
            matches!(fit, Some((true, ..))) && frames.fixed_frame() == Some(f.frame.as_str());
        let t0 = *first.get_or_insert(f.stamp);
        let time_s = f.stamp.signed_sub(t0) as f64 * 1e-9;
        let gt = (kind == GtKind::Synthetic)
            .then(|| synthetic.nearest(f.stamp, tolerance_ns))
            .flatten();
        scan_step(
            &f,
            (idx as i64, time_s),
            &mut runners,
            &mut odometry,
            gt,
            &mut out,
        );
        idx += 1;
        bar.inc(1);
    }
    let fixed_frame = frames.fixed_frame().unwrap_or_default().to_string();
    let unposed = frames.unposed() as i64;
    skips.merge(frames.skips().clone());
    if kind == GtKind::LegTracker {
        let (rows, gt_skips) = truth::person_positions(log, &seq.gt_topic)?;
        skips.merge(gt_skips);
        place_leg_tracker(&rows, &mut out);
    }
    let (rpe_m, rpe_deg) = odometry.rpe();
    let matched = odometry.matcher.as_ref().filter(|_| {
        odometry.withhold || odometry.sensor_frame || out.scans.iter().any(|s| !s.posed)
    });
    let unfit = fit.filter(|(ok, ..)| !ok);
    let session = SessionRow {
        odometry: match (matched, unfit) {
            (Some(_), _) => "scan_match",
            (None, Some(_)) => "none_scan_match_unfit",
            (None, None) => "tf",
        }
        .into(),
        scan_match_failures: match (matched, unfit) {
            (Some(m), _) => m.failures() as i64,
            (None, Some((_, failed, _))) => failed as i64,
            (None, None) => 0,
        },
        odometry_rpe_m: rpe_m,
        odometry_rpe_deg: rpe_deg,
        scan_topic: seq.scan_topic.clone(),
        gt_topic: seq.gt_topic.clone(),
        gt_kind: kind.name().into(),
        fixed_frame,
        scans: out.scans.len() as i64,
        unposed,
        gt_rows: out.truth.len() as i64,
        gt_dropped: out.gt_dropped,
        skipped_messages: i64::try_from(skips.total()).unwrap_or(i64::MAX),
        first_error: skips.first_error().map(str::to_string),
    };
    let mut t = SessionTables::from([
        (tables::SESSION.to_string(), SessionRow::frame(&[session])?),
        (tables::SCANS.to_string(), ScanRow::frame(&out.scans)?),
        (tables::TRUTH.to_string(), TruthRow::frame(&out.truth)?),
        (tables::TRACKS.to_string(), TrackRow::frame(&out.tracks)?),
    ]);
    out.view.into_tables(&mut t)?;
    Ok(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scan(scan_idx: i64, log_ms: i64) -> ScanRow {
        ScanRow {
            scan_idx,
            stamp_ns: 0,
            log_time_ns: log_ms * 1_000_000,
            posed: true,
            legs: 0,
            people: 0,
        }
    }

    /// The README's rule: an annotation belongs to the last scan logged strictly before it;
    /// one before the first scan, or a second position of an id on one scan, is dropped.
    #[test]
    fn annotations_belong_to_the_last_scan_logged_before_them() {
        let mut out = Collected {
            scans: vec![scan(0, 100), scan(1, 200), scan(2, 300)],
            ..Collected::default()
        };
        let at = |ms: u64, id: i64| truth::PersonPosition {
            log_time: Nanos(ms * 1_000_000),
            id,
            x: 1.0,
            y: f64::from(u32::try_from(ms).unwrap_or(0)),
        };
        let rows = [
            at(50, 1),
            at(150, 1),
            at(200, 2),
            at(250, 2),
            at(260, 2),
            at(350, 1),
        ];
        place_leg_tracker(&rows, &mut out);
        let got: Vec<(i64, i64, f64)> = out.truth.iter().map(|r| (r.scan_idx, r.id, r.y)).collect();
        assert_eq!(
            got,
            vec![(0, 1, 150.0), (0, 2, 200.0), (1, 2, 250.0), (2, 1, 350.0)]
        );
        assert_eq!(out.gt_dropped, 2);
    }

    #[test]
    fn positions_go_back_into_the_laser_frame() {
        use nalgebra::{Translation3, UnitQuaternion};
        let pose = Isometry3::from_parts(
            Translation3::new(1.0, 2.0, 0.0),
            UnitQuaternion::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_2),
        );
        // the laser's x axis points along the fixed frame's y axis
        let p = to_laser(Some(&pose), Point2::new(1.0, 5.0));
        assert!((p - Point2::new(3.0, 0.0)).norm() < 1e-12, "{p}");
        assert_eq!(to_laser(None, Point2::new(1.0, 5.0)), Point2::new(1.0, 5.0));
    }
}

//! Laser scans (`sensor_msgs/LaserScan`) with the sensor's pose at each scan's stamp.
//!
//! The pose is the TF transform `fixed_frame <- sensor frame` at the scan's header stamp
//! (interpolated by [`TfBuffer`]). The fixed frame is the one asked for in [`LaserOptions`],
//! else the first of `odom`, `map`, `world` that the TF tree connects to the first scan's
//! frame, else
//! the sensor frame itself (no TF: every pose is the identity). Frame ids lose a leading `/`
//! (ROS 1 logs). A scan whose pose cannot be looked up (beyond the TF samples by more than the
//! tolerance) has no pose and is counted ([`LaserFrames::unposed`]).
//!
//! Ranges are kept as the driver wrote them; NaN, ±inf and 0.0 are flagged as "no return"
//! ([`LaserFrame::no_return`]). Scans that do not decode are skipped and counted in [`Skips`].

use nalgebra::Isometry3;

use super::skips::Skips;
use crate::log::msgs::LaserScan;
use crate::log::tf::{TfError, normalize_frame};
use crate::log::{Decoders, LogError, MessageStream, SessionLog, TfBuffer};
use crate::time::Nanos;

/// Frames tried, in order, when no fixed frame is asked for.
pub const FIXED_FRAMES: [&str; 3] = ["odom", "map", "world"];

/// How scans are placed.
#[derive(Debug, Clone, PartialEq)]
pub struct LaserOptions {
    /// The frame poses map into; `None`: the first of [`FIXED_FRAMES`] TF connects.
    pub fixed_frame: Option<String>,
    /// How far (s) a lookup may lie outside an edge's TF samples (nearest sample used).
    pub tf_tolerance_s: f64,
}

impl Default for LaserOptions {
    fn default() -> Self {
        LaserOptions {
            fixed_frame: None,
            tf_tolerance_s: 0.5,
        }
    }
}

/// True for a range that is no return: NaN, ±inf or 0.0.
pub fn is_no_return(r: f32) -> bool {
    !r.is_finite() || r == 0.0
}

/// One scan.
#[derive(Debug, Clone, PartialEq)]
pub struct LaserFrame {
    /// Header stamp (log time where invalid).
    pub stamp: Nanos,
    pub log_time: Nanos,
    /// The sensor frame, without a leading `/`.
    pub frame: String,
    pub scan: LaserScan,
    /// Per beam: no return (NaN, ±inf or 0.0).
    pub no_return: Vec<bool>,
    /// `fixed_frame <- frame` at `stamp`; `None` when TF cannot place the scan.
    pub pose: Option<Isometry3<f64>>,
}

/// Iterator over scans; see the module doc.
pub struct LaserFrames<'a> {
    log: &'a SessionLog,
    stream: MessageStream,
    decoders: Decoders,
    tf: TfBuffer,
    asked: Option<String>,
    fixed: Option<String>,
    skips: Skips,
    unposed: u64,
}

/// Stream `topic`'s scans with TF from the log's `/tf` and `/tf_static`.
pub fn scans<'a>(
    log: &'a SessionLog,
    topic: &str,
    options: &LaserOptions,
) -> Result<LaserFrames<'a>, LogError> {
    let tf = TfBuffer::from_log(log, options.tf_tolerance_s)?;
    Ok(LaserFrames {
        log,
        stream: log.messages_on(&[topic])?,
        decoders: Decoders::new(),
        tf,
        asked: options
            .fixed_frame
            .as_deref()
            .map(|f| normalize_frame(f).to_string()),
        fixed: None,
        skips: Skips::new(),
        unposed: 0,
    })
}

impl LaserFrames<'_> {
    /// The frame poses map into (known after the first scan).
    pub fn fixed_frame(&self) -> Option<&str> {
        self.fixed.as_deref()
    }

    pub fn skips(&self) -> &Skips {
        &self.skips
    }

    /// Scans handed out without a pose.
    pub fn unposed(&self) -> u64 {
        self.unposed
    }

    fn choose_fixed(&self, sensor: &str, at: Nanos) -> String {
        if let Some(f) = &self.asked {
            return f.clone();
        }
        let known = self.tf.frames();
        FIXED_FRAMES
            .iter()
            .find(|f| {
                known.contains(f)
                    && !matches!(self.tf.lookup(f, sensor, at), Err(TfError::NoPath { .. }))
            })
            .map_or_else(|| sensor.to_string(), |f| (*f).to_string())
    }
}

impl Iterator for LaserFrames<'_> {
    type Item = Result<LaserFrame, LogError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            let m = match self.stream.next()? {
                Ok(m) => m,
                Err(e) => return Some(Err(e)),
            };
            let scan = match self.decoders.typed::<LaserScan>(self.log, &m) {
                Ok(s) => s,
                Err(e) => {
                    self.skips.note(m.topic(), e);
                    continue;
                }
            };
            let stamp = scan.header.stamp.nanos().unwrap_or(m.log_time);
            let frame = normalize_frame(&scan.header.frame_id).to_string();
            if self.fixed.is_none() {
                self.fixed = Some(self.choose_fixed(&frame, stamp));
            }
            let fixed = self.fixed.as_deref().unwrap_or(&frame);
            let pose = self.tf.lookup(fixed, &frame, stamp).ok();
            if pose.is_none() {
                self.unposed += 1;
            }
            let no_return = scan.ranges.iter().map(|r| is_no_return(*r)).collect();
            return Some(Ok(LaserFrame {
                stamp,
                log_time: m.log_time,
                frame,
                scan,
                no_return,
                pose,
            }));
        }
    }
}

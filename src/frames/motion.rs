//! The robot's motion: odometry samples sorted by header stamp with nearest-stamp lookups, and
//! whether a camera rides the robot (TF ancestry).

use super::skips::Skips;
use super::truth::Stamped;
use crate::log::msgs::Odometry;
use crate::log::tf::{TfBuffer, normalize_frame};
use crate::log::{Decoders, LogError, SessionLog};

/// A session's odometry.
#[derive(Debug, Clone, Default)]
pub struct Motion {
    /// Samples by header stamp (log time where the stamp is invalid).
    pub samples: Stamped<Odometry>,
    /// The first sample's `child_frame_id` (the robot's frame), without a leading `/`; empty
    /// when there is no sample.
    pub child_frame: String,
    pub skips: Skips,
}

/// Read `topic`'s odometry; a topic absent from the log gives no samples. Messages that do not
/// decode are skipped and counted.
pub fn odometry(log: &SessionLog, topic: &str) -> Result<Motion, LogError> {
    let mut out = Motion::default();
    if log.summary().channel(topic).is_none() {
        return Ok(out);
    }
    let mut dec = Decoders::new();
    let mut pairs = Vec::new();
    for m in log.messages_on(&[topic])? {
        let m = m?;
        match dec.typed::<Odometry>(log, &m) {
            Ok(o) => {
                if out.child_frame.is_empty() {
                    out.child_frame = normalize_frame(&o.child_frame_id).to_string();
                }
                pairs.push((o.header.stamp.nanos().unwrap_or(m.log_time), o));
            }
            Err(e) => out.skips.note(topic, e),
        }
    }
    out.samples = Stamped::new(pairs);
    Ok(out)
}

/// Does `camera`'s frame ride on the robot whose frame is `robot_frame` (odometry's child,
/// `base_link`)? True when TF puts `robot_frame` among the camera frame's ancestors (or it is
/// the camera frame); false when TF knows the camera frame but hangs it elsewhere (a camera
/// fixed in the world); true (odometry trusted) when TF does not know the camera frame as a
/// child. A cycle in TF gives false.
pub fn camera_rides_robot(tf: &TfBuffer, camera: &str, robot_frame: &str) -> bool {
    let edges = tf.tree();
    let parent_of = |f: &str| {
        edges
            .iter()
            .find(|e| e.child == f)
            .map(|e| e.parent.clone())
    };
    let mut frame = camera.to_string();
    if parent_of(&frame).is_none() {
        return true;
    }
    for _ in 0..=edges.len() {
        if frame == robot_frame {
            return true;
        }
        match parent_of(&frame) {
            Some(p) => frame = p,
            None => return false,
        }
    }
    false
}

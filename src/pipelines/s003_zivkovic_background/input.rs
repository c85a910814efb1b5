//! Reading a session's camera frames (with their exact masks, paired by header stamp), its
//! ground truth and its odometry; bad messages are counted, never fatal.

use std::collections::VecDeque;

use image::RgbImage;

use super::params::LocalEvalParams;
use crate::Nanos;
use crate::groundtruth::PeopleFrame;
use crate::log::image::{decode_compressed, decode_raw};
use crate::log::msgs::{CompressedImage, Image, Odometry};
use crate::log::tf::{TfBuffer, normalize_frame};
use crate::log::{Decoders, SessionLog, read_topic};

/// An image and its mask are paired by header stamp; one left alone this long is flushed (ns).
const PAIR_WAIT_NS: u64 = 1_000_000_000;

/// One camera frame with its exact mask when the session has one.
pub(super) struct CameraFrame {
    pub stamp: Nanos,
    pub rgb: RgbImage,
    pub mask: Option<Vec<u8>>,
}

/// Bad messages met while reading, counted and reported, never fatal.
#[derive(Default)]
pub(super) struct ReadCounts {
    pub bad_images: i64,
    pub bad_masks: i64,
    pub frames_without_mask: i64,
    pub first_error: Option<String>,
}

impl ReadCounts {
    fn note(&mut self, e: impl std::fmt::Display) {
        if self.first_error.is_none() {
            self.first_error = Some(e.to_string());
        }
    }
}

struct Pending {
    stamp: Nanos,
    log_time: Nanos,
    rgb: Option<RgbImage>,
    mask: Option<Vec<u8>>,
}

/// Stream the camera's frames (and masks, paired by header stamp) in log-time order.
pub(super) fn for_each_frame(
    log: &SessionLog,
    image_topic: &str,
    mask_topic: Option<&str>,
    counts: &mut ReadCounts,
    mut f: impl FnMut(CameraFrame) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    let compressed = log
        .summary()
        .channel(image_topic)
        .is_some_and(|c| c.schema_name().contains("CompressedImage"));
    let mut topics = vec![image_topic];
    topics.extend(mask_topic);
    let mut dec = Decoders::new();
    let mut pending: VecDeque<Pending> = VecDeque::new();
    let mut emit = |p: Pending, counts: &mut ReadCounts| -> anyhow::Result<()> {
        let Some(rgb) = p.rgb else {
            return Ok(()); // a mask without its image: nothing to score
        };
        let mask = p
            .mask
            .filter(|m| m.len() == (rgb.width() * rgb.height()) as usize);
        if mask_topic.is_some() && mask.is_none() {
            counts.frames_without_mask += 1;
        }
        f(CameraFrame {
            stamp: p.stamp,
            rgb,
            mask,
        })
    };
    for m in log.messages_on(&topics)? {
        let m = m?;
        let is_image = m.topic() == image_topic;
        let decoded: Result<(Nanos, Vec<u8>, Option<RgbImage>), String> = if is_image {
            let r = if compressed {
                dec.typed::<CompressedImage>(log, &m)
                    .map_err(|e| e.to_string())
                    .and_then(|c| {
                        let stamp = c.header.stamp.nanos().unwrap_or(m.log_time);
                        decode_compressed(&c)
                            .map(|img| (stamp, img.to_rgb8()))
                            .map_err(|e| {
                                format!(
                                    "{}: {image_topic} at {}: {e}",
                                    log.path().display(),
                                    m.log_time.0
                                )
                            })
                    })
            } else {
                dec.typed::<Image>(log, &m)
                    .map_err(|e| e.to_string())
                    .and_then(|c| {
                        let stamp = c.header.stamp.nanos().unwrap_or(m.log_time);
                        decode_raw(&c)
                            .map(|img| (stamp, img.to_rgb8()))
                            .map_err(|e| {
                                format!(
                                    "{}: {image_topic} at {}: {e}",
                                    log.path().display(),
                                    m.log_time.0
                                )
                            })
                    })
            };
            r.map(|(s, img)| (s, Vec::new(), Some(img)))
        } else {
            dec.typed::<Image>(log, &m)
                .map_err(|e| e.to_string())
                .and_then(|c| {
                    let stamp = c.header.stamp.nanos().unwrap_or(m.log_time);
                    decode_raw(&c)
                        .map(|img| (stamp, img.to_luma8().into_raw(), None))
                        .map_err(|e| {
                            format!(
                                "{}: {} at {}: {e}",
                                log.path().display(),
                                m.topic(),
                                m.log_time.0
                            )
                        })
                })
        };
        let (stamp, mask, rgb) = match decoded {
            Ok(x) => x,
            Err(e) => {
                if is_image {
                    counts.bad_images += 1;
                } else {
                    counts.bad_masks += 1;
                }
                counts.note(e);
                continue;
            }
        };
        match pending.iter_mut().find(|p| p.stamp == stamp) {
            Some(p) => {
                if is_image {
                    p.rgb = rgb;
                } else {
                    p.mask = Some(mask);
                }
            }
            None => pending.push_back(Pending {
                stamp,
                log_time: m.log_time,
                rgb,
                mask: (!is_image).then_some(mask),
            }),
        }
        // flush complete frames from the front, and any left waiting too long
        while let Some(front) = pending.front() {
            let complete = front.rgb.is_some() && (mask_topic.is_none() || front.mask.is_some());
            let stale = m.log_time.0.saturating_sub(front.log_time.0) > PAIR_WAIT_NS;
            if !(complete || stale) {
                break;
            }
            if let Some(p) = pending.pop_front() {
                emit(p, counts)?;
            }
        }
    }
    while let Some(p) = pending.pop_front() {
        emit(p, counts)?;
    }
    Ok(())
}

/// Ground-truth frames sorted by stamp (bad ones counted).
pub(super) fn read_ground_truth(
    log: &SessionLog,
    topic: &str,
) -> anyhow::Result<(Vec<PeopleFrame>, i64)> {
    let mut out = Vec::new();
    let mut bad = 0;
    if log.summary().channel(topic).is_none() {
        return Ok((out, 0));
    }
    for m in log.messages_on(&[topic])? {
        let m = m?;
        match serde_json::from_slice::<PeopleFrame>(&m.data) {
            Ok(f) => out.push(f),
            Err(_) => bad += 1,
        }
    }
    out.sort_by_key(|f| f.stamp_ns);
    Ok((out, bad))
}

/// Does the camera ride on the odometry's robot? True when TF puts the odometry's child frame
/// (`base_link`) among the camera frame's ancestors; false when TF knows the camera frame but
/// hangs it elsewhere (a camera fixed in the world: the robot's motion, or its odometry noise,
/// does not move it); true (odometry trusted) when TF does not know the camera frame.
pub(super) fn camera_rides_robot(tf: &TfBuffer, camera: &str, odom_child: &str) -> bool {
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
        if frame == odom_child {
            return true;
        }
        match parent_of(&frame) {
            Some(p) => frame = p,
            None => return false,
        }
    }
    false // a cycle: TF is broken, the camera is not known to ride the robot
}

/// `(stamp, moving)` from odometry, sorted, and the odometry's child frame (the robot's).
pub(super) fn read_motion(
    log: &SessionLog,
    topic: &str,
    p: &LocalEvalParams,
) -> anyhow::Result<(Vec<(Nanos, bool)>, String)> {
    let mut out = Vec::new();
    let mut child = String::new();
    if log.summary().channel(topic).is_none() {
        return Ok((out, child));
    }
    for r in read_topic::<Odometry>(log, topic)? {
        let (t, o) = r?;
        if child.is_empty() {
            child = normalize_frame(&o.child_frame_id).to_string();
        }
        let stamp = o.header.stamp.nanos().unwrap_or(t);
        let speed = o.linear.x.hypot(o.linear.y);
        let moving = speed > p.moving_speed_mps || o.angular.z.abs() > p.moving_turn_rad_s;
        out.push((stamp, moving));
    }
    out.sort_by_key(|x| x.0);
    Ok((out, child))
}

pub(super) fn nearest<T>(sorted: &[(Nanos, T)], t: Nanos, tol: u64) -> Option<&T> {
    let i = sorted.partition_point(|(s, _)| *s < t);
    let cands = [i.checked_sub(1), (i < sorted.len()).then_some(i)];
    cands
        .into_iter()
        .flatten()
        .map(|k| (sorted[k].0.abs_diff(t), k))
        .min()
        .filter(|(d, _)| *d <= tol)
        .map(|(_, k)| &sorted[k].1)
}

#[cfg(test)]
mod tests {
    use nalgebra::{Quaternion, Vector3};

    use super::*;
    use crate::log::msgs::{Header, Transform, TransformStamped};

    fn tf(edges: &[(&str, &str)]) -> TfBuffer {
        let mut b = TfBuffer::new(0.0);
        for (parent, child) in edges {
            b.insert(
                &TransformStamped {
                    header: Header::new(Nanos(1), *parent),
                    child_frame_id: (*child).to_string(),
                    transform: Transform {
                        translation: Vector3::zeros(),
                        rotation: Quaternion::identity(),
                    },
                },
                true,
            );
        }
        b
    }

    /// Regression: the fixed background cameras hang from `map`, yet the static robot's
    /// odometry yaw-rate noise (σ 0.01 rad/s against a 0.02 rad/s threshold) flagged ~6 % of
    /// their frames as "camera moving", each one pausing and restarting the background model.
    #[test]
    fn only_a_camera_below_the_robot_frame_is_moved_by_odometry() {
        let fixed = tf(&[("map", "cam_0"), ("map", "odom"), ("odom", "base_link")]);
        assert!(!camera_rides_robot(&fixed, "cam_0", "base_link"));
        let mounted = tf(&[
            ("map", "odom"),
            ("odom", "base_link"),
            ("base_link", "cam_0"),
        ]);
        assert!(camera_rides_robot(&mounted, "cam_0", "base_link"));
        let deeper = tf(&[
            ("odom", "base_link"),
            ("base_link", "mast"),
            ("mast", "cam_0"),
        ]);
        assert!(camera_rides_robot(&deeper, "cam_0", "base_link"));
        // TF does not know the camera: trust the odometry
        assert!(camera_rides_robot(&fixed, "cam_9", "base_link"));
    }
}

//! A transform buffer over `/tf` and `/tf_static`: lookups of `target_from_source` through the
//! frame tree at any stamp, interpolating each dynamic edge between its two nearest samples
//! (linear in translation, slerp in rotation), as `tf2::BufferCore::lookupTransform` does.
//!
//! Frame ids are normalised by dropping a leading `/` (ROS 1 logs write `/odom`, ROS 2 logs
//! `odom`). A stamp outside an edge's sample range is allowed up to a stated tolerance (the
//! nearest sample is used); beyond it the lookup is an extrapolation error naming the edge and
//! its range. Unlike tf2's 10 s cache, the whole session is kept: batch pipelines look up any
//! stamp. Memory is ~56 bytes per sample (a 2-minute log with 140k transforms: ~8 MB).

use std::collections::{BTreeMap, HashMap};

use nalgebra::{Isometry3, Translation3, UnitQuaternion};

use super::decode::read_topic;
use super::error::LogError;
use super::msgs::{TfMessage, TransformStamped};
use super::reader::SessionLog;
use crate::time::Nanos;

/// Drop a leading `/` from a frame id.
pub fn normalize_frame(frame: &str) -> &str {
    frame.strip_prefix('/').unwrap_or(frame)
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TfError {
    #[error("no transform path from frame `{from}` to frame `{target}` (known frames: {known})")]
    NoPath {
        target: String,
        from: String,
        known: String,
    },
    #[error(
        "lookup at {at} s extrapolates edge {parent} -> {child} (samples {first}..{last} s, tolerance {tolerance_s} s)"
    )]
    Extrapolation {
        parent: String,
        child: String,
        at: Nanos,
        first: Nanos,
        last: Nanos,
        tolerance_s: f64,
    },
}

#[derive(Debug, Clone)]
struct Edge {
    parent: String,
    is_static: bool,
    /// Sorted by time; a static edge holds one sample.
    samples: Vec<(Nanos, Isometry3<f64>)>,
}

/// Counts of what went into the buffer, for reports.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct TfStats {
    pub transforms: u64,
    /// Transforms skipped: zero quaternion, non-finite values, or a stamp before the epoch.
    pub skipped_invalid: u64,
    /// Times a child frame was re-parented (the newest parent wins, as in tf2).
    pub reparented: u64,
    /// Transforms for a child that is published both on `/tf` and on `/tf_static` with the
    /// same parent; the time-varying samples win, the static one is dropped.
    pub static_and_dynamic: u64,
}

/// One edge of the frame tree, for `inspect`.
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeSummary {
    pub parent: String,
    pub child: String,
    pub is_static: bool,
    pub samples: usize,
    pub first: Nanos,
    pub last: Nanos,
}

/// The frame tree of one session.
#[derive(Debug, Clone)]
pub struct TfBuffer {
    edges: HashMap<String, Edge>,
    tolerance: u64,
    stats: TfStats,
}

impl TfBuffer {
    /// A buffer that allows lookups up to `tolerance_s` outside an edge's samples.
    pub fn new(tolerance_s: f64) -> Self {
        TfBuffer {
            edges: HashMap::new(),
            tolerance: (tolerance_s.max(0.0) * 1e9) as u64,
            stats: TfStats::default(),
        }
    }

    /// Read `/tf` and `/tf_static` (whichever exist) from a log.
    pub fn from_log(log: &SessionLog, tolerance_s: f64) -> Result<TfBuffer, LogError> {
        let mut buf = TfBuffer::new(tolerance_s);
        for (topic, is_static) in [("/tf", false), ("/tf_static", true)] {
            if log.summary().channel(topic).is_none() {
                continue;
            }
            for item in read_topic::<TfMessage>(log, topic)? {
                let (_, msg) = item?;
                for t in &msg.transforms {
                    buf.insert(t, is_static);
                }
            }
        }
        Ok(buf)
    }

    pub fn stats(&self) -> &TfStats {
        &self.stats
    }

    /// Add one transform (`parent_from_child` at its header stamp).
    pub fn insert(&mut self, t: &TransformStamped, is_static: bool) {
        let parent = normalize_frame(&t.header.frame_id).to_string();
        let child = normalize_frame(&t.child_frame_id).to_string();
        let q = t.transform.rotation;
        let v = t.transform.translation;
        let valid = q.norm() > 1e-9 && q.coords.iter().chain(v.iter()).all(|x| x.is_finite());
        let Some(stamp) = t.header.stamp.nanos().filter(|_| valid && parent != child) else {
            self.stats.skipped_invalid += 1;
            return;
        };
        let iso = Isometry3::from_parts(Translation3::from(v), UnitQuaternion::from_quaternion(q));
        self.stats.transforms += 1;
        let edge = self.edges.entry(child).or_insert_with(|| Edge {
            parent: parent.clone(),
            is_static,
            samples: Vec::new(),
        });
        if edge.parent != parent {
            self.stats.reparented += 1;
            *edge = Edge {
                parent,
                is_static,
                samples: Vec::new(),
            };
        }
        if is_static {
            if !edge.is_static && !edge.samples.is_empty() {
                self.stats.static_and_dynamic += 1;
                return;
            }
            edge.is_static = true;
            edge.samples = vec![(stamp, iso)];
            return;
        }
        if edge.is_static {
            self.stats.static_and_dynamic += 1;
            edge.is_static = false;
            edge.samples.clear();
        }
        match edge.samples.binary_search_by_key(&stamp, |(s, _)| *s) {
            Ok(i) => edge.samples[i] = (stamp, iso),
            Err(i) => edge.samples.insert(i, (stamp, iso)),
        }
    }

    /// The edge `parent_from_child` at `at`.
    fn edge_at(&self, child: &str, edge: &Edge, at: Nanos) -> Result<Isometry3<f64>, TfError> {
        let s = &edge.samples;
        if edge.is_static || s.len() == 1 && s[0].0 == at {
            return Ok(s[0].1);
        }
        let (first, last) = (s[0].0, s[s.len() - 1].0);
        if at < first || at > last {
            let gap = if at < first {
                first.0 - at.0
            } else {
                at.0 - last.0
            };
            if gap > self.tolerance {
                return Err(TfError::Extrapolation {
                    parent: edge.parent.clone(),
                    child: child.to_string(),
                    at,
                    first,
                    last,
                    tolerance_s: self.tolerance as f64 * 1e-9,
                });
            }
            return Ok(if at < first { s[0].1 } else { s[s.len() - 1].1 });
        }
        let i = s.partition_point(|(t, _)| *t <= at);
        // s[i-1].0 <= at, and at <= last so i-1 is valid; i == len only when at == last
        let (t0, a) = s[i - 1];
        if t0 == at || i == s.len() {
            return Ok(a);
        }
        let (t1, b) = s[i];
        let w = (at.0 - t0.0) as f64 / (t1.0 - t0.0) as f64;
        let translation = a.translation.vector.lerp(&b.translation.vector, w);
        let rotation = a
            .rotation
            .try_slerp(&b.rotation, w, 1e-12)
            .unwrap_or(if w < 0.5 { a.rotation } else { b.rotation });
        Ok(Isometry3::from_parts(
            Translation3::from(translation),
            rotation,
        ))
    }

    /// Frames from `frame` up to the root.
    fn chain<'a>(&'a self, mut frame: &'a str) -> Vec<&'a str> {
        let mut out = vec![frame];
        while let Some(e) = self.edges.get(frame) {
            if out.contains(&e.parent.as_str()) || out.len() > self.edges.len() + 1 {
                break; // a cycle in bad data: stop rather than loop
            }
            frame = &e.parent;
            out.push(frame);
        }
        out
    }

    /// `root_from_frame` along `chain` up to (excluding) `stop`.
    fn compose_up(
        &self,
        chain: &[&str],
        stop: usize,
        at: Nanos,
    ) -> Result<Isometry3<f64>, TfError> {
        let mut acc = Isometry3::identity();
        for frame in &chain[..stop] {
            let e = &self.edges[*frame];
            acc = self.edge_at(frame, e, at)? * acc;
        }
        Ok(acc)
    }

    /// The transform `target_from_source` at `at`: it maps a point in `source` coordinates to
    /// `target` coordinates.
    pub fn lookup(&self, target: &str, source: &str, at: Nanos) -> Result<Isometry3<f64>, TfError> {
        let (target, source) = (normalize_frame(target), normalize_frame(source));
        if target == source {
            return Ok(Isometry3::identity());
        }
        let up_s = self.chain(source);
        let up_t = self.chain(target);
        let Some((i_s, i_t)) = up_s
            .iter()
            .enumerate()
            .find_map(|(i, f)| up_t.iter().position(|g| g == f).map(|j| (i, j)))
        else {
            let mut known: Vec<&str> = self.frames();
            known.sort_unstable();
            return Err(TfError::NoPath {
                target: target.to_string(),
                from: source.to_string(),
                known: known.join(", "),
            });
        };
        let common_from_source = self.compose_up(&up_s, i_s, at)?;
        let common_from_target = self.compose_up(&up_t, i_t, at)?;
        Ok(common_from_target.inverse() * common_from_source)
    }

    /// Every frame named in the buffer.
    pub fn frames(&self) -> Vec<&str> {
        let mut out: Vec<&str> = self.edges.keys().map(String::as_str).collect();
        for e in self.edges.values() {
            if !out.contains(&e.parent.as_str()) {
                out.push(&e.parent);
            }
        }
        out
    }

    /// The edges, sorted by (parent, child).
    pub fn tree(&self) -> Vec<EdgeSummary> {
        let mut out: Vec<EdgeSummary> = self
            .edges
            .iter()
            .map(|(child, e)| EdgeSummary {
                parent: e.parent.clone(),
                child: child.clone(),
                is_static: e.is_static,
                samples: e.samples.len(),
                first: e.samples.first().map_or(Nanos(0), |s| s.0),
                last: e.samples.last().map_or(Nanos(0), |s| s.0),
            })
            .collect();
        out.sort_by(|a, b| (&a.parent, &a.child).cmp(&(&b.parent, &b.child)));
        out
    }

    /// Indented text of the tree (roots first), for `inspect`.
    pub fn render_tree(&self) -> String {
        let tree = self.tree();
        let mut children: BTreeMap<&str, Vec<&EdgeSummary>> = BTreeMap::new();
        for e in &tree {
            children.entry(e.parent.as_str()).or_default().push(e);
        }
        let mut roots: Vec<&str> = children
            .keys()
            .copied()
            .filter(|p| !self.edges.contains_key(*p))
            .collect();
        roots.sort_unstable();
        let mut out = String::new();
        fn walk(
            out: &mut String,
            children: &BTreeMap<&str, Vec<&EdgeSummary>>,
            frame: &str,
            depth: usize,
        ) {
            for e in children.get(frame).into_iter().flatten() {
                let kind = if e.is_static {
                    "static".to_string()
                } else {
                    format!("{} samples", e.samples)
                };
                out.push_str(&format!("{}{} ({kind})\n", "  ".repeat(depth + 1), e.child));
                if depth < 32 {
                    walk(out, children, &e.child, depth + 1);
                }
            }
        }
        for r in roots {
            out.push_str(r);
            out.push('\n');
            walk(&mut out, &children, r, 0);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::log::msgs::{Header, Transform};
    use nalgebra::{Point3, Quaternion, Vector3};
    use std::f64::consts::FRAC_PI_2;

    fn tf(parent: &str, child: &str, t: u64, xyz: [f64; 3], yaw: f64) -> TransformStamped {
        let q = UnitQuaternion::from_euler_angles(0.0, 0.0, yaw);
        TransformStamped {
            header: Header::new(Nanos(t), parent),
            child_frame_id: child.into(),
            transform: Transform {
                translation: Vector3::from(xyz),
                rotation: *q.quaternion(),
            },
        }
    }

    #[test]
    fn composes_through_the_tree_and_normalises_slashes() {
        let mut b = TfBuffer::new(0.0);
        b.insert(
            &tf("/odom", "/base_link", 0, [1.0, 0.0, 0.0], FRAC_PI_2),
            false,
        );
        b.insert(
            &tf("/odom", "/base_link", 10, [1.0, 0.0, 0.0], FRAC_PI_2),
            false,
        );
        b.insert(&tf("base_link", "laser", 0, [0.5, 0.0, 0.2], 0.0), true);
        b.insert(&tf("odom", "cam", 0, [0.0, 3.0, 0.0], 0.0), true);
        // a point 1 m ahead of the laser: laser (1,0,0) -> base (1.5,0,0.2) -> odom (1, 1.5, 0.2)
        let odom_from_laser = b.lookup("odom", "laser", Nanos(5)).expect("path");
        let p = odom_from_laser * Point3::new(1.0, 0.0, 0.0);
        assert!((p - Point3::new(1.0, 1.5, 0.2)).norm() < 1e-12, "{p}");
        // sibling branch: cam_from_laser = inverse(odom_from_cam) * odom_from_laser
        let q = b.lookup("cam", "laser", Nanos(5)).expect("path") * Point3::new(1.0, 0.0, 0.0);
        assert!((q - Point3::new(1.0, -1.5, 0.2)).norm() < 1e-12, "{q}");
    }

    #[test]
    fn interpolates_translation_and_rotation() {
        let mut b = TfBuffer::new(0.0);
        b.insert(&tf("map", "robot", 0, [0.0, 0.0, 0.0], 0.0), false);
        b.insert(&tf("map", "robot", 100, [2.0, 0.0, 0.0], FRAC_PI_2), false);
        let m = b.lookup("map", "robot", Nanos(25)).expect("inside range");
        assert!((m.translation.vector - Vector3::new(0.5, 0.0, 0.0)).norm() < 1e-12);
        assert!((m.rotation.euler_angles().2 - FRAC_PI_2 / 4.0).abs() < 1e-12);
    }

    #[test]
    fn extrapolation_beyond_tolerance_is_an_error() {
        let mut b = TfBuffer::new(1e-8); // 10 ns
        b.insert(&tf("map", "robot", 100, [0.0; 3], 0.0), false);
        b.insert(&tf("map", "robot", 200, [1.0, 0.0, 0.0], 0.0), false);
        assert!(b.lookup("map", "robot", Nanos(205)).is_ok());
        let e = b.lookup("map", "robot", Nanos(250)).expect_err("too far");
        assert!(matches!(e, TfError::Extrapolation { .. }), "{e}");
        let e = b.lookup("map", "nowhere", Nanos(150)).expect_err("no path");
        assert!(e.to_string().contains("known frames: map, robot"), "{e}");
    }

    #[test]
    fn zero_quaternions_are_skipped_and_counted() {
        let mut b = TfBuffer::new(0.0);
        let mut t = tf("a", "b", 0, [0.0; 3], 0.0);
        t.transform.rotation = Quaternion::new(0.0, 0.0, 0.0, 0.0);
        b.insert(&t, false);
        assert_eq!(b.stats().skipped_invalid, 1);
        assert!(b.lookup("a", "b", Nanos(0)).is_err());
    }

    #[test]
    fn a_frame_on_both_tf_and_tf_static_keeps_its_moving_samples_either_order() {
        for static_first in [true, false] {
            let mut b = TfBuffer::new(0.0);
            let stat = tf("map", "odom", 0, [0.0; 3], 0.0);
            let moving = [
                tf("map", "odom", 0, [5.0, 0.0, 0.0], 0.0),
                tf("map", "odom", 10, [7.0, 0.0, 0.0], 0.0),
            ];
            if static_first {
                b.insert(&stat, true);
            }
            for m in &moving {
                b.insert(m, false);
            }
            if !static_first {
                b.insert(&stat, true);
            }
            let m = b.lookup("map", "odom", Nanos(5)).expect("moving edge");
            assert!(
                (m.translation.vector.x - 6.0).abs() < 1e-12,
                "static_first {static_first}: {m}"
            );
            assert_eq!(
                b.stats().static_and_dynamic,
                1,
                "static_first {static_first}"
            );
        }
    }
}

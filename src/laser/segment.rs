//! Jump-distance segmentation of a scan's points (in beam order, sensor frame).
//!
//! Two consecutive returns `p_i`, `p_j` (beams `b_i < b_j`) stay in one segment when
//!
//! - their beams are adjacent (`b_j = b_i + 1`): a no-return between two returns breaks the
//!   segment, and
//! - their distance `‖p_j − p_i‖` is at most the threshold:
//!   - [`Threshold::Fixed`]`(d)`: `d`;
//!   - [`Threshold::Adaptive`]`{ c0, c1 }` (Dietmayer, Sparbert & Streller 2001, "Model
//!     based object classification and object tracking in traffic scenes from range images"):
//!     `c0 + c1 · min(r_i, r_j) · √(2(1 − cos Δφ))`, with `Δφ` the angle between the two beams.
//!     `√(2(1 − cos Δφ)) = 2 sin(Δφ/2)` is the distance between two points at unit range
//!     `Δφ` apart, so `c1 = 1` is Dietmayer's `C1` exactly, and `c1 > 1` allows for surfaces
//!     seen at a slant; `c0` absorbs the range noise.
//!
//! Segments with fewer than `min_points` returns are dropped (their points stay in the list,
//! and still count as neighbours for the jump tests of [`crate::laser::legs`]).

use std::ops::Range;

use super::points::ScanPoint;

/// The jump threshold between consecutive returns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Threshold {
    /// A fixed distance (m).
    Fixed(f64),
    /// `c0 + c1 · min(r_i, r_j) · √(2(1 − cos Δφ))` (m).
    Adaptive { c0: f64, c1: f64 },
}

impl Threshold {
    /// The threshold between two returns.
    pub fn between(&self, a: &ScanPoint, b: &ScanPoint) -> f64 {
        match *self {
            Threshold::Fixed(d) => d,
            Threshold::Adaptive { c0, c1 } => {
                let dphi = b.angle - a.angle;
                c0 + c1 * a.range.min(b.range) * (2.0 * (1.0 - dphi.cos())).max(0.0).sqrt()
            }
        }
    }
}

/// Segmentation parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentOptions {
    pub threshold: Threshold,
    /// Segments with fewer returns are dropped.
    pub min_points: usize,
}

impl Default for SegmentOptions {
    /// Fixed 0.1 m and at least 3 points. 0.1 m is chosen on synthetic data (two legs of one
    /// person, 0.2 m apart, stay separate segments; a leg's own beams, a few cm apart, stay
    /// together); 3 points is the fewest a circle fits.
    fn default() -> Self {
        SegmentOptions {
            threshold: Threshold::Fixed(0.1),
            min_points: 3,
        }
    }
}

/// A run of consecutive returns.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Segment {
    /// Indices into the point list.
    pub points: Range<usize>,
    /// First and last beam index (inclusive).
    pub first_beam: usize,
    pub last_beam: usize,
}

/// Segments of `points` (in beam order, as [`crate::laser::points::project`] returns them).
pub fn segment(points: &[ScanPoint], options: &SegmentOptions) -> Vec<Segment> {
    let mut out = Vec::new();
    let mut start = 0;
    for i in 1..=points.len() {
        let split = i == points.len() || {
            let (a, b) = (&points[i - 1], &points[i]);
            let near = (b.sensor - a.sensor).norm() <= options.threshold.between(a, b); // NaN: false
            b.beam != a.beam + 1 || !near
        };
        if split {
            if i - start >= options.min_points.max(1) {
                out.push(Segment {
                    points: start..i,
                    first_beam: points[start].beam,
                    last_beam: points[i - 1].beam,
                });
            }
            start = i;
        }
    }
    out
}

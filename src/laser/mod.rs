//! Laser people detection and multi-person tracking: pure functions of scans and poses.
//!
//! Data flow per scan (each step one file):
//!
//! 1. [`points`]: ranges + beam geometry + sensor pose → 2-D points in the sensor frame and in
//!    the fixed (odometry/world) frame; no-returns (NaN, ±inf, 0.0, outside the range limits)
//!    are skipped but every point keeps its beam index.
//! 2. [`segment`]: jump-distance segmentation (fixed or range-adaptive threshold); a no-return
//!    between two returns breaks a segment.
//! 3. [`features`]: the per-segment geometric features of laser people detection, in a fixed
//!    order for a later classifier; [`circle`] is the circle fit they use.
//! 4. [`legs`]: the geometric leg model of seed 002 §3 (radius range, background jump, legs
//!    paired into people within a pair distance, observation = midpoint).
//! 5. [`tracker`]: multi-person tracking in the fixed frame (constant-velocity Kalman per
//!    person from [`crate::track::kalman`], global nearest neighbour with a Mahalanobis gate
//!    through [`crate::assign`], M-of-N initiation and deletion, single-leg updates).
//!
//! [`occupancy`] is leg_tracker's local occupancy grid (the scans mapped in the fixed frame,
//! tracked people left out); [`joint`] is leg_tracker's joint leg tracker (every cluster
//! tracked, leg pairs that move together through free space become people); [`people`] holds
//! the two together (`FreeSpaceTracker`). [`scan_match`] estimates the laser's motion from its
//! scans (point-to-line ICP) for logs without odometry, so that the grid has a fixed frame.
//!
//! [`follow`] is seed 001's single-target follower: blobs, their colour likelihood in the omni
//! image ([`crate::vision::cylinder`]) and a PDAF ([`crate::track::pdaf`]) with the `rst` rule.
//!
//! [`training`] builds labelled segment samples for a learned leg detector (leg_tracker's
//! training CSVs, parsed from text; synthetic ground-truth legs).
//!
//! No file I/O and no `frames` imports; of `log` only the decoded `LaserScan` message type
//! ([`points::ScanGeometry::of`]): a pipeline turns a `frames::laser::LaserFrame` into
//! [`points::ScanGeometry`] + ranges + pose. Nothing here
//! panics on NaN or infinite input.

pub mod circle;
pub mod features;
pub mod follow;
pub mod joint;
pub mod legs;
pub mod occupancy;
pub mod people;
pub mod points;
pub mod scan_match;
pub mod segment;
pub mod tracker;
pub mod training;

#[cfg(test)]
mod joint_tests;
#[cfg(test)]
mod tests;

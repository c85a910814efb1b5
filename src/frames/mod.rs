//! The frames layer: the one place that turns a session log into typed, time-aligned frames.
//! Pipelines read sensors through it instead of streaming messages themselves.
//!
//! Data flows one way: `log` → **`frames`** → stages → tables → report. This module imports
//! only `log`, `geometry`, `groundtruth`, `time` and the bottom primitives.
//!
//! | need | call | gives |
//! |---|---|---|
//! | a logical topic through `[topics]` | [`topic`]`(&topics, "image", default)` | `String` |
//! | one camera's images (+ mask) | [`camera::frames`]`(log, image, Some(mask))?` | iterator of `Result<`[`CameraFrame`]`, LogError>` |
//! | a camera's image topic by name | [`camera::image_topic`]`(log, "omni_camera")` | `/omni_camera/image_raw/compressed` or `/…/image_raw` |
//! | several cameras by stamp | [`multicam::group`]`::<ImageMsg>(log, &topics, tol_ns)?` | iterator of `Result<`[`MultiFrame`]`<ImageMsg>, LogError>` |
//! | detections of several cameras | [`multicam::group`]`::<Detection2DArray>(…)` | same, per camera `Option<Detection2DArray>` |
//! | images spread over the log | [`camera::spread`]`(log, &topics, n)?` | `Vec<Vec<RgbImage>>` per topic |
//! | calibrated cameras | [`rig::camera`]`(log, &tf, name, info_topic, "map", at)?` / [`rig::views`] | [`RigCamera`] / `Vec<CalibratedView>` |
//! | ground-truth people | [`truth::people`]`(log, PEOPLE_TOPIC)?` | ([`Stamped`]`<PeopleFrame>`, [`Skips`]) |
//! | `leg_tracker/msg/Person` positions (real laser logs) | [`truth::person_positions`]`(log, topic)?` | (`Vec<`[`truth::PersonPosition`]`>`, [`Skips`]) |
//! | nearest ground truth of a frame | `gt.nearest(stamp, tol_ns)` | `Option<&PeopleFrame>` |
//! | odometry, camera on robot? | [`motion::odometry`]`(log, "/odom")?`, [`motion::camera_rides_robot`] | [`Motion`], `bool` |
//! | laser scans with pose | [`laser::scans`]`(log, "/scan", &LaserOptions::default())?` | iterator of `Result<`[`LaserFrame`]`, LogError>` |
//!
//! # Usage
//!
//! ```no_run
//! # fn demo(log: &peopletrack::log::SessionLog) -> anyhow::Result<()> {
//! use peopletrack::frames::{self, camera, truth};
//! use peopletrack::groundtruth::PEOPLE_TOPIC;
//! let topics = std::collections::BTreeMap::new(); // the pipeline file's [topics]
//! let image = frames::topic(&topics, "image", "/cam_0/image_raw/compressed");
//! let (gt, gt_skips) = truth::people(log, PEOPLE_TOPIC)?;
//! let mut cam = camera::frames(log, &image, None)?;
//! for f in &mut cam {
//!     let f = f?; // only an unreadable log (corrupt chunk) is an error
//!     let _truth = gt.nearest(f.stamp, 20_000_000);
//!     let _ = (f.stamp, f.rgb.dimensions(), f.mask.is_some());
//! }
//! let skips = cam.into_skips(); // bad messages: per-topic counts and first error texts
//! println!("images: {skips}; ground truth: {gt_skips}");
//! # Ok(()) }
//! ```
//!
//! # Contracts
//!
//! - Iterators stream in log-time order with bounded memory; a message that cannot be read
//!   (corrupt chunk) is the iterator's `Err` and ends it. A message that reads but does not
//!   decode is skipped and counted in a [`Skips`] (per topic: count and the first error's
//!   text, naming file, topic and log time); `skips()` / `into_skips()` give them.
//! - Stamps are header stamps; camera images and multi-camera frames fall back to the log time
//!   when the header stamp is unset (zero), odometry and laser when it is invalid.
//! - Joins are nearest-stamp within a tolerance, ties to the earlier stamp, one implementation
//!   ([`crate::log::sync::nearest`], through [`Stamped`]).
//! - Mask pairing (s003) and multi-camera grouping (s004) are documented in [`camera`] and
//!   [`multicam`].//!
//! # Porting notes (where the layer differs from the loops it replaces)
//!
//! - s003 `for_each_frame`: a header stamp of zero now falls back to the log time (as in
//!   s004); a mask pairs only when its width and height equal the image's (before: its pixel
//!   count). Skip texts are unchanged. `ReadCounts` maps to `skips().count(image)`,
//!   `skips().count(mask)`, `frames_without_mask()`, `skips().first_error()`.
//! - s004: the raw/compressed choice is by schema name containing `CompressedImage` (same on
//!   all standard schemas); ground truth is read by [`truth::people`] in its own pass (same
//!   sorted result); images stay undecoded in [`MultiFrame`] so cameras decode in parallel.
//! - s000 (which fails on the first bad message): check `skips().first_error()` and bail.

pub mod audio;
pub mod camera;
pub mod laser;
pub mod motion;
pub mod multicam;
pub mod rig;
mod skips;
pub mod truth;

use std::collections::BTreeMap;

pub use camera::{CameraFrame, CameraFrames, ImageMsg};
pub use laser::{LaserFrame, LaserFrames, LaserOptions};
pub use motion::Motion;
pub use multicam::{MultiFrame, MultiFrames};
pub use rig::{RigCamera, RigError};
pub use skips::{SkipRow, Skips, TopicSkips};
pub use truth::Stamped;

/// The topic a logical name maps to in a pipeline file's `[topics]` table, else `default`.
pub fn topic(
    topics: &BTreeMap<String, String>,
    logical: &str,
    default: impl Into<String>,
) -> String {
    topics
        .get(logical)
        .cloned()
        .unwrap_or_else(|| default.into())
}

#[cfg(test)]
mod tests;

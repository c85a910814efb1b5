//! peopletrack: offline people-tracking analytics over MCAP session logs.
//!
//! Data flows one way: a log ([`log`]) is decoded into sensor frames, stages turn frames into
//! detections and tracks, and evaluation turns tracks into tables and figures. See
//! `ARCHITECTURE.md` for the map.

pub mod anchoring;
pub mod assign;
pub mod audio;
pub mod calib;
pub mod eval;
pub mod frames;
pub mod geometry;
pub mod groundtruth;
pub mod laser;
pub mod learn;
pub mod log;
pub mod names;
pub mod pipelines;
pub mod progress;
pub mod report;
pub mod rng;
pub mod run;
pub mod storage;
pub mod synth;
pub mod time;
pub mod track;
pub mod vision;

pub use time::Nanos;

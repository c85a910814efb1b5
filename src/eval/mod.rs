//! Evaluation: statistics for comparing methods, and tracking metrics.
//!
//! - [`stats`]: descriptive statistics, Student / Welch / paired t-tests with confidence
//!   intervals and effect sizes, multiple-comparison corrections, Pearson correlation.
//! - [`mot`]: CLEAR MOT, identity metrics (IDF1) and HOTA with optimal matching, and
//!   MOTChallenge CSV import/export.
//! - [`reid`]: re-identification scores (seed 003's mis-identified observations and people-count
//!   error, pairwise precision / recall / F1, adjusted Rand index).
//!
//! Pure functions of data: nothing here reads logs or writes files.

pub mod mot;
pub mod reid;
pub mod stats;

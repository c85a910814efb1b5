//! Evaluation: statistics for comparing methods, and tracking metrics.
//!
//! - [`stats`]: descriptive statistics, Student / Welch / paired t-tests with confidence
//!   intervals and effect sizes, multiple-comparison corrections, Pearson correlation.
//! - [`mot`]: CLEAR MOT, identity metrics (IDF1) and HOTA with optimal matching, and
//!   MOTChallenge CSV import/export.
//!
//! Pure functions of data: nothing here reads logs or writes files.

pub mod mot;
pub mod stats;

//! Trackers and filters. Pure: no I/O.
//!
//! - [`position`]: the position Kalman filter of seed 000 (x_k = x_{k−1} + u_k + w).

pub mod position;

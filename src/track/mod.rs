//! Trackers and filters: pure computation on detections and camera geometry, no I/O.
//!
//! - [`position`]: the position Kalman filter of seed 000 (x_k = x_{k−1} + u_k + w).
//! - [`kalman`]: linear Kalman filter, constant-velocity and random-walk models.
//! - [`jpda`]: joint probabilistic data association (gated clusters, exact joint events, the
//!   PDAF combined-innovation update).
//! - [`pdaf`]: the single-target filter of seed 001 §V — PDAF with feature likelihood ratios,
//!   CV / coordinated-turn / IMM models, elliptical and maneuver gates, the covariance reset
//!   test; nearest-neighbour variant.
//! - [`graph_match`]: 2-D tracking by graph matching of rectangles (seed 004 §4).
//! - [`height_ekf`]: the (x, y, height) EKF of seed 002 §5 — laser range–bearing and camera
//!   bearing + elevation updates, 3σ gate; a constant-velocity variant.
//! - [`height_tracks`]: several people for that EKF (our addition): GNN inside the 3σ gate,
//!   births from free leg pairs, deletion after a timeout; two-camera head triangulation.
//! - [`cylinders`]: multi-camera 3-D tracking of people as cylinders (seed 004 §5).
//! - [`reid`]: Bayesian re-identification of people across local tracks (seed 003 §IV):
//!   NIW kernels, the paper's spatio-temporal transition, assumed-density filtering.

pub mod cylinders;
pub mod graph_match;
pub mod height_ekf;
pub mod height_tracks;
pub mod jpda;
pub mod kalman;
pub mod pdaf;
pub mod position;
pub mod reid;

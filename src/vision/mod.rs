//! Vision stages: image kernels that turn camera frames into per-pixel masks and detections.
//!
//! - [`view`]: [`ImageView`], a borrowed, checked, tightly packed 8-bit image (grey or colour)
//!   that every kernel here reads.
//! - [`gmm`]: adaptive Gaussian-mixture background subtraction (Zivkovic, ICPR 2004 — the
//!   algorithm behind OpenCV's `BackgroundSubtractorMOG2`) and the Stauffer–Grimson baseline
//!   with a fixed number of components; foreground / shadow / background masks, the
//!   components-per-pixel image and the background image.
//! - [`blobs`]: connected components of a mask (shadow pixels removed) with their moments,
//!   and a 3×3 majority filter.
//! - [`ellipse`]: a region as centre + 2×2 covariance, its axes, Mahalanobis distance and the
//!   overlap (IoU) of two ellipses.
//! - [`colortrack`]: colour-histogram tracking — the EM-like 5-DOF tracker (Zivkovic & Kröse,
//!   CVPR 2004) and mean shift with the ±10 % scale test (Comaniciu et al., CVPR 2000); HS and
//!   RGB histograms, Bhattacharyya similarity.
//! - [`local`]: local tracks — GMM blobs tracked frame to frame, handed to the colour tracker
//!   when the camera moves or the person stands still (the input of re-identification).
//! - [`score`]: precision, recall and F-measure of a mask against a hand-segmented one.
//! - [`synthetic`]: a deterministic synthetic RGB scene (textured background, noise, a
//!   flickering region, a moving object with a shadow) for tests and benchmarks.
//! - [`gabor`]: the Gabor-feature background model and MAD threshold of seed 004 §2.
//! - [`jabri`]: seed 002 §4's background subtraction after Jabri et al. (colour × edge planes,
//!   recursive mean and σ with forgetting, moving-blob rectangles).
//! - [`klt`]: Shi–Tomasi corners and pyramidal Lucas–Kanade tracking (seed 003 §III's
//!   moving-camera features, seed 001's Method 1).
//! - [`skin`]: seed 002 §4's skin segmentation (normalised-rgb histogram back-projection,
//!   smoothing, hysteresis bounded by Canny edges) and the top-fifth person test.
//! - [`template`]: human-silhouette template detection of seed 004 §3.
//! - [`cylinder`]: seed 001 §V's colour feature of a laser blob: the paracatadioptric image on a
//!   cylinder, the blob's spherical ROI at chest height, hue–saturation histograms, the
//!   printed correlation and the likelihood ratio.
//! - [`egomotion`]: seed 001 §IV's Method 1 — omni image as 8 perspective views, KLT on the
//!   raw image, bilinear egomotion compensation per view, frame differencing, particle filter
//!   + EM clustering of the moving region's bearing.
//!
//! Kernels read frames and write into buffers the caller owns; nothing here reads logs or
//! writes files.

pub mod blobs;
pub mod colortrack;
pub mod cylinder;
pub mod egomotion;
pub mod ellipse;
pub mod faces;
pub mod gabor;
pub mod gmm;
pub mod jabri;
pub mod klt;
pub mod local;
pub mod moving;
pub mod omni;
pub mod score;
pub mod sg1999;
pub mod skin;
pub mod synthetic;
pub mod template;
pub mod view;

pub use gmm::{AdaptiveGmm, GmmError, GmmParams, Pruning};
pub use view::{ImageView, ViewError};

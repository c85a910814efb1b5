//! Image stages: background models, foreground segmentation and people detection on camera
//! frames. Kernels take a source and write into a caller-owned destination; they do no I/O.
//!
//! - [`gabor`]: the Gabor-feature background model and MAD threshold of seed 004 §2.
//! - [`template`]: human-silhouette template detection of seed 004 §3.

pub mod gabor;
pub mod template;

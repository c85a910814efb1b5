//! A person's torso colour (seed 003: "the clothing of the upper body part of a person is
//! observed by tracking the color of the person's torso", Fritsch et al. 2004): the
//! hue–saturation histogram of the region below the person's first associated face becomes
//! the model; in later frames the mean-shift colour tracker ([`crate::vision::colortrack`],
//! with its scale test) starts where the anchor's torso projects — so the pan-tilt unit's
//! motion does not throw it off — and reports where it settled and how alike it is.
//!
//! Region sizes are in face units: the torso is taken 2.8 face heights below the face
//! centre, ±0.8 face widths wide and ±1.2 face heights tall (the 2.5σ extent of the
//! tracker's Gaussian region); chosen a priori from adult proportions.

use nalgebra::Point3;

use super::view::{CameraView, FACE_WIDTH_M};
use crate::vision::colortrack::{BinImage, Histogram, kernel_histogram};
use crate::vision::colortrack::{DEFAULT_CUTOFF_SIGMA, MeanShiftParams, mean_shift_scaled};
use crate::vision::ellipse::Ellipse;
use crate::vision::faces::Face;

/// Torso centre below the face centre, in face heights.
const DROP_FACES: f64 = 2.8;
/// σ of the region in face widths (x) and face heights (y).
const SIGMA_X_FACES: f64 = 0.32;
const SIGMA_Y_FACES: f64 = 0.48;
/// Torso centre height as a share of the person's height (between hips at 0.52 and
/// shoulders at 0.82).
const TORSO_Z_SHARE: f64 = 0.67;

/// A torso model, or the face it is to be taken below.
#[derive(Debug, Clone)]
pub enum Torso {
    Pending(Face),
    Model(Histogram),
}

impl Torso {
    pub fn pending(face: Face) -> Torso {
        Torso::Pending(face)
    }

    /// Take the model (first call after [`Torso::pending`]) or track the torso of a person
    /// at `position` (world, m) of height `height_m`: the region's centre (px) and the
    /// Bhattacharyya coefficient with the model.
    pub fn track(
        &mut self,
        bins: &BinImage,
        view: &CameraView,
        position: [f64; 2],
        height_m: f64,
    ) -> Option<([f64; 2], f64)> {
        match self {
            Torso::Pending(f) => {
                let c = f.center();
                let region = Ellipse::from_parts(
                    c[0],
                    c[1] + DROP_FACES * f.height,
                    (SIGMA_X_FACES * f.width).powi(2),
                    0.0,
                    (SIGMA_Y_FACES * f.height).powi(2),
                );
                let model = kernel_histogram(bins, &region, DEFAULT_CUTOFF_SIGMA)?;
                *self = Torso::Model(model);
                Some(([region.center.x, region.center.y], 1.0))
            }
            Torso::Model(model) => {
                let p = Point3::new(position[0], position[1], TORSO_Z_SHARE * height_m);
                let px = view.pixel(&p, 0.0)?;
                let o = view.origin();
                let dist = (p - o).norm();
                let face_px = view.focal_px() * FACE_WIDTH_M / dist.max(0.3);
                let start = Ellipse::from_parts(
                    px[0],
                    px[1],
                    (SIGMA_X_FACES * face_px).powi(2),
                    0.0,
                    (SIGMA_Y_FACES * face_px * 1.2).powi(2),
                );
                let r = mean_shift_scaled(bins, model, &start, &MeanShiftParams::default()).ok()?;
                (!r.lost).then_some(([r.region.center.x, r.region.center.y], r.similarity))
            }
        }
    }
}

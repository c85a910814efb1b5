//! One camera's chain per frame: Gabor background (bootstrapped from images spread over the
//! log, §2) → silhouette templates (§3) or the log's detections → 2-D graph matching (§4).

use anyhow::Context;
use image::RgbImage;

use super::super::{BackgroundUpdate, Nms, Params};
use super::boxes::{box_head, boxes_from_detections, graph_params};
use super::errors;
use super::input::Payload;
use crate::geometry::triangulate::CalibratedView;
use crate::pipelines::s004_mohedano_multicam::tables::Error2dRow;
use crate::track::cylinders::Object2d;
use crate::track::graph_match::{Box2d, GraphTracker};
use crate::vision::gabor::{GaborBackground, GaborBank, GaborParams, GhostTest, Mask, Update};
use crate::vision::template::{self, Detection, DetectorParams, Silhouette};

/// Per-camera state of the paper's image chain.
pub(crate) struct CameraChain {
    /// Index of the camera (in `Params::cameras`).
    camera: usize,
    background: GaborBackground,
    mask: Mask,
    templates: Vec<Silhouette>,
    /// The template tried at each head position (`templates_by_position`).
    map: Option<template::TemplateMap>,
    tracker: GraphTracker,
}

/// One camera's output for one frame.
#[derive(Default)]
pub(crate) struct CameraOut {
    pub threshold: f64,
    pub foreground_frac: f64,
    pub detections: Vec<Detection>,
    pub objects: Vec<Object2d>,
    pub failed: Option<String>,
    pub present: bool,
    /// The misses and false detections of this frame with their causes (template chain, with
    /// ground truth).
    pub errors: Vec<Error2dRow>,
}

/// What every camera's chain shares.
pub(crate) struct ChainSetup {
    pub bank: GaborBank,
    pub detector: DetectorParams,
    /// The paper's image chain (false: log detections).
    pub use_images: bool,
}

impl ChainSetup {
    pub fn new(p: &Params, use_images: bool) -> anyhow::Result<ChainSetup> {
        Ok(ChainSetup {
            bank: GaborBank::new(GaborParams {
                sigma_px: p.gabor_sigma_px,
                wavelength_px: p.gabor_wavelength_px,
            })?,
            detector: DetectorParams {
                threshold: p.template_threshold,
                stride_px: p.template_stride_px,
                nms_iou: p.nms_iou,
                nms_contained: p.nms_contained,
                suppression: match p.nms {
                    Nms::Boxes => template::Suppression::Boxes,
                    Nms::Heads => template::Suppression::Heads {
                        radius: p.nms_head_radius,
                    },
                },
                ..DetectorParams::default()
            },
            use_images,
        })
    }
}

impl CameraChain {
    /// The chain of camera `c`: its calibrated templates and a background started from `boot`
    /// (the per-pixel median of those images; none: the first frame).
    pub fn new(
        c: usize,
        view: &CalibratedView,
        p: &Params,
        setup: &ChainSetup,
        boot: Option<&[RgbImage]>,
        file: &str,
    ) -> anyhow::Result<CameraChain> {
        let templates = if setup.use_images {
            template::calibrated_templates(
                view,
                p.room_m,
                p.person_height_m,
                p.template_scales,
                p.template_tilts,
            )
            .with_context(|| format!("{file}: templates of camera {}", p.cameras[c]))?
            .into_iter()
            .map(|t| {
                t.widened(p.template_width)
                    .grown(p.template_grow_px)
                    .padded(p.template_fill)
            })
            .collect()
        } else {
            Vec::new()
        };
        let update = match p.background_update {
            BackgroundUpdate::All => Update::All,
            BackgroundUpdate::Selective => Update::Selective {
                foreground_alpha: p.foreground_alpha,
                dilate_px: setup.bank.radius() as u32,
            },
        };
        let mut background =
            GaborBackground::new(setup.bank.clone(), p.alpha, p.mad_k)?.with_update(update)?;
        if p.ghost_removal {
            background = background.with_ghost_removal(GhostTest {
                band_px: p.ghost_band_px,
                frames: p.ghost_frames,
                grow_px: p.ghost_grow_px,
            });
        }
        if let Some(frames) = boot
            && !frames.is_empty()
        {
            background.bootstrap(frames).with_context(|| {
                format!("{file}: background bootstrap of camera {}", p.cameras[c])
            })?;
        }
        let map = (setup.use_images && p.templates_by_position).then(|| {
            template::TemplateMap::new(
                view,
                &templates,
                p.person_height_m,
                p.room_m,
                p.room_margin_m,
            )
        });
        Ok(CameraChain {
            camera: c,
            map,
            background,
            mask: Mask::default(),
            templates,
            tracker: GraphTracker::new(graph_params(p, 0.04)),
        })
    }

    /// One frame of this camera: its payload (none: the camera missed the frame) to 2-D
    /// objects; with `truth`, the template chain's errors are named too.
    pub fn step(
        &mut self,
        payload: Option<Payload>,
        p: &Params,
        view: &CalibratedView,
        detector: &DetectorParams,
        truth: Option<&errors::Context>,
    ) -> CameraOut {
        let mut out = CameraOut::default();
        let boxes: Vec<Box2d> = match payload {
            None => Vec::new(),
            Some(Payload::Detections(d)) => {
                out.present = true;
                boxes_from_detections(&d, box_head(p, view))
            }
            Some(Payload::Image(img)) => {
                out.present = true;
                match img.decode() {
                    Ok(rgb) => {
                        let boxes = self.detect(&rgb, detector, &mut out);
                        if let Some(ctx) = truth
                            && out.failed.is_none()
                        {
                            let ch = errors::Chain {
                                camera: &p.cameras[self.camera],
                                view,
                                templates: &self.templates,
                                map: self.map.as_ref(),
                                detector,
                                p,
                            };
                            out.errors = errors::classify(&ch, ctx, &self.mask, &out.detections);
                        }
                        boxes
                    }
                    Err(e) => {
                        out.failed = Some(e.to_string());
                        Vec::new()
                    }
                }
            }
        };
        let c = self.camera;
        let box_head = super::box_head_for_3d(p);
        out.objects = self
            .tracker
            .step(&boxes)
            .into_iter()
            .map(|o| Object2d {
                camera: c,
                id: o.id,
                head_px: if box_head {
                    boxes[o.detection].head_px
                } else {
                    o.head_px
                },
                width_px: o.width_px,
                foot_px: Some([(o.bbox[0] + o.bbox[2]) / 2.0, o.bbox[3]]),
            })
            .collect();
        out
    }

    /// Background subtraction and template detection on one image.
    fn detect(
        &mut self,
        rgb: &RgbImage,
        detector: &DetectorParams,
        out: &mut CameraOut,
    ) -> Vec<Box2d> {
        match self.background.apply(rgb, &mut self.mask) {
            Ok(seg) => {
                out.threshold = seg.threshold;
                out.foreground_frac =
                    seg.foreground as f64 / (f64::from(rgb.width()) * f64::from(rgb.height()));
                out.detections =
                    template::detect_with(&self.mask, &self.templates, self.map.as_ref(), detector);
                out.detections
                    .iter()
                    .map(|d| Box2d {
                        bbox: d.bbox,
                        head_px: d.head_px,
                        width_px: d.width_px,
                        height_px: d.height_px,
                    })
                    .collect()
            }
            Err(e) => {
                out.failed = Some(e.to_string());
                Vec::new()
            }
        }
    }
}

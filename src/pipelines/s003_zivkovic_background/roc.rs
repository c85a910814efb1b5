//! ROC of background subtraction (paper fig. 1), the per-session part: every ROC model at
//! every swept c_thr, scored against the exact person masks — the adaptive GMM, the fixed-M
//! baseline and the `[[params.roc.extra]]` variants (seed 003's model as printed, Stauffer &
//! Grimson as published, …); per session the mask counts, the mean components per pixel of
//! the variants, and the pixels of standing vs walking people that the adaptive model at
//! c_thr = 16 calls foreground (the TP ceiling of scenes where people stand). The tables,
//! summary and figures are in `roc_report`.
//!
//! A `gmm` model runs once per c_thr (c_thr also moves OpenCV's shadow test); an `sg1999`
//! model runs once, and its per-pixel distance to the background components is cut at every
//! c_thr (its update does not depend on c_thr).

use rayon::prelude::*;

use super::components::mean_components;
use super::params::{Params, RocParams, model_name};
use super::shared::Frame;
use crate::report::rows::Rows;
use crate::run::SessionTables;
use crate::table_row;
use crate::vision::gmm::{BACKGROUND, FOREGROUND};
use crate::vision::score::{MaskCounts, ShadowAs};
use crate::vision::sg1999::{Sg1999, Sg1999Params};
use crate::vision::{AdaptiveGmm, GmmParams};

/// The threshold at which the summary and the standing/walking counts read the models
/// (OpenCV's default varThreshold).
pub(super) const DEFAULT_C_THR: f64 = 16.0;
/// A ground-truth person slower than this (m/s) is standing.
pub(super) const STANDING_SPEED_MPS: f64 = 0.05;
/// Cached per-session tables.
pub(super) const COUNTS_TABLE: &str = "roc";
pub(super) const PEOPLE_TABLE: &str = "roc_people";
pub(super) const COMPONENTS_TABLE: &str = "roc_components";

table_row! {
    /// Cached per session: one model at one c_thr, mask counts summed over the scored frames.
    #[derive(Debug, Clone, PartialEq)]
    pub(super) struct RocCounts {
        pub model: String,
        pub var_threshold: f64,
        pub true_positive: i64,
        pub false_positive: i64,
        pub false_negative: i64,
        pub true_negative: i64,
        pub frames: i64,
    }
}

table_row! {
    /// Cached per session: person pixels (exact mask inside a person's box) of standing or
    /// walking people, and how the adaptive model at c_thr = 16 labelled them.
    #[derive(Debug, Clone, Default, PartialEq)]
    pub(super) struct PeopleCounts {
        pub standing: bool,
        pub views: i64,
        pub person_px: i64,
        pub foreground_px: i64,
        pub shadow_px: i64,
    }
}

table_row! {
    /// Cached per session: a variant's mean components per pixel summed over the frames
    /// with masks (the two timed models have theirs in `components`).
    #[derive(Debug, Clone, PartialEq)]
    pub(super) struct VariantComponents {
        pub model: String,
        pub mean_components_sum: f64,
        pub frames: i64,
    }
}

/// Which model a ROC curve comes from.
#[derive(Debug, Clone, Copy)]
pub(super) enum ModelSpec<'a> {
    Gmm(GmmParams),
    Sg1999(&'a Sg1999Params),
}

/// One ROC model: its `roc_summary` column, its `roc` label, the model.
#[derive(Debug, Clone, Copy)]
pub(super) struct Variant<'a> {
    pub name: &'a str,
    pub label: &'a str,
    pub spec: ModelSpec<'a>,
}

/// The ROC models in table order: the adaptive GMM, the fixed-M baseline, then
/// `[[params.roc.extra]]` in file order (an entry without a model table is left out; the
/// validation names it).
pub(super) fn variants(p: &RocParams) -> Vec<Variant<'_>> {
    let mut out = vec![
        Variant {
            name: "adaptive",
            label: model_name(true),
            spec: ModelSpec::Gmm(p.adaptive),
        },
        Variant {
            name: "fixed_m4",
            label: model_name(false),
            spec: ModelSpec::Gmm(p.baseline),
        },
    ];
    for v in &p.extra {
        let spec = match (&v.gmm, &v.sg1999) {
            (Some(g), _) => ModelSpec::Gmm(*g),
            (None, Some(sg)) => ModelSpec::Sg1999(sg),
            (None, None) => continue,
        };
        out.push(Variant {
            name: &v.name,
            label: &v.label,
            spec,
        });
    }
    out
}

/// A `gmm` model at one c_thr.
struct RocModel {
    /// Index into [`variants`].
    variant: usize,
    var_threshold: f32,
    gmm: AdaptiveGmm,
    mask: Vec<u8>,
    counts: MaskCounts,
    frames: i64,
}

/// An `sg1999` model, cut at every c_thr.
struct SgModel {
    variant: usize,
    model: Sg1999,
    dist2: Vec<f32>,
    mask: Vec<u8>,
    /// Per c_thr of `RocRun::thresholds`.
    counts: Vec<MaskCounts>,
    frames: i64,
}

/// The ROC models of one session and their counts.
pub(super) struct RocRun {
    labels: Vec<String>,
    thresholds: Vec<f32>,
    models: Vec<RocModel>,
    sg: Vec<SgModel>,
    /// Per variant: the sum over frames of its mean components per pixel, and the frames.
    components: Vec<(f64, i64)>,
    skip_frames: usize,
    /// Frames with an exact mask seen (scored or not).
    masked_frames: usize,
    camera: String,
    /// `[walking, standing]`.
    people: [PeopleCounts; 2],
}

impl RocRun {
    /// Every model at every c_thr when `active`; nothing otherwise.
    pub fn new(p: &Params, active: bool) -> anyhow::Result<Self> {
        let (mut models, mut sg, mut labels) = (Vec::new(), Vec::new(), Vec::new());
        if active {
            for (variant, v) in variants(&p.roc).into_iter().enumerate() {
                labels.push(v.label.to_string());
                match v.spec {
                    ModelSpec::Gmm(base) => {
                        for &var_threshold in &p.roc.var_thresholds {
                            models.push(RocModel {
                                variant,
                                var_threshold,
                                gmm: AdaptiveGmm::new(GmmParams {
                                    var_threshold,
                                    ..base
                                })?,
                                mask: Vec::new(),
                                counts: MaskCounts::default(),
                                frames: 0,
                            });
                        }
                    }
                    ModelSpec::Sg1999(params) => sg.push(SgModel {
                        variant,
                        model: Sg1999::new(*params)?,
                        dist2: Vec::new(),
                        mask: Vec::new(),
                        counts: vec![MaskCounts::default(); p.roc.var_thresholds.len()],
                        frames: 0,
                    }),
                }
            }
        }
        let people = [false, true].map(|standing| PeopleCounts {
            standing,
            ..Default::default()
        });
        Ok(Self {
            components: vec![(0.0, 0); labels.len()],
            labels,
            thresholds: p.roc.var_thresholds.clone(),
            models,
            sg,
            skip_frames: p.roc.skip_frames,
            masked_frames: 0,
            camera: p.camera.clone(),
            people,
        })
    }

    /// Update every model with a frame that has an exact mask; count after `skip_frames`.
    pub fn step(&mut self, f: &Frame) -> anyhow::Result<()> {
        let Some(truth) = f.mask else { return Ok(()) };
        if self.models.is_empty() && self.sg.is_empty() {
            return Ok(());
        }
        let scored = f.index as usize >= self.skip_frames;
        self.masked_frames += 1;
        let npx = truth.len();
        let thresholds = &self.thresholds;
        let (gmm, sg) = rayon::join(
            || {
                self.models
                    .par_iter_mut()
                    .try_for_each(|m| -> anyhow::Result<()> {
                        m.mask.resize(npx, 0);
                        m.gmm.apply(f.view, None, &mut m.mask)?;
                        if scored
                            && let Some(c) = MaskCounts::count(&m.mask, truth, ShadowAs::Background)
                        {
                            add_counts(&mut m.counts, &c);
                            m.frames += 1;
                        }
                        Ok(())
                    })
            },
            || {
                self.sg.iter_mut().try_for_each(|m| -> anyhow::Result<()> {
                    m.dist2.resize(npx, 0.0);
                    m.mask.resize(npx, 0);
                    m.model.apply_distance(f.view, &mut m.dist2)?;
                    if scored {
                        m.frames += 1;
                        for (k, &thr) in thresholds.iter().enumerate() {
                            for (o, &d) in m.mask.iter_mut().zip(&m.dist2) {
                                *o = if d < thr { BACKGROUND } else { FOREGROUND };
                            }
                            if let Some(c) = MaskCounts::count(&m.mask, truth, ShadowAs::Background)
                            {
                                add_counts(&mut m.counts[k], &c);
                            }
                        }
                    }
                    Ok(())
                })
            },
        );
        gmm?;
        sg?;
        self.count_components();
        self.count_people(f, truth, scored);
        Ok(())
    }

    /// Mean components per pixel of each extra variant (its first c_thr's model: a `gmm`
    /// model's components do not depend on c_thr).
    fn count_components(&mut self) {
        for variant in 2..self.labels.len() {
            let gmm = self.models.iter().find(|m| m.variant == variant);
            let mean = match gmm {
                Some(m) => mean_components(&m.gmm),
                None => match self.sg.iter().find(|m| m.variant == variant) {
                    Some(m) => mean_of(&m.model.components_per_pixel()),
                    None => continue,
                },
            };
            let c = &mut self.components[variant];
            c.0 += mean;
            c.1 += 1;
        }
    }

    /// The standing / walking person pixels and the adaptive model's labels at c_thr = 16.
    fn count_people(&mut self, f: &Frame, truth: &[u8], scored: bool) {
        let default = self
            .models
            .iter()
            .find(|m| m.variant == 0 && f64::from(m.var_threshold) == DEFAULT_C_THR);
        if let (true, Some(m), Some(people)) = (scored, default, f.truth) {
            let shadow = m.gmm.params().shadow_value;
            let width = f.rgb.width() as usize;
            for q in &people.people {
                let standing = q.vx.hypot(q.vy) < STANDING_SPEED_MPS;
                for v in q.cameras.iter().filter(|v| v.camera == self.camera) {
                    if let Some(b) = v.bbox {
                        let c = &mut self.people[usize::from(standing)];
                        c.views += 1;
                        count_person(&m.mask, truth, width, b, shadow, c);
                    }
                }
            }
        }
    }

    /// The cached `roc`, `roc_people` and `roc_components` tables (none when the models did
    /// not run).
    pub fn finish(self, out: &mut SessionTables) -> anyhow::Result<()> {
        if self.labels.is_empty() {
            return Ok(());
        }
        let all_frames = self.models.iter().map(|m| m.frames);
        if self.masked_frames > 0
            && all_frames
                .chain(self.sg.iter().map(|m| m.frames))
                .all(|n| n == 0)
        {
            // every masked frame fell inside the skipped start: the ROC would be 0/0 = NaN
            anyhow::bail!(
                "`params.roc.skip_frames` = {} leaves no frame to score: the session has {} \
                 frames with exact masks, all among its first {} frames",
                self.skip_frames,
                self.masked_frames,
                self.skip_frames
            );
        }
        let row = |variant: usize, thr: f32, c: &MaskCounts, frames: i64| RocCounts {
            model: self.labels[variant].clone(),
            var_threshold: f64::from(thr),
            true_positive: c.true_positive as i64,
            false_positive: c.false_positive as i64,
            false_negative: c.false_negative as i64,
            true_negative: c.true_negative as i64,
            frames,
        };
        let mut rows = Vec::new();
        for variant in 0..self.labels.len() {
            for m in self.models.iter().filter(|m| m.variant == variant) {
                rows.push(row(variant, m.var_threshold, &m.counts, m.frames));
            }
            for m in self.sg.iter().filter(|m| m.variant == variant) {
                for (&thr, c) in self.thresholds.iter().zip(&m.counts) {
                    rows.push(row(variant, thr, c, m.frames));
                }
            }
        }
        let components: Vec<VariantComponents> = (2..self.labels.len())
            .map(|v| VariantComponents {
                model: self.labels[v].clone(),
                mean_components_sum: self.components[v].0,
                frames: self.components[v].1,
            })
            .collect();
        out.insert(COUNTS_TABLE.into(), RocCounts::frame(&rows)?);
        out.insert(PEOPLE_TABLE.into(), PeopleCounts::frame(&self.people)?);
        out.insert(
            COMPONENTS_TABLE.into(),
            VariantComponents::frame(&components)?,
        );
        Ok(())
    }
}

fn mean_of(counts: &[u8]) -> f64 {
    let sum: u64 = counts.iter().map(|&c| u64::from(c)).sum();
    sum as f64 / counts.len().max(1) as f64
}

/// Person pixels of the exact mask inside `bbox` (`[x0, y0, x1, y1]` inclusive), and how many
/// of them `predicted` calls foreground or shadow.
fn count_person(
    predicted: &[u8],
    truth: &[u8],
    width: usize,
    bbox: [f64; 4],
    shadow: u8,
    c: &mut PeopleCounts,
) {
    let height = truth.len() / width.max(1);
    if width == 0 || height == 0 {
        return;
    }
    let x0 = bbox[0].max(0.0) as usize;
    let y0 = bbox[1].max(0.0) as usize;
    // the logged box is right and bottom exclusive: its last pixel is x1 - 1
    let x1 = ((bbox[2] - 1.0).max(0.0) as usize).min(width - 1);
    let y1 = ((bbox[3] - 1.0).max(0.0) as usize).min(height - 1);
    for y in y0..=y1 {
        for x in x0..=x1 {
            let i = y * width + x;
            if truth[i] != FOREGROUND {
                continue;
            }
            c.person_px += 1;
            c.foreground_px += i64::from(predicted[i] == FOREGROUND);
            c.shadow_px += i64::from(predicted[i] == shadow && shadow != FOREGROUND);
        }
    }
}

pub(super) fn add_counts(a: &mut MaskCounts, b: &MaskCounts) {
    a.true_positive += b.true_positive;
    a.false_positive += b.false_positive;
    a.false_negative += b.false_negative;
    a.true_negative += b.true_negative;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn skip_frames_past_every_masked_frame_is_an_error_naming_it() {
        let p = Params::default();
        // masked frames were seen, none was scored: 0/0 would be a NaN table
        let mut run = RocRun::new(&p, true).expect("models");
        run.masked_frames = 3;
        let err = run
            .finish(&mut SessionTables::new())
            .expect_err("nothing scored")
            .to_string();
        assert!(
            err.starts_with("`params.roc.skip_frames` = 45 leaves no frame to score")
                && err.contains(" 3 frames with exact masks"),
            "{err}"
        );
        // a session without masks has no ROC at all, and is not an error
        let mut out = SessionTables::new();
        RocRun::new(&p, true)
            .expect("models")
            .finish(&mut out)
            .expect("no masks");
        assert!(out.contains_key(COUNTS_TABLE));
    }

    #[test]
    fn the_variants_are_the_two_models_then_the_extras_in_file_order() {
        let p = Params::default();
        let v = variants(&p.roc);
        let names: Vec<&str> = v.iter().map(|v| v.name).collect();
        assert_eq!(names, ["adaptive", "fixed_m4", "printed", "sg1999"]);
        assert!(matches!(v[2].spec, ModelSpec::Gmm(g) if g == GmmParams::zivkovic_printed()));
        assert!(matches!(v[3].spec, ModelSpec::Sg1999(_)));
        // every gmm variant runs at every c_thr, an sg1999 variant once
        let run = RocRun::new(&p, true).expect("models");
        assert_eq!(run.models.len(), 3 * p.roc.var_thresholds.len());
        assert_eq!(run.sg.len(), 1);
        assert!(RocRun::new(&p, false).expect("none").labels.is_empty());
    }

    #[test]
    fn person_pixels_are_the_mask_inside_the_box() {
        // 4x3 image; the person is the 2x2 block at x 1..=2, y 0..=1, plus one pixel outside
        // the box that must not count
        let truth = [0, 255, 255, 0, 0, 255, 255, 0, 255, 0, 0, 0];
        let predicted = [0, 255, 127, 255, 0, 0, 255, 0, 255, 0, 0, 0];
        let mut c = PeopleCounts::default();
        // the logged box is right / bottom exclusive
        count_person(&predicted, &truth, 4, [1.0, 0.0, 3.0, 2.0], 127, &mut c);
        assert_eq!((c.person_px, c.foreground_px, c.shadow_px), (4, 2, 1));
    }
}

//! Seed 001 §V (Kobilarov et al.): the single-target tracker of a person-following robot.
//! Each scan is cut into blobs that might be people (the kinematic measurements); each blob's
//! region in the omni image, lifted to chest height, gives a hue–saturation histogram whose
//! correlation with the target's template is the feature likelihood ratio
//! ([`crate::vision::cylinder`]); a PDAF with a constant-velocity, coordinated-turn or IMM
//! model, or a nearest-neighbour filter ([`crate::track::pdaf`]), follows the target; when
//! the position covariance passes the `rst` limit the track is dropped (the robot stops) and
//! re-initialised.
//!
//! **Start and re-acquisition.** The track starts on the blob nearest the point the operator
//! gives (within `init_radius_m`); the colour template is taken there (or, when no omni frame
//! is there yet, on the first accepted scan that has one) and held, or updated with weight
//! `template_update` per accepted scan. After `rst` the follower looks within a radius of the
//! last prediction that grows at `v_max` from `reinit_radius_m` to `reinit_max_m`: with colour,
//! it takes the blob with the highest likelihood ratio among those whose **normalised**
//! correlation with the template is at least `reacquire_corr` (seed 001 §VI: descriptors kept
//! "so that the tracker can reacquire the correct human"); when none passes it stays lost —
//! the robot stops and turns towards the last prediction ([`StepOutput::look_at`]) — and keeps
//! looking. Without colour (or before any template) it takes the nearest blob, as at the start.
//!
//! **Colour watchdog** (our addition, off in the paper's configuration:
//! `FollowParams::colour_watch_s`). The paper's only `rst` is the covariance test, and a track
//! fed by the wrong blob never trips it: an occluder or a companion in the gate while the
//! target's own blob is missing takes nearly all the association weight whatever its colour,
//! because the no-target hypothesis weighs only λ|2πS|^{1/2}(1 − P_D P_G) ≈ 0.002 against
//! P_D·lr ≈ 0.05–0.2 for a blob of another colour. With the watchdog, when every update that
//! moved the track (β₀ < ½) for `colour_watch_s` seconds came mostly from a blob whose
//! normalised correlation with the template is below `reacquire_corr`, the track is dropped as
//! by `rst` and re-acquired by colour.
//!
//! **Other people** (our addition, off in the paper's configuration: `FollowParams::others`).
//! The follower also tracks every blob the target did not take, and a blob one of those
//! tracks predicts well counts less as the target's: the target's marginal of a JPDA over it
//! and the others, fed to the PDAF as a factor on the likelihood ratio ([`others`]). A
//! companion in the gate while the target's own blob is missing is then explained by the
//! companion's own track; the filter coasts and, if the gap lasts, `rst` fires and colour
//! re-acquires.
//!
//! **Blobs** (our reading of "connected components that might have originated from people"):
//! jump-distance segments ([`crate::laser::segment`]) merged while the gap between the end of
//! one and the start of the next is under `merge_gap_m` (a person's two legs), kept when at
//! most `max_width_m` wide (a ground hit of a pitching robot is a long arc and is not a
//! blob) and within `max_range_m`. The measurement is the mean of the blob's points; its
//! edges are its first and last points.
//!
//! Everything happens in one fixed frame (`odom` on the robot); the caller gives the points
//! there, and the camera pose that maps fixed-frame points into the omni camera frame.

use image::RgbImage;
use nalgebra::Isometry3;

use crate::geometry::camera::Paracatadioptric;
use crate::laser::points::{self, ScanPoint};
use crate::laser::segment::{self, SegmentOptions, Threshold};
use serde::{Deserialize, Serialize};

use crate::track::pdaf::{AssociationKind, FilterError, FilterParams, ModelKind, TargetFilter};
use crate::vision::cylinder::{self, CorrForm, CylinderMap};

pub mod others;
use others::{BlobColour, Others, OthersParams, Shared};

/// The default floor on the normalised correlation (a correlation coefficient, ≤ 1) with the
/// template for re-acquisition after `rst`: see `FollowParams::default`.
pub const REACQUIRE_CORR: f64 = 0.5;

/// Parameters of the follower (the filter's inside).
#[derive(Debug, Clone, PartialEq)]
pub struct FollowParams {
    pub filter: FilterParams,
    /// Jump distance that splits segments (m).
    pub jump_m: f64,
    /// Adjacent segments closer than this merge into one blob (m).
    pub merge_gap_m: f64,
    pub min_points: usize,
    pub max_width_m: f64,
    pub min_range_m: f64,
    pub max_range_m: f64,
    /// Use the colour likelihood ratio (false: lr = 1 for every blob).
    pub colour: bool,
    /// Height the blob is lifted to (chest) and half the ROI's vertical extent (m).
    pub chest_height_m: f64,
    pub roi_half_height_m: f64,
    /// The paper's corr_min ("a small negative number").
    pub corr_min: f64,
    /// Which correlation the likelihood ratio uses (normalised by default; `Printed` is the
    /// formula as printed, see [`crate::vision::cylinder`]).
    pub corr_form: CorrForm,
    /// Re-acquisition after `rst` with colour: the least normalised correlation with the
    /// template a blob needs.
    pub reacquire_corr: f64,
    /// Template update weight per accepted scan (0: the template stays as initialised).
    pub template_update: f64,
    /// The first blob must lie this close to the initial point (m).
    pub init_radius_m: f64,
    /// Re-initialisation after `rst`: the nearest blob within this radius of the last
    /// estimate (m), growing at `v_max` while the target is lost, up to `reinit_max_m`.
    pub reinit_radius_m: f64,
    pub reinit_max_m: f64,
    /// Cylinder resolution (columns over 2π, rows over the mirror's elevations).
    pub cylinder: [usize; 2],
    /// Our addition, off in the paper's configuration: a colour watchdog. When, for this many
    /// seconds, every update that moved the track (β₀ < ½) took it mostly from a blob whose
    /// normalised correlation with the template is below `reacquire_corr`, the track is
    /// dropped as by `rst` and re-acquired by colour (see the module doc).
    pub colour_watch_s: Option<f64>,
    /// Our reading of seed 001 §VI, off in the paper's configuration: returns placed (with
    /// the IMU's pitch and roll) below this height in the fixed frame are the ground and make
    /// no blob — "there are no valid measurements of the human" while the laser sees the
    /// ground ([`points::above_ground`]; needs [`ScanObs::laser_pose`]).
    pub ground_below_m: Option<f64>,
    /// Our addition, off in the paper's configuration: tracks of the other people, whose
    /// blobs then count less as the target's ([`others`]).
    pub others: Option<OthersParams>,
}

impl Default for FollowParams {
    /// Chosen a priori (not searched): blobs as wide as a person with both legs, the chest at
    /// 1.3 m for a 1.8 m person, ±0.3 m of torso, corr_min −0.1; the normalised correlation
    /// (the paper's text); re-acquisition on a normalised correlation of at least
    /// [`REACQUIRE_CORR`] within a radius growing to the blobs' `max_range_m`.
    fn default() -> Self {
        FollowParams {
            filter: FilterParams::default(),
            jump_m: 0.1,
            merge_gap_m: 0.5,
            min_points: 2,
            max_width_m: 1.0,
            min_range_m: 0.3,
            max_range_m: 10.0,
            colour: true,
            chest_height_m: 1.3,
            roi_half_height_m: 0.3,
            corr_min: -0.1,
            corr_form: CorrForm::Normalised,
            reacquire_corr: REACQUIRE_CORR,
            template_update: 0.0,
            init_radius_m: 1.0,
            reinit_radius_m: 1.5,
            reinit_max_m: 10.0,
            cylinder: [720, 120],
            colour_watch_s: None,
            ground_below_m: None,
            others: None,
        }
    }
}

/// The follower's settings as a pipeline or scenario file writes them (`[params.follower]`,
/// `[robot.follow.pdaf]`); [`FollowSpec::params`] picks the motion model, the association and
/// whether colour is used.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FollowSpec {
    pub p_d: f64,
    pub gate: f64,
    pub clutter_density: f64,
    pub sigma_r: f64,
    pub accel_noise: f64,
    pub turn_noise: f64,
    pub imm_switch: f64,
    pub v_max: f64,
    pub a_max: f64,
    pub reset_sigmas: f64,
    pub init_speed_sigma: f64,
    pub init_turn_sigma: f64,
    pub jump_m: f64,
    pub merge_gap_m: f64,
    pub min_points: usize,
    pub max_width_m: f64,
    pub min_range_m: f64,
    pub max_range_m: f64,
    pub chest_height_m: f64,
    pub roi_half_height_m: f64,
    pub corr_min: f64,
    pub corr_form: CorrForm,
    pub reacquire_corr: f64,
    pub template_update: f64,
    pub init_radius_m: f64,
    pub reinit_radius_m: f64,
    pub reinit_max_m: f64,
    /// The colour watchdog (our addition; absent: off, the paper's tracker).
    pub colour_watch_s: Option<f64>,
    /// Ground hits make no blob (our reading; absent: off, the paper's configuration).
    pub ground_below_m: Option<f64>,
    /// Tracks of the other people discount their blobs (our addition, [`others`]; false: the
    /// paper's tracker).
    pub others: bool,
}

impl Default for FollowSpec {
    fn default() -> Self {
        let p = FollowParams::default();
        let f = &p.filter;
        FollowSpec {
            p_d: f.p_d,
            gate: f.gate,
            clutter_density: f.clutter_density,
            sigma_r: f.sigma_r,
            accel_noise: f.accel_noise,
            turn_noise: f.turn_noise,
            imm_switch: f.imm_switch,
            v_max: f.v_max,
            a_max: f.a_max,
            reset_sigmas: f.reset_sigmas,
            init_speed_sigma: f.init_speed_sigma,
            init_turn_sigma: f.init_turn_sigma,
            jump_m: p.jump_m,
            merge_gap_m: p.merge_gap_m,
            min_points: p.min_points,
            max_width_m: p.max_width_m,
            min_range_m: p.min_range_m,
            max_range_m: p.max_range_m,
            chest_height_m: p.chest_height_m,
            roi_half_height_m: p.roi_half_height_m,
            corr_min: p.corr_min,
            corr_form: p.corr_form,
            reacquire_corr: p.reacquire_corr,
            template_update: p.template_update,
            init_radius_m: p.init_radius_m,
            reinit_radius_m: p.reinit_radius_m,
            reinit_max_m: p.reinit_max_m,
            colour_watch_s: p.colour_watch_s,
            ground_below_m: p.ground_below_m,
            others: p.others.is_some(),
        }
    }
}

impl FollowSpec {
    /// The follower's parameters with this motion model, association and colour setting.
    pub fn params(
        &self,
        model: ModelKind,
        association: AssociationKind,
        colour: bool,
    ) -> FollowParams {
        FollowParams {
            filter: FilterParams {
                model,
                association,
                p_d: self.p_d,
                gate: self.gate,
                clutter_density: self.clutter_density,
                sigma_r: self.sigma_r,
                accel_noise: self.accel_noise,
                turn_noise: self.turn_noise,
                imm_switch: self.imm_switch,
                v_max: self.v_max,
                a_max: self.a_max,
                reset_sigmas: self.reset_sigmas,
                init_speed_sigma: self.init_speed_sigma,
                init_turn_sigma: self.init_turn_sigma,
            },
            jump_m: self.jump_m,
            merge_gap_m: self.merge_gap_m,
            min_points: self.min_points,
            max_width_m: self.max_width_m,
            min_range_m: self.min_range_m,
            max_range_m: self.max_range_m,
            colour,
            chest_height_m: self.chest_height_m,
            roi_half_height_m: self.roi_half_height_m,
            corr_min: self.corr_min,
            corr_form: self.corr_form,
            reacquire_corr: self.reacquire_corr,
            template_update: self.template_update,
            init_radius_m: self.init_radius_m,
            reinit_radius_m: self.reinit_radius_m,
            reinit_max_m: self.reinit_max_m,
            cylinder: FollowParams::default().cylinder,
            colour_watch_s: self.colour_watch_s,
            ground_below_m: self.ground_below_m,
            others: self.others.then(OthersParams::default),
        }
    }

    /// Values that would make the follower meaningless: `(key, reason)`.
    pub fn problems(&self) -> Vec<(String, String)> {
        let mut out = Vec::new();
        for (k, v) in [
            ("sigma_r", self.sigma_r),
            ("gate", self.gate),
            ("accel_noise", self.accel_noise),
            ("turn_noise", self.turn_noise),
            ("v_max", self.v_max),
            ("a_max", self.a_max),
            ("reset_sigmas", self.reset_sigmas),
            ("init_speed_sigma", self.init_speed_sigma),
            ("init_turn_sigma", self.init_turn_sigma),
            ("jump_m", self.jump_m),
            ("max_width_m", self.max_width_m),
            ("max_range_m", self.max_range_m),
            ("init_radius_m", self.init_radius_m),
            ("reinit_radius_m", self.reinit_radius_m),
        ] {
            if !(v.is_finite() && v > 0.0) {
                out.push((k.to_string(), format!("{v} must be finite and > 0")));
            }
        }
        for (k, v) in [
            ("p_d", self.p_d),
            ("imm_switch", self.imm_switch),
            ("template_update", self.template_update),
        ] {
            if !(0.0..=1.0).contains(&v) {
                out.push((k.to_string(), format!("{v} is not in [0, 1]")));
            }
        }
        if !(self.clutter_density.is_finite() && self.clutter_density >= 0.0) {
            out.push((
                "clutter_density".into(),
                format!("{} must be finite and >= 0", self.clutter_density),
            ));
        }
        if let Some(g) = self.ground_below_m
            && !(g.is_finite() && (0.0..=1.0).contains(&g))
        {
            out.push(("ground_below_m".into(), format!("{g} is not in [0, 1] m")));
        }
        if let Some(w) = self.colour_watch_s
            && !(w.is_finite() && w > 0.0)
        {
            out.push((
                "colour_watch_s".into(),
                format!("{w} must be finite and > 0"),
            ));
        }
        if !(self.reacquire_corr.is_finite() && self.reacquire_corr <= 1.0) {
            out.push((
                "reacquire_corr".into(),
                format!(
                    "{} must be finite and <= 1 (a correlation coefficient)",
                    self.reacquire_corr
                ),
            ));
        }
        if !(self.corr_min.is_finite() && self.corr_min <= 0.0) {
            out.push((
                "corr_min".into(),
                format!("{} must be finite and <= 0", self.corr_min),
            ));
        }
        out
    }
}

/// A blob of one scan (fixed frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Blob {
    pub centre: [f64; 2],
    pub left: [f64; 2],
    pub right: [f64; 2],
    pub width: f64,
    pub points: usize,
    pub range: f64,
}

/// The blobs of one scan's points (beam order; see the module doc).
pub fn blobs(points: &[ScanPoint], p: &FollowParams) -> Vec<Blob> {
    let segs = segment::segment(
        points,
        &SegmentOptions {
            threshold: Threshold::Fixed(p.jump_m),
            min_points: 1,
        },
    );
    let mut groups: Vec<std::ops::Range<usize>> = Vec::new();
    for s in segs {
        if let Some(last) = groups.last_mut() {
            let a = points[last.end - 1].fixed;
            let b = points[s.points.start].fixed;
            if (a - b).norm() < p.merge_gap_m {
                last.end = s.points.end;
                continue;
            }
        }
        groups.push(s.points.clone());
    }
    groups
        .into_iter()
        .filter_map(|g| {
            let pts = &points[g];
            let (first, last) = (pts.first()?, pts.last()?);
            let width = (first.fixed - last.fixed).norm();
            let n = pts.len() as f64;
            let cx = pts.iter().map(|q| q.fixed.x).sum::<f64>() / n;
            let cy = pts.iter().map(|q| q.fixed.y).sum::<f64>() / n;
            let range = pts.iter().map(|q| q.range).sum::<f64>() / n;
            (pts.len() >= p.min_points
                && width <= p.max_width_m
                && range >= p.min_range_m
                && range <= p.max_range_m)
                .then_some(Blob {
                    centre: [cx, cy],
                    left: [first.fixed.x, first.fixed.y],
                    right: [last.fixed.x, last.fixed.y],
                    width,
                    points: pts.len(),
                    range,
                })
        })
        .collect()
}

/// The omni image of a scan, with the map from fixed-frame points into its camera frame.
pub struct OmniFrame<'a> {
    pub image: &'a RgbImage,
    pub camera_from_fixed: Isometry3<f64>,
    pub model: &'a Paracatadioptric,
}

/// One scan as the follower sees it.
pub struct ScanObs<'a> {
    pub t: f64,
    /// The scan's returns, fixed frame filled in.
    pub points: &'a [ScanPoint],
    pub omni: Option<OmniFrame<'a>>,
    /// `fixed <- laser`, the pose `points` were placed with (for `ground_below_m`).
    pub laser_pose: Option<&'a Isometry3<f64>>,
}

/// The filter's estimate (fixed frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    pub position: [f64; 2],
    pub velocity: [f64; 2],
    pub covariance: [[f64; 2]; 2],
    pub covariance_norm: f64,
    pub turn_rate: f64,
    /// IMM mode probabilities [CV, CT].
    pub modes: Option<[f64; 2]>,
}

/// What one scan did.
#[derive(Debug, Clone, PartialEq)]
pub struct StepOutput {
    /// `None` while the target is lost (the robot stops).
    pub estimate: Option<Estimate>,
    /// The `rst` rule fired on this scan (the covariance test, or the colour watchdog when
    /// `colour_reset` is set too).
    pub reset: bool,
    /// The colour watchdog (`FollowParams::colour_watch_s`) dropped the track on this scan.
    pub colour_reset: bool,
    /// The track was (re-)initialised on this scan.
    pub initialised: bool,
    pub blobs: usize,
    pub gated: usize,
    pub beta0: Option<f64>,
    /// The blob with the largest association probability (or the one used).
    pub chosen: Option<Blob>,
    /// Its likelihood ratio (1 without colour).
    pub chosen_lr: Option<f64>,
    /// Its normalised correlation with the template (colour, template and image present).
    pub chosen_corr: Option<f64>,
    /// While lost after `rst`: the last prediction, which the robot turns towards.
    pub look_at: Option<[f64; 2]>,
    /// Every blob's centre and normalised correlation with the template (colour, template and
    /// a histogram present), for the colour diagnostics.
    pub blob_corr: Vec<([f64; 2], f64)>,
}

impl StepOutput {
    /// A scan with `blobs` blobs and nothing else yet.
    pub fn empty(blobs: usize) -> StepOutput {
        StepOutput {
            estimate: None,
            reset: false,
            colour_reset: false,
            initialised: false,
            blobs,
            gated: 0,
            beta0: None,
            chosen: None,
            chosen_lr: None,
            chosen_corr: None,
            look_at: None,
            blob_corr: Vec::new(),
        }
    }
}

/// The follower's state.
pub struct FollowTracker {
    params: FollowParams,
    filter: Option<TargetFilter>,
    template: Option<Vec<f64>>,
    /// Where to look for the target when there is no track: the initial point, then the last
    /// estimate before `rst`.
    anchor: [f64; 2],
    lost_at: Option<f64>,
    started: bool,
    map: Option<CylinderMap>,
    /// Since when the track has been fed only by blobs of the wrong colour (the watchdog).
    off_colour_since: Option<f64>,
    /// The other people's tracks (`FollowParams::others`).
    others: Option<Others>,
}

/// One scan's blobs with what colour says about them.
struct Seen<'a> {
    blobs: &'a [Blob],
    hists: &'a [Option<Vec<f64>>],
    lr: &'a [f64],
    /// Normalised correlation with the template, per blob.
    corr: &'a [Option<f64>],
}

impl FollowTracker {
    /// A follower that starts on the blob nearest `init` (fixed frame).
    pub fn new(params: &FollowParams, init: [f64; 2]) -> FollowTracker {
        FollowTracker {
            params: params.clone(),
            filter: None,
            template: None,
            anchor: init,
            lost_at: None,
            started: false,
            map: None,
            off_colour_since: None,
            others: params.others.as_ref().map(Others::new),
        }
    }

    pub fn params(&self) -> &FollowParams {
        &self.params
    }

    /// The filter's values the other people's tracks share.
    fn shared(&self) -> Shared {
        let f = &self.params.filter;
        Shared {
            sigma_r: f.sigma_r,
            p_d: f.p_d,
            gate: f.gate,
            clutter_density: f.clutter_density,
        }
    }

    /// The other people's confirmed tracks (empty when `FollowParams::others` is off).
    pub fn other_people(&self) -> Vec<[f64; 2]> {
        self.others
            .as_ref()
            .map_or_else(Vec::new, Others::confirmed)
    }

    /// Drop the track as `rst` does (e.g. after a filter error): the next scans look for the
    /// target near its last estimate.
    pub fn drop_track(&mut self, t: f64) {
        if let Some(f) = self.filter.take() {
            self.anchor = f.position();
        }
        self.lost_at = Some(t);
    }

    /// The histogram of each blob, when colour is on and there is an image.
    fn histograms(&mut self, bl: &[Blob], omni: Option<&OmniFrame<'_>>) -> Vec<Option<Vec<f64>>> {
        let (true, Some(o)) = (self.params.colour, omni) else {
            return vec![None; bl.len()];
        };
        let [w, h] = self.params.cylinder;
        let map = match &self.map {
            Some(m) if m.model == *o.model => m,
            _ => self.map.insert(CylinderMap::new(o.model, w, h)),
        };
        bl.iter()
            .map(|b| {
                let roi = cylinder::roi_from_edges(
                    &o.camera_from_fixed,
                    b.left,
                    b.right,
                    self.params.chest_height_m,
                    self.params.roi_half_height_m,
                )?;
                cylinder::hs_histogram(o.image, map, &roi)
            })
            .collect()
    }

    /// Each histogram's correlation with the template in the configured form and in the
    /// normalised form (`None` without a histogram or a template).
    fn correlations(&self, hists: &[Option<Vec<f64>>]) -> Vec<Option<(f64, f64)>> {
        hists
            .iter()
            .map(|h| {
                let (h, t) = (h.as_ref()?, self.template.as_ref()?);
                Some((
                    self.params.corr_form.corr(h, t),
                    cylinder::corr_normalised(h, t),
                ))
            })
            .collect()
    }

    /// Process one scan (see the module doc).
    pub fn step(&mut self, obs: &ScanObs<'_>) -> Result<StepOutput, FilterError> {
        let bl = match (self.params.ground_below_m, obs.laser_pose) {
            (Some(z), Some(pose)) => {
                blobs(&points::above_ground(obs.points, pose, z).0, &self.params)
            }
            _ => blobs(obs.points, &self.params),
        };
        let hists = self.histograms(&bl, obs.omni.as_ref());
        let corrs = self.correlations(&hists);
        let lr: Vec<f64> = corrs
            .iter()
            .map(|c| {
                c.map_or(1.0, |(c, _)| {
                    cylinder::likelihood_ratio(c, self.params.corr_min)
                })
            })
            .collect();
        let corr: Vec<Option<f64>> = corrs.iter().map(|c| c.map(|(_, n)| n)).collect();
        let mut out = StepOutput::empty(bl.len());
        out.blob_corr = bl
            .iter()
            .zip(&corr)
            .filter_map(|(b, c)| Some((b.centre, (*c)?)))
            .collect();
        let seen = Seen {
            blobs: &bl,
            hists: &hists,
            lr: &lr,
            corr: &corr,
        };
        let z: Vec<[f64; 2]> = bl.iter().map(|b| b.centre).collect();
        let shared = self.shared();
        if let Some(o) = self.others.as_mut() {
            o.predict(obs.t);
        }
        let Some(filter) = self.filter.as_mut() else {
            let taken = self.initialise(obs.t, &seen, &mut out);
            if let Some(o) = self.others.as_mut() {
                if let Some(j) = taken {
                    o.forget_near(z[j], &shared);
                }
                o.update(obs.t, &z, &hists, taken, &shared);
            }
            return Ok(out);
        };
        filter.predict(obs.t)?;
        let (form, corr_min) = (self.params.corr_form, self.params.corr_min);
        let lr_of =
            move |h: &[f64], t: &[f64]| cylinder::likelihood_ratio(form.corr(h, t), corr_min);
        let colour = BlobColour {
            hists: &hists,
            lr: &lr_of,
        };
        let a = match self.others.as_ref() {
            Some(o) => {
                let f = o.discount(&z, &colour, &shared);
                let lr_others: Vec<f64> = lr.iter().zip(&f).map(|(l, f)| l * f).collect();
                filter.update(&z, &lr_others)?
            }
            None => filter.update(&z, &lr)?,
        };
        if let Some(o) = self.others.as_mut() {
            let taken = a.chosen.filter(|&j| a.beta[j] > a.beta0);
            o.update(obs.t, &z, &hists, taken, &shared);
            o.coalesce(filter.position(), filter.position_covariance());
        }
        out.gated = a.gated.len();
        out.beta0 = Some(a.beta0);
        let needs_reset = filter.needs_reset();
        let (position, estimate) = (filter.position(), estimate_of(filter));
        if let Some(j) = a.chosen {
            out.chosen = bl.get(j).copied();
            out.chosen_lr = lr.get(j).copied();
            out.chosen_corr = corr.get(j).copied().flatten();
            self.learn_template(hists.get(j).and_then(Option::as_ref));
        }
        let off_colour = self.watch_colour(obs.t, a.beta0, out.chosen_corr);
        if needs_reset || off_colour {
            out.reset = true;
            out.colour_reset = off_colour && !needs_reset;
            self.off_colour_since = None;
            self.anchor = position;
            self.lost_at = Some(obs.t);
            self.filter = None;
            out.look_at = Some(self.anchor);
            return Ok(out);
        }
        out.estimate = Some(estimate);
        Ok(out)
    }

    /// The colour watchdog (our addition, `colour_watch_s`): true when the track has been
    /// moved only by blobs below the re-acquisition floor for the configured time. An update
    /// that moved the track (β₀ < ½) from a blob of known correlation starts or clears the
    /// clock; coasting and blobs without a histogram leave it as it is.
    fn watch_colour(&mut self, t: f64, beta0: f64, chosen_corr: Option<f64>) -> bool {
        let Some(limit) = self.params.colour_watch_s else {
            return false;
        };
        match chosen_corr {
            Some(c) if beta0 < 0.5 && c < self.params.reacquire_corr => {
                let since = *self.off_colour_since.get_or_insert(t);
                t - since >= limit
            }
            Some(_) if beta0 < 0.5 => {
                self.off_colour_since = None;
                false
            }
            _ => false,
        }
    }

    /// The template from the accepted blob's histogram: taken when there is none yet (no
    /// omni frame at initialisation), blended with weight `template_update` otherwise.
    fn learn_template(&mut self, h: Option<&Vec<f64>>) {
        let Some(h) = h else { return };
        let w = self.params.template_update;
        match self.template.as_mut() {
            None => self.template = Some(h.clone()),
            Some(t) if w > 0.0 => t
                .iter_mut()
                .zip(h)
                .for_each(|(t, h)| *t = (1.0 - w) * *t + w * h),
            Some(_) => {}
        }
    }

    /// Start (or restart after `rst`): see the module doc. Returns the blob taken.
    fn initialise(&mut self, t: f64, seen: &Seen<'_>, out: &mut StepOutput) -> Option<usize> {
        let radius = match (self.started, self.lost_at) {
            (false, _) => self.params.init_radius_m,
            (true, lost) => (self.params.reinit_radius_m
                + self.params.filter.v_max * lost.map_or(0.0, |l| (t - l).max(0.0)))
            .min(self.params.reinit_max_m),
        };
        let by_colour = self.started && self.params.colour && self.template.is_some();
        let floor = by_colour.then_some(self.params.reacquire_corr);
        let pick = pick_blob(seen, self.anchor, radius, floor).map(|j| (j, &seen.blobs[j]));
        let Some((j, b)) = pick else {
            out.look_at = self.started.then_some(self.anchor);
            return None;
        };
        let filter = TargetFilter::new(&self.params.filter, t, b.centre);
        if self.template.is_none()
            && let Some(Some(h)) = seen.hists.get(j)
        {
            self.template = Some(h.clone());
        }
        out.initialised = true;
        out.chosen = Some(*b);
        out.chosen_lr = seen.lr.get(j).copied();
        out.chosen_corr = seen.corr.get(j).copied().flatten();
        out.estimate = Some(estimate_of(&filter));
        self.filter = Some(filter);
        self.started = true;
        self.lost_at = None;
        self.off_colour_since = None;
        Some(j)
    }
}

/// The blob a (re)start takes (see the module doc): within `radius` of `anchor` and with a
/// positive likelihood ratio; with a colour `floor`, the one with the highest likelihood ratio
/// among those whose normalised correlation reaches the floor (ties to the nearer), else the
/// nearest. `None`: nothing qualifies.
fn pick_blob(seen: &Seen<'_>, anchor: [f64; 2], radius: f64, floor: Option<f64>) -> Option<usize> {
    let d = |b: &Blob| (b.centre[0] - anchor[0]).hypot(b.centre[1] - anchor[1]);
    let ok = |j: usize, b: &Blob| {
        d(b) <= radius
            && seen.lr.get(j).is_some_and(|&l| l > 0.0)
            && floor.is_none_or(|f| seen.corr.get(j).copied().flatten().is_some_and(|c| c >= f))
    };
    let candidates = seen.blobs.iter().enumerate().filter(|(j, b)| ok(*j, b));
    let pick = if floor.is_some() {
        candidates.max_by(|a, b| {
            seen.lr[a.0]
                .total_cmp(&seen.lr[b.0])
                .then(d(b.1).total_cmp(&d(a.1)))
        })
    } else {
        candidates.min_by(|a, b| d(a.1).total_cmp(&d(b.1)))
    };
    pick.map(|(j, _)| j)
}

fn estimate_of(f: &TargetFilter) -> Estimate {
    Estimate {
        position: f.position(),
        velocity: f.velocity(),
        covariance: f.position_covariance(),
        covariance_norm: f.covariance_norm(),
        turn_rate: f.turn_rate(),
        modes: f.mode_probabilities(),
    }
}

#[cfg(test)]
mod tests;

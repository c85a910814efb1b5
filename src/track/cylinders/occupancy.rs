//! The `occupancy` association ([`super::Association::Occupancy`]): the [`super::ground`]
//! association made to degrade gracefully when the boxes come from a real detector — some
//! missed, their edges off by a few per cent of their height, and false person-shaped boxes
//! among them (issue 32; the noise model is `crate::log::import::detector_noise`).
//!
//! **Why the ground association breaks on a detector's boxes.** It has one pixel threshold,
//! `p_Th`, set from the annotation's accuracy (22.5 px on WILDTRACK), and it believes every
//! box: a box that joins no multi-camera person becomes a one-camera person, and every person
//! found in a frame is reported. Jittered edges push a true view past `p_Th`, so a person
//! splits into a smaller combination plus one-camera leftovers; a dropped box does the same to
//! the boxes left; a false box becomes a person outright. Each of those is a false positive
//! in the frame it happens, and at 2 fps with `N_app = 1` nothing filters them.
//!
//! **Box uncertainty in the fit.** A box's edges carry the detector's error `σ = j · h` (`j` the
//! detector's jitter as a fraction of the box height `h`), on top of the annotation-level error
//! `p_Th` already allows for. The foot point (bottom centre) has `σ/√2` across (the mean of two
//! edges) and `σ` down, the head point the same; so each residual coordinate is scaled by
//! `p_Th / √(p_Th² + (z₉₀ σ_k)²)`, with `z₉₀ = √(2 ln 10)` the 90 % point of a 2-D normal
//! error's norm in units of σ — the same quantile `p_Th` is (the annotation's p90). The fit,
//! its `E_m`, the gate `E_m ≤ p_Th`, the growth gate and the "explained" test all use the
//! scaled residuals, so a tall box close to a camera, whose edges are off by more pixels,
//! counts for less and is gated more widely, and with `j = 0` everything is the ground
//! association's, bit for bit. (Tried and dropped, on WILDTRACK's development frames: weight 0
//! for box edges at the image border. A box that constrains only some coordinates fits many
//! people, and as `E_c` rewards every camera added by a factor 10, combinations grew by such
//! boxes, taken from the people they belonged to: MOTA 0.95 → 0.12 on the annotated boxes.)
//!
//! **Every step of a growth is a candidate.** The ground association grows each seed pair
//! camera by camera and keeps only the last combination. In a crowd a far camera cannot tell
//! two people a metre apart along its line of sight, so when a neighbour's own box in that
//! camera is missing, the neighbour's larger combination takes this person's box (its `E_c`
//! is ten times lower per camera), and the person's own grown combination, which held the
//! same box, is lost with it — the boxes left become one-camera people. Here the seed and
//! every combination the growth passed through stay candidates of the greedy selection, so
//! the person keeps the combination without the taken box. (On WILDTRACK's development
//! frames with 20 % of the boxes dropped, 1,279 of the 1,445 one-camera people of a frame's
//! association were people with two to six boxes left.)
//!
//! **Soft evidence per camera, visibility-aware.** Each person found in a frame (from the
//! ground association's seeds, growth and greedy selection) gets the log-odds that
//! someone stands there against no one, from every camera that sees its ground point whole
//! (feet and head inside the image):
//!
//! `ℓ = ln(ρ a₀) + Σ_{c detects} ln(P_D / (μ_c a_c)) + Σ_{c sees, no box} ln(1 − P_D)`,
//!
//! with `ρ` the prior density of people on the ground (per m²), `P_D` the probability that a
//! camera seeing a person whole has a box of it, `μ_c = λ / A_c` the density of false boxes of
//! camera `c` on the ground (`λ` false boxes per camera frame, spread over the ground `A_c` the
//! camera sees whole, as the noise model draws them), `a_c = π (g_c d_c / f_c)² · s_c` the
//! ground area of the box's gate (`g_c` its gate in px, `d_c` the camera's distance to the
//! feet, `f_c` its focal length) and `a₀` the smallest of the discs `π (g_c d_c / f_c)²` (the
//! person's localisation cell; a one-camera person's is its `a_c`). `s_c = max(1, d_c / z_c)`
//! (`ray_gate`, `z_c` the camera's height) stretches the gate along the line of sight: a box
//! places the feet `d_c / z_c` times worse in depth than across (the foot point's row over a
//! ground seen at a slant), as the position's σ below already says, so a box is consistent
//! with every person standing on that stretch of its ray — in a crowd, with a neighbour's too.
//! Rounds 1–3 used the disc (`s_c = 1`, `ray_gate = false`), which made two boxes of two
//! different people crossing on the ground as strong as one person's; the stretch was chosen
//! on WILDTRACK's development frames (issue 32's fourth round, docs/s004_wildtrack.md). For one
//! camera the cell cancels: `ℓ = ln(ρ P_D A_c / λ) + (misses) · ln(1 − P_D)`. So a box that
//! only one of four cameras seeing the spot has is doubtful — three cameras say no one is
//! there — while a person seen by one camera at the edge of the coverage, or by two of two,
//! is believed. (The other people's boxes are not clutter here: feet and head together pin a
//! ground point, and a box fits only a person standing there.)
//!
//! **Which candidates become this frame's people** (`select`). The first design kept the
//! ground association's greedy selection by `E_c = E_m / 10^N_c` and scored the people it
//! chose. `E_c` rewards every camera by a factor ten whatever the other cameras say, so in a
//! crowd with missed and false boxes a combination grown by a neighbour's box (or a false
//! one) wins over the person's own smaller one. With `select = "evidence"` (the default) every
//! candidate — each valid combination a seed grew, each step of its growth, each box's
//! one-camera fit — is ranked by its *fitted* log-odds
//!
//! `ℓ_fit = ℓ + Σ_{c detects} (ln ln 10 − ½ χ²_c)`,
//!
//! the evidence above with each detecting camera's uniform gate density `1 / a_c` replaced by
//! the normal density of its residuals: `χ²_c` is the box's foot and head residuals (weighted
//! as in the fit) over `σ_w = p_Th / z₉₀` per coordinate, and `1 / (2π σ_g²) = ln 10 / a_c` as
//! `a_c = π z₉₀² σ_g²`. Candidates with `ℓ_fit > 0` are taken best first, each box once; the
//! boxes left become one-camera people as before (doubtful ones, which can only keep a track
//! alive). `select = "e_c"` is the first design, bit for bit.
//!
//! **Tracks as a prior** (`track_prior`, with `select = "evidence"`). The prior density of
//! people where a confirmed track's prediction points is higher than `ρ`: each candidate's
//! `ln ρ` becomes `ln(ρ + Σ_tracks N(x; x̂_t, P_t))` (the tracks' predicted ground positions
//! and covariances), so among candidates that share boxes the one continuing a track is
//! preferred. Tentative tracks do not count (a false box's track would vouch for itself).
//! Both choices were made on WILDTRACK's development frames (0–199, noise seed 101; docs/
//! s004_wildtrack.md): MOTA with drop 0.2, jitter 0.04 and one false box per camera frame
//! 0.593 (`e_c`) → 0.673 (`evidence`) → 0.702 (with the prior); on the annotated boxes
//! 0.946 → 0.948 → 0.946. Tried there and not kept: assignment by Mahalanobis distance with
//! the tracks' covariances (0.588), a gate growing with the frames a track coasted (0.667), a
//! person-height term in the assignment cost (0.684–0.692).
//!
//! **Track-level confirmation.** A track's score is the sum of the log-odds of the people it
//! was assigned (Kalman prediction; Hungarian assignment on the ground within `gate_m`, people
//! with `ℓ > 0` before doubtful ones and confirmed tracks before tentative ones; the ground
//! position's measurement noise from the boxes' gates and distances, so that a person placed
//! by one jittered box moves its track less than one seen by five cameras) and, in frames
//! without one, of the misses of the cameras that see
//! its predicted position (`Σ ln(1 − P_D)`), capped at `max_llr` so that a long-lived track
//! still ends a few frames after its person has gone. A track is confirmed in the frame its
//! score reaches `confirm_llr` (and it has been assigned in `N_app` frames), reported in every
//! frame it is assigned a person from then on — a coasting track keeps its identity for the
//! person's return but is not reported, as at 2 fps its prediction is rarely where a person
//! is (on WILDTRACK's development frames 4 of 438 coasting reports were) — and dropped when
//! the score falls below 0, after more than `max_coast_frames` frames without a person (where
//! no camera sees it, nothing else would end it; `N_dis` is not used), or when it coasts out
//! of the room. This is the sequential probability-ratio test of the multiple-hypothesis
//! tracking literature (Blackman & Popoli's track score) on our per-frame log-odds: a person
//! seen by three cameras is confirmed in its first frame; a one-camera person where only one
//! camera sees, in a few; a false box at a random place never, as it does not come back.
//!
//! **The tracks' motion model** is the tracker's constant velocity with white-noise
//! acceleration `accel_sigma` (the s004 pipeline's `accel_sigma_mps2`). The synthetic office's
//! 2.0 m/s² was chosen at 25 fps; at WILDTRACK's 2 fps it lets a track's velocity change by
//! 1 m/s between frames, and most identity switches were tracks whose prediction had been
//! thrown past the gate. WILDTRACK's file sets it from the annotated people's own second
//! differences (`log::import::wildtrack::motion`: 0.76 m/s²), which cut the identity
//! switches by 27–57 % at every noise level (issue 32's third round,
//! docs/s004_wildtrack.md).
//!
//! What it does not do: no occlusion reasoning (a camera that sees a point whole is assumed to
//! see a person there; people hidden by others in a crowd count as misses), no per-camera
//! detection rates, no appearance, and the per-frame choice is greedy over the grown
//! candidates (not a joint occupancy map as POM's).

use std::collections::BTreeMap;

use nalgebra::Point3;

use super::{
    Association, Cylinder, CylinderError, CylinderParams, CylinderTracker, Hypothesis, Object2d,
    Prepared, StepStats,
};
use crate::assign::min_cost_max_pairs;
use crate::geometry::triangulate::CalibratedView;
use crate::track::kalman::Kalman;

/// `z₉₀`: the 90 % point of the norm of an isotropic 2-D normal error in units of its σ,
/// `√(2 ln 10)` — the quantile `p_Th` (the annotation's p90) stands for.
pub const P90_SIGMAS: f64 = 2.145_966_026_289_347;
/// Step of the ground grid over which each camera's seen area `A_c` is counted (m).
const COVERAGE_STEP_M: f64 = 0.1;

/// The detector's model and the track scores of the `occupancy` association (see the module
/// doc for the symbols).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OccupancyParams {
    /// `P_D`: probability that a camera seeing a person whole has a box of it.
    pub p_detect: f64,
    /// `j`: standard deviation of a box edge as a fraction of the box height.
    pub jitter: f64,
    /// `λ`: false boxes per camera frame.
    pub false_per_frame: f64,
    /// `ρ`: prior density of people on the ground (per m²).
    pub people_per_m2: f64,
    /// Track score (log-odds) at which a track is reported.
    pub confirm_llr: f64,
    /// Cap of the track score.
    pub max_llr: f64,
    /// Frames a confirmed track coasts without a person before it is dropped (in place of
    /// `N_dis`, which stays the other associations').
    pub max_coast_frames: u32,
    /// How a frame's people are chosen among the candidate combinations (module doc).
    pub select: OccupancySelect,
    /// With `select = "evidence"`: the confirmed tracks' predictions raise the prior density
    /// of people where they point (module doc).
    pub track_prior: bool,
    /// A box's gate on the ground is stretched along the camera's line of sight by
    /// `d_c / z_c` (module doc); `false`: a disc of the gate's radius across it (rounds 1–3).
    pub ray_gate: bool,
}

/// How the `occupancy` association chooses a frame's people among its candidates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OccupancySelect {
    /// The ground association's greedy selection by `E_c`, one-camera people after (the
    /// first design, issue 32's first held-out run).
    #[serde(rename = "e_c")]
    Ec,
    /// Greedy by the fitted log-odds, believed candidates only, one- and multi-camera alike.
    Evidence,
}

impl Default for OccupancyParams {
    fn default() -> Self {
        OccupancyParams {
            p_detect: 0.95,
            jitter: 0.0,
            false_per_frame: 0.05,
            people_per_m2: 0.05,
            confirm_llr: 5.0,
            max_llr: 20.0,
            max_coast_frames: 2,
            select: OccupancySelect::Evidence,
            track_prior: true,
            ray_gate: true,
        }
    }
}

impl OccupancyParams {
    pub fn validate(&self) -> Result<(), CylinderError> {
        let bad =
            |name: &'static str, reason: String| Err(CylinderError::BadParameter { name, reason });
        if !(self.p_detect > 0.0 && self.p_detect < 1.0) {
            return bad("p_detect", format!("{} is not in (0, 1)", self.p_detect));
        }
        if !(self.jitter >= 0.0 && self.jitter <= 1.0) {
            return bad("jitter", format!("{} is not in [0, 1]", self.jitter));
        }
        for (name, v) in [
            ("false_per_frame", self.false_per_frame),
            ("people_per_m2", self.people_per_m2),
        ] {
            if !(v > 0.0 && v.is_finite()) {
                return bad(name, format!("{v} is not a positive rate"));
            }
        }
        if !(self.confirm_llr.is_finite() && self.max_llr >= self.confirm_llr) {
            return bad(
                "confirm_llr/max_llr",
                format!(
                    "need a finite confirm_llr ≤ max_llr, got {} and {}",
                    self.confirm_llr, self.max_llr
                ),
            );
        }
        Ok(())
    }
}

/// One track of the `occupancy` association.
#[derive(Debug, Clone)]
struct Track {
    /// Set when the track is confirmed (reported).
    id: Option<u32>,
    kf: Kalman<6>,
    support: Vec<(usize, u32)>,
    /// Accumulated log-odds, capped at `max_llr`.
    score: f64,
    /// Frames with a person assigned, and consecutive frames without.
    hits: u32,
    misses: u32,
    /// Frames since confirmation.
    age: u32,
    measured: Option<Hypothesis>,
}

/// The association's state: each camera's seen ground area and the tracks.
#[derive(Debug, Clone, Default)]
pub(super) struct State {
    /// `A_c` (m²): the room's ground on which camera `c` sees a person of mean head height whole.
    area_m2: Vec<f64>,
    tracks: Vec<Track>,
}

/// Whether `view` sees a person standing at `(x, y)` with the head at `z` whole: feet and head
/// in front of it and inside its image.
pub fn sees_whole(view: &CalibratedView, x: f64, y: f64, z: f64) -> bool {
    let inv = view.world_from_camera.inverse();
    [0.0, z].iter().all(|&h| {
        let p = Point3::new(x, y, h);
        (inv * p).z > 0.0 && view.project(&p).is_some_and(|q| view.model.in_image(&q))
    })
}

impl State {
    pub fn new(views: &[CalibratedView], p: &CylinderParams) -> State {
        let r = p.room_m;
        let z = 0.5 * (p.head_height_m.0 + p.head_height_m.1);
        let nx = ((r[2] - r[0]) / COVERAGE_STEP_M).ceil().max(1.0) as usize;
        let ny = ((r[3] - r[1]) / COVERAGE_STEP_M).ceil().max(1.0) as usize;
        let cell = ((r[2] - r[0]) / nx as f64) * ((r[3] - r[1]) / ny as f64);
        let area_m2 = views
            .iter()
            .map(|v| {
                let mut n = 0usize;
                for i in 0..nx {
                    for j in 0..ny {
                        let x = r[0] + (i as f64 + 0.5) * (r[2] - r[0]) / nx as f64;
                        let y = r[1] + (j as f64 + 0.5) * (r[3] - r[1]) / ny as f64;
                        n += usize::from(sees_whole(v, x, y, z));
                    }
                }
                n as f64 * cell
            })
            .collect();
        State {
            area_m2,
            tracks: Vec::new(),
        }
    }

    /// `A_c` of every camera (m²).
    pub fn seen_area_m2(&self) -> &[f64] {
        &self.area_m2
    }
}

impl CylinderTracker {
    /// The residual weights `(foot, head)` of a box, each `(across, down)` (module doc); 1 for
    /// the other associations.
    pub(super) fn residual_weights(&self, o: &Object2d) -> ([f64; 2], [f64; 2]) {
        let ones = ([1.0; 2], [1.0; 2]);
        if self.params.association != Association::Occupancy {
            return ones;
        }
        let Some(f) = o.foot_px else { return ones };
        let q = &self.params.occupancy;
        let p_th = self.params.p_th_px;
        let sigma = q.jitter * (f[1] - o.head_px[1]).abs();
        let w = |s: f64| p_th / (p_th * p_th + (P90_SIGMAS * s).powi(2)).sqrt();
        let (wx, wy) = (w(sigma / std::f64::consts::SQRT_2), w(sigma));
        ([wx, wy], [wx, wy])
    }

    /// The gate of a box's foot point in ideal px: `p_Th` widened by the box's jitter.
    fn gate_px(&self, o: &Prepared) -> f64 {
        let p_th = self.params.p_th_px;
        let h = o.foot_ideal.map_or(0.0, |f| (f.y - o.ideal.y).abs());
        let s = self.params.occupancy.jitter * h;
        (p_th * p_th + (P90_SIGMAS * s).powi(2)).sqrt()
    }

    /// `ln(1 − P_D)` for every camera that sees `(x, y, z)` whole, except those in `support`.
    fn miss_log_odds(&self, x: f64, y: f64, z: f64, support: &[(usize, u32)]) -> f64 {
        let q = &self.params.occupancy;
        let seeing = self
            .views
            .iter()
            .enumerate()
            .filter(|(c, v)| !support.iter().any(|s| s.0 == *c) && sees_whole(v, x, y, z))
            .count();
        seeing as f64 * (1.0 - q.p_detect).ln()
    }

    /// The per-frame log-odds `ℓ` of a person (module doc), and the standard deviation of its
    /// ground position (m): each camera's box error across its line of sight, `σ_px d_c / f_c`
    /// with `σ_px = g_c / z₉₀`, combined as independent measurements; one camera alone also
    /// places the feet along its line of sight, `d_c / z_c` times worse (`z_c` its height).
    fn evidence(&self, h: &Hypothesis, boxes: &BTreeMap<(usize, u32), &Prepared>) -> (f64, f64) {
        let q = &self.params.occupancy;
        let foot = Point3::new(h.head_m.x, h.head_m.y, 0.0);
        let mut cell = f64::INFINITY;
        let (mut detected, mut information, mut depth) = (0.0, 0.0, 1.0);
        for key in &h.support {
            let (Some(o), Some(&area)) = (boxes.get(key), self.occupancy.area_m2.get(key.0)) else {
                continue;
            };
            let view = &self.views[key.0];
            let (f, _) = view.focal_and_principal();
            let d = (view.center() - foot).norm();
            let r = self.gate_px(o) * d / f;
            let disc = std::f64::consts::PI * r * r;
            depth = d / view.center().z.max(0.1);
            // the box's gate on the ground: `r` across the line of sight, `depth` times more
            // along it (`ray_gate`); a one-camera person is localised only that well
            let a = if q.ray_gate {
                disc * depth.max(1.0)
            } else {
                disc
            };
            cell = cell.min(if h.support.len() == 1 { a } else { disc });
            // a camera that sees none of the room whole: its false boxes are everywhere
            let mu = q.false_per_frame / area.max(a);
            detected += (q.p_detect / (mu * a)).ln();
            information += (P90_SIGMAS / r).powi(2);
        }
        if !cell.is_finite() {
            return (f64::NEG_INFINITY, self.params.position_sigma_m);
        }
        let mut sigma = information.recip().sqrt();
        if h.support.len() == 1 {
            sigma *= depth.max(1.0);
        }
        let l = (q.people_per_m2 * cell).ln()
            + detected
            + self.miss_log_odds(h.head_m.x, h.head_m.y, h.head_m.z, &h.support);
        (l, sigma)
    }

    /// `χ²` of box `o` against the segment with head `head`: its foot and head residuals in
    /// weighted px over `σ_w = p_Th / z₉₀` per coordinate.
    fn box_chi2(&self, o: &Prepared, head: &Point3<f64>) -> Option<f64> {
        let view = &self.views[o.camera];
        let foot = view.project_ideal(&Point3::new(head.x, head.y, 0.0))? - o.foot_ideal?;
        let top = view.project_ideal(head)? - o.ideal;
        let sigma = self.params.p_th_px / P90_SIGMAS;
        let r = [
            foot.x * o.w_foot[0],
            foot.y * o.w_foot[1],
            top.x * o.w_head[0],
            top.y * o.w_head[1],
        ];
        Some(r.iter().map(|v| (v / sigma).powi(2)).sum())
    }

    /// `ℓ` with each detecting camera's box scored by its fit (module doc).
    fn fit_log_odds(
        &self,
        h: &Hypothesis,
        boxes: &BTreeMap<(usize, u32), &Prepared>,
        tracks: &[Track],
    ) -> f64 {
        let mut l = self.evidence(h, boxes).0;
        if !tracks.is_empty() {
            let rho = self.params.occupancy.people_per_m2;
            let mut density = rho;
            for t in tracks.iter().filter(|t| t.id.is_some()) {
                let (dx, dy) = (h.head_m.x - t.kf.x[0], h.head_m.y - t.kf.x[1]);
                let (a, b, c) = (t.kf.p[(0, 0)], t.kf.p[(0, 1)], t.kf.p[(1, 1)]);
                let det = a * c - b * b;
                if det > 0.0 {
                    let m = (c * dx * dx - 2.0 * b * dx * dy + a * dy * dy) / det;
                    density += (-0.5 * m).exp() / (std::f64::consts::TAU * det.sqrt());
                }
            }
            l += (density / rho).ln();
        }
        for key in &h.support {
            let chi2 = boxes.get(key).and_then(|o| self.box_chi2(o, &h.head_m));
            l += std::f64::consts::LN_10.ln() - 0.5 * chi2.unwrap_or(f64::INFINITY);
        }
        l
    }

    /// This frame's people by evidence: every candidate (multi- and one-camera), highest
    /// `fit_log_odds` first, each box once, believed ones only; then the leftovers.
    fn select_by_evidence(
        &self,
        prepared: &[Prepared],
        boxes: &BTreeMap<(usize, u32), &Prepared>,
        tracks: &[Track],
        stats: &mut StepStats,
    ) -> Vec<Hypothesis> {
        let c = self.ground_candidates(prepared, stats);
        let mut all: Vec<(f64, Vec<usize>, Hypothesis)> = c
            .multi
            .into_iter()
            .chain(
                c.usable
                    .iter()
                    .filter_map(|&i| c.single[i].clone().map(|h| (0.0, vec![i], h))),
            )
            .filter_map(|(_, combo, h)| {
                let l = self.fit_log_odds(&h, boxes, tracks);
                (l > 0.0).then_some((-l, combo, h))
            })
            .collect();
        all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut used = vec![false; prepared.len()];
        let selected = super::candidate::select_disjoint(all, &mut used);
        self.with_leftovers(prepared, &c.single, &c.usable, &used, selected)
    }

    /// The per-frame log-odds `ℓ` of a person (module doc).
    #[cfg(test)]
    fn log_odds(&self, h: &Hypothesis, boxes: &BTreeMap<(usize, u32), &Prepared>) -> f64 {
        self.evidence(h, boxes).0
    }

    /// People believed (`ℓ > 0`) before doubtful ones, and within each, confirmed tracks before
    /// tentative ones: each round assigns the tracks and people left by the Hungarian
    /// algorithm on ground distance within `gate_m`, so that a doubtful one-camera person next
    /// to a track never takes the place of the well-seen person it follows. `assigned[k]` is
    /// track k's person.
    fn assign_tracks(
        &self,
        tracks: &[Track],
        people: &[Hypothesis],
        odds: &[f64],
    ) -> Vec<Option<usize>> {
        let gate = self.params.gate_m;
        let mut taken = vec![false; people.len()];
        let mut assigned: Vec<Option<usize>> = vec![None; tracks.len()];
        for (believed, confirmed) in [(true, true), (true, false), (false, true), (false, false)] {
            let idx: Vec<usize> = (0..tracks.len())
                .filter(|&k| assigned[k].is_none() && tracks[k].id.is_some() == confirmed)
                .collect();
            let free: Vec<usize> = (0..people.len())
                .filter(|&j| !taken[j] && (odds[j] > 0.0) == believed)
                .collect();
            let pairs = min_cost_max_pairs(idx.len(), free.len(), |a, b| {
                let (t, h) = (&tracks[idx[a]], &people[free[b]]);
                let d = (h.head_m.x - t.kf.x[0]).hypot(h.head_m.y - t.kf.x[1]);
                if d <= gate { d } else { f64::INFINITY }
            });
            for (a, b) in pairs {
                assigned[idx[a]] = Some(free[b]);
                taken[free[b]] = true;
            }
        }
        assigned
    }

    /// Confirm `t` when its score and hits allow (module doc).
    fn maybe_confirm(&mut self, t: &mut Track, stats: &mut StepStats) {
        let q = &self.params.occupancy;
        if t.id.is_none() && t.score >= q.confirm_llr && t.hits >= self.params.n_app {
            t.id = Some(self.next_id);
            self.next_id += 1;
            stats.promoted += 1;
        }
    }

    /// [`CylinderTracker::step`] for the occupancy association (see the module doc).
    pub(super) fn step_occupancy(&mut self, objects: &[Object2d]) -> (Vec<Cylinder>, StepStats) {
        let mut stats = StepStats::default();
        let prepared = self.prepare(objects);
        let boxes: BTreeMap<(usize, u32), &Prepared> =
            prepared.iter().map(|o| ((o.camera, o.id), o)).collect();
        let (f, q) = self.transition();
        let mut tracks = std::mem::take(&mut self.occupancy.tracks);
        for t in tracks.iter_mut() {
            t.kf.predict(&f, &q);
        }
        let occ = &self.params.occupancy;
        let people = match occ.select {
            OccupancySelect::Evidence => {
                let prior: &[Track] = if occ.track_prior { &tracks } else { &[] };
                self.select_by_evidence(&prepared, &boxes, prior, &mut stats)
            }
            OccupancySelect::Ec => self.detect_ground(&prepared, &mut stats),
        };
        let (odds, sigmas): (Vec<f64>, Vec<f64>) =
            people.iter().map(|h| self.evidence(h, &boxes)).unzip();
        let assigned = self.assign_tracks(&tracks, &people, &odds);
        let mut taken = vec![false; people.len()];
        let max_llr = self.params.occupancy.max_llr;
        let mut kept = Vec::with_capacity(tracks.len());
        for (mut t, a) in tracks.into_iter().zip(assigned) {
            match a {
                Some(j) => {
                    taken[j] = true;
                    let h = &people[j];
                    self.measure_sigma(&mut t.kf, h, sigmas[j]);
                    t.support = h.support.clone();
                    t.score += odds[j];
                    t.hits += 1;
                    t.misses = 0;
                    t.measured = Some(h.clone());
                }
                None => {
                    t.score += self.miss_log_odds(t.kf.x[0], t.kf.x[1], t.kf.x[4], &[]);
                    t.misses += 1;
                    t.measured = None;
                }
            }
            t.score = t.score.min(max_llr);
            if t.id.is_some() {
                t.age += 1;
            }
            self.maybe_confirm(&mut t, &mut stats);
            if t.score < 0.0
                || t.misses > self.params.occupancy.max_coast_frames
                || !self.in_room(t.kf.x[0], t.kf.x[1])
            {
                stats.discarded += usize::from(t.id.is_some());
            } else {
                kept.push(t);
            }
        }
        for (j, h) in people.iter().enumerate() {
            if taken[j] || odds[j] <= 0.0 {
                continue;
            }
            let mut kf = self.new_filter(h);
            kf.p[(0, 0)] = sigmas[j] * sigmas[j];
            kf.p[(1, 1)] = sigmas[j] * sigmas[j];
            let mut t = Track {
                id: None,
                kf,
                support: h.support.clone(),
                score: odds[j].min(max_llr),
                hits: 1,
                misses: 0,
                age: 0,
                measured: Some(h.clone()),
            };
            self.maybe_confirm(&mut t, &mut stats);
            kept.push(t);
        }
        self.occupancy.tracks = kept;
        (self.occupancy_cylinders(), stats)
    }

    /// The confirmed tracks assigned a person this frame, as cylinders, sorted by id.
    fn occupancy_cylinders(&self) -> Vec<Cylinder> {
        let mut out: Vec<Cylinder> = self
            .occupancy
            .tracks
            .iter()
            .filter_map(|t| {
                let id = t.id?;
                t.measured.as_ref()?;
                let x: &nalgebra::Vector6<f64> = &t.kf.x;
                Some(Cylinder {
                    id,
                    x_m: x[0],
                    y_m: x[1],
                    vx_mps: x[2],
                    vy_mps: x[3],
                    height_m: x[4],
                    radius_m: x[5],
                    support: if t.measured.is_some() {
                        t.support.clone()
                    } else {
                        Vec::new()
                    },
                    measured: t.measured.clone(),
                    age: t.age,
                })
            })
            .collect();
        out.sort_by_key(|c| c.id);
        out
    }

    /// `A_c` of every camera (m²; empty unless the association is `occupancy`).
    pub fn seen_area_m2(&self) -> &[f64] {
        self.occupancy.seen_area_m2()
    }
}

#[cfg(test)]
mod tests;

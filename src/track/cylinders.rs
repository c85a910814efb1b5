//! The multi-camera geometry-based 3-D tracker of seed 004 §5: people as cylinders from
//! tracked 2-D objects in calibrated cameras.
//!
//! **Correspondences.** A *combination* picks at most one 2-D object per camera (cameras that
//! do not see the person pick none) and at least `min_cameras` (2) in all. Its head points —
//! lens distortion removed — are triangulated by the linear method
//! ([`crate::geometry::triangulate`]), and its geometric coherence is the mean reprojection
//! error in (ideal) pixels, `E_m = (1/N_c) Σ_c ‖h_c − P_c(h³ᴰ)‖` (eq. 4). Combinations with
//! `E_m > p_Th` are discarded at once. Among the rest, the *corrected* error
//! `E_c = E_m / 10^N_c` (eq. 5) chooses, so that combinations supported by more cameras win
//! ([`Selection::Mean`] chooses by `E_m` instead, for the paper's comparison).
//!
//! **3-D objects.** New objects are looked for among the 2-D objects that support no existing
//! object, by exhaustive search over all their combinations; the best combinations (by the
//! selection error, disjoint, greedily) are candidates, and a candidate whose combination
//! keeps being selected — each frame's combination differing from the previous one in at most
//! one 2-D object — for `N_app` consecutive frames is promoted to a 3-D object. Each frame,
//! every existing object is updated with the best valid combination among those that differ
//! from its previous support in at most one 2-D object (same objects; one replaced, added or
//! dropped); objects compete for 2-D objects greedily by selection error. An object with no
//! valid combination for `N_dis` consecutive frames is discarded (paper: `N_dis = N_app`).
//!
//! **Cylinders.** Ground position and height come straight from the triangulated head
//! (`x, y` and `z`: the top of the head); the radius from the 2-D widths by triangle
//! similarity (eq. 6–7): `R = (1/N_c) Σ_c ½ (w_c/β_c) cos²α_c ‖C_c − h³ᴰ‖` with
//! `α_c = arctan(‖h_c − p_c‖ / β_c)`, β_c the focal length and p_c the principal point in
//! pixels. A Kalman filter (constant velocity on the ground, random walks for height and
//! radius) smooths them, so that the cylinder stays steady when the supporting views change.
//!
//! **Additions not in the paper**, each a parameter: a plausibility check on triangulated
//! heads (height range, inside the room plus a margin; the paper constrains its templates by
//! the room size but says nothing here — without it, two-camera combinations of different
//! people can triangulate to heads under the floor; a coasting object predicted outside the
//! room plus the margin is dropped at once rather than after `N_dis` frames), and a gate on
//! the distance between an existing object's prediction and its update (`gate_m`). If the exhaustive search would
//! exceed `max_combinations`, only combinations whose every camera pair is itself coherent
//! within `2·p_Th` are tried — a pair's error is at most about `N_c/2` times the whole
//! combination's, so this drops almost nothing; the step reports when it happened.
//!
//! **Association variants** ([`Association`]): `Paper` is the exhaustive search above;
//! `Scalable` ([`scalable`]) builds new objects from pairwise-coherent head rays grown camera
//! by camera and from box bottoms on the ground (single-camera people), with the same greedy
//! selection by `E_c`; `Ground` ([`ground`]) associates every frame on the ground plane from
//! box feet and heads and tracks the people found by assignment on the ground; `Occupancy`
//! ([`occupancy`]) is the ground association for a noisy detector: box uncertainty in the fit,
//! each person's per-frame log-odds from the cameras that see its ground point, and tracks
//! reported once their accumulated log-odds confirm them.
//!
//! What it does not do: no appearance, no re-identification of discarded objects, no
//! occlusion reasoning beyond what the combinations express.

use std::collections::BTreeMap;

use nalgebra::{Matrix4x6, Matrix6, Point2, Point3, SMatrix, Vector4, Vector6};

use super::kalman::{Kalman, constant_velocity_2d};
use crate::geometry::triangulate::{CalibratedView, triangulate_rays};

mod candidate;
use candidate::select_disjoint;
mod ground;
mod head;
mod occupancy;
mod scalable;

pub use head::{box_head_px, cylinder_radius};
pub use occupancy::{OccupancyParams, OccupancySelect};

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CylinderError {
    #[error("bad parameter `{name}`: {reason}")]
    BadParameter { name: &'static str, reason: String },
    #[error("need at least 2 cameras, got {0}")]
    TooFewCameras(usize),
}

/// A 2-D object seen by one camera in the current frame: the 3-D stage's input, from the
/// 2-D tracker of [`super::graph_match`] or from any detector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Object2d {
    /// Index of the camera in the tracker's views.
    pub camera: usize,
    /// Identifier, unique within the camera (a 2-D track id).
    pub id: u32,
    /// Head position (raw pixels, with the lens distortion).
    pub head_px: [f64; 2],
    /// Width of the object's box (pixels), for eq. 6.
    pub width_px: f64,
    /// Bottom centre of the object's box (raw pixels): its ground point, used only by
    /// [`Association::Scalable`].
    pub foot_px: Option<[f64; 2]>,
}

/// How new 3-D objects are found among the free 2-D objects.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Association {
    /// Every combination (the paper's §5), pairwise-coherent ones above `max_combinations`.
    #[default]
    Paper,
    /// Pairwise ray seeds grown camera by camera, plus ground points ([`scalable`]).
    Scalable,
    /// Per frame on the ground plane (feet and heads), then tracks by assignment ([`ground`]).
    Ground,
    /// `Ground` for a noisy detector: box uncertainty, per-camera evidence, track scores
    /// ([`occupancy`]).
    Occupancy,
}

/// Which error chooses between valid combinations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Selection {
    /// `E_c = E_m / 10^N_c` (eq. 5), the paper's choice.
    Corrected,
    /// `E_m` (eq. 4).
    Mean,
}

/// Tracker settings (paper symbols in the docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CylinderParams {
    /// `p_Th`: maximum `E_m` of a valid combination (pixels).
    pub p_th_px: f64,
    /// `N_app`: consecutive frames before a candidate becomes a 3-D object.
    pub n_app: u32,
    /// `N_dis`: consecutive frames without support before an object is discarded.
    pub n_dis: u32,
    pub selection: Selection,
    /// Minimum cameras in a combination.
    pub min_cameras: usize,
    /// Plausible head heights (m).
    pub head_height_m: (f64, f64),
    /// Room floor `[x0, y0, x1, y1]` (m) and how far outside it a head may be.
    pub room_m: [f64; 4],
    pub room_margin_m: f64,
    /// Largest distance between an object's prediction and its update (m).
    pub gate_m: f64,
    /// Above this many combinations, only pairwise-coherent ones are tried.
    pub max_combinations: usize,
    pub association: Association,
    /// Scalable: a single-camera ground point this close to a selected or tracked person
    /// (m) is a view of that person, not a new one.
    pub ground_separation_m: f64,
    /// Frame period (s).
    pub dt_s: f64,
    /// White-noise acceleration on the ground (m/s²).
    pub accel_sigma: f64,
    /// Measurement noise of the ground position, height and radius (m).
    pub position_sigma_m: f64,
    pub height_sigma_m: f64,
    pub radius_sigma_m: f64,
    /// Random-walk rate of height and radius (m/√s).
    pub size_walk_m: f64,
    /// `Occupancy`: the detector's model and the track scores (unused by the others).
    pub occupancy: OccupancyParams,
}

impl Default for CylinderParams {
    fn default() -> Self {
        CylinderParams {
            p_th_px: 10.0,
            n_app: 5,
            n_dis: 5,
            selection: Selection::Corrected,
            min_cameras: 2,
            head_height_m: (1.0, 2.3),
            room_m: [0.0, 0.0, 8.0, 8.5],
            room_margin_m: 0.5,
            gate_m: 1.0,
            max_combinations: 20_000,
            association: Association::Paper,
            ground_separation_m: 0.5,
            dt_s: 0.04,
            accel_sigma: 2.0,
            position_sigma_m: 0.1,
            height_sigma_m: 0.05,
            radius_sigma_m: 0.05,
            size_walk_m: 0.05,
            occupancy: OccupancyParams::default(),
        }
    }
}

impl CylinderParams {
    pub fn validate(&self) -> Result<(), CylinderError> {
        let bad =
            |name: &'static str, reason: String| Err(CylinderError::BadParameter { name, reason });
        if !(self.p_th_px.is_finite() && self.p_th_px > 0.0) {
            return bad(
                "p_th_px",
                format!("{} is not a positive number of pixels", self.p_th_px),
            );
        }
        if self.n_app == 0 || self.n_dis == 0 {
            return bad("n_app/n_dis", "must be at least 1 frame".into());
        }
        if self.min_cameras < 2 {
            return bad("min_cameras", "triangulation needs at least 2".into());
        }
        if !(self.dt_s.is_finite() && self.dt_s > 0.0) {
            return bad("dt_s", format!("{} is not a positive period", self.dt_s));
        }
        if self.head_height_m.0.partial_cmp(&self.head_height_m.1) != Some(std::cmp::Ordering::Less)
        {
            return bad("head_height_m", "the range is empty".into());
        }
        if self.association == Association::Occupancy {
            self.occupancy.validate()?;
        }
        Ok(())
    }
}

/// A 2-D object ready for combinations: ray and ideal head pixel computed once.
#[derive(Debug, Clone, Copy)]
struct Prepared {
    camera: usize,
    id: u32,
    head_px: [f64; 2],
    width_px: f64,
    ideal: Point2<f64>,
    origin: Point3<f64>,
    dir: nalgebra::Vector3<f64>,
    /// Where the ray through the box bottom meets the ground (z = 0).
    ground: Option<Point3<f64>>,
    /// The box bottom in ideal pixels.
    foot_ideal: Option<Point2<f64>>,
    /// Multipliers of the foot and head residuals `(x, y)` (ideal px → px at the box's gate
    /// `p_Th`): 1 except under `Occupancy` (box uncertainty).
    w_foot: [f64; 2],
    w_head: [f64; 2],
}

/// A valid combination: its support, triangulated head and errors.
#[derive(Debug, Clone, PartialEq)]
pub struct Hypothesis {
    /// `(camera, 2-D id)`, sorted by camera.
    pub support: Vec<(usize, u32)>,
    pub head_m: Point3<f64>,
    /// `E_m` (eq. 4), pixels.
    pub e_m_px: f64,
    /// `E_c` (eq. 5), with `E_m` floored at [`E_M_FLOOR_PX`].
    pub e_c: f64,
    /// Radius by eq. 6 (m).
    pub radius_m: f64,
}

/// Reprojection errors below this (pixels) are rounding noise: the selection treats them as
/// equal, so that with noise-free input E_c still prefers more cameras instead of whichever
/// subset rounds closest to zero.
pub const E_M_FLOOR_PX: f64 = 1e-6;

impl Hypothesis {
    fn score(&self, s: Selection) -> f64 {
        match s {
            Selection::Corrected => self.e_c,
            Selection::Mean => self.e_m_px.max(E_M_FLOOR_PX),
        }
    }
}

/// One tracked person as the tracker reports it after a frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Cylinder {
    pub id: u32,
    /// Smoothed centre of the cylinder base on the ground (m).
    pub x_m: f64,
    pub y_m: f64,
    pub vx_mps: f64,
    pub vy_mps: f64,
    /// Smoothed height (top of the head) and radius (m).
    pub height_m: f64,
    pub radius_m: f64,
    /// Supporting 2-D objects this frame (empty when the object coasts).
    pub support: Vec<(usize, u32)>,
    /// This frame's measurement, if supported.
    pub measured: Option<Hypothesis>,
    /// Frames since the object was promoted.
    pub age: u32,
}

#[derive(Debug, Clone)]
struct Object3d {
    id: u32,
    kf: Kalman<6>,
    support: Vec<(usize, u32)>,
    misses: u32,
    age: u32,
    measured: Option<Hypothesis>,
}

#[derive(Debug, Clone)]
struct Candidate {
    support: Vec<(usize, u32)>,
    count: u32,
    kf: Kalman<6>,
    last: Hypothesis,
}

/// What one step did (for reports).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct StepStats {
    /// Combinations triangulated.
    pub combinations: usize,
    /// The exhaustive search was replaced by the pairwise-coherent one.
    pub pruned: bool,
    pub promoted: usize,
    pub discarded: usize,
}

/// Seed 004's 3-D tracker over a fixed set of calibrated cameras.
#[derive(Debug, Clone)]
pub struct CylinderTracker {
    views: Vec<CalibratedView>,
    params: CylinderParams,
    objects: Vec<Object3d>,
    candidates: Vec<Candidate>,
    next_id: u32,
    /// `Occupancy`: its tracks and each camera's view of the room.
    occupancy: occupancy::State,
}

/// Number of cameras where two supports differ (absent on one side counts).
pub fn support_difference(a: &[(usize, u32)], b: &[(usize, u32)]) -> usize {
    let ma: BTreeMap<usize, u32> = a.iter().copied().collect();
    let mb: BTreeMap<usize, u32> = b.iter().copied().collect();
    let mut cams: Vec<usize> = ma.keys().chain(mb.keys()).copied().collect();
    cams.sort_unstable();
    cams.dedup();
    cams.iter().filter(|c| ma.get(c) != mb.get(c)).count()
}

impl CylinderTracker {
    pub fn new(views: Vec<CalibratedView>, params: CylinderParams) -> Result<Self, CylinderError> {
        params.validate()?;
        if views.len() < 2 {
            return Err(CylinderError::TooFewCameras(views.len()));
        }
        let occupancy = if params.association == Association::Occupancy {
            occupancy::State::new(&views, &params)
        } else {
            occupancy::State::default()
        };
        Ok(CylinderTracker {
            views,
            params,
            objects: Vec::new(),
            candidates: Vec::new(),
            next_id: 1,
            occupancy,
        })
    }

    pub fn params(&self) -> &CylinderParams {
        &self.params
    }

    pub fn views(&self) -> &[CalibratedView] {
        &self.views
    }

    fn prepare(&self, objects: &[Object2d]) -> Vec<Prepared> {
        let mut out: Vec<Prepared> = objects
            .iter()
            .filter(|o| o.camera < self.views.len())
            .filter(|o| o.head_px.iter().all(|v| v.is_finite()) && o.width_px.is_finite())
            .filter_map(|o| {
                let view = &self.views[o.camera];
                let px = Point2::new(o.head_px[0], o.head_px[1]);
                let (origin, dir) = view.ray_in_world(&px)?;
                let ground = o.foot_px.and_then(|f| {
                    let (fo, fd) = view.ray_in_world(&Point2::new(f[0], f[1]))?;
                    let t = -fo.z / fd.z;
                    (t.is_finite() && t > 0.0).then(|| fo + fd * t)
                });
                let (w_foot, w_head) = self.residual_weights(o);
                Some(Prepared {
                    camera: o.camera,
                    id: o.id,
                    head_px: o.head_px,
                    width_px: o.width_px,
                    ideal: view.ideal_px(&px)?,
                    origin,
                    dir,
                    ground,
                    foot_ideal: o
                        .foot_px
                        .and_then(|f| view.ideal_px(&Point2::new(f[0], f[1]))),
                    w_foot,
                    w_head,
                })
            })
            .collect();
        out.sort_by_key(|p| (p.camera, p.id));
        out.dedup_by_key(|p| (p.camera, p.id));
        out
    }

    /// Inside the room plus its margin (ground plane).
    fn in_room(&self, x: f64, y: f64) -> bool {
        let (r, m) = (self.params.room_m, self.params.room_margin_m);
        x >= r[0] - m && x <= r[2] + m && y >= r[1] - m && y <= r[3] + m
    }

    /// Triangulate and check one combination (indices into `prepared`, one per camera).
    fn evaluate(&self, prepared: &[Prepared], combo: &[usize]) -> Option<Hypothesis> {
        let p = &self.params;
        if combo.len() < p.min_cameras {
            return match (p.association, combo) {
                (Association::Scalable, &[i]) => self.ground_hypothesis(prepared, i),
                _ => None,
            };
        }
        let rays: Vec<(Point3<f64>, nalgebra::Vector3<f64>)> = combo
            .iter()
            .map(|&i| (prepared[i].origin, prepared[i].dir))
            .collect();
        let head = triangulate_rays(&rays).ok()?;
        if head.z < p.head_height_m.0 || head.z > p.head_height_m.1 || !self.in_room(head.x, head.y)
        {
            return None;
        }
        let mut sum = 0.0;
        for &i in combo {
            let o = &prepared[i];
            let view = &self.views[o.camera];
            // behind a supporting camera: not a person it sees
            if (view.world_from_camera.inverse() * head).z <= 0.0 {
                return None;
            }
            let seen = view.project_ideal(&head)?;
            sum += (seen - o.ideal).norm();
        }
        let n = combo.len();
        let e_m = sum / n as f64;
        // NaN fails too
        if e_m.is_nan() || e_m > p.p_th_px {
            return None;
        }
        let support3: Vec<(&CalibratedView, [f64; 2], f64)> = combo
            .iter()
            .map(|&i| {
                (
                    &self.views[prepared[i].camera],
                    prepared[i].head_px,
                    prepared[i].width_px,
                )
            })
            .collect();
        Some(Hypothesis {
            support: combo
                .iter()
                .map(|&i| (prepared[i].camera, prepared[i].id))
                .collect(),
            head_m: head,
            e_m_px: e_m,
            e_c: e_m.max(E_M_FLOOR_PX) / 10f64.powi(n as i32),
            radius_m: cylinder_radius(&head, &support3),
        })
    }

    fn new_filter(&self, h: &Hypothesis) -> Kalman<6> {
        let p = &self.params;
        let x = Vector6::new(h.head_m.x, h.head_m.y, 0.0, 0.0, h.head_m.z, h.radius_m);
        let mut cov = Matrix6::zeros();
        cov[(0, 0)] = p.position_sigma_m.powi(2);
        cov[(1, 1)] = p.position_sigma_m.powi(2);
        cov[(2, 2)] = 1.0; // walking speeds are ~1 m/s
        cov[(3, 3)] = 1.0;
        cov[(4, 4)] = p.height_sigma_m.powi(2);
        cov[(5, 5)] = p.radius_sigma_m.powi(2);
        Kalman::new(x, cov)
    }

    fn transition(&self) -> (Matrix6<f64>, Matrix6<f64>) {
        let p = &self.params;
        let (f4, q4) = constant_velocity_2d(p.dt_s, p.accel_sigma);
        let mut f = Matrix6::identity();
        let mut q = Matrix6::zeros();
        f.fixed_view_mut::<4, 4>(0, 0).copy_from(&f4);
        q.fixed_view_mut::<4, 4>(0, 0).copy_from(&q4);
        let walk = p.size_walk_m.powi(2) * p.dt_s;
        q[(4, 4)] = walk;
        q[(5, 5)] = walk;
        (f, q)
    }

    fn measure(&self, kf: &mut Kalman<6>, h: &Hypothesis) {
        self.measure_sigma(kf, h, self.params.position_sigma_m);
    }

    /// [`Self::measure`] with this ground-position noise (m).
    fn measure_sigma(&self, kf: &mut Kalman<6>, h: &Hypothesis, position_sigma_m: f64) {
        let p = &self.params;
        let mut hm = Matrix4x6::zeros();
        hm[(0, 0)] = 1.0;
        hm[(1, 1)] = 1.0;
        hm[(2, 4)] = 1.0;
        hm[(3, 5)] = 1.0;
        let r = SMatrix::<f64, 4, 4>::from_diagonal(&Vector4::new(
            position_sigma_m.powi(2),
            position_sigma_m.powi(2),
            p.height_sigma_m.powi(2),
            p.radius_sigma_m.powi(2),
        ));
        let z = Vector4::new(h.head_m.x, h.head_m.y, h.head_m.z, h.radius_m);
        if z.iter().all(|v| v.is_finite()) {
            let _ = kf.update(&hm, &r, &z);
        } else {
            // radius undefined (zero width): position and height only
            let _ = kf.update(
                &hm.fixed_view::<3, 6>(0, 0).into_owned(),
                &r.fixed_view::<3, 3>(0, 0).into_owned(),
                &z.fixed_rows::<3>(0).into_owned(),
            );
        }
    }

    /// All combinations (as sorted index lists) of `free` objects, at most one per camera and
    /// at least `min_cameras`; pairwise-coherent ones only when there would be too many.
    fn combinations(
        &self,
        prepared: &[Prepared],
        free: &[usize],
        stats: &mut StepStats,
    ) -> Vec<Vec<usize>> {
        let n_cams = self.views.len();
        let mut per_cam: Vec<Vec<usize>> = vec![Vec::new(); n_cams];
        for &i in free {
            per_cam[prepared[i].camera].push(i);
        }
        let total: f64 = per_cam.iter().map(|v| (v.len() + 1) as f64).product();
        let pairwise = total > self.params.max_combinations as f64;
        let mut coherent = std::collections::HashSet::new();
        if pairwise {
            stats.pruned = true;
            let gate = CylinderParams {
                p_th_px: 2.0 * self.params.p_th_px,
                ..self.params
            };
            let relaxed = CylinderTracker {
                params: gate,
                ..self.clone()
            };
            for (a, &i) in free.iter().enumerate() {
                for &j in &free[a + 1..] {
                    if prepared[i].camera != prepared[j].camera {
                        let pair = [i.min(j), i.max(j)];
                        stats.combinations += 1;
                        if relaxed.evaluate(prepared, &pair).is_some() {
                            coherent.insert((pair[0], pair[1]));
                        }
                    }
                }
            }
        }
        let mut out = Vec::new();
        let mut current = Vec::new();
        fn rec(
            cam: usize,
            per_cam: &[Vec<usize>],
            current: &mut Vec<usize>,
            out: &mut Vec<Vec<usize>>,
            min: usize,
            coherent: Option<&std::collections::HashSet<(usize, usize)>>,
        ) {
            if cam == per_cam.len() {
                if current.len() >= min {
                    out.push(current.clone());
                }
                return;
            }
            // cameras left cannot bring the count up to `min`
            if current.len() + (per_cam.len() - cam) < min {
                return;
            }
            rec(cam + 1, per_cam, current, out, min, coherent);
            for &i in &per_cam[cam] {
                if let Some(ok) = coherent
                    && !current.iter().all(|&j| ok.contains(&(j.min(i), j.max(i))))
                {
                    continue;
                }
                current.push(i);
                rec(cam + 1, per_cam, current, out, min, coherent);
                current.pop();
            }
        }
        rec(
            0,
            &per_cam,
            &mut current,
            &mut out,
            self.params.min_cameras,
            pairwise.then_some(&coherent),
        );
        out
    }

    /// Advance one frame with this frame's 2-D objects; returns every 3-D object alive after
    /// it (supported or coasting), sorted by id.
    pub fn step(&mut self, objects: &[Object2d]) -> (Vec<Cylinder>, StepStats) {
        match self.params.association {
            Association::Ground => return self.step_ground(objects),
            Association::Occupancy => return self.step_occupancy(objects),
            Association::Paper | Association::Scalable => {}
        }
        let mut stats = StepStats::default();
        let prepared = self.prepare(objects);
        let (f, q) = self.transition();
        let mut used = self.update_objects(&prepared, (&f, &q), &mut stats);
        let selected = match self.params.association {
            Association::Paper => self.select_new(&prepared, &mut used, &mut stats),
            Association::Scalable | Association::Ground | Association::Occupancy => {
                self.select_new_scalable(&prepared, &mut used, &mut stats)
            }
        };
        self.continue_candidates(selected, (&f, &q), &mut stats);
        (self.cylinders(), stats)
    }

    /// Step 1: predict every object, then update it with the best combination differing in at
    /// most one 2-D object from its support; objects missed for N_dis frames (or coasting
    /// out of the room) are dropped. Returns which prepared 2-D objects were used.
    fn update_objects(
        &mut self,
        prepared: &[Prepared],
        transition: (&Matrix6<f64>, &Matrix6<f64>),
        stats: &mut StepStats,
    ) -> Vec<bool> {
        let index: BTreeMap<(usize, u32), usize> = prepared
            .iter()
            .enumerate()
            .map(|(i, p)| ((p.camera, p.id), i))
            .collect();
        let (f, q) = transition;
        let sel = self.params.selection;
        let mut options: Vec<(f64, usize, Vec<usize>, Hypothesis)> = Vec::new();
        for obj in self.objects.iter_mut() {
            obj.kf.predict(f, q);
            obj.age += 1;
        }
        for (k, obj) in self.objects.iter().enumerate() {
            let base: BTreeMap<usize, usize> = obj
                .support
                .iter()
                .filter_map(|s| index.get(s).map(|&i| (s.0, i)))
                .collect();
            let mut combos: Vec<Vec<usize>> = Vec::new();
            let as_combo = |m: &BTreeMap<usize, usize>| m.values().copied().collect::<Vec<usize>>();
            combos.push(as_combo(&base));
            for (i, p) in prepared.iter().enumerate() {
                if base.get(&p.camera) == Some(&i) {
                    continue;
                }
                let mut m = base.clone();
                m.insert(p.camera, i);
                combos.push(as_combo(&m));
            }
            for cam in base.keys() {
                let mut m = base.clone();
                m.remove(cam);
                combos.push(as_combo(&m));
            }
            let (px, py) = (obj.kf.x[0], obj.kf.x[1]);
            for mut c in combos {
                c.sort_by_key(|&i| prepared[i].camera);
                stats.combinations += usize::from(c.len() >= self.params.min_cameras);
                if let Some(h) = self.evaluate(prepared, &c)
                    && (h.head_m.x - px).hypot(h.head_m.y - py) <= self.params.gate_m
                {
                    options.push((h.score(sel), k, c, h));
                }
            }
        }
        options.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
        let mut used = vec![false; prepared.len()];
        let mut updated = vec![None; self.objects.len()];
        for (_, k, combo, h) in options {
            if updated[k].is_some() || combo.iter().any(|&i| used[i]) {
                continue;
            }
            for &i in &combo {
                used[i] = true;
            }
            updated[k] = Some(h);
        }
        let mut discarded = 0;
        let mut kept = Vec::with_capacity(self.objects.len());
        let objects = std::mem::take(&mut self.objects);
        for (mut obj, upd) in objects.into_iter().zip(updated) {
            match upd {
                Some(h) => {
                    self.measure(&mut obj.kf, &h);
                    obj.support = h.support.clone();
                    obj.misses = 0;
                    obj.measured = Some(h);
                }
                None => {
                    obj.misses += 1;
                    obj.measured = None;
                }
            }
            // a coasting object whose prediction has left the room has left it (or its
            // velocity is noise): not reported out there for the rest of N_dis
            if obj.misses >= self.params.n_dis || !self.in_room(obj.kf.x[0], obj.kf.x[1]) {
                discarded += 1;
            } else {
                kept.push(obj);
            }
        }
        self.objects = kept;
        stats.discarded = discarded;
        used
    }

    /// Step 2: new hypotheses among the 2-D objects that support no object, best first, each
    /// 2-D object in at most one; marks the ones it takes in `used`.
    fn select_new(
        &self,
        prepared: &[Prepared],
        used: &mut [bool],
        stats: &mut StepStats,
    ) -> Vec<Hypothesis> {
        let sel = self.params.selection;
        let free: Vec<usize> = (0..prepared.len()).filter(|&i| !used[i]).collect();
        let combos = self.combinations(prepared, &free, stats);
        stats.combinations += combos.len();
        let valid: Vec<(f64, Vec<usize>, Hypothesis)> = combos
            .into_iter()
            .filter_map(|c| self.evaluate(prepared, &c).map(|h| (h.score(sel), c, h)))
            .collect();
        select_disjoint(valid, used)
    }

    /// Step 3: candidates are continued when this frame's selection differs in at most one
    /// object from theirs, and promoted to objects after N_app frames.
    fn continue_candidates(
        &mut self,
        selected: Vec<Hypothesis>,
        (f, q): (&Matrix6<f64>, &Matrix6<f64>),
        stats: &mut StepStats,
    ) {
        let old = std::mem::take(&mut self.candidates);
        let mut taken = vec![false; old.len()];
        let mut next = Vec::new();
        for h in selected {
            let best = old
                .iter()
                .enumerate()
                .filter(|(j, _)| !taken[*j])
                .map(|(j, c)| (support_difference(&c.support, &h.support), j))
                .filter(|(d, _)| *d <= 1)
                .min();
            let prev = best.map(|(_, j)| {
                taken[j] = true;
                let mut c = old[j].clone();
                c.kf.predict(f, q);
                c
            });
            next.extend(self.advance_candidate(prev, h, stats));
        }
        self.candidates = next;
    }

    /// Every 3-D object alive (supported or coasting), sorted by id.
    fn cylinders(&self) -> Vec<Cylinder> {
        let mut out: Vec<Cylinder> = self
            .objects
            .iter()
            .map(|o| Cylinder {
                id: o.id,
                x_m: o.kf.x[0],
                y_m: o.kf.x[1],
                vx_mps: o.kf.x[2],
                vy_mps: o.kf.x[3],
                height_m: o.kf.x[4],
                radius_m: o.kf.x[5],
                support: if o.measured.is_some() {
                    o.support.clone()
                } else {
                    Vec::new()
                },
                measured: o.measured.clone(),
                age: o.age,
            })
            .collect();
        out.sort_by_key(|c| c.id);
        out
    }
}

#[cfg(test)]
mod tests;

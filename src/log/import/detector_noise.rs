//! A detector model of our own: a person detector's errors applied to exact boxes (WILDTRACK's
//! annotated boxes, a synthetic log's ground-truth boxes), seeded, so that a multi-camera
//! stage can be measured on what a real detector would give it (issue 32, part 2).
//!
//! Three independent errors, each with its own level:
//! - **drop** — each box is missed with probability `drop`, independently of the others (a
//!   real detector's misses cluster on occluded and small people; this model does not);
//! - **jitter** — each of the four edges moves by a normal error of standard deviation
//!   `jitter · h` (`h` the box's height in pixels), and the box is clipped to the image, as a
//!   detector never reports pixels outside it;
//! - **false boxes** — per camera frame, a Poisson number of mean `false_per_frame` of
//!   person-shaped boxes: the bounds of a standing cylinder ([`FALSE_HEIGHT_M`],
//!   [`FALSE_RADIUS_M`]) at a ground point drawn uniformly in the room among those the camera
//!   sees whole (feet and head in the image). Such a box agrees with the camera geometry like a
//!   real person's: the hardest kind of false alarm for a geometric 3-D stage, which only other
//!   cameras can expose. False boxes are jittered too.
//!
//! **Seeding.** Every draw comes from a ChaCha stream keyed by `(seed, kind, stamp, camera)`
//! ([`crate::rng::hash`]), so a frame's noise does not depend on which other frames were
//! processed or in which order, and the importer (`peopletrack import wildtrack
//! --detector-noise …`) and the pipeline's noise table draw the same boxes from the same seed.
//! The draws are common to all levels (a box dropped at 10 % is dropped at 20 %; the false boxes
//! at mean 1 are the first ones of those at mean 2; the jitter's normal deviates are the same,
//! scaled), so rows at several levels differ by the level, not by luck.
//!
//! What it does not model: misses and false alarms that persist over frames, boxes merged over
//! two people, misses caused by occlusion, or scores.

use nalgebra::Point3;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use crate::geometry::triangulate::CalibratedView;

/// Height range of a false box's person (m): WILDTRACK's annotated heights are 1.6–1.9 m for
/// most people (the importer's `person_size`); a priori, not tuned.
pub const FALSE_HEIGHT_M: (f64, f64) = (1.6, 1.9);
/// Radius of a false box's cylinder (m): WILDTRACK's annotation cylinder.
pub const FALSE_RADIUS_M: f64 = 0.25;
/// Ground points tried per false box before the camera is taken to see none of the room.
const FALSE_TRIES: usize = 64;
/// A jittered box narrower or lower than this (px) is no detection.
pub const MIN_BOX_PX: f64 = 2.0;
/// Points per circle of the cylinder whose bounds make a person's box.
const CIRCLE_POINTS: usize = 16;

/// Stream labels: one per kind of error, so that the kinds are independent.
const DROP: u64 = 1;
const JITTER: u64 = 2;
const FALSE: u64 = 3;
const FALSE_JITTER: u64 = 4;

/// The levels of the three errors.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DetectorNoise {
    /// Probability that a box is missed.
    pub drop: f64,
    /// Standard deviation of each edge as a fraction of the box height.
    pub jitter: f64,
    /// Mean number of false person-shaped boxes per camera frame (Poisson).
    #[serde(rename = "false")]
    pub false_per_frame: f64,
}

impl DetectorNoise {
    /// No error at all (the boxes pass unchanged).
    pub fn is_clean(&self) -> bool {
        self.drop == 0.0 && self.jitter == 0.0 && self.false_per_frame == 0.0
    }

    /// Why the levels are unusable, if they are.
    pub fn validate(&self) -> Result<(), String> {
        if !(0.0..1.0).contains(&self.drop) {
            return Err(format!("drop {} is not a probability in [0, 1)", self.drop));
        }
        if !(self.jitter >= 0.0 && self.jitter <= 1.0) {
            return Err(format!(
                "jitter {} is not a fraction of the box height in [0, 1]",
                self.jitter
            ));
        }
        if !(self.false_per_frame >= 0.0 && self.false_per_frame <= 100.0) {
            return Err(format!(
                "false {} is not a mean number of boxes per camera frame in [0, 100]",
                self.false_per_frame
            ));
        }
        Ok(())
    }

    /// `drop=0.2,jitter=0.04,false=1` (any subset, any order; absent keys are 0).
    pub fn parse(text: &str) -> Result<DetectorNoise, String> {
        let mut n = DetectorNoise::default();
        for part in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let (key, value) = part
                .split_once('=')
                .ok_or_else(|| format!("`{part}` is not key=value"))?;
            let v: f64 = value
                .trim()
                .parse()
                .map_err(|_| format!("`{value}` in `{part}` is not a number"))?;
            match key.trim() {
                "drop" => n.drop = v,
                "jitter" => n.jitter = v,
                "false" => n.false_per_frame = v,
                k => return Err(format!("unknown key `{k}` (drop, jitter, false)")),
            }
        }
        n.validate()?;
        Ok(n)
    }

    /// A short label for tables: `none` when clean, else the non-zero levels.
    pub fn label(&self) -> String {
        if self.is_clean() {
            return "none".to_string();
        }
        let mut parts = Vec::new();
        if self.drop > 0.0 {
            parts.push(format!("drop {}", self.drop));
        }
        if self.jitter > 0.0 {
            parts.push(format!("jitter {}", self.jitter));
        }
        if self.false_per_frame > 0.0 {
            parts.push(format!("false {}", self.false_per_frame));
        }
        parts.join(", ")
    }
}

/// Where one camera frame's noise is drawn from.
#[derive(Debug, Clone, Copy)]
pub struct CameraFrame<'a> {
    pub view: &'a CalibratedView,
    /// Index of the camera (part of the stream key).
    pub camera: usize,
    /// The frame's stamp (ns; part of the stream key).
    pub stamp_ns: u64,
    /// Floor `[x0, y0, x1, y1]` (m) where false boxes stand.
    pub room_m: [f64; 4],
}

fn stream(seed: u64, kind: u64, f: &CameraFrame, index: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(crate::rng::hash(
        seed,
        &[kind, f.stamp_ns, f.camera as u64, index],
    ))
}

/// The box of a standing cylinder (raw pixels): the bounds of its top and bottom circles;
/// `None` when part of it is behind the camera or does not project.
pub fn person_box(
    view: &CalibratedView,
    x: f64,
    y: f64,
    height_m: f64,
    radius_m: f64,
) -> Option<[f64; 4]> {
    let mut b = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    let inv = view.world_from_camera.inverse();
    for z in [0.0, height_m] {
        for k in 0..CIRCLE_POINTS {
            let a = std::f64::consts::TAU * k as f64 / CIRCLE_POINTS as f64;
            let p = Point3::new(x + radius_m * a.cos(), y + radius_m * a.sin(), z);
            if (inv * p).z <= 0.0 {
                return None;
            }
            let q = view.project(&p)?;
            b = [b[0].min(q.x), b[1].min(q.y), b[2].max(q.x), b[3].max(q.y)];
        }
    }
    b.iter().all(|v| v.is_finite()).then_some(b)
}

/// Whether the camera sees a box whole: its bottom and top centres inside the image.
pub fn whole_in_image(view: &CalibratedView, b: &[f64; 4]) -> bool {
    let (w, h) = view.model.size();
    let (w, h) = (f64::from(w), f64::from(h));
    let cx = 0.5 * (b[0] + b[2]);
    (0.0..=w).contains(&cx) && b[1] >= 0.0 && b[3] <= h && b[3] > b[1]
}

/// `b` with each edge moved by `jitter · height · z_k` and clipped to the image; `None` when
/// what is left is smaller than [`MIN_BOX_PX`].
fn jittered(view: &CalibratedView, b: [f64; 4], jitter: f64, z: [f64; 4]) -> Option<[f64; 4]> {
    let s = jitter * (b[3] - b[1]);
    let (w, h) = view.model.size();
    let (w, h) = (f64::from(w), f64::from(h));
    let mut x0 = b[0] + s * z[0];
    let mut y0 = b[1] + s * z[1];
    let mut x1 = b[2] + s * z[2];
    let mut y1 = b[3] + s * z[3];
    if jitter > 0.0 {
        x0 = x0.clamp(0.0, w);
        x1 = x1.clamp(0.0, w);
        y0 = y0.clamp(0.0, h);
        y1 = y1.clamp(0.0, h);
    }
    (x1 - x0 >= MIN_BOX_PX && y1 - y0 >= MIN_BOX_PX).then_some([x0, y0, x1, y1])
}

fn normals(rng: &mut ChaCha8Rng) -> [f64; 4] {
    std::array::from_fn(|_| StandardNormal.sample(rng))
}

/// The smallest `k` with `P(K ≤ k) ≥ u` for `K ~ Poisson(mean)`: one uniform per count, so a
/// larger mean never gives fewer boxes for the same draw.
pub fn poisson_quantile(mean: f64, u: f64) -> usize {
    if mean <= 0.0 {
        return 0;
    }
    let mut p = (-mean).exp();
    let mut cdf = p;
    let mut k = 0;
    while cdf < u && k < 10_000 {
        k += 1;
        p *= mean / k as f64;
        cdf += p;
    }
    k
}

/// False box number `index` of a camera frame: a cylinder at a ground point the camera sees
/// whole, drawn uniformly in the room (rejection sampling, [`FALSE_TRIES`] tries).
fn false_box(seed: u64, f: &CameraFrame, index: u64) -> Option<[f64; 4]> {
    let mut rng = stream(seed, FALSE, f, index);
    let r = f.room_m;
    for _ in 0..FALSE_TRIES {
        let x = r[0] + (r[2] - r[0]) * rng.random::<f64>();
        let y = r[1] + (r[3] - r[1]) * rng.random::<f64>();
        let h = FALSE_HEIGHT_M.0 + (FALSE_HEIGHT_M.1 - FALSE_HEIGHT_M.0) * rng.random::<f64>();
        if let Some(b) = person_box(f.view, x, y, h, FALSE_RADIUS_M)
            && whole_in_image(f.view, &b)
        {
            return Some(b);
        }
    }
    None
}

/// One camera frame's boxes `[x0, y0, x1, y1]` (raw pixels) through the detector model: the
/// kept boxes in their order, then the false ones.
pub fn apply(
    noise: &DetectorNoise,
    seed: u64,
    f: &CameraFrame,
    boxes: &[[f64; 4]],
) -> Vec<[f64; 4]> {
    if noise.is_clean() {
        return boxes.to_vec();
    }
    let mut drop = stream(seed, DROP, f, 0);
    let mut jit = stream(seed, JITTER, f, 0);
    let mut out = Vec::with_capacity(boxes.len() + 2);
    for &b in boxes {
        // both draws for every box, so that the levels share them
        let u: f64 = drop.random();
        let z = normals(&mut jit);
        if u < noise.drop {
            continue;
        }
        out.extend(jittered(f.view, b, noise.jitter, z));
    }
    let n = poisson_quantile(
        noise.false_per_frame,
        stream(seed, FALSE, f, u64::MAX).random(),
    );
    for k in 0..n as u64 {
        let z = normals(&mut stream(seed, FALSE_JITTER, f, k));
        if let Some(b) = false_box(seed, f, k) {
            out.extend(jittered(f.view, b, noise.jitter, z));
        }
    }
    out
}

#[cfg(test)]
mod tests;

//! Moving people seen from a moving camera (seed 003, Zajdel et al. §III-B): "We track 100
//! corner-like points using the Kanade-Lucas-Tomasi tracker. We use a robust method to estimate
//! the fundamental matrix and detect the points that deviate from the model. The detected
//! points correspond to the moving objects … To estimate the position of the object we use
//! again the second order moments to approximate the 2D shape of the object by an ellipse. We
//! use the moment estimates from the previous frame and keep them fixed. We use the mean-shift
//! algorithm to find the ellipse that will contain the [moving points]."
//!
//! Per frame: the previous frame's corners are tracked into this one (`vision::klt`), the set
//! is topped up to `corners` fresh Shi–Tomasi corners away from the tracked ones, and a RANSAC
//! fundamental matrix (`geometry::fundamental`) over the tracked pairs marks the outliers as
//! moving points. Each object of the previous frame moves by mean shift over the moving points
//! with its previous covariance held fixed (Gaussian kernel), then takes the moments of the
//! moving points within `gate_sigma` of its new centre as its ellipse for the next frame; an
//! object with fewer than `min_points` such points is lost. Moving points no object claims are
//! grouped (single link within `cluster_px`) and each group of at least `min_points` starts an
//! object from its moments. The text leaves these three numbers open; the defaults are a
//! priori (a person is several corners, and corners lie about `min_distance_px` apart).
//!
//! Written by hand on the project's KLT and fundamental-matrix modules (see their docs for why
//! no crate does those); the clustering and the kernel mean shift are a few lines each.

use image::GrayImage;
use nalgebra::{Matrix2, Point2};

use crate::geometry::fundamental::{self, Pair};
use crate::vision::ellipse::Ellipse;
use crate::vision::klt::{self, LkParams, Pyramid};

/// Settings of [`MovingDetector`].
#[derive(Debug, Clone, PartialEq)]
pub struct MovingParams {
    /// Corners kept per frame (the paper: 100).
    pub corners: usize,
    /// Shi–Tomasi quality relative to the best corner.
    pub quality: f32,
    /// No two corners closer than this (px).
    pub min_distance_px: f32,
    /// Pyramid levels of the tracker.
    pub levels: usize,
    /// RANSAC inlier threshold: Sampson distance (px).
    pub ransac_threshold_px: f64,
    pub ransac_iterations: usize,
    /// Seed of the RANSAC draws (each frame draws from its own stream).
    pub seed: u64,
    /// Fewest moving points that make or keep an object.
    pub min_points: usize,
    /// Single-link grouping distance of unclaimed moving points (px).
    pub cluster_px: f64,
    /// An object claims the moving points within this many standard deviations.
    pub gate_sigma: f64,
    /// Floor on an object's standard deviation along each axis (px), so that two or three
    /// collinear points still make an ellipse.
    pub min_sigma_px: f64,
}

impl Default for MovingParams {
    fn default() -> Self {
        Self {
            corners: 100,
            quality: 0.01,
            min_distance_px: 8.0,
            levels: 3,
            ransac_threshold_px: 1.0,
            ransac_iterations: 500,
            seed: 3,
            min_points: 3,
            cluster_px: 30.0,
            gate_sigma: 2.5,
            min_sigma_px: 3.0,
        }
    }
}

/// One object found moving against the scene.
#[derive(Debug, Clone, PartialEq)]
pub struct MovingObject {
    pub id: u64,
    pub ellipse: Ellipse,
    /// Moving points it holds this frame.
    pub points: usize,
}

/// What one frame gave.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MovingFrame {
    /// Corners tracked from the previous frame (`(previous, current)`, pixels).
    pub pairs: Vec<Pair>,
    /// Which pairs deviate from the fundamental matrix (empty when no fit was possible).
    pub moving: Vec<bool>,
    /// Whether a fundamental matrix was fitted (at least 8 non-degenerate pairs).
    pub fitted: bool,
    pub objects: Vec<MovingObject>,
}

impl MovingFrame {
    /// The moving points (current frame).
    pub fn moving_points(&self) -> Vec<Point2<f64>> {
        self.pairs
            .iter()
            .zip(&self.moving)
            .filter(|(_, m)| **m)
            .map(|(p, _)| Point2::new(p.1[0], p.1[1]))
            .collect()
    }
}

/// The detector's state between frames.
pub struct MovingDetector {
    p: MovingParams,
    prev: Option<(Pyramid, Vec<[f32; 2]>)>,
    objects: Vec<MovingObject>,
    next_id: u64,
    frame: u64,
}

impl MovingDetector {
    pub fn new(p: MovingParams) -> Self {
        Self {
            p,
            prev: None,
            objects: Vec::new(),
            next_id: 0,
            frame: 0,
        }
    }

    /// Forget everything (the camera stopped, or a gap in the frames).
    pub fn reset(&mut self) {
        self.prev = None;
        self.objects.clear();
    }

    /// One grey frame.
    pub fn step(&mut self, grey: &GrayImage) -> MovingFrame {
        let pyr = Pyramid::new(grey, self.p.levels.max(1));
        let mut pairs = Vec::new();
        let mut tracked: Vec<[f32; 2]> = Vec::new();
        if let Some((prev, pts)) = &self.prev {
            let moved = klt::track(prev, &pyr, pts, &LkParams::default());
            for (a, b) in pts.iter().zip(moved) {
                if let Some(b) = b {
                    pairs.push((
                        [f64::from(a[0]), f64::from(a[1])],
                        [f64::from(b[0]), f64::from(b[1])],
                    ));
                    tracked.push(b);
                }
            }
        }
        let out = self.detect(pairs);
        let corners = self.top_up(grey, tracked);
        self.prev = Some((pyr, corners));
        out
    }

    /// The geometric half of [`step`](Self::step): the moving points among the corner pairs
    /// `(previous, current)` and the objects they make.
    pub fn detect(&mut self, pairs: Vec<Pair>) -> MovingFrame {
        let mut out = MovingFrame {
            pairs,
            ..MovingFrame::default()
        };
        let seed = self.p.seed.wrapping_add(self.frame);
        self.frame += 1;
        if let Some(fit) = fundamental::ransac(
            &out.pairs,
            self.p.ransac_threshold_px,
            self.p.ransac_iterations,
            seed,
        ) {
            out.moving = fit.inliers.iter().map(|i| !i).collect();
            out.fitted = true;
        } else {
            out.moving = vec![false; out.pairs.len()];
        }
        self.update_objects(&out.moving_points());
        out.objects = self.objects.clone();
        out
    }

    /// The tracked corners plus fresh ones away from them, up to `corners`.
    fn top_up(&self, grey: &GrayImage, mut pts: Vec<[f32; 2]>) -> Vec<[f32; 2]> {
        let d2 = self.p.min_distance_px * self.p.min_distance_px;
        pts.truncate(self.p.corners);
        let fresh = klt::good_features(
            grey,
            self.p.corners * 2,
            self.p.quality,
            self.p.min_distance_px,
            3,
        );
        for c in fresh {
            if pts.len() >= self.p.corners {
                break;
            }
            if pts
                .iter()
                .all(|q| (q[0] - c[0]).powi(2) + (q[1] - c[1]).powi(2) >= d2)
            {
                pts.push(c);
            }
        }
        pts
    }

    /// Mean shift of every object, then new objects from the unclaimed moving points.
    fn update_objects(&mut self, pts: &[Point2<f64>]) {
        let mut claimed = vec![false; pts.len()];
        let mut kept = Vec::new();
        for o in &self.objects {
            let Some(center) = mean_shift(&o.ellipse, pts) else {
                continue;
            };
            let moved = Ellipse::new(center, o.ellipse.cov);
            let mine: Vec<usize> = (0..pts.len())
                .filter(|&i| !claimed[i] && within(&moved, pts[i], self.p.gate_sigma))
                .collect();
            if mine.len() < self.p.min_points {
                continue;
            }
            for &i in &mine {
                claimed[i] = true;
            }
            let members: Vec<Point2<f64>> = mine.iter().map(|&i| pts[i]).collect();
            kept.push(MovingObject {
                id: o.id,
                ellipse: moments(&members, self.p.min_sigma_px),
                points: members.len(),
            });
        }
        let free: Vec<Point2<f64>> = (0..pts.len())
            .filter(|&i| !claimed[i])
            .map(|i| pts[i])
            .collect();
        for group in single_link(&free, self.p.cluster_px) {
            if group.len() < self.p.min_points {
                continue;
            }
            let members: Vec<Point2<f64>> = group.iter().map(|&i| free[i]).collect();
            kept.push(MovingObject {
                id: self.next_id,
                ellipse: moments(&members, self.p.min_sigma_px),
                points: members.len(),
            });
            self.next_id += 1;
        }
        self.objects = kept;
    }
}

fn within(e: &Ellipse, p: Point2<f64>, k: f64) -> bool {
    e.mahalanobis2(p).is_some_and(|d2| d2 <= k * k)
}

/// The mode of the Gaussian-kernel density of `pts` nearest `e`'s centre, with `e`'s
/// covariance as the fixed bandwidth; `None` when no point has weight.
pub fn mean_shift(e: &Ellipse, pts: &[Point2<f64>]) -> Option<Point2<f64>> {
    let mut c = e.center;
    for _ in 0..30 {
        let (mut sx, mut sy, mut sw) = (0.0, 0.0, 0.0);
        for &p in pts {
            let d2 = Ellipse::new(c, e.cov).mahalanobis2(p)?;
            let w = (-0.5 * d2).exp();
            sx += w * p.x;
            sy += w * p.y;
            sw += w;
        }
        // also catches a NaN sum
        if sw.is_nan() || sw <= 1e-12 {
            return None;
        }
        let next = Point2::new(sx / sw, sy / sw);
        let step = (next - c).norm();
        c = next;
        if step < 0.01 {
            break;
        }
    }
    Some(c)
}

/// Mean and covariance of `pts` (population moments), each axis's variance floored at
/// `min_sigma²`.
pub fn moments(pts: &[Point2<f64>], min_sigma: f64) -> Ellipse {
    let n = pts.len().max(1) as f64;
    let (mx, my) = pts
        .iter()
        .fold((0.0, 0.0), |a, p| (a.0 + p.x / n, a.1 + p.y / n));
    let (mut vxx, mut vxy, mut vyy) = (0.0, 0.0, 0.0);
    for p in pts {
        let (dx, dy) = (p.x - mx, p.y - my);
        vxx += dx * dx / n;
        vxy += dx * dy / n;
        vyy += dy * dy / n;
    }
    let floor = min_sigma * min_sigma;
    Ellipse::new(
        Point2::new(mx, my),
        Matrix2::new(vxx + floor, vxy, vxy, vyy + floor),
    )
}

/// Groups of points linked by chains of distances at most `r` (indices, in first-point order).
pub fn single_link(pts: &[Point2<f64>], r: f64) -> Vec<Vec<usize>> {
    let mut group = vec![usize::MAX; pts.len()];
    let mut out: Vec<Vec<usize>> = Vec::new();
    for s in 0..pts.len() {
        if group[s] != usize::MAX {
            continue;
        }
        let g = out.len();
        group[s] = g;
        let mut members = vec![s];
        let mut k = 0;
        while k < members.len() {
            let a = members[k];
            for b in 0..pts.len() {
                if group[b] == usize::MAX && (pts[a] - pts[b]).norm() <= r {
                    group[b] = g;
                    members.push(b);
                }
            }
            k += 1;
        }
        members.sort_unstable();
        out.push(members);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moments_are_the_population_mean_and_covariance_plus_the_floor() {
        let pts = [
            Point2::new(0.0, 0.0),
            Point2::new(2.0, 0.0),
            Point2::new(0.0, 4.0),
            Point2::new(2.0, 4.0),
        ];
        let e = moments(&pts, 1.0);
        assert_eq!(e.center, Point2::new(1.0, 2.0));
        // var x = 1, var y = 4, cov 0; + 1 each
        assert_eq!(e.cov, Matrix2::new(2.0, 0.0, 0.0, 5.0));
    }

    #[test]
    fn single_link_chains_points_within_the_radius() {
        let pts = [
            Point2::new(0.0, 0.0),
            Point2::new(50.0, 0.0),
            Point2::new(3.0, 0.0),
            Point2::new(6.0, 0.0),
            Point2::new(53.5, 0.0),
        ];
        assert_eq!(
            single_link(&pts, 3.0),
            vec![vec![0, 2, 3], vec![1], vec![4]]
        );
        assert_eq!(single_link(&pts, 4.0), vec![vec![0, 2, 3], vec![1, 4]]);
        assert!(single_link(&[], 1.0).is_empty());
    }

    #[test]
    fn mean_shift_finds_the_mode_and_ignores_a_far_cluster() {
        // a symmetric cluster around (10, 20) and a far one at (100, 20); start at (13, 22)
        let mut pts = Vec::new();
        for (dx, dy) in [(-1.0, 0.0), (1.0, 0.0), (0.0, -1.0), (0.0, 1.0)] {
            pts.push(Point2::new(10.0 + dx, 20.0 + dy));
            pts.push(Point2::new(100.0 + dx, 20.0 + dy));
        }
        let e = Ellipse::from_parts(13.0, 22.0, 16.0, 0.0, 16.0);
        let c = mean_shift(&e, &pts).expect("mode");
        // the far cluster's weight is e^(−0.5·87²/16) ≈ 0: the fixed point is the near centre;
        // near it each iteration shrinks the offset 32-fold (Σd²/(4σ²) = 2/64), and the loop
        // stops at a step below 0.01 px, so the offset left is below 0.01/31 px
        assert!((c - Point2::new(10.0, 20.0)).norm() < 0.01 / 31.0, "{c}");
        let empty = Ellipse::from_parts(500.0, 500.0, 1.0, 0.0, 1.0);
        assert_eq!(mean_shift(&empty, &pts), None, "no weight");
    }

    /// Pinhole projection (f = 300 px, centre (160, 120)) of a camera-frame point.
    fn project(p: [f64; 3]) -> [f64; 2] {
        [160.0 + 300.0 * p[0] / p[2], 120.0 + 300.0 * p[1] / p[2]]
    }

    /// A robot driving forward 0.2 m per frame through a static scene (points 2–12 m deep)
    /// while a person of 12 corners 4 m ahead walks sideways 0.1 m per frame: exactly the
    /// person's pairs move off the epipolar lines, and one object follows them.
    #[test]
    fn a_person_walking_across_a_forward_moving_robot_is_its_moving_points() {
        let mut stream = crate::rng::stream(7, "moving test scene", 0);
        use rand::RngExt;
        let scene: Vec<[f64; 3]> = (0..80)
            .map(|_| {
                [
                    stream.random_range(-4.0..4.0),
                    stream.random_range(-1.0..1.5),
                    stream.random_range(2.0..12.0),
                ]
            })
            .collect();
        let body: Vec<[f64; 2]> = (0..12)
            .map(|i| {
                [
                    0.15 * f64::from(i % 3) - 0.15,
                    -0.9 + 0.35 * f64::from(i / 3),
                ]
            })
            .collect();
        let person = |k: usize| -> Vec<[f64; 3]> {
            body.iter()
                .map(|b| [-0.5 + 0.1 * k as f64 + b[0], b[1], 4.0])
                .collect()
        };
        let mut d = MovingDetector::new(MovingParams::default());
        let mut last = MovingFrame::default();
        for k in 0..5 {
            // camera at z = 0.2 k: a point at depth z is at z − 0.2 k; the person keeps its
            // world depth 4 + 0.2 k so it stays 4 m ahead
            let at = |p: &[f64; 3], k: usize| project([p[0], p[1], p[2] - 0.2 * k as f64]);
            let mut pairs: Vec<Pair> = scene.iter().map(|p| (at(p, k), at(p, k + 1))).collect();
            let (now, next) = (person(k), person(k + 1));
            pairs.extend(
                now.iter()
                    .zip(&next)
                    .map(|(a, b)| (project([a[0], a[1], a[2]]), project([b[0], b[1], b[2]]))),
            );
            last = d.detect(pairs);
        }
        assert!(last.fitted);
        let flags: Vec<bool> = last.moving.clone();
        assert!(flags[..80].iter().all(|m| !m), "a static point moved");
        assert!(
            flags[80..].iter().all(|m| *m),
            "a person point did not move"
        );
        assert_eq!(last.objects.len(), 1, "{:?}", last.objects);
        let o = &last.objects[0];
        // the person's corners now: x = −0.5 + 0.5 + {−0.15, 0, 0.15} at 4 m, mean 0 → 160 px
        assert!((o.ellipse.center.x - 160.0).abs() < 1e-6, "{o:?}");
        assert_eq!(o.points, 12);
        assert_eq!(o.id, 0, "the same object throughout");
    }
}

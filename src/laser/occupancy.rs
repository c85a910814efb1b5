//! A local occupancy grid in the fixed frame, built online from the scans: leg_tracker's
//! `local_occupancy_grid_mapping` (Leigh et al., ICRA 2015; `src/local_occupancy_grid_mapping.cpp`
//! at commit c7ff1e4, the one `leg_tracker_benchmarks` pins; read, not copied). It maps
//! everything but the people being tracked, so that a tracker can ask whether a position lies
//! in space known to be free ([`LocalGrid::occupancy_around`]).
//!
//! **Cells.** A square of `cells_per_side`² cells of `resolution_m`, centred on the laser's
//! first position and moved by whole cells when the laser is more than `shift_threshold_m`
//! from the centre (cells moved in start as unseen). Cell `(i, j)` stands for the point
//! `origin + (i, j) · resolution_m`. Each cell holds the log-odds `l` of being occupied,
//! clamped to `[logit(P_MIN), logit(1 − P_MIN)]`; unseen cells start at `logit(P_MIN)` (free:
//! leg_tracker's `unseen_is_freespace = true`).
//!
//! **Update** (the inverse sensor model, per cell within `range_max` of the laser): the beam
//! nearest the cell's bearing, `k = round((θ − angle_min) / Δθ)` (cells outside the scan's
//! bearings are unknown); with the beam's range `r` and the cell's distance `d`:
//!
//! - `r` a real return or `+inf` (nothing in range) is *valid*; NaN, `−inf`, 0 or a value
//!   outside `[range_min, range_max]` is *invalid* and leaves the cell unknown;
//! - unknown when `d > range_max`, `d > r + α/2`, or `r = +inf` and `d > reliable_inf_range_m`;
//! - `P_OBSTACLE` when `r < range_max`, `|d − r| < α/2` and the beam is not marked human;
//! - `P_FREE` otherwise (the cell lies on the beam before its return, or on a tracked person);
//!
//! and `l ← clamp(l + logit(p) − logit(½))` (unknown adds 0). With `decay > 0` every cell
//! first moves that share of the way back to the unseen value (our option; see
//! [`GridParams::decay`]).
//!
//! **Free space** ([`LocalGrid::occupancy_around`]): the mean occupancy probability over the
//! 5 × 5 cells around a point; a point off the grid gets 1 (never free).
//!
//! Differences from leg_tracker, chosen a priori and stated: the beam index is counted from
//! `angle_min` (leg_tracker adds half the beam count to `round(θ/Δθ)`, exact only for scans
//! symmetric about 0, which the outdoor log is not); the free-space kernel is the centred 5 × 5
//! mean (leg_tracker sums the 4 × 4 cells at offsets −2..1 and divides by 25); cells outside
//! `range_max` are skipped (leg_tracker updates them with "unknown", which changes nothing).
//! No file I/O; pure function of the scans and poses.

use nalgebra::{Isometry3, Point2, Point3};

use super::points::ScanGeometry;

/// α: radial thickness (m) of the band around a return counted as the obstacle (leg_tracker's
/// `ALPHA`).
pub const ALPHA_M: f64 = 0.2;
/// Occupancy probability of a hit cell (leg_tracker's `OBSTACLE`).
pub const P_OBSTACLE: f64 = 0.7;
/// Occupancy probability of a cell a beam passed through (leg_tracker's `FREE_SPACE`).
pub const P_FREE: f64 = 0.4;
/// Clamp of the occupancy probability, `[P_MIN, 1 − P_MIN]` (leg_tracker's `MIN_PROB`).
pub const P_MIN: f64 = 0.001;
/// Half width (cells) of the free-space kernel: 5 × 5 cells.
pub const KERNEL_HALF: i64 = 2;

fn logit(p: f64) -> f64 {
    (p / (1.0 - p)).ln()
}

fn logistic(l: f64) -> f64 {
    1.0 / (1.0 + (-l).exp())
}

/// Settings of the grid (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridParams {
    pub resolution_m: f64,
    pub cells_per_side: usize,
    pub shift_threshold_m: f64,
    pub reliable_inf_range_m: f64,
    /// Per scan, every cell's log-odds moves this share of the way back to the unseen value
    /// before the update (0: never, as leg_tracker's code).
    pub decay: f64,
}

impl Default for GridParams {
    /// - `resolution_m` 0.05 and `cells_per_side` 400 (a 20 m square): leg_tracker's code
    ///   defaults (`local_map_resolution`, `local_map_cells_per_side`), which its launch files
    ///   keep.
    /// - `shift_threshold_m` 0.5 and `reliable_inf_range_m` 10: the values of
    ///   `leg_tracker_benchmarks`' launch files for both annotated sequences (code defaults 1.0
    ///   and 5.0).
    /// - `decay` 0: those launch files set `decay = 0.05`, but the grid node at the pinned
    ///   commit never reads a `decay` parameter, so the benchmarks ran without one.
    fn default() -> Self {
        GridParams {
            resolution_m: 0.05,
            cells_per_side: 400,
            shift_threshold_m: 0.5,
            reliable_inf_range_m: 10.0,
            decay: 0.0,
        }
    }
}

/// What one cell learns from one scan.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CellUpdate {
    Unknown,
    Free,
    Obstacle,
}

/// The inverse sensor model of one cell at distance `d` from the laser, with `r` the range of
/// its beam and `human` whether that beam belongs to a tracked person (module doc).
pub fn cell_update(d: f64, r: f32, human: bool, g: &ScanGeometry, p: &GridParams) -> CellUpdate {
    let r = f64::from(r);
    let valid = r == f64::INFINITY || g.is_return(r);
    if !valid || !d.is_finite() {
        return CellUpdate::Unknown;
    }
    if d > g.range_max || d > r + ALPHA_M / 2.0 || (r.is_infinite() && d > p.reliable_inf_range_m) {
        return CellUpdate::Unknown;
    }
    if r < g.range_max && (d - r).abs() < ALPHA_M / 2.0 && !human {
        CellUpdate::Obstacle
    } else {
        CellUpdate::Free
    }
}

/// The grid (see the module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct LocalGrid {
    pub params: GridParams,
    /// Log-odds, cell `(i, j)` at `i + n·j`.
    l: Vec<f32>,
    /// Centre of the grid in the fixed frame, set by the first scan.
    centre: Option<[f64; 2]>,
}

impl LocalGrid {
    pub fn new(params: GridParams) -> Self {
        let n = params.cells_per_side.max(1);
        LocalGrid {
            params,
            l: vec![logit(P_MIN) as f32; n * n],
            centre: None,
        }
    }

    fn n(&self) -> usize {
        self.params.cells_per_side.max(1)
    }

    /// The fixed-frame point of cell `(0, 0)`, once a scan placed the grid.
    pub fn origin(&self) -> Option<[f64; 2]> {
        let half = self.n() as f64 / 2.0 * self.params.resolution_m;
        self.centre.map(|[x, y]| [x - half, y - half])
    }

    /// Cell indices of a fixed-frame point, if it lies on the grid.
    pub fn cell_of(&self, p: Point2<f64>) -> Option<(usize, usize)> {
        let [ox, oy] = self.origin()?;
        let res = self.params.resolution_m;
        let (i, j) = (((p.x - ox) / res).round(), ((p.y - oy) / res).round());
        let n = self.n() as f64;
        (i >= 0.0 && j >= 0.0 && i < n && j < n).then_some((i as usize, j as usize))
    }

    /// Occupancy probability of the cell holding `p` (`None` off the grid).
    pub fn occupancy(&self, p: Point2<f64>) -> Option<f64> {
        let (i, j) = self.cell_of(p)?;
        Some(logistic(f64::from(self.l[i + self.n() * j])))
    }

    /// Mean occupancy probability of the 5 × 5 cells around `p`; 1 when any lies off the grid
    /// (or before the first scan).
    pub fn occupancy_around(&self, p: Point2<f64>) -> f64 {
        let Some((i, j)) = self.cell_of(p) else {
            return 1.0;
        };
        let n = self.n() as i64;
        let (i, j) = (i as i64, j as i64);
        let mut sum = 0.0;
        for dj in -KERNEL_HALF..=KERNEL_HALF {
            for di in -KERNEL_HALF..=KERNEL_HALF {
                let (a, b) = (i + di, j + dj);
                if a < 0 || b < 0 || a >= n || b >= n {
                    return 1.0;
                }
                sum += logistic(f64::from(self.l[(a + n * b) as usize]));
            }
        }
        sum / ((2 * KERNEL_HALF + 1) * (2 * KERNEL_HALF + 1)) as f64
    }

    /// Move the grid by whole cells so that it is centred on `(x, y)`; new cells are unseen.
    fn shift_to(&mut self, x: f64, y: f64) {
        let Some([cx, cy]) = self.centre else {
            self.centre = Some([x, y]);
            return;
        };
        let res = self.params.resolution_m;
        let (tx, ty) = (
            ((x - cx) / res).round() as i64,
            ((y - cy) / res).round() as i64,
        );
        let n = self.n() as i64;
        let unseen = logit(P_MIN) as f32;
        let mut moved = vec![unseen; self.l.len()];
        for j in 0..n {
            for i in 0..n {
                let (a, b) = (i + tx, j + ty);
                if a >= 0 && b >= 0 && a < n && b < n {
                    moved[(i + n * j) as usize] = self.l[(a + n * b) as usize];
                }
            }
        }
        self.l = moved;
        self.centre = Some([cx + tx as f64 * res, cy + ty as f64 * res]);
    }

    /// One scan: `ranges` with their beam geometry, the laser's pose in the fixed frame
    /// (`None`: the fixed frame is the laser's), and per beam whether it belongs to a tracked
    /// person (`human`, shorter than `ranges`: the rest count as not human).
    pub fn update(
        &mut self,
        ranges: &[f32],
        g: &ScanGeometry,
        pose: Option<&Isometry3<f64>>,
        human: &[bool],
    ) {
        let (lx, ly, yaw) = match pose {
            Some(p) => {
                let o = p * Point3::origin();
                let x = p * Point3::new(1.0, 0.0, 0.0);
                (o.x, o.y, (x.y - o.y).atan2(x.x - o.x))
            }
            None => (0.0, 0.0, 0.0),
        };
        let inc_ok = g.angle_increment.is_finite() && g.angle_increment != 0.0;
        if !(lx.is_finite() && ly.is_finite() && yaw.is_finite()) || ranges.is_empty() || !inc_ok {
            return;
        }
        match self.centre {
            None => self.centre = Some([lx, ly]),
            Some([cx, cy]) if (cx - lx).hypot(cy - ly) > self.params.shift_threshold_m => {
                self.shift_to(lx, ly)
            }
            Some(_) => {}
        }
        let p = self.params;
        if p.decay > 0.0 {
            let unseen = logit(P_MIN) as f32;
            let k = p.decay.clamp(0.0, 1.0) as f32;
            for v in &mut self.l {
                *v += k * (unseen - *v);
            }
        }
        let Some([ox, oy]) = self.origin() else {
            return;
        };
        let (l_min, l_max) = (logit(P_MIN) as f32, logit(1.0 - P_MIN) as f32);
        let add_free = logit(P_FREE) as f32;
        let add_obstacle = logit(P_OBSTACLE) as f32;
        let n = self.n() as i64;
        let res = p.resolution_m;
        let reach = g.range_max.min(n as f64 * res);
        let lo = |c: f64, o: f64| (((c - reach - o) / res).floor() as i64).clamp(0, n);
        let hi = |c: f64, o: f64| (((c + reach - o) / res).ceil() as i64 + 1).clamp(0, n);
        let last = ranges.len() - 1;
        let inc = g.angle_increment;
        let angle_max = g.angle(last);
        for j in lo(ly, oy)..hi(ly, oy) {
            let dy = oy + j as f64 * res - ly;
            for i in lo(lx, ox)..hi(lx, ox) {
                let dx = ox + i as f64 * res - lx;
                let d = dx.hypot(dy);
                if d > g.range_max {
                    continue;
                }
                let theta = wrap(dy.atan2(dx) - yaw);
                if !(theta > g.angle_min - inc.abs() / 2.0 && theta < angle_max + inc.abs() / 2.0) {
                    continue;
                }
                let k = ((theta - g.angle_min) / inc)
                    .round()
                    .clamp(0.0, last as f64) as usize;
                let human_k = human.get(k).copied().unwrap_or(false);
                let add = match cell_update(d, ranges[k], human_k, g, &p) {
                    CellUpdate::Unknown => continue,
                    CellUpdate::Free => add_free,
                    CellUpdate::Obstacle => add_obstacle,
                };
                let cell = &mut self.l[(i + n * j) as usize];
                *cell = (*cell + add).clamp(l_min, l_max);
            }
        }
    }
}

/// An angle in `(−π, π]`.
fn wrap(a: f64) -> f64 {
    let t = std::f64::consts::TAU;
    let w = a.rem_euclid(t);
    if w > std::f64::consts::PI { w - t } else { w }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn geometry() -> ScanGeometry {
        // 181 beams, −90°..90° in 1° steps, 0.05..8 m
        ScanGeometry {
            angle_min: -std::f64::consts::FRAC_PI_2,
            angle_increment: 1f64.to_radians(),
            range_min: 0.05,
            range_max: 8.0,
        }
    }

    fn small() -> GridParams {
        GridParams {
            cells_per_side: 200,
            ..GridParams::default()
        }
    }

    /// The inverse sensor model's cases, value by value (leg_tracker's rule).
    #[test]
    fn cell_update_follows_the_inverse_sensor_model() {
        let g = geometry();
        let p = GridParams::default();
        use CellUpdate::*;
        assert_eq!(cell_update(1.0, 3.0, false, &g, &p), Free); // before the return
        assert_eq!(cell_update(2.95, 3.0, false, &g, &p), Obstacle); // within α/2
        assert_eq!(cell_update(3.05, 3.0, false, &g, &p), Obstacle);
        assert_eq!(cell_update(3.0, 3.0, true, &g, &p), Free); // a tracked person
        assert_eq!(cell_update(3.2, 3.0, false, &g, &p), Unknown); // behind the return
        assert_eq!(cell_update(5.0, f32::INFINITY, false, &g, &p), Free); // nothing in range
        assert_eq!(cell_update(8.5, f32::INFINITY, false, &g, &p), Unknown); // beyond range_max
        assert_eq!(cell_update(1.0, f32::NAN, false, &g, &p), Unknown); // invalid
        assert_eq!(cell_update(1.0, 0.0, false, &g, &p), Unknown); // driver's no-return
        assert_eq!(cell_update(1.0, f32::NEG_INFINITY, false, &g, &p), Unknown);
        let near = GridParams {
            reliable_inf_range_m: 4.0,
            ..p
        };
        assert_eq!(cell_update(5.0, f32::INFINITY, false, &g, &near), Unknown);
    }

    /// A wall 3 m ahead seen `k` times: its cells hold exactly
    /// `logistic(logit(P_MIN) + k · logit(P_OBSTACLE))`, the cells before it stay at `P_MIN`
    /// (free updates saturate at the clamp), cells behind it are unseen (`P_MIN`).
    #[test]
    fn repeated_hits_add_their_log_odds_exactly() {
        let g = geometry();
        let ranges = vec![3.0f32; 181];
        let mut grid = LocalGrid::new(small());
        for k in 1..=4 {
            grid.update(&ranges, &g, None, &[]);
            let want = logistic(logit(P_MIN) + f64::from(k) * logit(P_OBSTACLE));
            let got = grid.occupancy(Point2::new(3.0, 0.0)).expect("on the grid");
            assert!((got - want).abs() < 1e-5, "scan {k}: {got} vs {want}");
        }
        let before = grid.occupancy(Point2::new(1.5, 0.0)).expect("on the grid");
        assert!((before - P_MIN).abs() < 1e-6, "{before}");
        let behind = grid.occupancy(Point2::new(3.5, 0.0)).expect("on the grid");
        assert!((behind - P_MIN).abs() < 1e-6, "{behind}");
        // off the grid: never free
        assert_eq!(grid.occupancy_around(Point2::new(50.0, 0.0)), 1.0);
        // the same beams marked human leave the wall free
        let mut human = LocalGrid::new(small());
        human.update(&ranges, &g, None, &[true; 181]);
        let c = human.occupancy(Point2::new(3.0, 0.0)).expect("on the grid");
        assert!((c - P_MIN).abs() < 1e-6);
    }

    /// A laser that moves 1 m along x and turns 90°: the obstacle it saw stays where it is in
    /// the fixed frame after the grid shifts, and a cell its new scan sees as free is
    /// updated along the new bearing.
    #[test]
    fn the_grid_keeps_the_fixed_frame_when_the_laser_moves_and_turns() {
        use nalgebra::{Translation3, UnitQuaternion};
        let g = geometry();
        let mut grid = LocalGrid::new(small());
        let mut ranges = vec![f32::INFINITY; 181];
        ranges[90] = 2.0; // straight ahead: the point (2, 0)
        for _ in 0..5 {
            grid.update(&ranges, &g, None, &[]);
        }
        // five hits from the clamped free prior: still below ½ (≈ 0.065)
        let hit = grid.occupancy(Point2::new(2.0, 0.0)).expect("on");
        let five = logistic(logit(P_MIN) + 5.0 * logit(P_OBSTACLE));
        assert!((hit - five).abs() < 1e-5, "{hit} vs {five}");
        let pose = Isometry3::from_parts(
            Translation3::new(1.0, 0.0, 0.0),
            UnitQuaternion::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_2),
        );
        let far = vec![f32::INFINITY; 181];
        grid.update(&far, &g, Some(&pose), &[]);
        assert_eq!(
            grid.origin(),
            Some([1.0 - 5.0, -5.0]),
            "shifted by 20 cells"
        );
        // (2, 0) lies at bearing −90° from the new pose: on beam 0, nothing in range → free
        let after = grid.occupancy(Point2::new(2.0, 0.0)).expect("on");
        let want = logistic(logit(P_MIN) + 5.0 * logit(P_OBSTACLE) + logit(P_FREE));
        assert!((after - want).abs() < 1e-5, "{after} vs {want}");
        // (1, 3) straight ahead of the new pose: free, clamped at P_MIN
        let ahead = grid.occupancy(Point2::new(1.0, 3.0)).expect("on");
        assert!((ahead - P_MIN).abs() < 1e-6);
    }

    #[test]
    fn decay_moves_cells_back_towards_unseen() {
        let g = geometry();
        let mut grid = LocalGrid::new(GridParams {
            decay: 0.5,
            ..small()
        });
        let hit = vec![3.0f32; 181];
        grid.update(&hit, &g, None, &[]);
        let nan = vec![f32::NAN; 181];
        grid.update(&nan, &g, None, &[]); // unknown everywhere: only the decay acts
        let l1 = logit(P_MIN) + logit(P_OBSTACLE);
        let want = logistic(l1 + 0.5 * (logit(P_MIN) - l1));
        let got = grid.occupancy(Point2::new(3.0, 0.0)).expect("on");
        assert!((got - want).abs() < 1e-5, "{got} vs {want}");
    }
}

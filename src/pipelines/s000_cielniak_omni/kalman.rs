//! Sub-experiment 7 (section 5, fig. 6): the position Kalman filter on the appearance model's
//! positions — Q and R estimated from the training frames (eq. 10), errors against the
//! measurement system with an unpaired t-test, the noise table and a fragment of the path.

use nalgebra::{Matrix2, Vector2};

use super::ann::{Learner, Split0};
use super::dataset::{Dataset, Row};
use super::shared::{fmt_ms, frame_named, mean_std, verdict};
use crate::eval::stats::{self, DEFAULT_LEVEL};
use crate::report::figure::{Circle, FigureKind, Mark, Sensor, Series, TopView};
use crate::report::rows::Rows;
use crate::report::{Figure, Table};
use crate::run::Products;
use crate::table_row;
use crate::track::position::{PositionKf, covariance};

/// Run the position Kalman filter (eq. 1–9) over appearance-model positions `z`; `starts[i]`
/// restarts it (a new session or a gap). With `velocity`, u_k is the difference of the last two
/// estimates (the paper's "estimated velocity of the person"); without, u_k = 0.
pub fn kalman_track(
    z: &[Vector2<f64>],
    starts: &[bool],
    q: Matrix2<f64>,
    r: Matrix2<f64>,
    velocity: bool,
) -> Vec<Vector2<f64>> {
    let mut est = vec![Vector2::zeros(); z.len()];
    let mut kf: Option<PositionKf> = None;
    for i in 0..z.len() {
        match kf.as_mut() {
            Some(k) if !starts[i] => {
                let u = if velocity && i >= 2 && !starts[i - 1] {
                    est[i - 1] - est[i - 2]
                } else {
                    Vector2::zeros()
                };
                k.predict(u);
                k.correct(z[i]);
            }
            _ => kf = Some(PositionKf::new(z[i], q, r)),
        }
        est[i] = kf.as_ref().map_or(z[i], |k| k.x);
    }
    est
}

/// Where a track starts: the first frame, a new session, or more than `gap` ns since the last.
pub fn starts(rows: &[Row], gap: i64) -> Vec<bool> {
    (0..rows.len())
        .map(|i| {
            i == 0
                || rows[i].session != rows[i - 1].session
                || rows[i].stamp - rows[i - 1].stamp > gap
        })
        .collect()
}

/// The noise covariances of eq. 10 (m²).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Noise {
    /// Deviations of the measured path from constant velocity.
    pub q: Matrix2<f64>,
    /// Appearance-model position errors.
    pub r: Matrix2<f64>,
    /// The random-walk variant's Q: per-step displacements.
    pub q_rw: Matrix2<f64>,
}

/// Estimate [`Noise`] on the training frames from the measured path `ext` and the appearance
/// model's positions `z`; a second difference counts when its three frames are in one session
/// within `2 gap` ns.
pub fn noise(
    rows: &[Row],
    ext: &[Vector2<f64>],
    z: &[Vector2<f64>],
    in_train: &[bool],
    gap: i64,
) -> Noise {
    let r_samples: Vec<Vector2<f64>> = (0..rows.len())
        .filter(|i| in_train[*i])
        .map(|i| z[i] - ext[i])
        .collect();
    let consecutive = |i: usize| {
        i >= 2
            && rows[i].session == rows[i - 2].session
            && rows[i].stamp - rows[i - 2].stamp <= 2 * gap
    };
    let q_samples: Vec<Vector2<f64>> = (2..rows.len())
        .filter(|i| in_train[*i] && consecutive(*i))
        .map(|i| ext[i] - ext[i - 1] - (ext[i - 1] - ext[i - 2]))
        .collect();
    let starts = starts(rows, gap);
    let q_rw: Vec<Vector2<f64>> = (1..rows.len())
        .filter(|i| in_train[*i] && !starts[*i])
        .map(|i| ext[i] - ext[i - 1])
        .collect();
    Noise {
        q: covariance(&q_samples),
        r: covariance(&r_samples),
        q_rw: covariance(&q_rw),
    }
}

/// The tracked positions of every frame and the test frames, for the tables, the figure and
/// the truth check.
pub struct Tracked {
    pub test: Vec<usize>,
    /// Measurement system, appearance model, Kalman filter, Kalman filter with u = 0.
    pub ext: Vec<Vector2<f64>>,
    pub z: Vec<Vector2<f64>>,
    pub est: Vec<Vector2<f64>>,
    pub est_rw: Vec<Vector2<f64>>,
    pub noise: Noise,
}

/// Positions from split 0's model, noise from its training frames, both filters.
pub fn track(l: &Learner, rows: &[Row], split0: &Split0, max_gap_s: f64) -> Tracked {
    let mut in_train = vec![false; rows.len()];
    for i in &split0.train {
        in_train[*i] = true;
    }
    let z: Vec<Vector2<f64>> = rows
        .iter()
        .zip(&l.xs)
        .map(|(r, x)| {
            let d = split0.model.predict(x);
            Vector2::new(
                r.cam.0 + d * r.omni_bearing.cos(),
                r.cam.1 + d * r.omni_bearing.sin(),
            )
        })
        .collect();
    let ext: Vec<Vector2<f64>> = rows
        .iter()
        .map(|r| Vector2::new(r.ext.0, r.ext.1))
        .collect();
    let gap = (max_gap_s * 1e9) as i64;
    let noise = noise(rows, &ext, &z, &in_train, gap);
    let starts = starts(rows, gap);
    let est = kalman_track(&z, &starts, noise.q, noise.r, true);
    // extra: the same filter with u = 0 (a random walk), Q from per-step displacements
    let est_rw = kalman_track(&z, &starts, noise.q_rw, noise.r, false);
    Tracked {
        test: split0.test.clone(),
        ext,
        z,
        est,
        est_rw,
        noise,
    }
}

/// Distances between `a` and `b` on the frames `idx`.
pub fn errors(a: &[Vector2<f64>], b: &[Vector2<f64>], idx: &[usize]) -> Vec<f64> {
    idx.iter().map(|i| (a[*i] - b[*i]).norm()).collect()
}

table_row! {
    /// A row of the `kalman` table.
    pub struct KalmanRow {
        pub tracking_method: String,
        pub ours_m: String,
        pub paper_m: String,
        pub frames: i64,
    }
}

table_row! {
    /// One test frame's errors (the `kalman` table's samples).
    pub struct KalmanSample {
        pub stamp: i64,
        pub appearance_error_m: f64,
        pub kalman_error_m: f64,
        pub kalman_u0_error_m: f64,
    }
}

table_row! {
    /// A row of a 2 × 2 matrix, ours and the paper's: the `kalman_noise` table.
    pub struct NoiseRow {
        pub matrix: String,
        pub row: i64,
        pub ours_col1: f64,
        pub ours_col2: f64,
        pub paper_col1: f64,
        pub paper_col2: f64,
    }
}

/// The paper's Q and R (eq. 10).
const PAPER_Q: [[f64; 2]; 2] = [[0.024, -0.001], [-0.001, 0.043]];
const PAPER_R: [[f64; 2]; 2] = [[0.011, -0.004], [-0.004, 0.020]];

/// The noise table's four rows.
pub fn noise_rows(n: &Noise) -> Vec<NoiseRow> {
    let mut rows = Vec::new();
    for (name, ours, paper) in [("Q", n.q, PAPER_Q), ("R", n.r, PAPER_R)] {
        for k in 0..2 {
            rows.push(NoiseRow {
                matrix: name.into(),
                row: k as i64 + 1,
                ours_col1: ours[(k, 0)],
                ours_col2: ours[(k, 1)],
                paper_col1: paper[k][0],
                paper_col2: paper[k][1],
            });
        }
    }
    rows
}

/// Track, then the `kalman` and `kalman_noise` tables, the summary line and fig. 6.
pub fn run(
    l: &Learner,
    data: &Dataset,
    split0: &Split0,
    max_gap_s: f64,
    out: &mut Products,
) -> anyhow::Result<Tracked> {
    let rows = &data.rows;
    let t = track(l, rows, split0, max_gap_s);
    let rw_err = errors(&t.est_rw, &t.ext, &t.test);
    let app_err = errors(&t.z, &t.ext, &t.test);
    let kf_err = errors(&t.est, &t.ext, &t.test);
    let tt = stats::student_t(&kf_err, &app_err, DEFAULT_LEVEL)?;
    let ((am, asd), (km, ksd), (rm, rsd)) =
        (mean_std(&app_err), mean_std(&kf_err), mean_std(&rw_err));
    let tt_rw = stats::student_t(&rw_err, &app_err, DEFAULT_LEVEL)?;
    let row = |method: &str, ours: String, paper: &str, frames: usize| KalmanRow {
        tracking_method: method.into(),
        ours_m: ours,
        paper_m: paper.into(),
        frames: frames as i64,
    };
    let table = [
        row(
            "Appearance model",
            fmt_ms(am, asd),
            "0.154 ± 0.094",
            app_err.len(),
        ),
        row(
            "With Kalman filter",
            fmt_ms(km, ksd),
            "0.145 ± 0.092",
            kf_err.len(),
        ),
        row(
            "Extra: Kalman filter with u = 0",
            fmt_ms(rm, rsd),
            "—",
            rw_err.len(),
        ),
    ];
    let samples: Vec<KalmanSample> = t
        .test
        .iter()
        .enumerate()
        .map(|(k, i)| KalmanSample {
            stamp: rows[*i].stamp,
            appearance_error_m: app_err[k],
            kalman_error_m: kf_err[k],
            kalman_u0_error_m: rw_err[k],
        })
        .collect();
    out.tables.push(
        Table::new(
            "kalman",
            "Position error: appearance model alone vs with the Kalman filter",
            frame_named(&table, &["tracking method", "ours_m", "paper_m", "frames"])?,
        )
        .with_note(format!(
            "Unpaired Student t-test (Kalman − appearance): t = {:.3}, df = {:.0}, p = {:.4}, 99 % CI [{:.3}, {:.3}] m; {} at the 99 % level, the filter's error is {} (paper: significantly better). Errors on test frames against the measurement system. The filter is eq. 1–9 as written: u_k, the person's velocity, is the difference of the last two estimates, and P ignores its uncertainty, so the prediction overshoots where the person turns or stops. Extra row: the same filter with u = 0 and Q from per-step displacements, t-test against the appearance model: t = {:.3}, p = {:.4} ({}).",
            tt.t,
            tt.df,
            tt.p_two_sided,
            tt.ci_low,
            tt.ci_high,
            verdict(tt.significant(0.01)),
            if km < am { "lower" } else { "higher" },
            tt_rw.t,
            tt_rw.p_two_sided,
            verdict(tt_rw.significant(0.01))
        ))
        .with_samples(KalmanSample::frame(&samples)?),
    );
    out.tables.push(
        Table::new(
            "kalman_noise",
            "Kalman noise covariances estimated from the training data (eq. 10)",
            NoiseRow::frame(&noise_rows(&t.noise))?,
        )
        .with_precision("ours_col1", 4)
        .with_precision("ours_col2", 4)
        .with_note("Q from deviations of the measured path from constant velocity, R from appearance-model position errors, both on training frames (m²)."),
    );
    out.summary.push(format!(
        "Kalman: {} → {} m, p = {:.4} (paper 0.154 → 0.145, significant).",
        fmt_ms(am, asd),
        fmt_ms(km, ksd),
        tt.p_two_sided
    ));
    out.figures.push(path_figure(data, &t));
    Ok(t)
}

/// Fig. 6: a fragment of the tracked path (60 frames of session 0, from a quarter of the
/// frames in), with the simulator's truth when every frame of it has one.
fn path_figure(data: &Dataset, t: &Tracked) -> Figure {
    let rows = &data.rows;
    let frag: Vec<usize> = (0..rows.len())
        .filter(|i| rows[*i].session == 0)
        .skip(rows.len() / 4)
        .take(60)
        .collect();
    let pts = |v: &[Vector2<f64>]| frag.iter().map(|i| (v[*i].x, v[*i].y)).collect::<Vec<_>>();
    let mut traj = vec![
        Series::line("measurement system", pts(&t.ext), 0),
        Series::points("appearance model", pts(&t.z), 5),
        Series::line("Kalman filter", pts(&t.est), 6).with_mark(Mark::Dashed),
    ];
    let truth_pts: Vec<(f64, f64)> = frag.iter().filter_map(|i| rows[*i].truth).collect();
    if truth_pts.len() == frag.len() {
        traj.push(Series::line("simulator truth", truth_pts, 3).with_mark(Mark::Dashed));
    }
    Figure::new(
        "fig6_path",
        "Fragment of the tracked path in room coordinates (fig. 6)",
        FigureKind::TopView(TopView {
            outline: Vec::new(),
            obstacles: Vec::new(),
            sensors: vec![Sensor {
                x: data.cam_xy.0,
                y: data.cam_xy.1,
                heading: Some(data.cam_yaw),
                label: "omnicam".into(),
            }],
            trajectories: traj,
            circles: Vec::<Circle>::new(),
        }),
    )
}

#[cfg(test)]
mod tests {
    use super::super::dataset::test_row;
    use super::*;

    /// Frames 1 s apart; a gap of 5 s before frame 6; session 1 from frame 8.
    fn path_rows() -> Vec<Row> {
        let stamps = [0, 1, 2, 3, 4, 5, 10, 11, 12, 13];
        stamps
            .iter()
            .enumerate()
            .map(|(i, s)| test_row(usize::from(i >= 8), s * 1_000_000_000, 1, [0.0; 3]))
            .collect()
    }

    #[test]
    fn tracks_start_at_the_first_frame_a_gap_and_a_new_session() {
        let s = starts(&path_rows(), 1_500_000_000);
        assert_eq!(
            s,
            [
                true, false, false, false, false, false, true, false, true, false
            ]
        );
    }

    #[test]
    fn noise_on_a_constant_velocity_path_with_alternating_errors() {
        let rows: Vec<Row> = (0..8)
            .map(|i| test_row(0, i * 1_000_000_000, 1, [0.0; 3]))
            .collect();
        // the measured path moves 0.5 m/step along x: no deviation from constant velocity,
        // every displacement (0.5, 0)
        let ext: Vec<Vector2<f64>> = (0..8)
            .map(|i| Vector2::new(0.5 * f64::from(i), 1.0))
            .collect();
        // the appearance model is off by ±0.1 m in y, alternating: mean 0, variance
        // 8 · 0.01 / 7 over the eight frames
        let z: Vec<Vector2<f64>> = ext
            .iter()
            .enumerate()
            .map(|(i, e)| e + Vector2::new(0.0, if i % 2 == 0 { 0.1 } else { -0.1 }))
            .collect();
        let n = noise(&rows, &ext, &z, &[true; 8], 1_500_000_000);
        assert!(n.q.norm() < 1e-12, "Q = {}", n.q);
        assert!(n.q_rw.norm() < 1e-12, "Q (u = 0) = {}", n.q_rw);
        let expected = Matrix2::new(0.0, 0.0, 0.0, 0.08 / 7.0);
        assert!((n.r - expected).norm() < 1e-12, "R = {}", n.r);
        // only training frames count: two frames give one sample each way (R's mean removed)
        let mut in_train = [false; 8];
        in_train[3] = true;
        in_train[4] = true;
        let n = noise(&rows, &ext, &z, &in_train, 1_500_000_000);
        assert!(
            (n.r - Matrix2::new(0.0, 0.0, 0.0, 0.02)).norm() < 1e-12,
            "R = {}",
            n.r
        );
    }

    #[test]
    fn a_curved_path_gives_q_from_its_second_differences() {
        // x = i², so every second difference is (2, 0), y second differences alternate ±1:
        // Q = diag(0, var(±1)) with the sample variance of five ±1 values
        let rows: Vec<Row> = (0..7)
            .map(|i| test_row(0, i * 1_000_000_000, 1, [0.0; 3]))
            .collect();
        let ext: Vec<Vector2<f64>> = (0..7)
            .map(|i: i32| Vector2::new(f64::from(i * i), if i % 2 == 0 { 0.0 } else { 0.5 }))
            .collect();
        let n = noise(&rows, &ext, &ext, &[true; 7], 1_500_000_000);
        // second differences in y: i = 2..6 → -1, 1, -1, 1, -1 (mean -0.2)
        let mean = -0.2;
        let var = (3.0 * (-1.0f64 - mean).powi(2) + 2.0 * (1.0f64 - mean).powi(2)) / 4.0;
        assert!(
            (n.q - Matrix2::new(0.0, 0.0, 0.0, var)).norm() < 1e-12,
            "Q = {}",
            n.q
        );
        assert!(n.r.norm() < 1e-12, "z = ext: R = 0");
    }

    #[test]
    fn a_person_standing_still_is_tracked_exactly_and_a_restart_takes_the_measurement() {
        let z: Vec<Vector2<f64>> = [(1.0, 2.0), (1.0, 2.0), (1.0, 2.0), (4.0, 0.5), (4.0, 0.5)]
            .iter()
            .map(|(x, y)| Vector2::new(*x, *y))
            .collect();
        let starts = [true, false, false, true, false];
        let (q, r) = (Matrix2::identity() * 0.01, Matrix2::identity() * 0.04);
        for velocity in [true, false] {
            let est = kalman_track(&z, &starts, q, r, velocity);
            for (e, m) in est.iter().zip(&z) {
                assert!((e - m).norm() < 1e-12, "{e} vs {m}");
            }
        }
    }

    #[test]
    fn on_a_moving_person_u_zero_lags_and_the_velocity_input_catches_up() {
        let z: Vec<Vector2<f64>> = (0..4).map(|i| Vector2::new(f64::from(i), 2.0)).collect();
        let starts = [true, false, false, false];
        let (q, r) = (Matrix2::identity() * 0.01, Matrix2::identity() * 0.04);
        let rw = kalman_track(&z, &starts, q, r, false);
        let kf = kalman_track(&z, &starts, q, r, true);
        assert_eq!((rw[0], kf[0]), (z[0], z[0]));
        assert!(
            rw[1].x > z[0].x && rw[1].x < z[1].x,
            "between prediction and z"
        );
        assert_eq!(rw[1], kf[1], "no velocity yet at the second frame");
        for i in 2..4 {
            assert!((kf[i] - z[i]).norm() < (rw[i] - z[i]).norm(), "frame {i}");
        }
    }

    #[test]
    fn the_noise_table_has_q_then_r_row_by_row_beside_the_paper() {
        let n = Noise {
            q: Matrix2::new(1.0, 2.0, 3.0, 4.0),
            r: Matrix2::new(5.0, 6.0, 7.0, 8.0),
            q_rw: Matrix2::zeros(),
        };
        let rows = noise_rows(&n);
        let cells: Vec<(&str, i64, f64, f64, f64)> = rows
            .iter()
            .map(|r| {
                (
                    r.matrix.as_str(),
                    r.row,
                    r.ours_col1,
                    r.ours_col2,
                    r.paper_col1,
                )
            })
            .collect();
        assert_eq!(
            cells,
            [
                ("Q", 1, 1.0, 2.0, 0.024),
                ("Q", 2, 3.0, 4.0, -0.001),
                ("R", 1, 5.0, 6.0, 0.011),
                ("R", 2, 7.0, 8.0, -0.004)
            ]
        );
    }
}

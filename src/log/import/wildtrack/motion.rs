//! How the annotated people move, for the 3-D tracks' motion model: the σ of a white-noise
//! acceleration that is constant over each frame period (`track::kalman::constant_velocity_2d`)
//! from the second differences of the annotated ground positions.
//!
//! Under that model a person's position in three frames `T` apart obeys
//! `p₊ − 2p + p₋ = (a₋ + a) T² / 2` per axis (the two periods' accelerations), so each axis
//! of the second difference is normal with `σ_d = σ_a T² / √2`. Its norm over the two axes is
//! Rayleigh, whose median is `σ_d √(2 ln 2)`: the median is taken, not the mean square, because
//! a few annotated tracks jump by metres (an identity given to two people, a mis-clicked
//! position) and would dominate a variance. The annotation's own position error is in the
//! differences too (the 2.5 cm grid and the clicks), so the σ is, if anything, high.

use super::{AnnotatedFrame, FRAME_PERIOD_NS};

/// The annotated people's motion over some frames (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionCheck {
    /// Second differences used (a person annotated in three evenly spaced frames).
    pub samples: usize,
    /// The frame period `T` of those differences (s).
    pub period_s: f64,
    /// Median of `|p₊ − 2p + p₋|` (m).
    pub median_m: f64,
    /// `σ_a` (m/s²).
    pub accel_sigma_mps2: f64,
}

/// The motion of the people of `frames` (in file order; the first `n` of a dataset are its
/// development frames): every person annotated in three consecutive frames spaced alike.
/// `None` without such a person or with unevenly spaced frames only.
pub fn motion_check<'a>(frames: &'a [AnnotatedFrame]) -> Option<MotionCheck> {
    let mut norms = Vec::new();
    let mut period = None;
    for w in frames.windows(3) {
        let (a, b, c) = (&w[0], &w[1], &w[2]);
        let step = b.frame.checked_sub(a.frame)?;
        if step == 0 || c.frame.checked_sub(b.frame) != Some(step) {
            continue;
        }
        if period.is_some_and(|p| p != step) {
            // the annotation's rate changed: the differences would mix periods
            return None;
        }
        period = Some(step);
        for q in &c.people {
            let find = |f: &'a AnnotatedFrame| f.people.iter().find(|p| p.person == q.person);
            if let (Some(pa), Some(pb)) = (find(a), find(b)) {
                let dx = q.x_m - 2.0 * pb.x_m + pa.x_m;
                let dy = q.y_m - 2.0 * pb.y_m + pa.y_m;
                norms.push(dx.hypot(dy));
            }
        }
    }
    let period_s = f64::from(period?) * FRAME_PERIOD_NS as f64 * 1e-9;
    let samples = norms.len();
    let median_m = super::median(norms)?;
    let sigma_d = median_m / (2.0 * std::f64::consts::LN_2).sqrt();
    Some(MotionCheck {
        samples,
        period_s,
        median_m,
        accel_sigma_mps2: std::f64::consts::SQRT_2 * sigma_d / (period_s * period_s),
    })
}

#[cfg(test)]
mod tests {
    use super::super::Annotation;
    use super::*;

    fn frame(frame: u32, people: &[(u32, f64, f64)]) -> AnnotatedFrame {
        AnnotatedFrame {
            frame,
            people: people
                .iter()
                .map(|&(person, x_m, y_m)| Annotation {
                    person,
                    x_m,
                    y_m,
                    boxes: Vec::new(),
                })
                .collect(),
        }
    }

    #[test]
    fn constant_velocity_has_no_acceleration() {
        let frames: Vec<_> = (0..6)
            .map(|k| frame(5 * k, &[(1, 0.5 * f64::from(k), -0.2 * f64::from(k))]))
            .collect();
        let m = motion_check(&frames).expect("three frames");
        assert_eq!(m.samples, 4);
        assert!((m.period_s - 0.5).abs() < 1e-12);
        assert!(m.median_m < 1e-12 && m.accel_sigma_mps2 < 1e-9, "{m:?}");
    }

    #[test]
    fn the_median_second_difference_gives_sigma_in_closed_form() {
        // frames 0-5-10: person 1 starts moving (0.2 m), person 2 too (0.1 m); frames 5-10-15:
        // person 1 keeps its speed (0); person 3 is in one frame only → median of 0.2, 0.1, 0
        let frames = vec![
            frame(0, &[(1, 0.0, 0.0), (2, 0.0, 0.0)]),
            frame(5, &[(1, 0.0, 0.0), (2, 0.0, 0.0), (3, 1.0, 1.0)]),
            frame(10, &[(1, 0.2, 0.0), (2, 0.0, 0.1)]),
            frame(15, &[(1, 0.4, 0.0)]),
        ];
        let m = motion_check(&frames).expect("samples");
        assert_eq!(m.samples, 3);
        assert!((m.median_m - 0.1).abs() < 1e-12, "{m:?}");
        let want = std::f64::consts::SQRT_2 * 0.1 / (2.0 * std::f64::consts::LN_2).sqrt() / 0.25;
        assert!((m.accel_sigma_mps2 - want).abs() < 1e-12, "{m:?}");
    }

    #[test]
    fn the_estimate_recovers_a_simulated_white_noise_acceleration() {
        // 200 people under the model itself (σ_a = 0.8 m/s², T = 0.5 s): within 5 %
        use rand_distr::Distribution;
        let mut rng = crate::rng::stream(7, "motion check", 0);
        let (sigma, t) = (0.8, 0.5);
        let normal = rand_distr::Normal::new(0.0, sigma).expect("σ > 0");
        let mut tracks: Vec<Vec<(f64, f64)>> = Vec::new();
        for _ in 0..200 {
            let (mut p, mut v) = ([0.0, 0.0], [1.0, 0.0]);
            let mut track = Vec::new();
            for _ in 0..20 {
                track.push((p[0], p[1]));
                for i in 0..2 {
                    let a: f64 = normal.sample(&mut rng);
                    p[i] += v[i] * t + 0.5 * a * t * t;
                    v[i] += a * t;
                }
            }
            tracks.push(track);
        }
        let frames: Vec<_> = (0..20)
            .map(|k| {
                let people: Vec<_> = tracks
                    .iter()
                    .enumerate()
                    .map(|(i, tr)| (i as u32, tr[k].0, tr[k].1))
                    .collect();
                frame(5 * k as u32, &people)
            })
            .collect();
        let m = motion_check(&frames).expect("samples");
        assert_eq!(m.samples, 200 * 18);
        assert!((m.accel_sigma_mps2 / sigma - 1.0).abs() < 0.05, "{m:?}");
    }

    #[test]
    fn unevenly_spaced_or_too_few_frames_give_nothing() {
        let two = vec![frame(0, &[(1, 0.0, 0.0)]), frame(5, &[(1, 1.0, 0.0)])];
        assert_eq!(motion_check(&two), None);
        let uneven = vec![
            frame(0, &[(1, 0.0, 0.0)]),
            frame(5, &[(1, 1.0, 0.0)]),
            frame(15, &[(1, 2.0, 0.0)]),
        ];
        assert_eq!(motion_check(&uneven), None);
    }
}

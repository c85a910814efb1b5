//! Property tests for the tracking metrics on generated scenes (deterministic runner):
//! a perfect tracker scores MOTA = IDF1 = HOTA = 1; swapping two ids mid-track costs exactly
//! two ID switches; renaming the hypothesis ids by any bijection changes nothing.
//!
//! Scenes: people walk in separate horizontal lanes (boxes of different people never
//! overlap, so the right answer is unambiguous); the noisy tracker jitters boxes, drops
//! some, adds false positives and sometimes gives a person a new id.

use std::collections::HashMap;

use peopletrack::eval::mot::{BoxPx, Geometry, MatchRule, Metrics, Observation, evaluate};
use proptest::prelude::*;

const RULE: MatchRule = MatchRule::Iou { min_iou: 0.5 };
/// Lane pitch and the tallest box, in pixels: lanes never overlap.
const LANE_PX: f64 = 100.0;
const MAX_HEIGHT_PX: f64 = 80.0;

struct XorShift(u64);

impl XorShift {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn bx(frame: i64, id: i64, left: f64, top: f64, w: f64, h: f64) -> Observation {
    Observation {
        frame,
        id,
        geometry: Geometry::Box(BoxPx {
            left_px: left,
            top_px: top,
            width_px: w,
            height_px: h,
        }),
        confidence: 1.0,
    }
}

/// Ground truth: `people` people over `frames` frames, person p in lane p. With `always`
/// everyone is present in every frame; otherwise each has a random span with a gap.
fn scene(people: usize, frames: i64, seed: u64, always: bool) -> Vec<Observation> {
    let mut rng = XorShift(seed | 1);
    let mut out = Vec::new();
    let tracks: Vec<(f64, f64, f64, f64, i64, i64, i64)> = (0..people)
        .map(|_| {
            let x0 = 600.0 * rng.unit();
            let vx = 10.0 * rng.unit() - 5.0;
            let w = 20.0 + 40.0 * rng.unit();
            let h = 40.0 + (MAX_HEIGHT_PX - 40.0) * rng.unit();
            let (start, end, gap) = if always {
                (0, frames, -1)
            } else {
                let a = (rng.next() % frames as u64) as i64;
                let b = (rng.next() % frames as u64) as i64;
                (a.min(b), a.max(b) + 1, (rng.next() % frames as u64) as i64)
            };
            (x0, vx, w, h, start, end, gap)
        })
        .collect();
    for f in 0..frames {
        for (p, &(x0, vx, w, h, start, end, gap)) in tracks.iter().enumerate() {
            if f < start || f >= end || f == gap {
                continue;
            }
            let top = p as f64 * LANE_PX;
            out.push(bx(f, p as i64 + 1, x0 + vx * f as f64, top, w, h));
        }
    }
    out
}

/// A noisy tracker's output for `gt`: jitter, misses, false positives, new ids.
fn noisy_tracker(gt: &[Observation], seed: u64, miss: f64, fp: f64, reid: f64) -> Vec<Observation> {
    let mut rng = XorShift(seed ^ 0x5851_f42d_4c95_7f2d | 1);
    let mut next_id = 1000;
    let mut id_of: HashMap<i64, i64> = HashMap::new();
    let mut out = Vec::new();
    for o in gt {
        let Geometry::Box(b) = o.geometry else {
            continue;
        };
        if rng.unit() < reid || !id_of.contains_key(&o.id) {
            next_id += 1;
            id_of.insert(o.id, next_id);
        }
        if rng.unit() < miss {
            continue;
        }
        let j = |rng: &mut XorShift, s: f64| s * (2.0 * rng.unit() - 1.0);
        out.push(bx(
            o.frame,
            id_of[&o.id],
            b.left_px + j(&mut rng, 6.0),
            b.top_px + j(&mut rng, 6.0),
            b.width_px + j(&mut rng, 4.0),
            b.height_px + j(&mut rng, 4.0),
        ));
        if rng.unit() < fp {
            out.push(bx(
                o.frame,
                5000 + o.id,
                900.0 + 200.0 * rng.unit(),
                b.top_px,
                30.0,
                60.0,
            ));
        }
    }
    out
}

/// Every number in the metrics, in a fixed order.
fn numbers(m: &Metrics) -> Vec<f64> {
    fn walk(v: &serde_json::Value, out: &mut Vec<f64>) {
        match v {
            serde_json::Value::Number(n) => out.push(n.as_f64().unwrap_or(f64::NAN)),
            serde_json::Value::Array(a) => a.iter().for_each(|x| walk(x, out)),
            serde_json::Value::Object(o) => o.values().for_each(|x| walk(x, out)),
            _ => out.push(f64::NAN),
        }
    }
    let mut out = Vec::new();
    walk(&serde_json::to_value(m).expect("serialises"), &mut out);
    out
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 200,
        failure_persistence: None,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x6d6f_745f_6d65_7472),
        ..ProptestConfig::default()
    })]

    #[test]
    fn a_perfect_tracker_scores_one(
        people in 1usize..7, frames in 2i64..40, seed in any::<u64>(), always in any::<bool>()
    ) {
        let gt = scene(people, frames, seed, always);
        prop_assume!(!gt.is_empty());
        let m = evaluate(&gt, &gt, RULE).expect("scores").metrics;
        prop_assert_eq!(m.clear.mota, 1.0);
        prop_assert_eq!(m.identity.idf1, 1.0);
        prop_assert!((m.hota.hota - 1.0).abs() < 1e-12, "HOTA {}", m.hota.hota);
        prop_assert!((m.hota.det_a - 1.0).abs() < 1e-12 && (m.hota.ass_a - 1.0).abs() < 1e-12);
        prop_assert_eq!(m.clear.motp, 0.0);
        prop_assert_eq!(
            (m.clear.num_switches, m.clear.num_misses, m.clear.num_false_positives),
            (0, 0, 0)
        );
        prop_assert_eq!(m.clear.mostly_tracked, people as u64 - count_absent(&gt, people));
    }

    #[test]
    fn swapping_two_ids_mid_track_is_two_switches(
        people in 2usize..7, frames in 2i64..40, seed in any::<u64>(),
        pick in any::<(prop::sample::Index, prop::sample::Index)>(), at in any::<prop::sample::Index>()
    ) {
        let gt = scene(people, frames, seed, true);
        let a = pick.0.index(people) as i64 + 1;
        let b = (a - 1 + 1 + pick.1.index(people - 1) as i64) % people as i64 + 1;
        prop_assert_ne!(a, b);
        let swap_from = 1 + at.index(frames as usize - 1) as i64;
        let hyp: Vec<Observation> = gt
            .iter()
            .map(|o| {
                let id = match o.id {
                    id if o.frame >= swap_from && id == a => b,
                    id if o.frame >= swap_from && id == b => a,
                    id => id,
                };
                Observation { id: 100 + id, ..*o }
            })
            .collect();
        let m = evaluate(&gt, &hyp, RULE).expect("scores").metrics;
        prop_assert_eq!(m.clear.num_switches, 2);
        prop_assert_eq!((m.clear.num_misses, m.clear.num_false_positives), (0, 0));
        prop_assert!((m.clear.mota - (1.0 - 2.0 / gt.len() as f64)).abs() < 1e-12);
        prop_assert!(m.identity.idf1 < 1.0);
    }

    #[test]
    fn relabelling_hypothesis_ids_changes_nothing(
        people in 1usize..7, frames in 2i64..40, seed in any::<u64>(),
        miss in 0.0f64..0.4, fp in 0.0f64..0.3, reid in 0.0f64..0.15,
        mult in prop::sample::select(vec![-7i64, -1, 3, 11, 1_000_003]), offset in -1000i64..1000
    ) {
        let gt = scene(people, frames, seed, false);
        let hyp = noisy_tracker(&gt, seed, miss, fp, reid);
        // id → mult · id + offset is a bijection on the integers used here.
        let rename = |id: i64| mult * id + offset;
        let renamed: Vec<Observation> =
            hyp.iter().map(|o| Observation { id: rename(o.id), ..*o }).collect();
        let one = evaluate(&gt, &hyp, RULE).expect("scores");
        let two = evaluate(&gt, &renamed, RULE).expect("scores");
        let (x, y) = (numbers(&one.metrics), numbers(&two.metrics));
        prop_assert_eq!(x.len(), y.len());
        for (k, (p, q)) in x.iter().zip(&y).enumerate() {
            prop_assert!(p == q || (p.is_nan() && q.is_nan()), "value {}: {} vs {}", k, p, q);
        }
        prop_assert_eq!(one.events.len(), two.events.len());
        for (e, f) in one.events.iter().zip(&two.events) {
            prop_assert_eq!(e.hyp_id.map(rename), f.hyp_id);
            prop_assert_eq!((e.frame, e.kind, e.gt_id, e.distance), (f.frame, f.kind, f.gt_id, f.distance));
        }
    }
}

/// People of `0..people` that never appear (their span was empty): 0 with the scenes here,
/// kept so the MT count states what it expects.
fn count_absent(gt: &[Observation], people: usize) -> u64 {
    (1..=people as i64)
        .filter(|p| !gt.iter().any(|o| o.id == *p))
        .count() as u64
}

//! Known answers for the recursion, and the vectorised kernel against the scalar reference.

use super::reference::ReferenceGmm;
use super::*;

/// A deterministic generator (SplitMix64) so no test depends on an unseeded source.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

fn model(params: GmmParams) -> AdaptiveGmm {
    AdaptiveGmm::new(params).expect("valid parameters")
}

/// Feed one pixel (1x1 RGB frames) the colours `seq`; return the mask byte of each frame.
fn run_pixel(m: &mut AdaptiveGmm, seq: &[[u8; 3]], lr: Option<f32>) -> Vec<u8> {
    seq.iter()
        .map(|px| {
            let view = ImageView::new(px, 1, 1, 3).expect("1x1 rgb");
            let mut mask = [0u8; 1];
            m.apply(view, lr, &mut mask).expect("apply");
            mask[0]
        })
        .collect()
}

fn comps(m: &AdaptiveGmm) -> Vec<Component> {
    m.components(0, 0).expect("pixel (0, 0)")
}

#[test]
fn constant_pixel_is_one_component_of_weight_one() {
    // Frame 1 starts the component with π = 1; eq. 14 then maps π = 1 to
    // ((1 - α) + α - αc_T) / (1 - αc_T) = 1 every frame, and |x - µ| = 0 shrinks σ² by
    // (1 - α/π) each frame down to the clamp fVarMin.
    let mut m = model(GmmParams::default());
    let masks = run_pixel(&mut m, &[[90, 120, 30]; 1000], None);
    let c = comps(&m);
    assert_eq!(c.len(), 1);
    assert!((c[0].weight - 1.0).abs() <= 1e-6, "{c:?}");
    assert_eq!(c[0].variance, DEFAULT_VAR_MIN);
    assert_eq!(c[0].mean, [90.0, 120.0, 30.0]);
    assert!(masks[1..].iter().all(|&v| v == BACKGROUND));
    assert_eq!(m.components_per_pixel(), vec![1]);
    assert_eq!(m.background_image().expect("seen"), vec![90, 120, 30]);
}

/// Weights after frame 1 at colour A and `n` frames at colour B with a fixed α, by the
/// recursion (eq. 14 then renormalisation, new component at π = α), in f64.
fn expected_two_colours(alpha: f64, ct: f64, n: usize) -> (f64, Option<f64>) {
    let (mut wa, mut wb) = (Some(1.0f64), None::<f64>);
    for _ in 0..n {
        let prune = -alpha * ct;
        let a = wa.map(|w| (1.0 - alpha) * w + prune);
        let a = a.filter(|&w| w >= -prune);
        match wb {
            None => {
                // B is new: normalise A (the only weight, so the total is A itself), then B
                // takes α and A is scaled by 1 - α.
                let total = a.unwrap_or(1.0);
                wa = a.map(|w| w / total * (1.0 - alpha));
                wb = Some(alpha);
            }
            Some(b) => {
                let b = (1.0 - alpha) * b + prune + alpha;
                let total = b + a.unwrap_or(0.0);
                wa = a.map(|w| w / total);
                wb = Some(b / total);
            }
        }
    }
    (wb.unwrap_or(0.0), wa)
}

#[test]
fn weight_after_n_frames_follows_the_recursion() {
    const ALPHA: f32 = 0.01;
    const N: usize = 200;
    for ct in [0.0f32, DEFAULT_COMPLEXITY_REDUCTION] {
        let mut m = model(GmmParams {
            complexity_reduction: ct,
            ..GmmParams::default()
        });
        let mut seq = vec![[50u8, 50, 50]];
        seq.extend([[200u8, 200, 200]; N]);
        run_pixel(&mut m, &seq, Some(ALPHA));
        let (wb, wa) = expected_two_colours(f64::from(ALPHA), f64::from(ct), N);
        let c = comps(&m);
        if ct == 0.0 {
            // Without the prior the closed form holds: π_B = 1 - (1 - α)^N.
            assert!((wb - (1.0 - (1.0 - f64::from(ALPHA)).powi(N as i32))).abs() < 1e-12);
        }
        assert_eq!(c[0].mean, [200.0; 3], "ct {ct}: B leads");
        assert!(
            (f64::from(c[0].weight) - wb).abs() < 1e-5,
            "ct {ct}: {c:?} vs {wb}"
        );
        match wa {
            Some(wa) => {
                assert_eq!(c.len(), 2, "ct {ct}");
                assert!((f64::from(c[1].weight) - wa).abs() < 1e-5, "{c:?} vs {wa}");
            }
            None => assert_eq!(c.len(), 1, "ct {ct}: A was dropped"),
        }
    }
}

#[test]
fn alternating_pixel_keeps_two_components() {
    let mut m = model(GmmParams::default());
    let seq: Vec<[u8; 3]> = (0..2000)
        .map(|i| if i % 2 == 0 { [100; 3] } else { [160, 40, 90] })
        .collect();
    let masks = run_pixel(&mut m, &seq, None);
    let c = comps(&m);
    assert_eq!(c.len(), 2, "{c:?}");
    for comp in &c {
        assert!((comp.weight - 0.5).abs() < 0.01, "{c:?}");
        assert_eq!(comp.variance, DEFAULT_VAR_MIN);
    }
    // Both modes are background once each has ~half the weight.
    assert!(masks[1000..].iter().all(|&v| v == BACKGROUND));
}

/// Object frames (1-based) until a static object that covers a trained background pixel
/// becomes background, with a fixed α.
fn frames_until_background(params: GmmParams, alpha: f32) -> usize {
    let mut m = model(params);
    run_pixel(&mut m, &[[60, 60, 60]; 300], None);
    let masks = run_pixel(&mut m, &[[200, 40, 90]; 400], Some(alpha));
    let first = masks
        .iter()
        .position(|&v| v == BACKGROUND)
        .expect("absorbed")
        + 1;
    assert!(masks[..first - 1].iter().all(|&v| v == FOREGROUND));
    assert!(masks[first - 1..].iter().all(|&v| v == BACKGROUND));
    first
}

#[test]
fn static_object_becomes_background_after_the_papers_frame_count() {
    // Section 3: the object's component joins the background when the old one's weight
    // (1 - α)^k drops below 1 - c_f, i.e. after log(1 - c_f) / log(1 - α) = 105.3 frames
    // for c_f = 0.1, α = 0.001 ("we get 105 frames"): foreground for 105 frames, background
    // from the 106th. The margin (0.999^105 - 0.9 = 2.8e-4) is far above f32 rounding, so
    // the frame is exact without the prior.
    let paper = (0.9f64.ln() / 0.999f64.ln()).ceil() as usize;
    assert_eq!(paper, 106);
    assert_eq!(
        frames_until_background(GmmParams::stauffer_grimson(), 0.001),
        paper
    );

    // With the prior (c_T = 0.05) both weights lose αc_T a frame and are then renormalised,
    // which changes the old weight's decay; the recursion in f64 gives the frame. Allowed ±1: our
    // f32 recursion and the f64 one may round a weight within ~1e-6 of 0.9 differently.
    let alpha = 0.001f64;
    let ct = f64::from(DEFAULT_COMPLEXITY_REDUCTION);
    let (mut old, mut new) = (1.0 - alpha, alpha);
    let mut expected = 0;
    for k in 2.. {
        old = (1.0 - alpha) * old - alpha * ct;
        if old < 0.9 {
            expected = k;
            break;
        }
        new = (1.0 - alpha) * new - alpha * ct + alpha;
        let total = old + new;
        (old, new) = (old / total, new / total);
    }
    let got = frames_until_background(GmmParams::default(), 0.001);
    assert!(
        got.abs_diff(expected) <= 1,
        "got {got}, recursion {expected}"
    );
    eprintln!("with the prior: {got} frames (recursion {expected})");
}

#[test]
fn darker_background_is_shadow_other_hue_is_foreground() {
    for detect in [true, false] {
        let params = GmmParams {
            detect_shadows: detect,
            ..GmmParams::default()
        };
        let shadow = if detect {
            DEFAULT_SHADOW_VALUE
        } else {
            FOREGROUND
        };
        let bg = [200u8, 150, 100];
        let check = |px: [u8; 3], want: u8| {
            let mut m = model(params);
            run_pixel(&mut m, &[bg; 100], None);
            assert_eq!(run_pixel(&mut m, &[px], None), vec![want], "{px:?}");
        };
        check([140, 105, 70], shadow); // 0.7 x background
        check([110, 82, 55], shadow); // 0.55 x: still within τ = 0.5
        check([90, 68, 45], FOREGROUND); // 0.45 x: darker than τ allows
        check([100, 150, 200], FOREGROUND); // another hue
        check([240, 180, 120], FOREGROUND); // brighter
        check([201, 150, 99], BACKGROUND);
    }
    // Grey frames: a darker grey is a shadow too.
    let mut m = model(GmmParams::default());
    let mut mask = [0u8];
    for v in [[200u8]; 50].iter().chain([[140u8]].iter()) {
        m.apply(ImageView::new(v, 1, 1, 1).expect("1x1"), None, &mut mask)
            .expect("apply");
    }
    assert_eq!(mask[0], DEFAULT_SHADOW_VALUE);
}

#[test]
fn first_frame_matches_opencv() {
    // OpenCV's first frame: a new component per pixel, no component was there to call the
    // pixel background, and the pixel is "a darker copy" (a = 1) of its new component, so
    // every non-black pixel is a shadow and a black one is foreground.
    let mut m = model(GmmParams::default());
    let frame = [0u8, 0, 0, 10, 20, 30];
    let mut mask = [9u8; 2];
    m.apply(
        ImageView::new(&frame, 2, 1, 3).expect("2x1"),
        None,
        &mut mask,
    )
    .expect("apply");
    assert_eq!(mask, [FOREGROUND, DEFAULT_SHADOW_VALUE]);
}

#[test]
fn learning_rate_zero_freezes_and_one_restarts() {
    let mut m = model(GmmParams::default());
    run_pixel(&mut m, &[[10, 10, 10]; 20], None);
    let before = comps(&m);
    // α = 0: no weight moves and no component is created.
    assert_eq!(
        run_pixel(&mut m, &[[250, 10, 10]; 5], Some(0.0)),
        vec![FOREGROUND; 5]
    );
    assert_eq!(comps(&m), before);
    // α ≥ 1: the model restarts from this frame (OpenCV's rule).
    run_pixel(&mut m, &[[250, 10, 10]], Some(1.0));
    assert_eq!(m.frames_seen(), 1);
    assert_eq!(comps(&m).len(), 1);
    assert_eq!(comps(&m)[0].mean, [250.0, 10.0, 10.0]);
}

#[test]
fn bad_input_is_an_error() {
    let mut m = model(GmmParams::default());
    let rgb = [0u8; 12];
    let view = ImageView::new(&rgb, 2, 2, 3).expect("2x2");
    let mut mask = [0u8; 3];
    assert!(matches!(
        m.apply(view, None, &mut mask),
        Err(GmmError::MaskSize { have: 3, need: 4 })
    ));
    let mut mask = [0u8; 4];
    let rgba = [0u8; 16];
    let four = ImageView::new(&rgba, 2, 2, 4).expect("2x2x4");
    assert!(matches!(
        m.apply(four, None, &mut mask),
        Err(GmmError::UnsupportedChannels { channels: 4 })
    ));
    assert!(matches!(
        m.apply(view, Some(-0.5), &mut mask),
        Err(GmmError::BadLearningRate(_))
    ));
    assert!(matches!(
        m.apply(view, Some(f32::NAN), &mut mask),
        Err(GmmError::BadLearningRate(_))
    ));
    assert_eq!(m.frames_seen(), 0, "a refused frame changes nothing");
    m.apply(view, None, &mut mask).expect("first frame");
    let grey = [0u8; 4];
    let g = ImageView::new(&grey, 2, 2, 1).expect("2x2x1");
    assert!(matches!(
        m.apply(g, None, &mut mask),
        Err(GmmError::ShapeMismatch { .. })
    ));
    assert!(matches!(
        m.components(2, 0),
        Err(GmmError::OutOfBounds { .. })
    ));
    m.reset();
    m.apply(g, None, &mut mask).expect("after reset any shape");
    assert!(matches!(
        model(GmmParams::default()).background_image(),
        Err(GmmError::NoFrames)
    ));
    for p in [
        GmmParams {
            n_mixtures: 0,
            ..GmmParams::default()
        },
        GmmParams {
            n_mixtures: MAX_MIXTURES + 1,
            ..GmmParams::default()
        },
        GmmParams {
            history: 0,
            ..GmmParams::default()
        },
        GmmParams {
            var_threshold: f32::NAN,
            ..GmmParams::default()
        },
        GmmParams {
            var_init: -1.0,
            ..GmmParams::default()
        },
    ] {
        assert!(matches!(
            AdaptiveGmm::new(p),
            Err(GmmError::BadParam { .. })
        ));
    }
}

/// Frames that exercise every path: per-pixel multimodal backgrounds, noise, objects that
/// come and stay, dark copies (shadows), black pixels (shadow test's zero denominator).
fn stress_frames(w: usize, h: usize, c: usize, n: usize, seed: u64) -> Vec<Vec<u8>> {
    let mut rng = Rng(seed);
    let modes: Vec<[u8; 6]> = (0..w * h)
        .map(|_| std::array::from_fn(|_| rng.below(256) as u8))
        .collect();
    (0..n)
        .map(|t| {
            let mut f = vec![0u8; w * h * c];
            for p in 0..w * h {
                let r = rng.below(100);
                let base: [u8; 3] = if r < 60 {
                    [modes[p][0], modes[p][1], modes[p][2]]
                } else if r < 80 {
                    [modes[p][3], modes[p][4], modes[p][5]]
                } else if r < 88 {
                    let k = 4 + rng.below(7);
                    let s = |v: u8| (u32::from(v) * k as u32 / 10) as u8;
                    [s(modes[p][0]), s(modes[p][1]), s(modes[p][2])]
                } else if r < 92 || (t > n / 2 && p % 7 == 0) {
                    [0, 0, 0]
                } else {
                    std::array::from_fn(|_| rng.below(256) as u8)
                };
                for ch in 0..c {
                    let noise = rng.below(9) as i32 - 4;
                    f[p * c + ch] = (i32::from(base[ch]) + noise).clamp(0, 255) as u8;
                }
            }
            f
        })
        .collect()
}

fn assert_same_state(m: &AdaptiveGmm, r: &ReferenceGmm, w: usize, frame: usize) {
    for p in 0..r.used.len() {
        let got = m.components(p % w, p / w).expect("in bounds");
        assert_eq!(got.len(), r.used[p], "frame {frame} pixel {p}");
        for (g, s) in got.iter().zip(&r.slots[p]) {
            assert_eq!(
                g.weight.to_bits(),
                s.weight.to_bits(),
                "frame {frame} px {p}"
            );
            assert_eq!(g.variance.to_bits(), s.variance.to_bits());
            for ch in 0..r.channels {
                assert_eq!(g.mean[ch].to_bits(), s.mean[ch].to_bits());
            }
        }
    }
}

#[test]
fn kernel_matches_scalar_reference_bit_for_bit() {
    let tight = GmmParams {
        n_mixtures: 3,
        var_threshold_gen: 4.0,
        complexity_reduction: 0.3,
        history: 40,
        ..GmmParams::default()
    };
    let cases = [
        (GmmParams::default(), 3, None),
        (GmmParams::default(), 1, None),
        (GmmParams::stauffer_grimson(), 3, Some(0.02)),
        (tight, 3, None),
        (tight, 1, Some(0.05)),
        // the paper's pruning rule ("drop when negative") and c_T = 0.01
        (GmmParams::zivkovic_printed(), 3, None),
        (
            GmmParams {
                pruning: Pruning::Negative,
                ..tight
            },
            1,
            Some(0.05),
        ),
        (
            GmmParams {
                n_mixtures: 1,
                ..GmmParams::default()
            },
            3,
            None,
        ),
    ];
    let (w, h, n) = (13, 5, 120);
    let isas = Isa::available();
    for (i, (params, c, lr)) in cases.into_iter().enumerate() {
        for &isa in &isas {
            let frames = stress_frames(w, h, c, n, 7 + i as u64);
            let mut m = model(params);
            let mut r = ReferenceGmm::new(params, w * h, c);
            let (mut got, mut want) = (vec![0u8; w * h], vec![0u8; w * h]);
            for (t, f) in frames.iter().enumerate() {
                let view = ImageView::new(f, w, h, c).expect("frame");
                m.apply_with(isa, view, lr, None, &mut got).expect("apply");
                r.apply(f, lr, &mut want);
                assert_eq!(got, want, "case {i} frame {t}");
                assert_same_state(&m, &r, w, t);
            }
            let max = m.components_per_pixel().into_iter().max().unwrap_or(0);
            assert!(usize::from(max) == params.n_mixtures, "case {i} fills M");
        }
    }
}

#[test]
fn save_load_round_trip_and_corrupt_input() {
    let (w, h) = (11, 3);
    let frames = stress_frames(w, h, 3, 40, 99);
    let mut m = model(GmmParams::default());
    let mut mask = vec![0u8; w * h];
    for f in &frames[..20] {
        m.apply(ImageView::new(f, w, h, 3).expect("f"), None, &mut mask)
            .expect("apply");
    }
    let mut bytes = Vec::new();
    m.save(&mut bytes).expect("save");
    // A clone holds the same state (its aligned buffer may start at another offset).
    let mut copy = Vec::new();
    m.clone().save(&mut copy).expect("save clone");
    assert_eq!(copy, bytes);
    let mut back = AdaptiveGmm::load(&mut bytes.as_slice()).expect("load");
    let mut again = Vec::new();
    back.save(&mut again).expect("save again");
    assert_eq!(bytes, again);
    let mut mask2 = vec![0u8; w * h];
    for f in &frames[20..] {
        let v = ImageView::new(f, w, h, 3).expect("f");
        m.apply(v, None, &mut mask).expect("apply");
        back.apply(v, None, &mut mask2).expect("apply");
        assert_eq!(mask, mask2);
    }
    for cut in 0..bytes.len() {
        assert!(
            AdaptiveGmm::load(&mut &bytes[..cut]).is_err(),
            "prefix {cut}"
        );
    }
    let mut long = bytes.clone();
    long.push(0);
    assert!(AdaptiveGmm::load(&mut long.as_slice()).is_err());
    let mut wrong = bytes.clone();
    wrong[0] = b'X';
    assert!(AdaptiveGmm::load(&mut wrong.as_slice()).is_err());
    // An unused model round-trips too.
    let fresh = model(GmmParams::stauffer_grimson());
    let mut b = Vec::new();
    fresh.save(&mut b).expect("save");
    let back = AdaptiveGmm::load(&mut b.as_slice()).expect("load");
    assert_eq!(back.params(), &GmmParams::stauffer_grimson());
    assert_eq!(back.shape(), None);
}

/// Run `frames` through the kernel (on `isa`, in a rayon pool of `threads`) and through the
/// scalar reference; every mask and every component must agree bit for bit. Returns the
/// kernel's last mask.
fn check_against_reference(
    params: GmmParams,
    (w, h, c): (usize, usize, usize),
    frames: &[Vec<u8>],
    lr: Option<f32>,
    isa: Isa,
    threads: usize,
) -> Vec<u8> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    let mut m = model(params);
    let mut r = ReferenceGmm::new(params, w * h, c);
    let (mut got, mut want) = (vec![0u8; w * h], vec![0u8; w * h]);
    for (t, f) in frames.iter().enumerate() {
        let view = ImageView::new(f, w, h, c).expect("frame");
        pool.install(|| m.apply_with(isa, view, lr, None, &mut got))
            .expect("apply");
        r.apply(f, lr, &mut want);
        assert_eq!(got, want, "{w}x{h}x{c} frame {t} on {threads} threads");
        assert_same_state(&m, &r, w, t);
    }
    got
}

#[test]
fn kernel_matches_reference_at_lane_remainder_widths_and_thread_counts() {
    // Widths around the 8-lane group: 1 (seven padding lanes), 7, 8 (none), 9 (a group of
    // one), 17; two rows so the rows can go to different threads.
    for (i, w) in [1usize, 7, 8, 9, 17].into_iter().enumerate() {
        for c in [1, 3] {
            let frames = stress_frames(w, 2, c, 60, 100 + i as u64);
            for isa in Isa::available() {
                for threads in [1, 2] {
                    check_against_reference(
                        GmmParams::default(),
                        (w, 2, c),
                        &frames,
                        None,
                        isa,
                        threads,
                    );
                }
            }
        }
    }
}

#[test]
fn hand_made_lanes_with_different_histories_match_reference_and_known_answers() {
    // Nine RGB pixels (one full group of eight and a group of one), M = 3; each pixel has
    // its own story, so within a group the lanes hold different numbers of components and
    // take different branches in the same frame. α = 0.05 after the first frame makes the
    // pruning quick: the weight of a component no sample owns follows
    // π ← 0.95π − 0.0025 (then a renormalisation by about 1.005) and falls below
    // αc_T = 0.0025 about 60 frames after its last sample.
    let lr = Some(0.05);
    let params = GmmParams {
        n_mixtures: 3,
        ..GmmParams::default()
    };
    let (w, n) = (9, 160);
    let grey = |v: u8| [v, v, v];
    let story = |p: usize, t: usize| -> [u8; 3] {
        match p {
            // Constant: one component.
            0 | 8 => grey(90),
            // Two colours in turn: two components.
            1 => grey(if t.is_multiple_of(2) { 30 } else { 220 }),
            // Four colours in turn with room for three: every frame creates a component,
            // replacing the weakest once the pixel is full.
            2 => grey([20u8, 80, 150, 240][t % 4]),
            // One frame of another colour, then constant: that component is dropped.
            3 => grey(if t == 0 { 250 } else { 40 }),
            // A background whose last frame is 0.7 times as bright: a shadow.
            4 => {
                if t + 1 == n {
                    [140, 105, 70]
                } else {
                    [200, 150, 100]
                }
            }
            // The same background, last frame another hue: foreground.
            5 => {
                if t + 1 == n {
                    [100, 150, 200]
                } else {
                    [200, 150, 100]
                }
            }
            // Black: the shadow test's zero denominator.
            6 => [0, 0, 0],
            // Black, then white from the middle: a new component takes over, the old one is
            // dropped.
            _ => grey(if t < n / 2 { 0 } else { 255 }),
        }
    };
    let frames: Vec<Vec<u8>> = (0..n)
        .map(|t| (0..w).flat_map(|p| story(p, t)).collect())
        .collect();
    for isa in Isa::available() {
        for threads in [1, 2] {
            let last = check_against_reference(params, (w, 1, 3), &frames, lr, isa, threads);
            // Pixel 2: a sample no component owns starts a component with µ = x before the
            // shadow test (OpenCV's order); the older weights sum to less than 1 − c_f, so
            // the test reaches it and finds x an undarkened copy (a = 1): "shadow". Pixel 5:
            // there the background alone weighs 1 − α = 0.95 > 0.9 and the search stops.
            assert_eq!(
                last,
                [
                    BACKGROUND,
                    BACKGROUND,
                    DEFAULT_SHADOW_VALUE,
                    BACKGROUND,
                    DEFAULT_SHADOW_VALUE,
                    FOREGROUND,
                    BACKGROUND,
                    BACKGROUND,
                    BACKGROUND,
                ]
            );
        }
    }
    let mut m = model(params);
    let mut mask = vec![0u8; w];
    for f in &frames {
        m.apply(ImageView::new(f, w, 1, 3).expect("frame"), lr, &mut mask)
            .expect("apply");
    }
    // The shadow and the other hue each started a component on the last frame.
    assert_eq!(m.components_per_pixel(), [1, 2, 3, 1, 2, 2, 1, 1, 1]);
}

/// Selective learning ([`AdaptiveGmm::apply_selective`]): the kernel against the scalar
/// reference with a random update mask (every instruction set), and known answers — a frozen
/// pixel's mixture is exactly what it was, an unfrozen pixel's mixture and every pixel's mask
/// are those of the unmasked run, a pixel frozen from the first frame has no component, and an
/// all-true mask is the plain update bit for bit.
#[test]
fn masked_update_freezes_exactly_the_masked_pixels() {
    let (w, h, c) = (11, 3, 3);
    let frames = stress_frames(w, h, c, 60, 4242);
    let params = GmmParams::default();
    for isa in Isa::available() {
        let mut rng = Rng(17);
        let mut m = model(params);
        let mut r = ReferenceGmm::new(params, w * h, c);
        let (mut got, mut want) = (vec![0u8; w * h], vec![0u8; w * h]);
        for (t, f) in frames.iter().enumerate() {
            let learn: Vec<bool> = (0..w * h).map(|_| rng.below(3) != 0).collect();
            let view = ImageView::new(f, w, h, c).expect("frame");
            m.apply_with(isa, view, None, Some(&learn), &mut got)
                .expect("apply");
            r.apply_masked(f, None, Some(&learn), &mut want);
            assert_eq!(got, want, "masked frame {t}");
            assert_same_state(&m, &r, w, t);
        }
    }
    // Known answers against the unmasked run: pixels 3 and 20 frozen on frames 10..30.
    let frozen = |p: usize| p == 3 || p == 20;
    let mut plain = model(params);
    let mut sel = model(params);
    let (mut a, mut b) = (vec![0u8; w * h], vec![0u8; w * h]);
    let mut before: Vec<Vec<Component>> = Vec::new();
    for (t, f) in frames.iter().enumerate() {
        let view = ImageView::new(f, w, h, c).expect("frame");
        let learn: Vec<bool> = (0..w * h)
            .map(|p| !(10..30).contains(&t) || !frozen(p))
            .collect();
        if t == 10 {
            before = (0..w * h)
                .map(|p| sel.components(p % w, p / w).expect("px"))
                .collect();
        }
        plain.apply(view, None, &mut a).expect("apply");
        sel.apply_selective(view, None, &learn, &mut b)
            .expect("apply");
        if t <= 10 {
            assert_eq!(
                a, b,
                "same masks until the first frozen frame is classified ({t})"
            );
        }
        for p in 0..w * h {
            let (x, y) = (p % w, p / w);
            let got = sel.components(x, y).expect("px");
            if (10..30).contains(&t) && frozen(p) {
                assert_eq!(got, before[p], "frozen pixel {p} changed on frame {t}");
            } else if !frozen(p) {
                assert_eq!(
                    got,
                    plain.components(x, y).expect("px"),
                    "pixel {p} frame {t}"
                );
                assert_eq!(a[p], b[p], "mask of pixel {p} frame {t}");
            }
        }
    }
    // A pixel frozen from the first frame has no model; an all-true mask is `apply`.
    let mut fresh = model(params);
    let mut all = model(params);
    let mut mask = vec![0u8; w * h];
    let mut learn = vec![true; w * h];
    learn[5] = false;
    let view = ImageView::new(&frames[0], w, h, c).expect("frame");
    fresh
        .apply_selective(view, None, &learn, &mut mask)
        .expect("apply");
    assert!(fresh.components(5, 0).expect("px").is_empty());
    assert_eq!(fresh.components(6, 0).expect("px").len(), 1);
    let mut plain = model(params);
    for f in &frames {
        let view = ImageView::new(f, w, h, c).expect("frame");
        plain.apply(view, None, &mut a).expect("apply");
        all.apply_selective(view, None, &vec![true; w * h], &mut b)
            .expect("apply");
        assert_eq!(a, b);
    }
    let (mut s1, mut s2) = (Vec::new(), Vec::new());
    plain.save(&mut s1).expect("save");
    all.save(&mut s2).expect("save");
    assert_eq!(s1, s2);
    assert!(matches!(
        all.apply_selective(view, None, &[true; 4], &mut b),
        Err(GmmError::UpdateMaskSize { have: 4, need: 33 })
    ));
}

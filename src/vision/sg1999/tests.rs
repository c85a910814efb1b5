//! Known answers: ρ and the mean/variance step against the closed form, the ω/σ ranking
//! against an ω ranking, and the frame at which a new static value becomes background.

use super::*;

fn model(params: Sg1999Params) -> Sg1999 {
    Sg1999::new(params).expect("valid parameters")
}

/// Feed one grey or RGB pixel; return the model's own mask per frame.
fn run(m: &mut Sg1999, seq: &[&[u8]]) -> Vec<u8> {
    seq.iter()
        .map(|px| {
            let view = ImageView::new(px, 1, 1, px.len()).expect("1x1");
            let mut mask = [0u8; 1];
            m.apply(view, &mut mask).expect("apply");
            mask[0]
        })
        .collect()
}

#[test]
fn rho_and_the_matched_update_follow_the_closed_form() {
    let p = Sg1999Params::default();
    let alpha = 1.0 / f64::from(p.history);
    for (first, second) in [
        (&[100u8][..], &[120u8][..]),
        (&[100, 50, 20], &[110, 40, 35]),
    ] {
        let n = first.len();
        let mut m = model(p);
        run(&mut m, &[first]);
        let c = m.components(0, 0);
        // frame 1: one component at the sample, the high variance, weight 1 after renormalising
        assert_eq!(c.len(), 1);
        assert_eq!((c[0].weight, c[0].variance), (1.0, p.var_init));
        run(&mut m, &[second]);
        let c = m.components(0, 0);
        assert_eq!(c.len(), 1, "20 grey levels is within 2.5 σ = 75");
        // ρ = α η(x | µ, σ²I) = α (2πσ²)^(−n/2) exp(−|δ|²/(2σ²))
        let delta: Vec<f64> = (0..n)
            .map(|k| f64::from(second[k]) - f64::from(first[k]))
            .collect();
        let dd: f64 = delta.iter().map(|d| d * d).sum();
        let rho = alpha
            * (2.0 * std::f64::consts::PI * p.var_init).powf(-(n as f64) / 2.0)
            * (-dd / (2.0 * p.var_init)).exp();
        for k in 0..n {
            let mu = f64::from(first[k]) + rho * delta[k];
            assert!((c[0].mean[k] - mu).abs() < 1e-12, "{c:?} vs {mu}");
        }
        // σ² ← (1 − ρ)σ² + ρ|x − µ_new|², x − µ_new = (1 − ρ)δ
        let var = (1.0 - rho) * p.var_init + rho * (1.0 - rho).powi(2) * dd;
        assert!((c[0].variance - var).abs() < 1e-9, "{c:?} vs {var}");
        assert!(c[0].variance < p.var_init, "ρ > 0 shrank the variance");
        // the weight: (1 − α) · 1 + α = 1
        assert!((c[0].weight - 1.0).abs() < 1e-15);
    }
}

/// A pixel holding `comps` (already in ω/σ order as the model keeps them).
fn with_components(p: Sg1999Params, comps: &[SgComponent]) -> Sg1999 {
    let mut m = model(p);
    run(&mut m, &[&[0u8]]);
    for (slot, c) in m.slots.iter_mut().zip(comps) {
        *slot = *c;
    }
    m.used[0] = comps.len() as u8;
    m
}

#[test]
fn ranking_by_weight_over_sigma_decides_the_background() {
    // A: weight 0.6, σ = 30 (ω/σ = 0.02); B: weight 0.4, σ = 2 (ω/σ = 0.2). With T = 0.3
    // the first component alone is the background: B by ω/σ (the original), A by ω.
    let p = Sg1999Params {
        background_ratio: 0.3,
        ..Sg1999Params::default()
    };
    let a = SgComponent {
        weight: 0.6,
        variance: 900.0,
        mean: [50.0, 0.0, 0.0],
    };
    let b = SgComponent {
        weight: 0.4,
        variance: 4.0,
        mean: [200.0, 0.0, 0.0],
    };
    assert!(b.key() > a.key() && a.weight > b.weight);
    // a sample at A's mean: matched by A (distance 0), which is not among the first B
    let mut m = with_components(p, &[b, a]);
    let mut mask = [0u8; 1];
    m.apply(ImageView::new(&[50], 1, 1, 1).expect("1x1"), &mut mask)
        .expect("apply");
    assert_eq!(mask[0], FOREGROUND, "ω/σ ranking: only B is background");
    // the distance output: to B only, (200 − 50)² / 4
    let mut m = with_components(p, &[b, a]);
    let mut d = [0.0f32; 1];
    m.apply_distance(ImageView::new(&[50], 1, 1, 1).expect("1x1"), &mut d)
        .expect("apply");
    assert_eq!(d[0], (150.0f32 * 150.0) / 4.0);
    // a sample at B's mean is background
    let mut m = with_components(p, &[b, a]);
    m.apply(ImageView::new(&[200], 1, 1, 1).expect("1x1"), &mut mask)
        .expect("apply");
    assert_eq!(mask[0], BACKGROUND);
    // ranked by ω alone (A first), the sample at A's mean would be background: the same
    // pixel with A's σ lowered to 1 puts A first by ω/σ too (0.6 > 0.2), and it is
    let a1 = SgComponent { variance: 1.0, ..a };
    let mut m = with_components(p, &[a1, b]);
    m.apply(ImageView::new(&[50], 1, 1, 1).expect("1x1"), &mut mask)
        .expect("apply");
    assert_eq!(mask[0], BACKGROUND);
    // and the model keeps its components in ω/σ order after an update
    let mut m = with_components(p, &[a1, b]);
    m.apply(ImageView::new(&[0], 1, 1, 1).expect("1x1"), &mut mask)
        .expect("apply");
    let keys: Vec<f64> = m.components(0, 0).iter().map(SgComponent::key).collect();
    assert!(keys.windows(2).all(|w| w[0] >= w[1]), "{keys:?}");
}

#[test]
fn a_new_static_value_becomes_background_after_the_closed_form_frames() {
    // var_min = var_init keeps every σ at σ₀ (a matched component's σ² only shrinks and is
    // floored), so the ω/σ order is the ω order. The pixel shows a for 50 frames (one
    // component, ω = 1), then b (225 σ² away: no match). At the switch frame (j = 0, foreground)
    // the old weight becomes (1 − α) and the new one ω₀, renormalised: v₁ = ω₀ / (1 − α + ω₀),
    // u₁ = 1 − v₁. Frame j ≥ 1 after the switch is decided with u_j = u₁ (1 − α)^(j − 1): it is
    // background once u_j ≤ T (B then includes the new component, which b matches):
    // j* = 1 + ceil(log(T / u₁) / log(1 − α)).
    let p = Sg1999Params {
        var_init: 100.0,
        var_min: 100.0,
        history: 200,
        background_ratio: 0.7,
        ..Sg1999Params::default()
    };
    let alpha = 1.0 / f64::from(p.history);
    let u1 = 1.0 - p.weight_init / (1.0 - alpha + p.weight_init);
    let exact = (p.background_ratio / u1).ln() / (1.0 - alpha).ln();
    assert!(
        exact.fract() > 0.05 && exact.fract() < 0.95,
        "{exact}: far from a boundary"
    );
    let predicted = 1 + exact.ceil() as usize;
    let mut m = model(p);
    let mut seq: Vec<&[u8]> = vec![&[50u8]; 50];
    seq.extend(vec![&[200u8][..]; predicted + 20]);
    let masks = run(&mut m, &seq);
    assert_eq!(masks[0], FOREGROUND, "frame 1: no component yet");
    assert!(masks[1..50].iter().all(|&v| v == BACKGROUND));
    // the switch frame has index 50, frame j after it index 50 + j
    let first = masks[50..]
        .iter()
        .position(|&v| v == BACKGROUND)
        .expect("becomes background");
    assert_eq!(first, predicted, "j* = {predicted} ({exact})");
    assert!(masks[50 + predicted..].iter().all(|&v| v == BACKGROUND));
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let mut m = model(Sg1999Params::default());
    let mut mask = [0u8; 2];
    assert!(matches!(
        m.apply(
            ImageView::new(&[0; 4], 2, 1, 2).expect("2 channels"),
            &mut mask
        ),
        Err(GmmError::UnsupportedChannels { channels: 2 })
    ));
    assert!(matches!(
        m.apply(ImageView::new(&[0; 3], 3, 1, 1).expect("3x1"), &mut mask),
        Err(GmmError::MaskSize { have: 2, need: 3 })
    ));
    m.apply(ImageView::new(&[0; 2], 2, 1, 1).expect("2x1"), &mut mask)
        .expect("first frame");
    assert!(matches!(
        m.apply(ImageView::new(&[0; 2], 1, 2, 1).expect("1x2"), &mut mask),
        Err(GmmError::ShapeMismatch { .. })
    ));
    for p in [
        Sg1999Params {
            k: 0,
            ..Sg1999Params::default()
        },
        Sg1999Params {
            history: 0,
            ..Sg1999Params::default()
        },
        Sg1999Params {
            var_init: f64::NAN,
            ..Sg1999Params::default()
        },
    ] {
        assert!(matches!(Sg1999::new(p), Err(GmmError::BadParam { .. })));
    }
}

use nalgebra::{Matrix2, Matrix4, Vector2, Vector4};

use super::*;
use crate::track::jpda::joint_marginals;

fn shared() -> Shared {
    Shared {
        sigma_r: 0.2,
        p_d: 0.9,
        gate: 9.21,
        clutter_density: 0.05,
    }
}

/// A confirmed track at `(x, y)` with position variance `var` (m²), at rest.
fn track(x: f64, y: f64, var: f64) -> Track {
    let mut p = Matrix4::identity();
    p[(0, 0)] = var;
    p[(1, 1)] = var;
    p[(0, 1)] = 0.3 * var;
    p[(1, 0)] = 0.3 * var;
    Track {
        kf: Kalman::new(Vector4::new(x, y, 0.0, 0.0), p),
        hits: 5,
        last_hit: 0.0,
        template: None,
    }
}

/// Blobs of the JPDA tests: the target's, one between the target and the first other track,
/// that track's own, one near the second other track, one far from everyone.
const BLOBS: [[f64; 2]; 5] = [
    [0.0, 0.0],
    [0.7, 0.1],
    [1.25, 0.15],
    [-0.8, 0.3],
    [5.0, 5.0],
];

/// The JPDA weights `P_D N(z; ẑ, S)` of a position with covariance `s` (gated) for `z`.
fn weights(mean: [f64; 2], s: Matrix2<f64>, z: &[[f64; 2]], sh: &Shared, lr: &[f64]) -> Vec<f64> {
    let inv = s.try_inverse().expect("positive definite");
    z.iter()
        .zip(lr)
        .map(|(zj, l)| {
            let nu = Vector2::new(zj[0] - mean[0], zj[1] - mean[1]);
            let d2 = (nu.transpose() * inv * nu)[(0, 0)];
            if d2 <= sh.gate {
                sh.p_d * gaussian_2d(d2, s.determinant()) * l
            } else {
                0.0
            }
        })
        .collect()
}

/// The target's marginals from the discounted PDAF equal those of the full JPDA over the
/// target and two other tracks that share no blob (exact by the module doc's algebra).
#[test]
fn discounted_pdaf_is_the_jpda_marginal_of_the_target() {
    let sh = shared();
    let others = Others {
        params: OthersParams::default(),
        tracks: vec![track(1.3, 0.1, 0.02), track(-1.0, 0.4, 0.05)],
        t: Some(0.0),
    };
    let z = BLOBS;
    let lr = [0.9, 0.3, 0.1, 0.6, 1.0];
    let s_t = Matrix2::new(0.12, 0.02, 0.02, 0.09);
    let w_t = weights([0.1, 0.05], s_t, &z, &sh, &lr);
    let mut rows = vec![w_t.clone()];
    for tr in &others.tracks {
        let s = tr.kf.p.fixed_view::<2, 2>(0, 0) + Matrix2::identity() * sh.sigma_r.powi(2);
        rows.push(weights([tr.kf.x[0], tr.kf.x[1]], s, &z, &sh, &[1.0; 5]));
    }
    let miss = sh.clutter_density * (1.0 - sh.p_d * sh.p_g());
    let exact = joint_marginals(&rows, &[miss; 3], 100_000).expect("a small cluster");
    // the two other tracks share no blob (else the factorisation is not exact)
    assert!((0..5).all(|j| rows[1][j] == 0.0 || rows[2][j] == 0.0));
    assert!(
        rows[1][1] > 0.0
            && rows[2][1] == 0.0
            && rows[1][2] > 0.0
            && rows[2][3] > 0.0
            && w_t[1] > 0.0
    );
    let f = others.discount(&z, &BlobColour::none(), &sh);
    assert_eq!(f[4], 1.0);
    let p: Vec<f64> = w_t.iter().zip(&f).map(|(w, f)| w * f).collect();
    let total = miss + p.iter().sum::<f64>();
    for (j, (pj, b)) in p.iter().zip(&exact.beta[0]).enumerate() {
        assert!(
            (pj / total - b).abs() < 1e-12,
            "blob {j}: {} vs {b}",
            pj / total
        );
    }
    assert!((miss / total - exact.beta0[0]).abs() < 1e-12);
    // the blob other 1 predicts well counts far less as the target's than under the
    // paper's PDAF, which takes every other blob for uniform clutter
    assert!(w_t[3] > 0.0);
    let plain = w_t[3] / (miss + w_t.iter().sum::<f64>());
    assert!(
        exact.beta[0][3] < 0.2 * plain,
        "{} vs {plain}",
        exact.beta[0][3]
    );
}

/// Tentative tracks do not discount; a track is confirmed after `confirm_hits` scans, the
/// blob the target took starts nothing, and a track without a hit for `max_coast_s` is gone.
#[test]
fn tracks_are_confirmed_then_forgotten() {
    let sh = shared();
    let mut o = Others::new(&OthersParams::default());
    let z = [[0.0, 0.0], [2.0, 0.0]];
    for k in 0..3 {
        let t = 0.1 * k as f64;
        o.predict(t);
        assert_eq!(
            o.discount(&z, &BlobColour::none(), &sh),
            vec![1.0, 1.0],
            "scan {k}"
        );
        o.update(t, &z, &[], Some(0), &sh);
    }
    assert_eq!(o.tracks.len(), 1);
    let c = o.confirmed();
    assert_eq!(c.len(), 1);
    assert!((c[0][0] - 2.0).abs() < 1e-9 && c[0][1].abs() < 1e-9);
    o.predict(0.3);
    let f = o.discount(&z, &BlobColour::none(), &sh);
    assert_eq!(f[0], 1.0);
    assert!(f[1] < 0.05, "{f:?}");
    // its last hit was at 0.2 s: kept up to 1.2 s without its blob, deleted after
    for t in [0.5, 0.8, 1.15] {
        o.predict(t);
        o.update(t, &z[..1], &[], Some(0), &sh);
        assert_eq!(o.tracks.len(), 1, "{t}");
    }
    o.predict(1.25);
    o.update(1.25, &z[..1], &[], Some(0), &sh);
    assert!(o.tracks.is_empty());
}

#[test]
fn forget_near_deletes_the_track_of_the_blob() {
    let sh = shared();
    let mut o = Others {
        params: OthersParams::default(),
        tracks: vec![track(0.0, 0.0, 0.02), track(3.0, 0.0, 0.02)],
        t: Some(0.0),
    };
    o.forget_near([2.9, 0.1], &sh);
    assert_eq!(o.confirmed(), vec![[0.0, 0.0]]);
    o.forget_near([10.0, 0.0], &sh);
    assert_eq!(o.tracks.len(), 1);
}

/// A track on the target's estimate (0.1 m off, both covariances 0.02 m²: d² = 0.25) is the
/// target and goes; one 0.5 m off (d² = 6.25) is someone else and stays.
#[test]
fn a_track_on_the_target_is_the_target() {
    let mut o = Others {
        params: OthersParams::default(),
        tracks: vec![track(0.1, 0.0, 0.02), track(0.5, 0.0, 0.02)],
        t: Some(0.0),
    };
    // track() gives the position covariance a 0.3 correlation; the target's is diagonal
    o.coalesce([0.0, 0.0], [[0.02, 0.0], [0.0, 0.02]]);
    assert_eq!(o.confirmed(), vec![[0.5, 0.0]]);
}

/// With colour, each other track's pair weights carry its own likelihood ratio, and the
/// discounted PDAF is still exactly the JPDA's marginal (now with every track's colour).
#[test]
fn colour_on_the_other_tracks_is_the_jpda_with_their_colour() {
    let sh = shared();
    let mut red = track(1.3, 0.1, 0.02);
    red.template = Some(vec![1.0, 0.0]);
    let others = Others {
        params: OthersParams::default(),
        // the second track has no template yet: its ratios are 1
        tracks: vec![red, track(-1.0, 0.4, 0.05)],
        t: Some(0.0),
    };
    let z = BLOBS;
    let hists = [
        Some(vec![0.0, 1.0]),
        Some(vec![1.0, 0.0]),
        None,
        Some(vec![0.5, 0.5]),
        Some(vec![0.0, 1.0]),
    ];
    let lr_of = |h: &[f64], t: &[f64]| 0.05 + 2.0 * (h[0] * t[0] + h[1] * t[1]);
    let colour = BlobColour {
        hists: &hists,
        lr: &lr_of,
    };
    let lr = [0.9, 0.3, 0.1, 0.6, 1.0];
    let s_t = Matrix2::new(0.12, 0.02, 0.02, 0.09);
    let mut rows = vec![weights([0.1, 0.05], s_t, &z, &sh, &lr)];
    let lr_red: Vec<f64> = hists
        .iter()
        .map(|h| h.as_deref().map_or(1.0, |h| lr_of(h, &[1.0, 0.0])))
        .collect();
    assert_eq!(lr_red, vec![0.05, 2.05, 1.0, 1.05, 0.05]);
    for (tr, l) in others.tracks.iter().zip([lr_red, vec![1.0; 5]]) {
        let s = tr.kf.p.fixed_view::<2, 2>(0, 0) + Matrix2::identity() * sh.sigma_r.powi(2);
        rows.push(weights([tr.kf.x[0], tr.kf.x[1]], s, &z, &sh, &l));
    }
    let miss = sh.clutter_density * (1.0 - sh.p_d * sh.p_g());
    let exact = joint_marginals(&rows, &[miss; 3], 100_000).expect("a small cluster");
    let f = others.discount(&z, &colour, &sh);
    let p: Vec<f64> = rows[0].iter().zip(&f).map(|(w, f)| w * f).collect();
    let total = miss + p.iter().sum::<f64>();
    for (j, (pj, b)) in p.iter().zip(&exact.beta[0]).enumerate() {
        assert!((pj / total - b).abs() < 1e-12, "blob {j}");
    }
    // colour off: the same tracks by position alone, not the coloured JPDA
    let plain = Others {
        params: OthersParams {
            colour: false,
            ..OthersParams::default()
        },
        tracks: others.tracks.clone(),
        t: Some(0.0),
    };
    assert_eq!(
        plain.discount(&z, &colour, &sh),
        plain.discount(&z, &BlobColour::none(), &sh)
    );
}

/// Round 5's failure: a companion's track (red) drifts 0.25 m from the target's blob (blue)
/// while the companion's own blob is missing. By position alone it leaves the target 0.4 % of
/// its blob's weight; with its colour (ratio 0.02) 16 %, forty times more — the missed
/// weight m ≈ 0.0055 is small, so only ratios near 0 (corr ≤ 0) leave the blob whole.
#[test]
fn a_companion_of_another_colour_does_not_discount_the_target() {
    let sh = shared();
    let mut red = track(0.25, 0.0, 0.02);
    red.template = Some(vec![1.0, 0.0]);
    let z = [[0.0, 0.0]];
    let hists = [Some(vec![0.0, 1.0])];
    let lr_of = |h: &[f64], t: &[f64]| 0.02 + (h[0] * t[0] + h[1] * t[1]);
    let colour = BlobColour {
        hists: &hists,
        lr: &lr_of,
    };
    let with = |on: bool| Others {
        params: OthersParams {
            colour: on,
            ..OthersParams::default()
        },
        tracks: vec![red.clone()],
        t: Some(0.0),
    };
    let off = with(false).discount(&z, &colour, &sh)[0];
    let on = with(true).discount(&z, &colour, &sh)[0];
    // closed form: m / (m + P_D N lr) with S = [[a, b], [b, a]], a = 0.02 + 0.2², b = 0.3 ·
    // 0.02 (the track's correlated position covariance plus σ_r² I): the offset (0.25, 0)
    // has d² = 0.25² · a / (a² − b²)
    let (a, b) = (0.06, 0.006);
    let det = a * a - b * b;
    let n = gaussian_2d(0.0625 * a / det, det);
    let m = sh.clutter_density * (1.0 - sh.p_d * sh.p_g());
    assert!((off - m / (m + sh.p_d * n)).abs() < 1e-12, "{off}");
    assert!((on - m / (m + sh.p_d * n * 0.02)).abs() < 1e-12, "{on}");
    assert!(off < 0.005 && on > 40.0 * off, "off {off}, on {on}");
}

/// A new track takes its first blob's histogram as its template and holds it; a track born
/// without one takes the first histogram it is assigned.
#[test]
fn other_tracks_hold_their_first_histogram() {
    let sh = shared();
    let mut o = Others::new(&OthersParams::default());
    let z = [[0.0, 0.0], [2.0, 0.0], [-2.0, 0.0]];
    o.predict(0.0);
    o.update(0.0, &z, &[None, Some(vec![1.0, 0.0]), None], Some(0), &sh);
    assert_eq!(o.tracks.len(), 2);
    assert_eq!(o.tracks[0].template, Some(vec![1.0, 0.0]));
    assert_eq!(o.tracks[1].template, None);
    o.predict(0.1);
    let h = [None, Some(vec![0.0, 1.0]), Some(vec![0.5, 0.5])];
    o.update(0.1, &z, &h, Some(0), &sh);
    assert_eq!(o.tracks[0].template, Some(vec![1.0, 0.0]), "held");
    assert_eq!(
        o.tracks[1].template,
        Some(vec![0.5, 0.5]),
        "taken when first seen"
    );
}

use super::*;
use crate::vision::egomotion::DiffViews;
use crate::vision::egomotion::views::{Plane, ViewParams, Views, tests::omni};
use nalgebra::Point2;

/// Zero difference images for the default views, with discs of value `v` and radius `r` px
/// painted at `(view, centre)`.
fn diffs_with(blobs: &[(usize, [f64; 2], f64, f32)]) -> (Views, Vec<Plane>) {
    let views = Views::new(&omni(), &ViewParams::default()).expect("valid");
    let mut d = vec![Plane::new(160, 120, 0.0); views.len()];
    for &(k, c, r, v) in blobs {
        for y in 0..120 {
            for x in 0..160 {
                if (x as f64 + 0.5 - c[0]).hypot(y as f64 + 0.5 - c[1]) <= r {
                    d[k].v[y * 160 + x] = v;
                }
            }
        }
    }
    (views, d)
}

fn direction(views: &Views, k: usize, c: [f64; 2]) -> (f64, f64) {
    let r = views.views()[k].ray(&Point2::new(c[0], c[1]));
    (r.y.atan2(r.x), r.z.atan2(r.x.hypot(r.y)))
}

fn run(views: &Views, d: &[Plane], steps: usize, seed: u64) -> Option<Cluster> {
    let field = DiffViews {
        views,
        diffs: d,
        threshold: 15.0,
        half_window: 2,
    };
    let band = (-0.45, 0.45);
    let mut pf = ParticleFilter::new(&ParticleParams::default(), band, seed);
    let mut last = None;
    for _ in 0..steps {
        last = pf.step(&field);
    }
    last
}

#[test]
fn one_blob_is_found_at_its_centre() {
    let centre = [100.5, 50.5];
    let (views, d) = diffs_with(&[(2, centre, 8.0, 200.0)]);
    let (az, el) = direction(&views, 2, centre);
    let c = run(&views, &d, 12, 7).expect("a detection");
    assert!(
        wrap_angle(c.azimuth - az).abs() < 0.01,
        "azimuth {} vs {az}",
        c.azimuth
    );
    assert!(
        (c.elevation - el).abs() < 0.01,
        "elevation {} vs {el}",
        c.elevation
    );
    // and within a pixel of the blob centre in its view
    let (se, ce) = c.elevation.sin_cos();
    let dir = nalgebra::Vector3::new(ce * c.azimuth.cos(), ce * c.azimuth.sin(), se);
    let px = views.views()[2].project(&dir).expect("in front");
    assert!((px.x - centre[0]).hypot(px.y - centre[1]) < 1.0, "{px}");
}

#[test]
fn of_two_blobs_the_stronger_is_chosen() {
    let strong = [40.5, 70.5];
    let weak = [120.5, 60.5];
    for (strong_view, weak_view) in [(6, 1), (1, 6)] {
        let (views, d) = diffs_with(&[
            (strong_view, strong, 8.0, 220.0),
            (weak_view, weak, 8.0, 100.0),
        ]);
        let (az, _) = direction(&views, strong_view, strong);
        let c = run(&views, &d, 12, 3).expect("a detection");
        assert!(
            wrap_angle(c.azimuth - az).abs() < 0.02,
            "strong blob in view {strong_view}: got azimuth {}, want {az}",
            c.azimuth
        );
    }
}

#[test]
fn the_same_seed_gives_the_same_particles_and_detection() {
    let (views, d) = diffs_with(&[
        (4, [70.5, 60.5], 10.0, 150.0),
        (5, [30.5, 40.5], 6.0, 140.0),
    ]);
    let a = run(&views, &d, 6, 11);
    let b = run(&views, &d, 6, 11);
    assert_eq!(a, b);
    assert!(a.is_some());
}

#[test]
fn nothing_above_the_threshold_gives_no_detection() {
    let (views, d) = diffs_with(&[(3, [80.5, 60.5], 20.0, 15.0)]);
    assert_eq!(run(&views, &d, 3, 1), None);
}

/// Particles on a symmetric grid around `(az, el)`, spacing 0.01 rad, total weight `w`.
fn cloud(az: f64, el: f64, w: f64) -> Vec<Particle> {
    let mut out = Vec::new();
    for i in -3..=3 {
        for j in -3..=3 {
            out.push(Particle {
                azimuth: wrap_angle(az + 0.01 * f64::from(i)),
                elevation: el + 0.01 * f64::from(j),
                weight: w / 49.0,
            });
        }
    }
    out
}

#[test]
fn em_separates_two_clouds_with_their_weights_and_means() {
    let mut pts = cloud(0.5, 0.1, 0.7);
    pts.extend(cloud(-2.0, -0.2, 0.3));
    let mut got = em_clusters(&pts, 3, 50);
    assert_eq!(got.len(), 2, "{got:?}");
    got.sort_by(|a, b| b.weight.total_cmp(&a.weight));
    for (c, (az, el, w)) in got.iter().zip([(0.5, 0.1, 0.7), (-2.0, -0.2, 0.3)]) {
        assert!(
            (c.azimuth - az).abs() < 1e-9 && (c.elevation - el).abs() < 1e-9,
            "{c:?}"
        );
        assert!((c.weight - w).abs() < 1e-9, "{c:?}");
        // the grid's variance per axis: 0.01² · mean(i²), i = −3..3, = 0.0004, plus the floor
        let var = 0.0001 * (2.0 * (9.0 + 4.0 + 1.0)) / 7.0 + MIN_VARIANCE;
        assert!(
            (c.cov[0][0] - var).abs() < 1e-9 && c.cov[0][1].abs() < 1e-9,
            "{c:?}"
        );
    }
}

#[test]
fn em_handles_a_cloud_across_the_azimuth_seam() {
    let pts = cloud(std::f64::consts::PI - 0.005, 0.0, 1.0);
    let got = em_clusters(&pts, 3, 30);
    assert_eq!(got.len(), 1, "{got:?}");
    assert!(
        wrap_angle(got[0].azimuth - (std::f64::consts::PI - 0.005)).abs() < 1e-9,
        "{got:?}"
    );
    assert!(em_clusters(&[], 3, 10).is_empty());
}

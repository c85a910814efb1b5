use super::*;

/// The synthetic `segway_park` omnicam (640 × 480, f = 130 px, ring 28..238 px), centre moved
/// off the image centre so that a centre mix-up shows.
pub(crate) fn omni() -> Paracatadioptric {
    Paracatadioptric {
        width: 640,
        height: 480,
        xc: 321.3,
        yc: 239.4,
        f: 130.0,
        r_min: 28.0,
        r_max: 238.0,
    }
}

fn views() -> Views {
    Views::new(&omni(), &ViewParams::default()).expect("valid")
}

#[test]
fn view_axes_are_45_degrees_apart_and_horizontal() {
    let v = views();
    assert_eq!(v.len(), 8);
    for (k, view) in v.views().iter().enumerate() {
        let want = wrap_angle(k as f64 * 45f64.to_radians());
        assert!((wrap_angle(view.azimuth - want)).abs() < 1e-12);
        let axis = view.ray(&Point2::new(80.0, 60.0));
        assert!(
            (axis - Vector3::new(want.cos(), want.sin(), 0.0)).norm() < 1e-12,
            "{k}: {axis}"
        );
        // "up" in the view (smaller y) is the camera's +z
        let above = view.ray(&Point2::new(80.0, 10.0));
        assert!(above.z > 0.0);
    }
}

#[test]
fn an_omni_projection_mapped_into_its_view_is_the_pinhole_projection() {
    let (o, v) = (omni(), views());
    let mut checked = 0;
    for i in 0..36 {
        for (el_deg, dist) in [
            (-18.0f64, 2.0),
            (-5.0, 7.5),
            (0.0, 3.0),
            (9.0, 1.2),
            (20.0, 4.0),
        ] {
            let az = (i as f64 * 10.0 + 3.7).to_radians();
            let el = el_deg.to_radians();
            let p = Point3::new(
                dist * el.cos() * az.cos(),
                dist * el.cos() * az.sin(),
                dist * el.sin(),
            );
            let omni_px = o.project(&p).expect("inside the ring");
            let (k, got) = v.omni_to_view(&omni_px).expect("in a view");
            assert_eq!(k, v.nearest_view(az));
            let view = &v.views()[k];
            let want = view
                .pinhole
                .project(&Point3::from(view.view_from_camera * p.coords))
                .expect("in front");
            assert!(
                (got - want).norm() < 1e-6,
                "az {az} el {el}: {got} vs {want}"
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 180);
}

#[test]
fn view_and_omni_positions_round_trip() {
    let v = views();
    let (mut same, mut other) = (0, 0);
    for k in 0..v.len() {
        for j in 0..12 {
            for i in 0..16 {
                let px = Point2::new(3.3 + 10.0 * i as f64, 2.1 + 10.0 * j as f64);
                let o = v.view_to_omni(k, &px).expect("views lie inside the ring");
                let (k2, px2) = v.omni_to_view(&o).expect("in a view");
                if k2 == k {
                    assert!((px2 - px).norm() < 1e-6, "view {k} {px}: back at {px2}");
                    same += 1;
                } else {
                    // the overlap: another view holds it; that view maps back to the same omni pixel
                    assert!(wrap_angle(v.views()[k2].azimuth - v.views()[k].azimuth).abs() < 0.8);
                    let o2 = v.view_to_omni(k2, &px2).expect("on the mirror");
                    assert!((o2 - o).norm() < 1e-6);
                    other += 1;
                }
            }
        }
    }
    assert!(same > 0 && other > 0, "{same} {other}");
}

#[test]
fn views_of_a_uniform_ring_are_uniform_and_outside_the_ring_is_nan() {
    let o = omni();
    let img = GrayImage::from_fn(640, 480, |x, y| {
        let r = (f64::from(x) + 0.5 - o.xc).hypot(f64::from(y) + 0.5 - o.yc);
        image::Luma([if r <= o.r_max + 2.0 { 100 } else { 0 }])
    });
    let mut out = Vec::new();
    views().render(&img, &mut out);
    assert_eq!(out.len(), 8);
    for p in &out {
        assert_eq!((p.width, p.height), (160, 120));
        assert!(
            p.v.iter().all(|&x| (x - 100.0).abs() < 1e-4),
            "a view pixel misses the ring"
        );
    }
    // views tilted 60° up see past the ring's inner edge (camera elevation 65.7°)
    let tilted = Views::new(
        &o,
        &ViewParams {
            elevation_deg: 60.0,
            ..ViewParams::default()
        },
    )
    .expect("valid");
    tilted.render(&img, &mut out);
    assert!(out[0].v.iter().any(|x| x.is_nan()));
}

#[test]
fn bad_view_parameters_are_errors() {
    for p in [
        ViewParams {
            count: 0,
            ..ViewParams::default()
        },
        ViewParams {
            hfov_deg: 180.0,
            ..ViewParams::default()
        },
        ViewParams {
            elevation_deg: f64::NAN,
            ..ViewParams::default()
        },
    ] {
        assert!(Views::new(&omni(), &p).is_err());
    }
}

use super::*;

/// Paint a silhouette into a mask at a top-left corner.
fn paint(mask: &mut Mask, t: &Silhouette, x: i64, y: i64) {
    for (r, &(a, b)) in t.spans.iter().enumerate() {
        let yy = y + r as i64;
        if yy < 0 || yy >= i64::from(mask.height) {
            continue;
        }
        for xx in (x + i64::from(a))..(x + i64::from(b)) {
            if xx >= 0 && xx < i64::from(mask.width) {
                mask.data[(yy * i64::from(mask.width) + xx) as usize] = 1;
            }
        }
    }
}

#[test]
fn profile_is_human_shaped() {
    // shoulders wider than the head, head wider than the neck, legs narrower than shoulders
    assert!(profile_half_width(0.3) > profile_half_width(0.06));
    assert!(profile_half_width(0.06) > profile_half_width(0.14));
    assert!(profile_half_width(0.8) < profile_half_width(0.25));
    let s = Silhouette::new(100.0, 0.0);
    assert_eq!(s.height, 100);
    assert!((s.body_width_px - 24.0).abs() <= 1.0, "{}", s.body_width_px);
    // upright: head at the middle column
    assert!((s.head.0 - f64::from(s.width) / 2.0).abs() <= 1.0);
    // filled fraction of the window: the profile's mean width over its widest (the
    // shoulders, 2 · 0.12): head half-ellipse 0.13 · (π/4) · 0.052, neck 0.02 · 0.035,
    // shoulder ramp 0.05 · 0.0775, torso 0.3 · 0.1125, legs 0.5 · 0.09
    let closed = (0.13 * std::f64::consts::FRAC_PI_4 * 0.052
        + 0.02 * 0.035
        + 0.05 * 0.0775
        + 0.3 * 0.1125
        + 0.5 * 0.09)
        / 0.12;
    let fill = f64::from(s.area) / f64::from(s.width * s.height);
    assert!((fill - closed).abs() < 0.02, "{fill} vs {closed}");
    // a tilted one puts the head to the right of the feet
    let t = Silhouette::new(100.0, 0.2);
    let feet = t
        .spans
        .last()
        .map(|(a, b)| f64::from(a + b) / 2.0)
        .unwrap_or(0.0);
    assert!(t.head.0 > feet + 10.0);
}

#[test]
fn a_painted_silhouette_is_found_with_a_perfect_score_at_its_place() {
    let t = Silhouette::new(60.0, 0.0);
    let mut mask = Mask::new(120, 90);
    paint(&mut mask, &t, 31, 14);
    let dets = detect(
        &mask,
        std::slice::from_ref(&t),
        &DetectorParams {
            stride_px: 1,
            ..Default::default()
        },
    );
    assert_eq!(dets.len(), 1, "{dets:?}");
    let d = dets[0];
    assert!((d.score - 1.0).abs() < 1e-12);
    assert_eq!(d.bbox[0], 31.0);
    assert_eq!(d.bbox[1], 14.0);
    assert!((d.head_px[0] - (31.0 + t.head.0)).abs() < 1e-9);
    assert_eq!(d.head_px[1], 14.0);
}

#[test]
fn mse_score_has_its_closed_form() {
    // an empty mask scores 1 − |T| / A: below the threshold, so nothing is detected
    let t = Silhouette::new(40.0, 0.0);
    let mask = Mask::new(80, 60);
    let sums = Sums::new(&mask);
    let s = score_at(&sums, &t, 10, 5, 0.0, 0.5).expect("allowed");
    let want = 1.0 - f64::from(t.area) / f64::from(t.width * t.height);
    assert!((s - want).abs() < 1e-12);
    assert!(detect(&mask, std::slice::from_ref(&t), &DetectorParams::default()).is_empty());
    // a full window scores the fraction of the window inside the silhouette
    let full = Mask {
        width: 80,
        height: 60,
        data: vec![1; 80 * 60],
    };
    let sums = Sums::new(&full);
    let s = score_at(&sums, &t, 10, 5, 0.0, 0.5).expect("allowed");
    assert!((s - f64::from(t.area) / f64::from(t.width * t.height)).abs() < 1e-12);
}

#[test]
fn a_padded_template_finds_the_silhouette_and_ignores_filled_regions() {
    let tight = Silhouette::new(60.0, 0.1);
    let t = tight.clone().padded(0.5);
    // the margin brings the fill to the target (rounding up the margins: at most 0.5)
    assert!(tight.fill() > 0.65, "{}", tight.fill());
    assert!(t.fill() <= 0.5 && t.fill() > 0.45, "{}", t.fill());
    assert_eq!(t.area, tight.area);
    assert_eq!(
        t.body_height_px(),
        f64::from(tight.height),
        "the body box is the tight silhouette"
    );
    // painted with the tight silhouette, found with the padded one: score 1, tight box
    let mut mask = Mask::new(140, 110);
    paint(&mut mask, &tight, 41, 24);
    let p = DetectorParams {
        stride_px: 1,
        ..Default::default()
    };
    let dets = detect(&mask, std::slice::from_ref(&t), &p);
    assert_eq!(dets.len(), 1, "{dets:?}");
    assert!((dets[0].score - 1.0).abs() < 1e-12);
    assert_eq!(
        dets[0].bbox,
        [41.0, 24.0, 41.0 + f64::from(tight.width), 24.0 + 60.0]
    );
    assert!((dets[0].head_px[0] - (41.0 + tight.head.0)).abs() < 1e-9);
    assert_eq!(dets[0].head_px[1], 24.0);
    // a completely filled window scores its fill: the tight box (≈ 0.71) passes the
    // paper's threshold on any large blob, the padded one (≤ 0.5) never does
    let full = Mask {
        width: 140,
        height: 110,
        data: vec![1; 140 * 110],
    };
    let sums = Sums::new(&full);
    let s = score_at(&sums, &t, 30, 20, 0.0, 0.5).expect("allowed");
    assert!((s - t.fill()).abs() < 1e-12);
    assert!(detect(&full, std::slice::from_ref(&t), &p).is_empty());
    assert!(!detect(&full, std::slice::from_ref(&tight), &p).is_empty());
    // unchanged when the target is not below the fill
    assert_eq!(tight.clone().padded(0.9), tight);
}

fn corner_view() -> CalibratedView {
    use crate::geometry::camera::{CameraModel, Pinhole};
    let mut pin = Pinhole::from_fov(352, 288, 78.0);
    pin.dist = [-0.24, 0.06, 0.0, 0.0, 0.0];
    CalibratedView::new(
        CameraModel::Pinhole(pin),
        crate::geometry::look_at(Point3::new(0.15, 0.15, 2.85), Point3::new(4.0, 4.25, 0.7)),
    )
}

#[test]
fn the_position_map_predicts_the_projected_height_of_a_person() {
    let view = corner_view();
    let room = [0.0, 0.0, 8.0, 8.5];
    let mut checked = 0;
    for &(x, y) in &[(1.5, 2.0), (4.0, 4.0), (6.5, 7.5), (2.0, 6.0), (7.0, 1.5)] {
        let head = view.project(&Point3::new(x, y, 1.75)).expect("head");
        let foot = view.project(&Point3::new(x, y, 0.0)).expect("foot");
        let a = expected_appearance(&view, &head, 1.75, room, 0.5).expect("in the room");
        let want = (head.x - foot.x).hypot(foot.y - head.y);
        assert!((a.height_px - want).abs() < 1e-6 * want, "{a:?} vs {want}");
        assert!((a.tilt_rad - (head.x - foot.x).atan2(foot.y - head.y)).abs() < 1e-9);
        checked += 1;
    }
    assert_eq!(checked, 5);
    // a head outside the room (behind the wall, past the margin) gets none
    let out = view
        .project(&Point3::new(9.5, 4.0, 1.75))
        .expect("projects");
    assert!(expected_appearance(&view, &out, 1.75, room, 0.5).is_none());
    // the map picks, at a head pixel, the template nearest in height
    let templates: Vec<Silhouette> = [40.0, 60.0, 90.0, 135.0]
        .iter()
        .map(|&h| Silhouette::new(h, 0.0).padded(0.5))
        .collect();
    let map = TemplateMap::new(&view, &templates, 1.75, room, 0.5);
    let head = view.project(&Point3::new(4.0, 4.0, 1.75)).expect("head");
    let a = expected_appearance(&view, &head, 1.75, room, 0.5).expect("a");
    let want = (0..4)
        .min_by(|&i, &j| {
            let d = |k: usize| (templates[k].body_height_px() / a.height_px).ln().abs();
            d(i).total_cmp(&d(j))
        })
        .expect("some");
    assert_eq!(map.at(head.x as i64, head.y as i64), Some(want));
}

#[test]
fn lower_body_occlusion_lowers_the_score_but_stays_in_the_paper_range() {
    // a desk hides the legs (lower 40 %): the score drops to ~0.75-0.8, still detected
    let t = Silhouette::new(80.0, 0.0);
    let mut mask = Mask::new(100, 100);
    paint(&mut mask, &t, 30, 10);
    for y in (10 + 48)..100 {
        for x in 0..100 {
            mask.data[y * 100 + x] = 0;
        }
    }
    let dets = detect(&mask, std::slice::from_ref(&t), &DetectorParams::default());
    assert_eq!(dets.len(), 1);
    assert!(
        dets[0].score > 0.7 && dets[0].score < 0.9,
        "{}",
        dets[0].score
    );
    // the blob centroid moved up, the head did not
    assert!(dets[0].centroid_px[1] < 10.0 + 0.35 * 80.0);
    assert!((dets[0].head_px[1] - 10.0).abs() <= 2.0);
}

#[test]
fn two_people_give_two_detections() {
    let t = Silhouette::new(50.0, 0.0);
    let mut mask = Mask::new(160, 80);
    paint(&mut mask, &t, 20, 10);
    paint(&mut mask, &t, 100, 20);
    let dets = detect(&mask, std::slice::from_ref(&t), &DetectorParams::default());
    assert_eq!(dets.len(), 2, "{dets:?}");
}

/// The mask of a silhouette dilated by a square of radius `g`, pixel by pixel (the reference
/// for [`Silhouette::grown`]).
fn dilated_mask(t: &Silhouette, x: i64, y: i64, g: i64, w: u32, h: u32) -> Mask {
    let mut base = Mask::new(w, h);
    paint(&mut base, t, x, y);
    let mut out = Mask::new(w, h);
    for yy in 0..i64::from(h) {
        for xx in 0..i64::from(w) {
            let hit = (-g..=g).any(|dy| {
                (-g..=g).any(|dx| {
                    let (a, b) = (xx + dx, yy + dy);
                    a >= 0
                        && b >= 0
                        && a < i64::from(w)
                        && b < i64::from(h)
                        && base.get(a as u32, b as u32) != 0
                })
            });
            out.data[(yy * i64::from(w) + xx) as usize] = u8::from(hit);
        }
    }
    out
}

#[test]
fn a_grown_silhouette_is_the_pixelwise_dilation_and_reports_the_person() {
    let t = Silhouette::new(50.0, 0.2);
    let g = t.clone().grown(3);
    assert_eq!((g.width, g.height), (t.width + 6, t.height + 6));
    // painted at (20, 15), the grown one at (17, 12) covers exactly the dilated pixels
    let want = dilated_mask(&t, 20, 15, 3, 100, 90);
    let mut got = Mask::new(100, 90);
    paint(&mut got, &g, 17, 12);
    assert_eq!(got, want);
    assert_eq!(g.area as usize, want.count());
    // the person's box, head and width are the undilated silhouette's, 3 px inside
    assert_eq!(g.body, [3, 3, t.width + 3, t.height + 3]);
    assert_eq!(g.head, (t.head.0 + 3.0, t.head.1 + 3.0));
    assert_eq!(g.body_height_px(), t.body_height_px());
    assert_eq!(g.body_width_px, t.body_width_px);
    assert_eq!(t.clone().grown(0), t);
    // found on the dilated mask with a perfect score, reporting the person's own box (above
    // 0.9: a placement moved 19 px down the body still scores 0.72, and box suppression keeps it)
    let p = DetectorParams {
        stride_px: 1,
        threshold: 0.9,
        ..Default::default()
    };
    let dets = detect(&want, std::slice::from_ref(&g.clone().padded(0.5)), &p);
    assert_eq!(dets.len(), 1, "{dets:?}");
    assert!((dets[0].score - 1.0).abs() < 1e-12);
    assert_eq!(
        dets[0].bbox,
        [
            20.0,
            15.0,
            20.0 + f64::from(t.width),
            15.0 + f64::from(t.height)
        ]
    );
    assert!((dets[0].head_px[0] - (20.0 + t.head.0)).abs() < 1e-9);
    assert_eq!(dets[0].head_px[1], 15.0);
}

#[test]
fn the_probe_sees_what_the_detector_tried_and_splits_the_error() {
    let t = Silhouette::new(60.0, 0.0).padded(0.5);
    let small = Silhouette::new(30.0, 0.0).padded(0.5);
    let set = [small, t.clone()];
    let mut mask = Mask::new(160, 120);
    let tight = Silhouette::new(60.0, 0.0);
    paint(&mut mask, &tight, 50, 30);
    let head = [50.0 + tight.head.0, 30.0];
    let p = DetectorParams {
        stride_px: 1,
        ..Default::default()
    };
    let dets = detect(&mask, &set, &p);
    let probe = Probe::new(&mask, p.min_inside);
    let fit = probe
        .best_near(&set, None, head, 3.0, 1)
        .expect("a placement");
    // the best placement near the head is the detection
    assert_eq!(fit.template, 1);
    assert!((fit.score - 1.0).abs() < 1e-12);
    assert_eq!(fit.bbox, dets[0].bbox);
    // the same placement filled: nothing missing, nothing extra
    let f = probe.fill_at(&t, head, 0).expect("allowed");
    assert!((f.score - 1.0).abs() < 1e-12);
    assert_eq!(
        (f.inside, f.margin, f.missing, f.extra),
        (1.0, 0.0, 0.0, 0.0)
    );
    // the small template alone: its best score near the head is below 1, as in the detector
    let only_small = probe
        .best_near(&set[..1], None, head, 3.0, 1)
        .expect("a placement");
    assert!(only_small.score < 0.9, "{only_small:?}");
    // a band of foreground under the feet: extra margin pixels, all in the lower quarter
    for y in 91..96u32 {
        for x in 40..90u32 {
            mask.data[(y * 160 + x) as usize] = 1;
        }
    }
    let probe = Probe::new(&mask, p.min_inside);
    let f = probe.fill_at(&t, head, 0).expect("allowed");
    assert_eq!(f.missing, 0.0);
    assert!(f.extra > 0.0 && f.margin_low == 1.0, "{f:?}");
    assert!((f.score - (1.0 - f.extra)).abs() < 1e-12);
}

#[test]
fn head_suppression_keeps_two_people_whose_boxes_overlap_where_they_are() {
    // two people 60 px tall (14 px wide) side by side, heads 9 px apart (boxes at IoU 0.22):
    // box suppression at IoU 0.1 drops the second person's own placement and keeps a worse
    // one 10 px above their head; suppression over the score image in a window of half the
    // body (7 x 30 px) keeps both people at their heads and nothing else
    let t = Silhouette::new(60.0, 0.0);
    assert_eq!(t.body_width_px, 14.0);
    let mut mask = Mask::new(160, 100);
    paint(&mut mask, &t, 40, 20);
    paint(&mut mask, &t, 49, 20);
    let set = [t.clone()];
    let boxes = DetectorParams {
        stride_px: 1,
        threshold: 0.6,
        nms_iou: 0.1,
        ..Default::default()
    };
    let heads = DetectorParams {
        suppression: Suppression::Heads { radius: 0.5 },
        ..boxes
    };
    let (h0, h1) = ([40.0 + t.head.0, 20.0], [49.0 + t.head.0, 20.0]);
    let near = |d: &Detection, h: [f64; 2]| (d.head_px[0] - h[0]).hypot(d.head_px[1] - h[1]) < 1.0;
    let b = detect(&mask, &set, &boxes);
    assert!(b.iter().any(|d| near(d, h0)), "{b:?}");
    assert!(!b.iter().any(|d| near(d, h1)), "{b:?}");
    let h = detect(&mask, &set, &heads);
    assert_eq!(h.len(), 2, "{h:?}");
    assert!(near(&h[0], h0) || near(&h[0], h1), "{h:?}");
    assert!(near(&h[1], h0) || near(&h[1], h1), "{h:?}");
}

#[test]
fn a_widened_silhouette_scales_every_row_about_its_centre() {
    let t = Silhouette::new(80.0, 0.15);
    assert_eq!(t.clone().widened(1.0), t);
    let w = t.clone().widened(1.5);
    assert_eq!(w.height, t.height);
    // each row 1.5 times as wide (± rounding of both ends), centred where it was
    let off = t.head.0 - w.head.0;
    for (a, b) in t.spans.iter().zip(&w.spans) {
        let (wa, wb) = (f64::from(a.1 - a.0), f64::from(b.1 - b.0));
        assert!((wb - 1.5 * wa).abs() <= 1.0, "{a:?} {b:?}");
        let (ca, cb) = (0.5 * f64::from(a.0 + a.1), 0.5 * f64::from(b.0 + b.1) + off);
        assert!((ca - cb).abs() <= 0.5, "{a:?} {b:?}");
    }
    assert!((w.body_width_px - 1.5 * t.body_width_px).abs() <= 1.0);
    assert_eq!(w.body, [0, 0, w.width, w.height]);
    // a wide silhouette painted is found by its own template with a perfect score
    let mut mask = Mask::new(160, 120);
    paint(&mut mask, &w, 30, 20);
    let dets = detect(&mask, std::slice::from_ref(&w), &DetectorParams::default());
    assert!((dets[0].score - 1.0).abs() < 1e-12, "{dets:?}");
}

//! Error analysis of the paper's 2-D chain (issue 32): every missed person and every false
//! detection of the `detections_2d` scoring (the same one-to-one head matching, `truth`) gets
//! one cause, found while the frame's foreground mask is at hand.
//!
//! A **missed** person (visible box `g`, true head `h`, `w` = visible box width) is followed
//! through the chain in its order, and the first stage that lost them names the cause:
//! 1. `image border`: the true head is outside the image, or the person's own template cannot
//!    be placed with at least half of its window inside (the detector's border rule).
//! 2. A candidate was there — the detector's best placement with its head within the matching
//!    tolerance (`0.5 w` of `h`, [`Probe::best_near`]) scores above the threshold — but
//!    non-maximum suppression removed it for a better detection: that detection matched
//!    another person (`merged: a neighbour's detection took it`), or it lies on this person
//!    with its head beyond the tolerance (`mislocated`), or neither (`suppressed by a false
//!    detection`).
//! 3. No template the calibration allows at those head positions reaches the threshold, but
//!    another of the set does (`template choice`).
//! 4. None of the set does, but the person's own silhouette — the template of their true
//!    projected height and tilt (head top and ground point from the ground truth and the
//!    calibration), with the same window margin, placed at `h` (± 2 px) — does (`template
//!    set: no scale or tilt fits`).
//! 5. Not even their own silhouette reaches the threshold: the mask does not hold the
//!    person ([`Probe::fill_at`] splits the error into missing silhouette pixels and extra
//!    margin pixels). Missing pixels dominate: `desk occlusion` (visibility below
//!    `occluded_visibility` and no other person's box overlapping — the head-vs-centroid
//!    table's definition), `people occlusion` (visibility below it with another person
//!    overlapping), `standing, absorbed` (slower than [`STANDING_MPS`]) or `weak foreground`
//!    (a walking, visible person whose pixels stay under the MAD threshold). Extra pixels
//!    dominate: `merged with a neighbour` (another person's visible box reaches the window),
//!    `shadow` (at least half of the extra foreground in the window's lower quarter, where the
//!    floor shadow falls) or `extra foreground` (ghost, trail, clutter around them).
//!
//! A **false** detection (no person matched): on two or more people's visible boxes
//! (`merged: one box on several people`); on one person matched to another detection
//! (`split`); on one unmatched person (`mislocated`: the head beyond the tolerance); on no
//! person, with its ground point (the head ray at the nominal height) within
//! [`SHADOW_REACH_M`] of a person (`shadow`), or within [`GHOST_REACH_M`] of where a person
//! stood at some frame of the session (`ghost or trail`), or neither (`clutter`). "On" a box:
//! at least [`ON_PERSON`] of the detection's box inside it, or half of the person's box
//! inside the detection's.
//!
//! Each row also keeps the scores that tell "the threshold" apart: a miss whose best
//! candidate scores in the paper's range (≥ 0.6) would be found at the paper's lowest
//! threshold; a false detection under 0.75 would be rejected at its highest.
//!
//! What it does not do: no causes for the 3-D stage; the chain's output is not changed.

use std::collections::BTreeSet;

use nalgebra::{Point2, Point3};

use super::super::Params;
use super::boxes::{BoxHead, boxes_from_truth};
use super::truth::{DETECTION_HEAD_TOL, match_heads};
use crate::geometry::rect::{area, intersection};
use crate::geometry::triangulate::CalibratedView;
use crate::groundtruth::{PeopleFrame, PersonTruth};
use crate::pipelines::s004_mohedano_multicam::tables::Error2dRow;
use crate::track::graph_match::Box2d;
use crate::vision::gabor::Mask;
use crate::vision::template::{self, Detection, DetectorParams, Probe, Silhouette, TemplateMap};

/// A person slower than this (m/s) counts as standing.
pub(crate) const STANDING_MPS: f64 = 0.2;
/// A false detection whose ground point lies within this of a person (m) is on their floor
/// shadow (the synthetic shadow darkens the floor up to twice its 0.35–0.37 m radius).
pub(crate) const SHADOW_REACH_M: f64 = 0.75;
/// A false detection within this of where a person stood at some frame (m) is their ghost or
/// trail in the background.
pub(crate) const GHOST_REACH_M: f64 = 0.5;
/// A detection lies on a person when this fraction of its box is inside the person's box.
pub(crate) const ON_PERSON: f64 = 0.25;
/// The person's own template is moved this far (pixels, each way) around the true head.
const EXACT_SEARCH_PX: i64 = 2;
/// Share of the window margin's foreground in its lower quarter that makes it a shadow.
const SHADOW_LOW_SHARE: f64 = 0.5;
/// Cell of the visited-places grid (m).
const CELL_M: f64 = 0.1;

pub(crate) const MISS: &str = "miss";
pub(crate) const FALSE: &str = "false";

/// Where people stood over a whole session (cells of [`CELL_M`]).
#[derive(Debug, Default, Clone)]
pub(crate) struct Visited(BTreeSet<(i64, i64)>);

impl Visited {
    pub fn new<'a>(frames: impl IntoIterator<Item = &'a PeopleFrame>) -> Visited {
        let mut set = BTreeSet::new();
        for f in frames {
            for p in &f.people {
                set.insert(((p.x / CELL_M).floor() as i64, (p.y / CELL_M).floor() as i64));
            }
        }
        Visited(set)
    }

    /// Whether a person stood within `reach` of `(x, y)` (to the cell's resolution).
    pub fn near(&self, x: f64, y: f64, reach: f64) -> bool {
        let n = (reach / CELL_M).ceil() as i64 + 1;
        let (cx, cy) = ((x / CELL_M).floor() as i64, (y / CELL_M).floor() as i64);
        (cx - n..=cx + n).any(|i| {
            (cy - n..=cy + n).any(|j| {
                let (mx, my) = ((i as f64 + 0.5) * CELL_M, (j as f64 + 0.5) * CELL_M);
                (mx - x).hypot(my - y) <= reach + CELL_M * std::f64::consts::FRAC_1_SQRT_2
                    && self.0.contains(&(i, j))
            })
        })
    }
}

/// What one camera's chain needs at one frame to name its errors.
pub(crate) struct Context<'a> {
    pub frame: usize,
    pub gt: &'a PeopleFrame,
    pub visited: &'a Visited,
}

/// The camera's side: its view, templates and detector.
pub(crate) struct Chain<'a> {
    pub camera: &'a str,
    pub view: &'a CalibratedView,
    pub templates: &'a [Silhouette],
    pub map: Option<&'a TemplateMap>,
    pub detector: &'a DetectorParams,
    pub p: &'a Params,
}

/// One scored person of one camera.
struct Person<'a> {
    truth: &'a PersonTruth,
    b: Box2d,
    visibility: f64,
    head_inside: bool,
}

/// Every miss and false detection of one camera at one frame, with its cause.
pub(crate) fn classify(
    ch: &Chain,
    ctx: &Context,
    mask: &Mask,
    dets: &[Detection],
) -> Vec<Error2dRow> {
    let people = people(ch, ctx.gt, mask);
    let boxes: Vec<Box2d> = people.iter().map(|x| x.b).collect();
    let pairs = match_heads(&boxes, dets, DETECTION_HEAD_TOL);
    let (mut det_of, mut person_of) = (vec![None; people.len()], vec![None; dets.len()]);
    for &(i, j) in &pairs {
        det_of[i] = Some(j);
        person_of[j] = Some(i);
    }
    let probe = Probe::new(mask, ch.detector.min_inside);
    let mut out = Vec::new();
    for (i, person) in people.iter().enumerate() {
        if det_of[i].is_none() {
            let m = miss(ch, &probe, &people, i, dets, &person_of);
            out.push(row(ctx.frame, ch.camera, MISS, m, Some(person)));
        }
    }
    for (j, d) in dets.iter().enumerate() {
        if person_of[j].is_none() {
            let cause = false_cause(ch, ctx, &people, &det_of, d);
            let m = Measured {
                cause,
                det: d.score,
                ..Measured::default()
            };
            out.push(row(ctx.frame, ch.camera, FALSE, m, None));
        }
    }
    out
}

/// The scored people of the camera (the `detections_2d` set: visible boxes of at least
/// `MIN_BOX_HEIGHT_PX`, the true head point).
fn people<'a>(ch: &Chain, gt: &'a PeopleFrame, mask: &Mask) -> Vec<Person<'a>> {
    let (w, h) = (f64::from(mask.width), f64::from(mask.height));
    boxes_from_truth(gt, ch.camera, BoxHead::Truth)
        .into_iter()
        .filter_map(|(id, b)| {
            let truth = gt.people.iter().find(|p| p.id == id)?;
            let view = truth.cameras.iter().find(|v| v.camera == ch.camera)?;
            let head_inside = view
                .head_px
                .is_some_and(|q| q[0] >= 0.0 && q[1] >= 0.0 && q[0] < w && q[1] < h);
            Some(Person {
                truth,
                b,
                visibility: view.visibility,
                head_inside,
            })
        })
        .collect()
}

/// The cause of a miss and the scores that decided it.
#[derive(Debug, Clone, Copy)]
struct Measured {
    cause: &'static str,
    /// The person's own silhouette, the best of the whole set, the best the detector tried
    /// (near the head); the detection's score (false detections).
    exact: f64,
    any: f64,
    set: f64,
    det: f64,
}

impl Default for Measured {
    fn default() -> Self {
        Measured {
            cause: "",
            exact: f64::NAN,
            any: f64::NAN,
            set: f64::NAN,
            det: f64::NAN,
        }
    }
}

fn row(frame: usize, camera: &str, kind: &str, m: Measured, person: Option<&Person>) -> Error2dRow {
    Error2dRow {
        frame: frame as i64,
        camera: camera.to_string(),
        kind: kind.to_string(),
        cause: m.cause.to_string(),
        person: person.map_or(-1, |x| i64::from(x.truth.id)),
        visibility: person.map_or(f64::NAN, |x| x.visibility),
        speed_mps: person.map_or(f64::NAN, |x| x.truth.vx.hypot(x.truth.vy)),
        exact_score: m.exact,
        any_score: m.any,
        set_score: m.set,
        det_score: m.det,
    }
}

/// The template of the person's true projected height and tilt, and its window's box placed
/// at the true head.
fn own_template(ch: &Chain, person: &Person) -> Option<(Silhouette, [f64; 4])> {
    let head = person.b.head_px;
    let t = person.truth;
    let foot = ch.view.project(&Point3::new(t.x, t.y, 0.0))?;
    let (dx, dy) = (head[0] - foot.x, foot.y - head[1]);
    if dy <= 1.0 {
        return None;
    }
    let s = Silhouette::new(dx.hypot(dy), dx.atan2(dy))
        .widened(ch.p.template_width)
        .grown(ch.p.template_grow_px)
        .padded(ch.p.template_fill);
    let x0 = head[0] - s.head.0;
    let y0 = head[1] - s.head.1;
    let window = [x0, y0, x0 + f64::from(s.width), y0 + f64::from(s.height)];
    Some((s, window))
}

/// The first stage of the chain that lost person `i`.
fn miss(
    ch: &Chain,
    probe: &Probe,
    people: &[Person],
    i: usize,
    dets: &[Detection],
    person_of: &[Option<usize>],
) -> Measured {
    let person = &people[i];
    let thr = ch.detector.threshold;
    let radius = DETECTION_HEAD_TOL * person.b.width_px;
    let head = person.b.head_px;
    let stride = ch.detector.stride_px;
    let set = probe.best_near(ch.templates, ch.map, head, radius, stride);
    let any = probe.best_near(ch.templates, None, head, radius, stride);
    let own = own_template(ch, person);
    let exact = own
        .as_ref()
        .and_then(|(s, _)| probe.fill_at(s, head, EXACT_SEARCH_PX));
    let mut m = Measured {
        exact: exact.map_or(f64::NAN, |f| f.score),
        any: any.map_or(f64::NAN, |f| f.score),
        set: set.map_or(f64::NAN, |f| f.score),
        ..Measured::default()
    };
    m.cause = if !person.head_inside || (exact.is_none() && any.is_none()) {
        "image border"
    } else if let Some(c) = set.filter(|f| f.score >= thr) {
        let t = &ch.templates[c.template];
        let cand = Candidate {
            bbox: c.bbox,
            head_px: [
                c.bbox[0] - f64::from(t.body[0]) + t.head.0,
                c.bbox[1] - f64::from(t.body[1]) + t.head.1,
            ],
            t,
        };
        suppressed_by(ch, people, i, &cand, dets, person_of)
    } else if any.is_some_and(|f| f.score >= thr) {
        "template choice"
    } else if exact.is_some_and(|f| f.score >= thr) {
        "template set: no scale or tilt fits"
    } else if let (Some(f), Some((_, window))) = (exact, own) {
        let others = people
            .iter()
            .enumerate()
            .filter(|(k, _)| *k != i)
            .map(|(_, q)| q.b.bbox);
        segmentation(ch, person, &f, window, others)
    } else {
        "image border"
    };
    m
}

/// A candidate the detector tried: its box, head and template.
struct Candidate<'a> {
    bbox: [f64; 4],
    head_px: [f64; 2],
    t: &'a Silhouette,
}

/// Which detection suppressed candidate `cand` of person `i`.
fn suppressed_by(
    ch: &Chain,
    people: &[Person],
    i: usize,
    cand: &Candidate,
    dets: &[Detection],
    person_of: &[Option<usize>],
) -> &'static str {
    let by = dets
        .iter()
        .enumerate()
        .find(|(_, d)| template::suppresses(d, &cand.bbox, cand.head_px, cand.t, ch.detector));
    match by {
        Some((j, _)) if person_of[j].is_some_and(|k| k != i) => {
            "merged: a neighbour's detection took it"
        }
        Some((_, d)) if on(&d.bbox, &people[i].b.bbox) => "mislocated",
        Some(_) => "suppressed by a false detection",
        // a grid candidate the detector kept elsewhere (cannot happen: it would be a
        // detection); named rather than hidden
        None => "not suppressed",
    }
}

/// Why the mask does not hold the person's own silhouette.
fn segmentation(
    ch: &Chain,
    person: &Person,
    f: &template::Fill,
    window: [f64; 4],
    mut others: impl Iterator<Item = [f64; 4]>,
) -> &'static str {
    if f.missing >= f.extra {
        let overlapped = others.any(|o| intersection(&o, &person.b.bbox) > 0.0);
        if person.visibility < ch.p.occluded_visibility {
            if overlapped {
                "people occlusion"
            } else {
                "desk occlusion"
            }
        } else if person.truth.vx.hypot(person.truth.vy) < STANDING_MPS {
            "standing, absorbed"
        } else {
            "weak foreground"
        }
    } else if others.any(|o| intersection(&o, &window) > 0.0) {
        "merged with a neighbour"
    } else if f.margin_low >= SHADOW_LOW_SHARE {
        "shadow"
    } else {
        "extra foreground"
    }
}

/// Whether a detection's box `d` lies on a person's box `g`.
fn on(d: &[f64; 4], g: &[f64; 4]) -> bool {
    let inter = intersection(d, g);
    inter > 0.0 && (inter >= ON_PERSON * area(d) || inter >= 0.5 * area(g))
}

/// The cause of a false detection.
fn false_cause(
    ch: &Chain,
    ctx: &Context,
    people: &[Person],
    det_of: &[Option<usize>],
    d: &Detection,
) -> &'static str {
    let under: Vec<usize> = (0..people.len())
        .filter(|&k| on(&d.bbox, &people[k].b.bbox))
        .collect();
    match under.as_slice() {
        [] => {}
        [k] if det_of[*k].is_some() => return "split",
        [_] => return "mislocated",
        _ => return "merged: one box on several people",
    }
    let Some((x, y)) = ground_point(ch.view, d.head_px, ch.p.person_height_m) else {
        return "clutter";
    };
    if ctx
        .gt
        .people
        .iter()
        .any(|q| (q.x - x).hypot(q.y - y) <= SHADOW_REACH_M)
    {
        "shadow"
    } else if ctx.visited.near(x, y, GHOST_REACH_M) {
        "ghost or trail"
    } else {
        "clutter"
    }
}

/// Where the ray through a head pixel meets the plane at head height `z` (m).
fn ground_point(view: &CalibratedView, head: [f64; 2], z: f64) -> Option<(f64, f64)> {
    let (o, d) = view.ray_in_world(&Point2::new(head[0], head[1]))?;
    if d.z.abs() < 1e-9 {
        return None;
    }
    let t = (z - o.z) / d.z;
    (t > 0.0).then(|| (o.x + d.x * t, o.y + d.y * t))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::groundtruth::CameraView;
    use crate::vision::template::detect_with;

    fn view() -> CalibratedView {
        use crate::geometry::camera::{CameraModel, Pinhole};
        CalibratedView::new(
            CameraModel::Pinhole(Pinhole::from_fov(352, 288, 78.0)),
            crate::geometry::look_at(Point3::new(0.15, 0.15, 2.85), Point3::new(4.0, 4.25, 0.7)),
        )
    }

    /// A walking person of 1.75 m at (3, 3.5) painted into the mask as their own silhouette
    /// (no dilation); their ground truth in camera `cam_0`.
    fn scene(view: &CalibratedView) -> (Mask, PeopleFrame, Silhouette, [f64; 2]) {
        let (x, y) = (3.0, 3.5);
        let head = view.project(&Point3::new(x, y, 1.75)).expect("head");
        let foot = view.project(&Point3::new(x, y, 0.0)).expect("foot");
        let (dx, dy) = (head.x - foot.x, foot.y - head.y);
        let s = Silhouette::new(dx.hypot(dy), dx.atan2(dy));
        let (x0, y0) = ((head.x - s.head.0).round() as i64, head.y.round() as i64);
        let mut mask = Mask::new(352, 288);
        for (r, &(a, b)) in s.spans.iter().enumerate() {
            for xx in x0 + i64::from(a)..x0 + i64::from(b) {
                mask.data[((y0 + r as i64) * 352 + xx) as usize] = 1;
            }
        }
        let bbox = [
            x0 as f64,
            y0 as f64,
            (x0 + i64::from(s.width)) as f64,
            (y0 + i64::from(s.height)) as f64,
        ];
        let head_px = [x0 as f64 + s.head.0, y0 as f64];
        let person = PersonTruth {
            id: 7,
            x,
            y,
            vx: 1.0,
            vy: 0.0,
            height: 1.75,
            head_z: 1.63,
            radius: 0.2,
            legs: [[x, y]; 2],
            leg_radius: 0.06,
            cameras: vec![CameraView {
                camera: "cam_0".into(),
                bbox: Some(bbox),
                head_px: Some(head_px),
                visibility: 1.0,
            }],
        };
        let gt = PeopleFrame {
            stamp_ns: 0,
            people: vec![person],
        };
        (mask, gt, s, head_px)
    }

    fn fake(head: [f64; 2], bbox: [f64; 4]) -> Detection {
        Detection {
            bbox,
            head_px: head,
            centroid_px: head,
            width_px: bbox[2] - bbox[0],
            height_px: bbox[3] - bbox[1],
            score: 0.72,
            template: 0,
        }
    }

    #[test]
    fn misses_and_false_detections_get_the_cause_of_the_stage_that_made_them() {
        let view = view();
        let (mask, gt, s, head) = scene(&view);
        // the mask holds the silhouette undilated and at the profile's width: so does the
        // person's own template
        let p = Params {
            template_grow_px: 0,
            template_width: 1.0,
            ..Params::default()
        };
        let det = DetectorParams {
            threshold: p.template_threshold,
            ..DetectorParams::default()
        };
        // somewhere nobody stands, and somewhere a person stood at another frame
        let at = |x: f64, y: f64| {
            let q = view.project(&Point3::new(x, y, 1.75)).expect("in view");
            [q.x, q.y]
        };
        let (far, trail) = (at(6.5, 1.0), at(1.0, 6.5));
        let (tx, ty) = ground_point(&view, trail, p.person_height_m).expect("on the floor");
        let elsewhere = PeopleFrame {
            stamp_ns: 1,
            people: vec![PersonTruth {
                x: tx,
                y: ty,
                ..gt.people[0].clone()
            }],
        };
        let visited = Visited::new([&gt, &elsewhere]);
        let ctx = Context {
            frame: 3,
            gt: &gt,
            visited: &visited,
        };
        // the person's own template finds them: no error
        let own = [s.clone().padded(p.template_fill)];
        let chain = |templates| Chain {
            camera: "cam_0",
            view: &view,
            templates,
            map: None,
            detector: &det,
            p: &p,
        };
        let own = &own[..];
        let dets = detect_with(&mask, own, None, &det);
        assert_eq!(dets.len(), 1, "{dets:?}");
        assert!(classify(&chain(own), &ctx, &mask, &dets).is_empty());
        // plus a box on the matched person, one where nobody ever stood, one on a trail
        let b = gt.people[0].cameras[0].bbox.expect("box");
        let on_body = fake(
            [head[0], b[1] + 0.3 * (b[3] - b[1])],
            [b[0], b[1] + 0.3 * (b[3] - b[1]), b[2], b[3]],
        );
        let nobody = fake(far, [far[0] - 5.0, far[1], far[0] + 5.0, far[1] + 30.0]);
        let on_trail = fake(
            trail,
            [trail[0] - 5.0, trail[1], trail[0] + 5.0, trail[1] + 30.0],
        );
        let all = [dets[0], on_body, nobody, on_trail];
        let rows = classify(&chain(own), &ctx, &mask, &all);
        let causes: Vec<(&str, &str, f64)> = rows
            .iter()
            .map(|r| (r.kind.as_str(), r.cause.as_str(), r.det_score))
            .collect();
        assert_eq!(
            causes,
            [
                (FALSE, "split", 0.72),
                (FALSE, "clutter", 0.72),
                (FALSE, "ghost or trail", 0.72)
            ]
        );
        assert!(rows.iter().all(|r| r.frame == 3 && r.person == -1));
        // a set of half-height templates: the person's own silhouette fits, none of the set
        let small = [Silhouette::new(0.5 * s.body_height_px(), s.tilt_rad).padded(p.template_fill)];
        let small = &small[..];
        let dets = detect_with(&mask, small, None, &det);
        let rows = classify(&chain(small), &ctx, &mask, &dets);
        let misses: Vec<&Error2dRow> = rows.iter().filter(|r| r.kind == MISS).collect();
        assert_eq!(misses.len(), 1, "{rows:?}");
        let m = misses[0];
        assert_eq!(m.cause, "template set: no scale or tilt fits");
        assert_eq!((m.person, m.visibility, m.speed_mps), (7, 1.0, 1.0));
        // (not exactly 1: the own template is rebuilt from the ground truth's projected head and
        // feet, a fraction of a pixel from the painted one; measured 0.980)
        assert!(
            m.exact_score > 0.95 && m.exact_score > det.threshold,
            "{m:?}"
        );
        assert!(
            m.any_score < det.threshold && m.set_score == m.any_score,
            "{m:?}"
        );
        // an empty mask: not even the person's own silhouette fits, pixels are missing and
        // the person walks in plain view
        let empty = Mask::new(352, 288);
        let rows = classify(&chain(own), &ctx, &empty, &[]);
        assert_eq!(rows.len(), 1);
        assert_eq!(rows[0].cause, "weak foreground");
    }

    #[test]
    fn visited_places_are_found_within_the_reach_and_not_beyond() {
        let f = PeopleFrame {
            stamp_ns: 0,
            people: vec![],
        };
        let mut v = Visited::new([&f]);
        assert!(!v.near(1.0, 1.0, 0.5));
        v.0.insert((20, 30)); // the cell [2.0, 2.1) x [3.0, 3.1)
        assert!(v.near(2.05, 3.05, 0.1));
        assert!(v.near(2.5, 3.05, 0.5));
        assert!(!v.near(2.9, 3.05, 0.5));
        assert!(!v.near(2.05, 4.0, 0.5));
    }

    #[test]
    fn a_detection_is_on_a_box_by_a_quarter_of_itself_or_half_of_the_person() {
        let g = [0.0, 0.0, 10.0, 40.0];
        // a quarter of a 10x10 box inside
        assert!(on(&[5.0, 35.0, 15.0, 45.0], &g));
        assert!(!on(&[6.0, 36.0, 16.0, 46.0], &g));
        // a large box holding the whole person
        assert!(on(&[-50.0, -50.0, 60.0, 90.0], &g));
        assert!(!on(&[20.0, 0.0, 30.0, 40.0], &g));
    }
}

//! Per-view measurements of a person for the cylinder tracker: the head pixel of an image box
//! and the cylinder radius of eq. 6–7.

use nalgebra::{Point2, Point3};

use crate::geometry::triangulate::CalibratedView;

/// The head pixel of a person's image box (our addition; the paper's templates give the head
/// directly): the point of the box's top row on the image of the vertical line through the
/// person. That line is found by casting the ray through the box centre to the height
/// `centre_height_m` (about half a person's height; the result barely depends on it) and
/// projecting the vertical through that ground point, with the lens distortion.
///
/// Why not the top centre of the box: away from the image centre of a wide, tilted corner
/// camera a standing person's image leans, so the box's horizontal centre lies between the
/// head and the feet — on `multicam_office` the top centre is 6.7 px (0.21 box widths) from
/// the projected head top of fully visible people, about 0.12 m on the ground. Falls back to
/// the top centre when the line does not cross the top row (`None` only for a box without a
/// ray).
pub fn box_head_px(
    view: &CalibratedView,
    bbox: [f64; 4],
    centre_height_m: f64,
) -> Option<[f64; 2]> {
    let top_centre = [(bbox[0] + bbox[2]) / 2.0, bbox[1]];
    // a box cut by the left or right image border is not centred on the person
    let (w, _) = view.model.size();
    if bbox[0] <= 1.0 || bbox[2] >= f64::from(w) - 1.0 {
        return Some(top_centre);
    }
    let centre = Point2::new(top_centre[0], (bbox[1] + bbox[3]) / 2.0);
    let (o, d) = view.ray_in_world(&centre)?;
    if d.z.abs() < 1e-9 {
        return Some(top_centre);
    }
    let t = (centre_height_m - o.z) / d.z;
    if t <= 0.0 {
        return Some(top_centre);
    }
    let g = o + d * t;
    // image row of the vertical at height z; rows decrease upwards for a camera above the
    // point, so bracket the top row between the centre height and the camera height
    let at = |z: f64| view.project(&Point3::new(g.x, g.y, z));
    let row = |z: f64| at(z).map(|p| p.y - bbox[1]);
    let (mut lo, mut hi) = (centre_height_m, (o.z - 0.05).max(centre_height_m));
    match (row(lo), row(hi)) {
        (Some(a), Some(b)) if a >= 0.0 && b <= 0.0 => {}
        _ => return Some(top_centre),
    }
    for _ in 0..50 {
        let mid = 0.5 * (lo + hi);
        match row(mid) {
            Some(r) if r > 0.0 => lo = mid,
            Some(_) => hi = mid,
            None => return Some(top_centre),
        }
    }
    at(0.5 * (lo + hi)).map(|p| [p.x, p.y])
}

/// The cylinder radius of eq. 6–7 from a triangulated head and its supporting 2-D objects
/// `(view, raw head pixel, box width in pixels)`.
pub fn cylinder_radius(head_m: &Point3<f64>, support: &[(&CalibratedView, [f64; 2], f64)]) -> f64 {
    if support.is_empty() {
        return f64::NAN;
    }
    let mut sum = 0.0;
    for (view, head_px, width_px) in support {
        let (beta, principal) = view.focal_and_principal();
        let ideal = view
            .ideal_px(&Point2::new(head_px[0], head_px[1]))
            .unwrap_or(Point2::new(head_px[0], head_px[1]));
        let d = (ideal - principal).norm() / beta;
        let alpha = d.atan();
        let dist = (view.center() - head_m).norm();
        sum += 0.5 * (width_px / beta) * alpha.cos().powi(2) * dist;
    }
    sum / support.len() as f64
}

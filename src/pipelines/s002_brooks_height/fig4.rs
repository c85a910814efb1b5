//! Fig. 4 of seed 002: one frame in the paper's four panels, composed in the session stage
//! (where the images are) and cached as a PNG: upper left the camera image with red crosshairs
//! at the laser + camera filter's head-top estimate before this frame and the blue box of this
//! frame's detection; upper right the motion mask; lower left the skin mask; lower right the
//! laser scan from above (map frame) with the red 3σ ellipse of the estimate. Drawing with
//! imageproc's line and circle primitives.

use base64::Engine;
use image::{Rgb, RgbImage};
use imageproc::drawing::{draw_filled_circle_mut, draw_line_segment_mut};
use nalgebra::{Isometry3, Point3};

use super::camera::{self, Frame};
use super::fusion::{self, Method, Sensors};
use super::params::Params;
use super::tables::{CameraObsRow, Fig4Row, LaserObsRow};
use crate::frames::laser::{self as laser_frames, LaserOptions};
use crate::geometry::camera::CameraModel;
use crate::laser::points::{self, ScanGeometry};
use crate::log::SessionLog;
use crate::track::height_ekf::Motion;
use crate::vision::jabri::{JabriBackground, Planes};

const RED: Rgb<u8> = Rgb([230, 30, 30]);
const BLUE: Rgb<u8> = Rgb([40, 80, 255]);

fn rect(img: &mut RgbImage, r: [f32; 4], c: Rgb<u8>) {
    let [x0, y0, x1, y1] = r;
    for (a, b) in [
        ((x0, y0), (x1, y0)),
        ((x1, y0), (x1, y1)),
        ((x1, y1), (x0, y1)),
        ((x0, y1), (x0, y0)),
    ] {
        draw_line_segment_mut(img, a, b, c);
    }
}

fn mask_image(mask: &[u8], w: u32, h: u32) -> RgbImage {
    RgbImage::from_fn(w, h, |x, y| {
        let v = mask.get((y * w + x) as usize).copied().unwrap_or(0);
        Rgb([v, v, v])
    })
}

/// The 3σ ellipse of a 2×2 covariance around `(x, y)` as a closed polyline.
pub fn ellipse(x: f64, y: f64, c: [[f64; 2]; 2], k: f64) -> Vec<(f64, f64)> {
    let (a, b, d) = (c[0][0], c[0][1], c[1][1]);
    let tr = (a + d) / 2.0;
    let det = (a * d - b * b).max(0.0);
    let disc = (tr * tr - det).max(0.0).sqrt();
    let (l1, l2) = (tr + disc, (tr - disc).max(0.0));
    let theta = 0.5 * (2.0 * b).atan2(a - d);
    let (s, co) = theta.sin_cos();
    (0..=48)
        .map(|i| {
            let t = std::f64::consts::TAU * f64::from(i) / 48.0;
            let (u, v) = (k * l1.sqrt() * t.cos(), k * l2.sqrt() * t.sin());
            (x + co * u - s * v, y + s * u + co * v)
        })
        .collect()
}

/// The laser panel: scan returns and the 3σ ellipse, `room` scaled into `w × h`.
fn laser_panel(
    p: &Params,
    scan: &[(f64, f64)],
    est: Option<&fusion::Estimate>,
    w: u32,
    h: u32,
) -> RgbImage {
    let mut img = RgbImage::from_pixel(w, h, Rgb([255, 255, 255]));
    let [x0, y0, x1, y1] = p.room_m;
    let s = (f64::from(w) / (x1 - x0)).min(f64::from(h) / (y1 - y0));
    let px = |x: f64, y: f64| (((x - x0) * s) as f32, (f64::from(h) - (y - y0) * s) as f32);
    rect(
        &mut img,
        [
            px(x0, y1).0,
            px(x0, y1).1,
            px(x1, y0).0 - 1.0,
            px(x1, y0).1 - 1.0,
        ],
        Rgb([0, 0, 0]),
    );
    for &(x, y) in scan {
        let (u, v) = px(x, y);
        draw_filled_circle_mut(&mut img, (u as i32, v as i32), 1, Rgb([60, 60, 60]));
    }
    if let Some(e) = est {
        let pts = ellipse(e.x, e.y, e.pos_cov, 3.0);
        for pair in pts.windows(2) {
            draw_line_segment_mut(
                &mut img,
                px(pair[0].0, pair[0].1),
                px(pair[1].0, pair[1].1),
                RED,
            );
        }
    }
    img
}

/// Scan returns (map frame) of the scan nearest `stamp_ns`.
fn scan_near(log: &SessionLog, p: &Params, stamp_ns: i64) -> anyhow::Result<Vec<(f64, f64)>> {
    let options = LaserOptions {
        fixed_frame: Some("map".into()),
        ..LaserOptions::default()
    };
    let mut best: Option<(i64, Vec<(f64, f64)>)> = None;
    for f in laser_frames::scans(log, &p.scan_topic, &options)? {
        let f = f?;
        let Some(pose) = f.pose else { continue };
        let d = (i64::try_from(f.stamp.0).unwrap_or(i64::MAX) - stamp_ns).abs();
        if best.as_ref().is_none_or(|b| d < b.0) {
            let g = ScanGeometry::of(&f.scan);
            let pts = points::project(&f.scan.ranges, &g, Some(&pose));
            best = Some((d, pts.iter().map(|q| (q.fixed.x, q.fixed.y)).collect()));
        }
    }
    Ok(best.map(|b| b.1).unwrap_or_default())
}

/// Compose fig. 4 for the detection nearest the middle of the session (none without one).
pub fn compose(
    log: &SessionLog,
    p: &Params,
    frames: &[Frame],
    laser: &[LaserObsRow],
    obs: &[CameraObsRow],
    model: &CameraModel,
    world_from_camera: &Isometry3<f64>,
) -> anyhow::Result<Vec<Fig4Row>> {
    let mid = frames.len() as i64 / 2;
    let Some(o) = obs
        .iter()
        .min_by_key(|o| ((o.frame_idx - mid).abs(), o.frame_idx))
    else {
        return Ok(Vec::new());
    };
    let k = usize::try_from(o.frame_idx).unwrap_or(0);
    let Some(frame) = frames.get(k) else {
        return Ok(Vec::new());
    };
    // the filter's estimate from everything before this frame
    let before_l: Vec<LaserObsRow> = laser
        .iter()
        .filter(|r| r.stamp_ns < o.stamp_ns)
        .cloned()
        .collect();
    let before_c: Vec<CameraObsRow> = obs
        .iter()
        .filter(|r| r.stamp_ns < o.stamp_ns)
        .cloned()
        .collect();
    let m = Method {
        name: "laser+camera",
        sensors: Sensors::Fused,
        motion: Motion::ConstantPosition,
        walk: false,
    };
    let run = fusion::run(&before_l, &before_c, p, m);
    let est = run.last().copied();
    // motion mask of this frame: the tracking planes run again up to it
    let mut bg = JabriBackground::new(
        Planes {
            colour: p.colour,
            edges: p.edges,
        },
        p.jabri(),
    );
    let mut motion = Vec::new();
    for f in &frames[..=k] {
        (motion, _) = camera::detect(&mut bg, p, f)?;
    }
    let (w, h) = frame.rgb.dimensions();
    let mut img = frame.rgb.clone();
    rect(
        &mut img,
        [o.x0 as f32, o.y0 as f32, o.x1 as f32, o.y1 as f32],
        BLUE,
    );
    if let Some(e) = est {
        let q = world_from_camera.inverse() * Point3::new(e.x, e.y, e.h);
        if let Some(px) = model.project(&q) {
            let (u, v) = (px.x as f32, px.y as f32);
            draw_line_segment_mut(&mut img, (u - 8.0, v), (u + 8.0, v), RED);
            draw_line_segment_mut(&mut img, (u, v - 8.0), (u, v + 8.0), RED);
        }
    }
    let scan = scan_near(log, p, o.stamp_ns)?;
    let mut out = RgbImage::new(2 * w, 2 * h);
    image::imageops::replace(&mut out, &img, 0, 0);
    image::imageops::replace(&mut out, &mask_image(&motion, w, h), i64::from(w), 0);
    image::imageops::replace(&mut out, &mask_image(&frame.skin, w, h), 0, i64::from(h));
    image::imageops::replace(
        &mut out,
        &laser_panel(p, &scan, est.as_ref(), w, h),
        i64::from(w),
        i64::from(h),
    );
    let mut png = Vec::new();
    out.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)?;
    Ok(vec![Fig4Row {
        frame_idx: o.frame_idx,
        stamp_ns: o.stamp_ns,
        png_base64: base64::engine::general_purpose::STANDARD.encode(&png),
    }])
}

/// The cached PNG back as an image.
pub fn decode(row: &Fig4Row) -> Option<RgbImage> {
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(&row.png_base64)
        .ok()?;
    image::load_from_memory(&bytes).ok().map(|i| i.to_rgb8())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_3_sigma_ellipse_of_a_diagonal_covariance_has_its_axes_on_x_and_y() {
        // σx = 2, σy = 1 around (1, 1): 3σ extremes at x = 1 ± 6, y = 1 ± 3
        let pts = ellipse(1.0, 1.0, [[4.0, 0.0], [0.0, 1.0]], 3.0);
        let max_x = pts.iter().map(|p| p.0).fold(f64::MIN, f64::max);
        let min_y = pts.iter().map(|p| p.1).fold(f64::MAX, f64::min);
        assert!(
            (max_x - 7.0).abs() < 1e-9 && (min_y + 2.0).abs() < 1e-9,
            "{max_x} {min_y}"
        );
        // a correlated covariance: every point at Mahalanobis distance 3
        let c = [[2.0, 0.8], [0.8, 1.0]];
        let det = c[0][0] * c[1][1] - c[0][1] * c[0][1];
        for (x, y) in ellipse(0.0, 0.0, c, 3.0) {
            let d2 = (c[1][1] * x * x - 2.0 * c[0][1] * x * y + c[0][0] * y * y) / det;
            assert!((d2 - 9.0).abs() < 1e-9, "{d2}");
        }
    }
}

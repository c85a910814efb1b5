//! Seed 001 §IV, first step of Method 1: the raw paracatadioptric image seen as a ring of
//! perspective images. View `k` looks along azimuth `θ_k = k · 360°/n` (n = 8: axes 45° apart)
//! at elevation `e` (both in the omni camera frame), with the same horizontal field of view
//! for every view (60° by default, so that neighbours overlap by 15°, 7.5° on each side of the
//! bisector) and square pixels. A view pixel is a ray (pinhole model with the view's rotation),
//! the ray is an omni pixel ([`Paracatadioptric::project`]), and the view image samples the omni
//! image there bilinearly. An omni pixel belongs to the view whose axis is nearest in azimuth
//! (the "perspective image it projects onto").
//!
//! Orientation: the view frame follows ROS optical conventions (x right, y down, z along the
//! axis) with "up" the camera frame's +z (the mirror axis). On the synthetic `segway_park`
//! robot the omnicam is mounted turned over (roll 180°), so its +z points at the ground and the
//! views come out upside down and mirrored; a bilinear map is blind to that, so nothing else
//! changes. The mirror ring `r_min..r_max` of that camera (28..238 px, f = 130 px) holds camera
//! elevations from +65.7° (r_min) down to −32.7° (r_max), i.e. world elevations −65.7°..+32.7°
//! because the frame is turned over; views at elevation 0 with 60° × 46.8° (160 × 120 px) cover
//! ±23.4° and lie inside the ring, so the default elevation is 0 (horizontal axes). View pixels
//! whose ray misses the ring have no value (`NaN`).
//!
//! Pixel positions follow [`crate::geometry::camera`]: pixel `(i, j)` covers `[i, i+1) ×
//! [j, j+1)`, its centre is `(i + 0.5, j + 0.5)`.

use image::GrayImage;
use nalgebra::{Point2, Point3, Rotation3, Vector3};

use super::EgomotionError;
use crate::geometry::camera::{Paracatadioptric, Pinhole};

/// How the ring of perspective views is laid out.
#[derive(Debug, Clone, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct ViewParams {
    /// Number of views, axes equally spaced in azimuth (paper: 45° apart, so 8).
    pub count: usize,
    /// Horizontal field of view of each view (degrees).
    pub hfov_deg: f64,
    pub width: u32,
    pub height: u32,
    /// Elevation of the view axes in the omni camera frame (degrees).
    pub elevation_deg: f64,
}

impl Default for ViewParams {
    fn default() -> Self {
        Self {
            count: 8,
            hfov_deg: 60.0,
            width: 160,
            height: 120,
            elevation_deg: 0.0,
        }
    }
}

/// One perspective view: its axis, intrinsics and rotation.
#[derive(Debug, Clone, PartialEq)]
pub struct PerspectiveView {
    /// Azimuth of the axis in the omni camera frame (rad).
    pub azimuth: f64,
    /// Elevation of the axis in the omni camera frame (rad).
    pub elevation: f64,
    /// Ideal pinhole (no distortion), principal point at the image centre.
    pub pinhole: Pinhole,
    /// Rotates omni-camera-frame vectors into the view's optical frame.
    pub view_from_camera: Rotation3<f64>,
}

impl PerspectiveView {
    fn new(azimuth: f64, elevation: f64, p: &ViewParams) -> PerspectiveView {
        let (se, ce) = elevation.sin_cos();
        let (sa, ca) = azimuth.sin_cos();
        let forward = Vector3::new(ce * ca, ce * sa, se);
        let up = Vector3::z();
        let right = forward.cross(&up).normalize();
        let down = forward.cross(&right);
        let view_from_camera = Rotation3::from_matrix_unchecked(nalgebra::Matrix3::from_rows(&[
            right.transpose(),
            down.transpose(),
            forward.transpose(),
        ]));
        PerspectiveView {
            azimuth,
            elevation,
            pinhole: Pinhole::from_fov(p.width, p.height, p.hfov_deg),
            view_from_camera,
        }
    }

    /// Where a direction (omni camera frame) lands in this view's image plane; `None` behind
    /// the view. The position may lie outside the image.
    pub fn project(&self, dir_in_camera: &Vector3<f64>) -> Option<Point2<f64>> {
        let v = self.view_from_camera * dir_in_camera;
        self.pinhole.project(&Point3::from(v))
    }

    /// The unit ray (omni camera frame) through a view pixel position.
    pub fn ray(&self, px: &Point2<f64>) -> Vector3<f64> {
        self.view_from_camera.inverse() * self.pinhole.ray(px).dir
    }

    /// True when a position lies inside the view image.
    pub fn contains(&self, px: &Point2<f64>) -> bool {
        px.x >= 0.0
            && px.y >= 0.0
            && px.x < f64::from(self.pinhole.width)
            && px.y < f64::from(self.pinhole.height)
    }
}

/// A single-channel `f32` image; `NaN` marks pixels without a value.
#[derive(Debug, Clone, PartialEq)]
pub struct Plane {
    pub width: usize,
    pub height: usize,
    pub v: Vec<f32>,
}

impl Plane {
    pub fn new(width: usize, height: usize, fill: f32) -> Plane {
        Plane {
            width,
            height,
            v: vec![fill; width * height],
        }
    }

    pub fn at(&self, x: usize, y: usize) -> f32 {
        self.v[y * self.width + x]
    }

    /// Bilinear value at a continuous position (pixel centres at `i + 0.5`); `NaN` outside the
    /// image's centres or where a neighbour has no value.
    pub fn sample(&self, x: f64, y: f64) -> f32 {
        bilinear(&self.v, self.width, self.height, x, y, f32::NAN, |v| v)
    }
}

/// Bilinear sample of a row-major buffer at a continuous position (pixel centres at `i + 0.5`),
/// `outside` beyond the outermost centres.
fn bilinear<T: Copy>(
    buf: &[T],
    w: usize,
    h: usize,
    x: f64,
    y: f64,
    outside: f32,
    to_f32: impl Fn(T) -> f32,
) -> f32 {
    let (xs, ys) = (x - 0.5, y - 0.5);
    if !(xs >= 0.0 && ys >= 0.0 && xs <= (w as f64 - 1.0) && ys <= (h as f64 - 1.0)) {
        return outside;
    }
    let (x0, y0) = (xs.floor() as usize, ys.floor() as usize);
    let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
    let (fx, fy) = ((xs - x0 as f64) as f32, (ys - y0 as f64) as f32);
    let at = |xx: usize, yy: usize| to_f32(buf[yy * w + xx]);
    let top = at(x0, y0) * (1.0 - fx) + at(x1, y0) * fx;
    let bottom = at(x0, y1) * (1.0 - fx) + at(x1, y1) * fx;
    top * (1.0 - fy) + bottom * fy
}

/// The ring of views over one omni camera, with each view pixel's omni position precomputed.
#[derive(Debug, Clone)]
pub struct Views {
    omni: Paracatadioptric,
    views: Vec<PerspectiveView>,
    /// Per view, per pixel (row-major): the omni position of its centre, `None` off the mirror.
    lookup: Vec<Vec<Option<[f64; 2]>>>,
}

/// Wrap an angle into `(−π, π]`.
pub fn wrap_angle(a: f64) -> f64 {
    let t = a.rem_euclid(std::f64::consts::TAU);
    if t > std::f64::consts::PI {
        t - std::f64::consts::TAU
    } else {
        t
    }
}

impl Views {
    pub fn new(omni: &Paracatadioptric, p: &ViewParams) -> Result<Views, EgomotionError> {
        let bad = |why: &str| EgomotionError::BadParams(format!("views: {why}"));
        if p.count == 0 || p.width == 0 || p.height == 0 {
            return Err(bad("count, width and height must be positive"));
        }
        if !(p.hfov_deg > 0.0 && p.hfov_deg < 170.0) {
            return Err(bad("hfov_deg must be in (0, 170)"));
        }
        if p.elevation_deg.is_nan() || p.elevation_deg.abs() >= 80.0 {
            return Err(bad("elevation_deg must be in (-80, 80)"));
        }
        let step = std::f64::consts::TAU / p.count as f64;
        let views: Vec<PerspectiveView> = (0..p.count)
            .map(|k| {
                PerspectiveView::new(wrap_angle(k as f64 * step), p.elevation_deg.to_radians(), p)
            })
            .collect();
        let lookup = views
            .iter()
            .map(|v| {
                let (w, h) = (v.pinhole.width, v.pinhole.height);
                (0..h)
                    .flat_map(|j| (0..w).map(move |i| (i, j)))
                    .map(|(i, j)| {
                        let ray = v.ray(&Point2::new(f64::from(i) + 0.5, f64::from(j) + 0.5));
                        omni.project(&Point3::from(ray)).map(|q| [q.x, q.y])
                    })
                    .collect()
            })
            .collect();
        Ok(Views {
            omni: omni.clone(),
            views,
            lookup,
        })
    }

    pub fn views(&self) -> &[PerspectiveView] {
        &self.views
    }

    pub fn len(&self) -> usize {
        self.views.len()
    }

    pub fn is_empty(&self) -> bool {
        self.views.is_empty()
    }

    pub fn omni(&self) -> &Paracatadioptric {
        &self.omni
    }

    /// Index of the view whose axis is nearest in azimuth to `azimuth` (rad).
    pub fn nearest_view(&self, azimuth: f64) -> usize {
        let step = std::f64::consts::TAU / self.views.len() as f64;
        ((azimuth.rem_euclid(std::f64::consts::TAU) / step).round() as usize) % self.views.len()
    }

    /// The view a direction (omni camera frame) projects onto — the one nearest in azimuth —
    /// and its position there; `None` when it falls outside that view's image.
    pub fn ray_to_view(&self, dir: &Vector3<f64>) -> Option<(usize, Point2<f64>)> {
        let k = self.nearest_view(dir.y.atan2(dir.x));
        let px = self.views[k].project(dir)?;
        self.views[k].contains(&px).then_some((k, px))
    }

    /// Omni pixel position → (view, view position); `None` off the mirror or outside the view.
    pub fn omni_to_view(&self, px: &Point2<f64>) -> Option<(usize, Point2<f64>)> {
        let ray = self.omni.ray(px)?;
        self.ray_to_view(&ray.dir)
    }

    /// View position → omni pixel position; `None` when the ray misses the mirror ring.
    pub fn view_to_omni(&self, view: usize, px: &Point2<f64>) -> Option<Point2<f64>> {
        let ray = self.views.get(view)?.ray(px);
        self.omni.project(&Point3::from(ray))
    }

    /// The views of one grey omni image, written into `out` (resized to the views).
    pub fn render(&self, omni_grey: &GrayImage, out: &mut Vec<Plane>) {
        let (w, h) = (omni_grey.width() as usize, omni_grey.height() as usize);
        let raw = omni_grey.as_raw();
        out.resize_with(self.views.len(), || Plane::new(0, 0, f32::NAN));
        for ((view, lut), plane) in self.views.iter().zip(&self.lookup).zip(out.iter_mut()) {
            let (vw, vh) = (view.pinhole.width as usize, view.pinhole.height as usize);
            if plane.width != vw || plane.height != vh {
                *plane = Plane::new(vw, vh, f32::NAN);
            }
            for (dst, src) in plane.v.iter_mut().zip(lut) {
                *dst = match src {
                    Some([x, y]) => bilinear(raw, w, h, *x, *y, f32::NAN, f32::from),
                    None => f32::NAN,
                };
            }
        }
    }
}

#[cfg(test)]
pub(crate) mod tests;

//! Per-pixel ray casting of the world for any [`CameraModel`] (each pixel is a ray), in
//! parallel over rows and deterministic whatever the thread count.
//!
//! Speed comes from two things. Every primitive's bounding sphere is projected once per frame
//! to a conservative screen rectangle and binned into 16×16-pixel tiles, so a pixel tests only
//! the primitives that can cover it (planes, walls and other large shapes are tested
//! everywhere). And a camera fixed in the world renders its static scene once: per pixel the
//! nearest static hit, its world point and its light-independent radiance are cached, so a
//! frame only tests moving things and re-applies the current light level and shadows.
//!
//! Shading: albedo × (ambient + diffuse) × light level × floor shadow, emissive screens
//! unshaded, sky for misses outdoors; then a display gamma of 1/2.2 and Gaussian sensor noise
//! (σ in 8-bit units) from a hash of (session, camera, frame, pixel).

use nalgebra::{Isometry3, Point2, Point3, Vector3};
use rayon::prelude::*;

use super::person::shadow_factor;
use super::shapes::Shape;
use super::world::{Primitive, World, sky};
use crate::geometry::camera::{CameraModel, Ray};
use crate::rng;

const TILE: usize = 16;
/// Primitives larger than this (m) are tested at every pixel rather than binned.
const ALWAYS_RADIUS: f64 = 4.0;

/// Cached static scene of a fixed camera.
struct StaticCache {
    origin: Vec<Point3<f32>>,
    dir: Vec<Vector3<f32>>,
    t: Vec<f32>,
    /// Radiance before light level and shadows.
    radiance: Vec<[f32; 3]>,
    point: Vec<Point3<f32>>,
    floor: Vec<bool>,
    emissive: Vec<bool>,
}

/// A camera ready to render.
pub struct Camera {
    pub name: String,
    pub model: CameraModel,
    pub noise: f32,
    /// Rays in the camera frame (`None` outside the model's field, e.g. off the mirror).
    rays: Vec<Option<Ray>>,
    cache: Option<StaticCache>,
    index: u64,
}

/// One rendered frame.
pub struct Frame {
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<u8>,
    /// Object id of the nearest surface per pixel (0: static background or nothing).
    pub ids: Vec<u32>,
    /// Ground-truth skin per pixel: the nearest surface is a person's skin (face, neck, hands).
    pub skin: Vec<bool>,
}

/// What changes per frame.
pub struct FrameInput<'a> {
    pub world: &'a World,
    /// Moving background and people at this instant.
    pub dynamic: &'a [Primitive],
    /// People's floor shadows `[x, y, r]`.
    pub shadows: &'a [[f64; 3]],
    pub t: f64,
    /// `world_from_camera` at this instant.
    pub pose: Isometry3<f64>,
    /// Noise key (session seed, frame number).
    pub noise_key: u64,
}

#[derive(Debug, Clone, Copy)]
enum Bounds {
    Skip,
    Full,
    Rect(usize, usize, usize, usize),
}

/// Unit directions for sampling a bounding sphere's outline.
fn sphere_dirs() -> Vec<Vector3<f64>> {
    let mut v = Vec::new();
    for x in [-1.0, 0.0, 1.0] {
        for y in [-1.0, 0.0, 1.0] {
            for z in [-1.0, 0.0, 1.0] {
                let d = Vector3::new(x, y, z);
                if d.norm() > 0.0 {
                    v.push(d.normalize());
                }
            }
        }
    }
    v
}

fn screen_bounds(
    model: &CameraModel,
    cam_from_world: &Isometry3<f64>,
    c: &Point3<f64>,
    r: f64,
    dirs: &[Vector3<f64>],
) -> Bounds {
    if r >= ALWAYS_RADIUS || !r.is_finite() {
        return Bounds::Full;
    }
    let cc = cam_from_world * c;
    if cc.coords.norm() < 1.5 * r + 0.3 {
        return Bounds::Full;
    }
    let (w, h) = model.size();
    let (mut x0, mut y0, mut x1, mut y1) = (
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    );
    let mut any = false;
    for p in std::iter::once(cc).chain(dirs.iter().map(|d| cc + d * r)) {
        if let Some(px) = model.project(&p) {
            any = true;
            x0 = x0.min(px.x);
            y0 = y0.min(px.y);
            x1 = x1.max(px.x);
            y1 = y1.max(px.y);
        }
    }
    if !any {
        return Bounds::Skip;
    }
    let m = 2.0 + 0.15 * (x1 - x0).max(y1 - y0);
    let (x0, y0, x1, y1) = (x0 - m, y0 - m, x1 + m, y1 + m);
    if x1 < 0.0 || y1 < 0.0 || x0 >= f64::from(w) || y0 >= f64::from(h) {
        return Bounds::Skip;
    }
    let cl = |v: f64, hi: u32| (v.max(0.0) as usize).min(hi as usize - 1);
    Bounds::Rect(cl(x0, w), cl(y0, h), cl(x1, w), cl(y1, h))
}

/// Tile lists: for each tile, indices of primitives that may cover it; plus the always-list.
struct Tiles {
    cols: usize,
    lists: Vec<Vec<u32>>,
    always: Vec<u32>,
}

impl Tiles {
    fn build(
        model: &CameraModel,
        cam_from_world: &Isometry3<f64>,
        prims: &[Primitive],
        dirs: &[Vector3<f64>],
    ) -> Tiles {
        let (w, h) = model.size();
        let cols = (w as usize).div_ceil(TILE);
        let rows = (h as usize).div_ceil(TILE);
        let mut lists = vec![Vec::new(); cols * rows];
        let mut always = Vec::new();
        for (k, p) in prims.iter().enumerate() {
            match screen_bounds(model, cam_from_world, &p.center, p.radius, dirs) {
                Bounds::Skip => {}
                Bounds::Full => always.push(k as u32),
                Bounds::Rect(x0, y0, x1, y1) => {
                    for ty in y0 / TILE..=y1 / TILE {
                        for tx in x0 / TILE..=x1 / TILE {
                            lists[ty * cols + tx].push(k as u32);
                        }
                    }
                }
            }
        }
        Tiles {
            cols,
            lists,
            always,
        }
    }

    fn at(&self, x: usize, y: usize) -> impl Iterator<Item = u32> + '_ {
        self.always
            .iter()
            .chain(&self.lists[(y / TILE) * self.cols + x / TILE])
            .copied()
    }
}

/// Nearest hit among `prims` (indices from `candidates`) below `t_max`.
fn nearest<'a>(
    prims: &'a [Primitive],
    candidates: impl Iterator<Item = u32>,
    o: &Point3<f64>,
    d: &Vector3<f64>,
    t_max: f64,
) -> Option<(f64, Vector3<f64>, &'a Primitive)> {
    let mut best: Option<(f64, Vector3<f64>, &Primitive)> = None;
    let mut limit = t_max;
    for k in candidates {
        let p = &prims[k as usize];
        // bounding-sphere rejection
        if p.radius.is_finite() {
            let oc = p.center - o;
            let along = oc.dot(d);
            if along < -p.radius
                || oc.norm_squared() - along * along > p.radius * p.radius
                || along - p.radius > limit
            {
                continue;
            }
        }
        if let Some(hit) = p.shape.intersect(o, d, 1e-4, limit) {
            limit = hit.t;
            best = Some((hit.t, hit.normal, p));
        }
    }
    best
}

/// Display radiance of a surface hit (before gamma and noise).
fn shade(
    world: &World,
    t: f64,
    p: &Point3<f64>,
    n: &Vector3<f64>,
    prim: &Primitive,
    shadows: &[[f64; 3]],
) -> [f32; 3] {
    let uv = prim.shape.rect_uv(p);
    let a = prim.material.albedo_at(p, uv);
    if prim.material.emissive {
        return [a[0] * 1.3, a[1] * 1.3, a[2] * 1.3];
    }
    let mut k = world.lighting.shade(n) * world.lighting.level(t, p);
    if matches!(prim.shape, Shape::Plane { up: true, .. }) {
        k *= shadow_factor(p.x, p.y, shadows);
    }
    [a[0] * k, a[1] * k, a[2] * k]
}

/// Linear radiance → 8-bit with display gamma and noise.
#[inline]
fn encode(lin: f32, noise: f32) -> u8 {
    let v = lin.max(0.0).powf(1.0 / 2.2) * 255.0 + noise;
    v.round().clamp(0.0, 255.0) as u8
}

impl Camera {
    /// A camera; `fixed` is its world pose if it never moves (enables the static cache).
    pub fn new(
        name: &str,
        model: CameraModel,
        noise: f64,
        fixed: Option<(Isometry3<f64>, &World)>,
        index: u64,
    ) -> Camera {
        let (w, h) = model.size();
        let rays: Vec<Option<Ray>> = (0..h as usize * w as usize)
            .map(|i| {
                let (x, y) = (i % w as usize, i / w as usize);
                model.ray(&Point2::new(x as f64 + 0.5, y as f64 + 0.5))
            })
            .collect();
        let mut cam = Camera {
            name: name.to_string(),
            model,
            noise: noise as f32,
            rays,
            cache: None,
            index,
        };
        if let Some((pose, world)) = fixed {
            cam.cache = Some(cam.build_cache(&pose, world));
        }
        cam
    }

    pub fn size(&self) -> (u32, u32) {
        self.model.size()
    }

    fn build_cache(&self, pose: &Isometry3<f64>, world: &World) -> StaticCache {
        let (w, _) = self.model.size();
        let dirs = sphere_dirs();
        let tiles = Tiles::build(&self.model, &pose.inverse(), &world.statics, &dirs);
        let n = self.rays.len();
        let per_pixel: Vec<_> = (0..n)
            .into_par_iter()
            .map(|i| {
                let (x, y) = (i % w as usize, i / w as usize);
                let Some(ray) = self.rays[i] else {
                    return (
                        Point3::origin(),
                        Vector3::zeros(),
                        f32::NAN,
                        [0.0; 3],
                        Point3::origin(),
                        false,
                        false,
                    );
                };
                let o = pose * ray.origin;
                let d = pose * ray.dir;
                match nearest(&world.statics, tiles.at(x, y), &o, &d, f64::INFINITY) {
                    Some((t, nrm, prim)) => {
                        let p = o + d * t;
                        let uv = prim.shape.rect_uv(&p);
                        let a = prim.material.albedo_at(&p, uv);
                        let k = if prim.material.emissive {
                            1.3
                        } else {
                            world.lighting.shade(&nrm)
                        };
                        (
                            o.cast(),
                            d.cast(),
                            t as f32,
                            [a[0] * k, a[1] * k, a[2] * k],
                            p.cast(),
                            matches!(prim.shape, Shape::Plane { up: true, .. }),
                            prim.material.emissive,
                        )
                    }
                    None => {
                        let s = if world.outdoor { sky(&d) } else { [0.0; 3] };
                        (
                            o.cast(),
                            d.cast(),
                            f32::INFINITY,
                            s,
                            Point3::origin(),
                            false,
                            true,
                        )
                    }
                }
            })
            .collect();
        let mut c = StaticCache {
            origin: Vec::with_capacity(n),
            dir: Vec::with_capacity(n),
            t: Vec::with_capacity(n),
            radiance: Vec::with_capacity(n),
            point: Vec::with_capacity(n),
            floor: Vec::with_capacity(n),
            emissive: Vec::with_capacity(n),
        };
        for (o, d, t, r, p, f, e) in per_pixel {
            c.origin.push(o);
            c.dir.push(d);
            c.t.push(t);
            c.radiance.push(r);
            c.point.push(p);
            c.floor.push(f);
            c.emissive.push(e);
        }
        c
    }

    /// Render one frame.
    pub fn render(&self, input: &FrameInput) -> Frame {
        let (w, h) = self.model.size();
        let (wu, hu) = (w as usize, h as usize);
        let cam_from_world = input.pose.inverse();
        let dirs = sphere_dirs();
        let dyn_tiles = Tiles::build(&self.model, &cam_from_world, input.dynamic, &dirs);
        let static_tiles = self
            .cache
            .is_none()
            .then(|| Tiles::build(&self.model, &cam_from_world, &input.world.statics, &dirs));
        let key = rng::hash(input.noise_key, &[self.index]);
        let mut rgb = vec![0u8; wu * hu * 3];
        let mut ids = vec![0u32; wu * hu];
        let mut skin = vec![false; wu * hu];
        rgb.par_chunks_mut(wu * 3)
            .zip(ids.par_chunks_mut(wu))
            .zip(skin.par_chunks_mut(wu))
            .enumerate()
            .for_each(|(y, ((row, id_row), skin_row))| {
                for x in 0..wu {
                    let i = y * wu + x;
                    let (o, d, static_t) = match &self.cache {
                        Some(c) => {
                            if c.t[i].is_nan() {
                                continue; // outside the mirror: black
                            }
                            (
                                c.origin[i].cast::<f64>(),
                                c.dir[i].cast::<f64>(),
                                f64::from(c.t[i]),
                            )
                        }
                        None => {
                            let Some(ray) = self.rays[i] else { continue };
                            (input.pose * ray.origin, input.pose * ray.dir, f64::INFINITY)
                        }
                    };
                    let mut lin;
                    let mut id = 0u32;
                    let mut t_best = static_t;
                    // static layer
                    match (&self.cache, &static_tiles) {
                        (Some(c), _) => {
                            let r = c.radiance[i];
                            let k = if c.emissive[i] {
                                1.0
                            } else {
                                let p = c.point[i].cast::<f64>();
                                let mut k = input.world.lighting.level(input.t, &p);
                                if c.floor[i] {
                                    k *= shadow_factor(p.x, p.y, input.shadows);
                                }
                                k
                            };
                            lin = [r[0] * k, r[1] * k, r[2] * k];
                        }
                        (None, Some(tiles)) => match nearest(
                            &input.world.statics,
                            tiles.at(x, y),
                            &o,
                            &d,
                            f64::INFINITY,
                        ) {
                            Some((t, n, prim)) => {
                                t_best = t;
                                lin = shade(
                                    input.world,
                                    input.t,
                                    &(o + d * t),
                                    &n,
                                    prim,
                                    input.shadows,
                                );
                            }
                            None => {
                                lin = if input.world.outdoor {
                                    sky(&d)
                                } else {
                                    [0.0; 3]
                                }
                            }
                        },
                        (None, None) => unreachable!("static tiles exist without a cache"),
                    }
                    if let Some((t, n, prim)) =
                        nearest(input.dynamic, dyn_tiles.at(x, y), &o, &d, t_best)
                    {
                        let p = o + d * t;
                        lin = shade(input.world, input.t, &p, &n, prim, input.shadows);
                        id = prim.object;
                        skin_row[x] = prim.skin_below.is_some_and(|z| p.z < z);
                    }
                    id_row[x] = id;
                    for (c, v) in lin.iter().enumerate() {
                        let noise = if self.noise > 0.0 {
                            self.noise * rng::gauss(rng::hash(key, &[i as u64, c as u64]))
                        } else {
                            0.0
                        };
                        row[3 * x + c] = encode(*v, noise);
                    }
                }
            });
        Frame {
            width: w,
            height: h,
            rgb,
            ids,
            skin,
        }
    }

    /// Pixels a set of primitives would cover if nothing hid them (for visibility fractions).
    pub fn unoccluded_pixels(&self, pose: &Isometry3<f64>, prims: &[Primitive]) -> u64 {
        if prims.is_empty() {
            return 0;
        }
        let (w, h) = self.model.size();
        let cam_from_world = pose.inverse();
        let dirs = sphere_dirs();
        // union of the primitives' screen rectangles
        let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
        for p in prims {
            match screen_bounds(&self.model, &cam_from_world, &p.center, p.radius, &dirs) {
                Bounds::Skip => {}
                Bounds::Full => {
                    (x0, y0, x1, y1) = (0, 0, w as usize - 1, h as usize - 1);
                }
                Bounds::Rect(a, b, c, d) => {
                    x0 = x0.min(a);
                    y0 = y0.min(b);
                    x1 = x1.max(c);
                    y1 = y1.max(d);
                }
            }
        }
        if x0 > x1 || y0 > y1 {
            return 0;
        }
        let all: Vec<u32> = (0..prims.len() as u32).collect();
        (y0..=y1)
            .into_par_iter()
            .map(|y| {
                (x0..=x1)
                    .filter(|x| {
                        let i = y * w as usize + x;
                        self.rays[i].is_some_and(|ray| {
                            let (o, d) = (pose * ray.origin, pose * ray.dir);
                            nearest(prims, all.iter().copied(), &o, &d, f64::INFINITY).is_some()
                        })
                    })
                    .count() as u64
            })
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::camera::Pinhole;
    use crate::geometry::look_at;
    use crate::synth::world::{Lighting, Material};

    fn empty_world() -> World {
        World {
            statics: vec![Primitive::new(
                Shape::Plane { z: 0.0, up: true },
                Material::flat([128, 128, 128]),
                0,
            )],
            moving: Vec::new(),
            obstacles: Vec::new(),
            lighting: Lighting {
                spec: crate::synth::scenario::Light::default(),
                sun: Vector3::z(),
                outdoor: true,
            },
            doors: Vec::new(),
            size: [10.0, 10.0],
            outdoor: true,
        }
    }

    /// A small sphere at a known point is painted exactly where each camera model projects it.
    #[test]
    fn a_sphere_lands_on_its_projected_pixel() {
        use crate::geometry::camera::{ConicalMirror, Paracatadioptric};
        use nalgebra::{Translation3, UnitQuaternion};
        let world = empty_world();
        let down = |z: f64| {
            Isometry3::from_parts(
                Translation3::new(0.0, 0.0, z),
                UnitQuaternion::from_euler_angles(std::f64::consts::PI, 0.0, 0.0),
            )
        };
        let cases = [
            (
                CameraModel::Pinhole(Pinhole {
                    dist: [-0.2, 0.05, 0.0, 0.0, 0.0],
                    ..Pinhole::from_fov(160, 120, 70.0)
                }),
                look_at(Point3::new(0.0, 0.0, 2.0), Point3::new(4.0, 1.0, 0.5)),
                Point3::new(4.3, 1.6, 0.9),
            ),
            (
                CameraModel::Paracatadioptric(Paracatadioptric {
                    width: 160,
                    height: 160,
                    xc: 80.0,
                    yc: 80.0,
                    f: 36.0,
                    r_min: 6.0,
                    r_max: 78.0,
                }),
                down(1.2),
                Point3::new(2.0, 1.0, 0.4),
            ),
            (
                CameraModel::ConicalMirror(ConicalMirror {
                    width: 160,
                    height: 160,
                    xc: 80.0,
                    yc: 80.0,
                    f: 50.0,
                    d: 0.05,
                    alpha: 77.5f64.to_radians(),
                    z_top: 0.076,
                }),
                Isometry3::translation(0.0, 0.0, 1.7),
                Point3::new(2.0, -1.0, 0.6),
            ),
        ];
        for (model, pose, target) in cases {
            let (w, _) = model.size();
            let ball = Primitive::new(
                Shape::Ellipsoid {
                    center: target,
                    radii: Vector3::new(0.05, 0.05, 0.05),
                    yaw: 0.0,
                },
                Material::flat([255, 0, 0]),
                1007,
            );
            for fixed in [false, true] {
                let cam = Camera::new("c", model.clone(), 0.0, fixed.then_some((pose, &world)), 0);
                let f = cam.render(&FrameInput {
                    world: &world,
                    dynamic: std::slice::from_ref(&ball),
                    shadows: &[],
                    t: 0.0,
                    pose,
                    noise_key: 1,
                });
                let px = model.project(&(pose.inverse() * target)).expect("visible");
                let hits: Vec<(usize, usize)> = f
                    .ids
                    .iter()
                    .enumerate()
                    .filter(|(_, id)| **id == 1007)
                    .map(|(i, _)| (i % w as usize, i / w as usize))
                    .collect();
                assert!(!hits.is_empty(), "{model:?}: sphere not painted");
                let (mx, my) = hits.iter().fold((0.0, 0.0), |a, h| {
                    (a.0 + h.0 as f64 + 0.5, a.1 + h.1 as f64 + 0.5)
                });
                let (mx, my) = (mx / hits.len() as f64, my / hits.len() as f64);
                assert!(
                    (mx - px.x).abs() < 0.75 && (my - px.y).abs() < 0.75,
                    "{model:?}: centroid ({mx}, {my}) vs projection {px}"
                );
                let i = hits[hits.len() / 2];
                let k = 3 * (i.1 * w as usize + i.0);
                assert!(f.rgb[k] > 150 && f.rgb[k + 1] < 30, "red");
            }
        }
    }
}

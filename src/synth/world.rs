//! The static world and moving background of a scenario: floors, walls, ceilings, desks,
//! trees, bushes, doors, monitors with rolling bars, swaying plants and passing traffic, with
//! their materials (procedural textures, evaluated at the hit point so every sensor sees the
//! same surface) and the lighting (level drifting and switching over time, different per place).

use nalgebra::{Point3, Vector3};
use rand::RngExt;

use super::scenario::{
    DynamicSpec, Light, Rgb, Scenario, TextureSpec, World as WorldSpec, WorldKind,
};
use super::shapes::Shape;
use crate::rng;

mod clutter;
mod scatter;

/// Object ids: 0 is static background, 1..PERSON_BASE moving background, PERSON_BASE + id a person.
pub const PERSON_BASE: u32 = 1000;

/// Surface appearance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Texture {
    Flat,
    Tiles {
        size: f32,
        contrast: f32,
    },
    Noise {
        scale: f32,
        amp: f32,
    },
    /// Above height `z` the surface has the `above` albedo (hair on a head).
    Split {
        z: f32,
        above: [f32; 3],
    },
    /// A monitor: rolling horizontal bars, phase in [0, 1).
    Screen {
        phase: f32,
    },
    /// A head with a face looking toward `yaw` ([`super::face`]); the albedo is the skin.
    Face {
        center: [f32; 3],
        yaw: f32,
        hair: [f32; 3],
        style: &'static super::face::FaceStyle,
    },
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Linear albedo.
    pub albedo: [f32; 3],
    pub texture: Texture,
    /// Emits light (screens): shading is not applied.
    pub emissive: bool,
}

/// sRGB byte colour to linear albedo.
pub fn linear(c: Rgb) -> [f32; 3] {
    let f = |v: u8| (f32::from(v) / 255.0).powf(2.2);
    [f(c[0]), f(c[1]), f(c[2])]
}

impl Material {
    pub fn flat(c: Rgb) -> Material {
        Material {
            albedo: linear(c),
            texture: Texture::Flat,
            emissive: false,
        }
    }

    pub fn textured(c: Rgb, t: TextureSpec) -> Material {
        let texture = match t {
            TextureSpec::Flat => Texture::Flat,
            TextureSpec::Tiles { size, contrast } => Texture::Tiles {
                size: size as f32,
                contrast: contrast as f32,
            },
            TextureSpec::Noise { scale, amp } => Texture::Noise {
                scale: scale as f32,
                amp: amp as f32,
            },
        };
        Material {
            albedo: linear(c),
            texture,
            emissive: false,
        }
    }

    /// Albedo at a world point (`uv` for screens).
    pub fn albedo_at(&self, p: &Point3<f64>, uv: Option<(f64, f64)>) -> [f32; 3] {
        let scale = |k: f32| [self.albedo[0] * k, self.albedo[1] * k, self.albedo[2] * k];
        match self.texture {
            Texture::Flat => self.albedo,
            Texture::Tiles { size, contrast } => {
                let (i, j) = (
                    (p.x as f32 / size).floor() as i64,
                    (p.y as f32 / size).floor() as i64,
                );
                let grout = {
                    let (fx, fy) = (
                        (p.x as f32 / size).fract().abs(),
                        (p.y as f32 / size).fract().abs(),
                    );
                    fx < 0.03 || fy < 0.03
                };
                let k = if grout {
                    0.6
                } else if (i + j) % 2 == 0 {
                    1.0
                } else {
                    1.0 - contrast
                };
                let grain = 1.0 + 0.06 * value_noise(p, 0.35);
                scale(k * grain)
            }
            Texture::Noise { scale: s, amp } => scale(1.0 + amp * value_noise(p, f64::from(s))),
            Texture::Split { z, above } => {
                if p.z as f32 > z {
                    above
                } else {
                    self.albedo
                }
            }
            Texture::Face {
                center,
                yaw,
                hair,
                style,
            } => super::face::albedo(
                [p.x, p.y, p.z],
                center.map(f64::from),
                f64::from(yaw),
                self.albedo,
                hair,
                style,
            ),
            Texture::Screen { phase } => {
                let v = uv.map_or(0.0, |(_, v)| v) as f32;
                let bars = 0.5 + 0.5 * (std::f32::consts::TAU * (v * 1.5 + phase)).sin();
                scale(0.45 + 0.55 * bars)
            }
        }
    }
}

/// Smooth value noise in [−1, 1] at spatial scale `scale` m (trilinear, hashed lattice).
pub fn value_noise(p: &Point3<f64>, scale: f64) -> f32 {
    let q = p.coords / scale;
    let (x0, y0, z0) = (q.x.floor(), q.y.floor(), q.z.floor());
    let (fx, fy, fz) = (q.x - x0, q.y - y0, q.z - z0);
    let s = |t: f64| t * t * (3.0 - 2.0 * t);
    let (sx, sy, sz) = (s(fx), s(fy), s(fz));
    let h = |dx: i64, dy: i64, dz: i64| {
        let k = rng::hash(
            0x5eed,
            &[
                (x0 as i64 + dx) as u64,
                (y0 as i64 + dy) as u64,
                (z0 as i64 + dz) as u64,
            ],
        );
        f64::from(rng::unit(k)) * 2.0 - 1.0
    };
    let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
    let x00 = lerp(h(0, 0, 0), h(1, 0, 0), sx);
    let x10 = lerp(h(0, 1, 0), h(1, 1, 0), sx);
    let x01 = lerp(h(0, 0, 1), h(1, 0, 1), sx);
    let x11 = lerp(h(0, 1, 1), h(1, 1, 1), sx);
    lerp(lerp(x00, x10, sy), lerp(x01, x11, sy), sz) as f32
}

/// Something to intersect: a shape with its material and object id.
#[derive(Debug, Clone, PartialEq)]
pub struct Primitive {
    pub shape: Shape,
    pub material: Material,
    pub object: u32,
    pub center: Point3<f64>,
    pub radius: f64,
    /// Ground-truth skin: hits on this primitive below this height (m) are skin pixels in the
    /// optional skin mask (`None`: never skin). Changes no rendered colour.
    pub skin_below: Option<f64>,
}

impl Primitive {
    pub fn new(shape: Shape, material: Material, object: u32) -> Primitive {
        let (center, radius) = shape.bounds();
        Primitive {
            shape,
            material,
            object,
            center,
            radius,
            skin_below: None,
        }
    }

    /// The same primitive, its hits below `z` (m) marked as skin in the ground-truth skin mask.
    pub fn skin_below(mut self, z: f64) -> Primitive {
        self.skin_below = Some(z);
        self
    }
}

/// Light at a time and place.
#[derive(Debug, Clone)]
pub struct Lighting {
    pub spec: Light,
    /// Direction *towards* the main light.
    pub sun: Vector3<f64>,
    pub outdoor: bool,
}

impl Lighting {
    /// Level at time `t` (s) at a world point.
    pub fn level(&self, t: f64, p: &Point3<f64>) -> f32 {
        let l = &self.spec;
        let mut level = l.level;
        for [at, new] in &l.switches {
            if t >= *at {
                level = *new;
            }
        }
        if l.drift != 0.0 {
            level *= 1.0 + l.drift * (std::f64::consts::TAU * t / l.drift_period_s).sin();
        }
        // places: blend towards each place's level near it
        for pl in &l.places {
            let d = ((p.x - pl.at[0]).powi(2) + (p.y - pl.at[1]).powi(2)).sqrt();
            let w = ((pl.radius + 1.0 - d) / 2.0).clamp(0.0, 1.0);
            level = level * (1.0 - w) + pl.level * w;
        }
        level as f32
    }

    /// Lambertian factor for a normal (ambient + directional).
    pub fn shade(&self, n: &Vector3<f64>) -> f32 {
        let a = self.spec.ambient as f32;
        a + (1.0 - a) * (n.dot(&self.sun).max(0.0) as f32)
    }
}

/// A footprint that blocks walking, for motion planning and top views: a disc (tree trunk,
/// bush; `hx = hy = r`, `round`) or a rectangle turned by `yaw` (desk, cupboard).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Obstacle {
    pub x: f64,
    pub y: f64,
    pub hx: f64,
    pub hy: f64,
    pub yaw: f64,
    pub round: bool,
}

impl Obstacle {
    pub fn disc(x: f64, y: f64, r: f64) -> Obstacle {
        Obstacle {
            x,
            y,
            hx: r,
            hy: r,
            yaw: 0.0,
            round: true,
        }
    }

    /// An upright ellipse: semi-axis `a` along `yaw`, `b` across it.
    pub fn ellipse(x: f64, y: f64, a: f64, b: f64, yaw: f64) -> Obstacle {
        Obstacle {
            x,
            y,
            hx: a,
            hy: b,
            yaw,
            round: true,
        }
    }

    /// Distance from a point to the footprint (negative inside). Exact for discs and boxes; for
    /// an ellipse, the distance to its outline along the ray from its centre (no shorter than
    /// the true distance outside, equal on the axes).
    pub fn distance(&self, px: f64, py: f64) -> f64 {
        let (dx, dy) = (px - self.x, py - self.y);
        if self.round && self.hx == self.hy {
            return dx.hypot(dy) - self.hx;
        }
        let (s, c) = self.yaw.sin_cos();
        let (ux, uy) = (c * dx + s * dy, -s * dx + c * dy);
        if self.round {
            let n = ux.hypot(uy);
            let k = (ux / self.hx).hypot(uy / self.hy);
            return if k > 0.0 {
                n * (1.0 - 1.0 / k)
            } else {
                -self.hx.min(self.hy)
            };
        }
        let (lx, ly) = (ux.abs() - self.hx, uy.abs() - self.hy);
        let outside = lx.max(0.0).hypot(ly.max(0.0));
        outside + lx.max(ly).min(0.0)
    }

    /// Outline for drawing.
    pub fn outline(&self) -> Vec<(f64, f64)> {
        let (s, c) = self.yaw.sin_cos();
        let at = |lx: f64, ly: f64| (self.x + c * lx - s * ly, self.y + s * lx + c * ly);
        if self.round {
            return (0..16)
                .map(|k| {
                    let a = k as f64 / 16.0 * std::f64::consts::TAU;
                    at(self.hx * a.cos(), self.hy * a.sin())
                })
                .collect();
        }
        [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)]
            .iter()
            .map(|(ex, ey)| at(ex * self.hx, ey * self.hy))
            .collect()
    }
}

/// Moving background, evaluated per frame.
#[derive(Debug, Clone)]
pub enum Moving {
    Monitor {
        rect: Shape,
        color: Rgb,
        period_s: f64,
    },
    Plant {
        base: [f64; 2],
        height: f64,
        radius: f64,
        color: Rgb,
        sway_m: f64,
        period_s: f64,
    },
    Traffic {
        y: f64,
        x_range: [f64; 2],
        speed: f64,
        every_s: f64,
        size: [f64; 3],
        colors: Vec<Rgb>,
    },
}

/// The world of one session.
#[derive(Debug, Clone)]
pub struct World {
    pub statics: Vec<Primitive>,
    pub moving: Vec<Moving>,
    pub obstacles: Vec<Obstacle>,
    pub lighting: Lighting,
    pub doors: Vec<[f64; 2]>,
    pub size: [f64; 2],
    pub outdoor: bool,
}

/// Sky colour for rays that hit nothing (outdoor): brighter towards the horizon.
pub fn sky(dir: &Vector3<f64>) -> [f32; 3] {
    let e = dir.z.clamp(0.0, 1.0) as f32;
    [0.55 - 0.25 * e, 0.68 - 0.2 * e, 0.9 - 0.05 * e]
}

/// Ceiling, the four walls and the doors of a room, after the floor.
fn push_room(w: &WorldSpec, statics: &mut Vec<Primitive>) {
    let (sx, sy, h) = (w.size[0], w.size[1], w.wall_height);
    let wall = w
        .walls
        .clone()
        .map_or(Material::flat([200, 200, 195]), |s| {
            Material::textured(s.color, s.texture)
        });
    statics.push(Primitive::new(
        Shape::Plane { z: h, up: false },
        Material::flat([235, 235, 230]),
        0,
    ));
    let t = 0.1;
    for (center, half) in [
        (
            Point3::new(-t, sy / 2.0, h / 2.0),
            Vector3::new(t, sy / 2.0 + 2.0 * t, h / 2.0),
        ),
        (
            Point3::new(sx + t, sy / 2.0, h / 2.0),
            Vector3::new(t, sy / 2.0 + 2.0 * t, h / 2.0),
        ),
        (
            Point3::new(sx / 2.0, -t, h / 2.0),
            Vector3::new(sx / 2.0 + 2.0 * t, t, h / 2.0),
        ),
        (
            Point3::new(sx / 2.0, sy + t, h / 2.0),
            Vector3::new(sx / 2.0 + 2.0 * t, t, h / 2.0),
        ),
    ] {
        statics.push(Primitive::new(
            Shape::Box {
                center,
                half,
                yaw: 0.0,
            },
            wall,
            0,
        ));
    }
    // doors: dark rectangles on the nearest wall, facing into the room
    for d in &w.doors {
        let [x, y] = d.at;
        let hw = d.width / 2.0;
        let dist = [x, sx - x, y, sy - y];
        let k = (0..4)
            .min_by(|a, b| dist[*a].total_cmp(&dist[*b]))
            .unwrap_or(0);
        let (center, u) = match k {
            0 => (Point3::new(0.005, y, 1.0), Vector3::new(0.0, -hw, 0.0)),
            1 => (Point3::new(sx - 0.005, y, 1.0), Vector3::new(0.0, hw, 0.0)),
            2 => (Point3::new(x, 0.005, 1.0), Vector3::new(hw, 0.0, 0.0)),
            _ => (Point3::new(x, sy - 0.005, 1.0), Vector3::new(-hw, 0.0, 0.0)),
        };
        // one-sided rect faces u × v; v is up
        statics.push(Primitive::new(
            Shape::Rect {
                center,
                u,
                v: Vector3::new(0.0, 0.0, 1.0),
            },
            Material::textured(
                [96, 70, 52],
                TextureSpec::Noise {
                    scale: 0.2,
                    amp: 0.15,
                },
            ),
            0,
        ));
    }
}

/// Boxes (desks, cabinets), with legs when raised and as obstacles when not.
fn push_boxes(w: &WorldSpec, statics: &mut Vec<Primitive>, obstacles: &mut Vec<Obstacle>) {
    for b in &w.boxes {
        let half = Vector3::new(b.size[0] / 2.0, b.size[1] / 2.0, b.size[2] / 2.0);
        let center = Point3::new(b.at[0], b.at[1], b.raised + half.z);
        statics.push(Primitive::new(
            Shape::Box {
                center,
                half,
                yaw: b.yaw_deg.to_radians(),
            },
            Material::textured(b.color, b.texture),
            0,
        ));
        if b.raised > 0.0 {
            // four thin legs, so a laser below the top sees them
            let (s, c) = b.yaw_deg.to_radians().sin_cos();
            for (ex, ey) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
                let (lx, ly) = (ex * (half.x - 0.05), ey * (half.y - 0.05));
                statics.push(Primitive::new(
                    Shape::Cylinder {
                        x: b.at[0] + c * lx - s * ly,
                        y: b.at[1] + s * lx + c * ly,
                        z0: 0.0,
                        z1: b.raised,
                        r: 0.02,
                    },
                    Material::flat([90, 90, 95]),
                    0,
                ));
            }
        } else {
            obstacles.push(Obstacle {
                x: b.at[0],
                y: b.at[1],
                hx: half.x,
                hy: half.y,
                yaw: b.yaw_deg.to_radians(),
                round: false,
            });
        }
    }
}

/// The moving background, with the static parts (monitor bezels, plant pots) it needs.
fn moving_background(s: &Scenario, session: u64, statics: &mut Vec<Primitive>) -> Vec<Moving> {
    let mut moving = Vec::new();
    for d in &s.world.dynamic {
        match d {
            DynamicSpec::Monitor {
                at,
                size,
                yaw_deg,
                color,
                bar_period_s,
            } => {
                let (s_, c) = yaw_deg.to_radians().sin_cos();
                // facing direction is the yaw; u runs to the right of the screen
                let facing = Vector3::new(c, s_, 0.0);
                let u = Vector3::new(s_, -c, 0.0) * (size[0] / 2.0);
                let v = Vector3::new(0.0, 0.0, size[1] / 2.0);
                let (u, v) = if u.cross(&v).dot(&facing) > 0.0 {
                    (u, v)
                } else {
                    (-u, v)
                };
                let center = Point3::from(*at);
                statics.push(Primitive::new(
                    Shape::Box {
                        center: center - facing * 0.06,
                        half: Vector3::new(0.05, size[0] / 2.0 + 0.03, size[1] / 2.0 + 0.03),
                        yaw: yaw_deg.to_radians(),
                    },
                    Material::flat([30, 30, 32]),
                    0,
                ));
                moving.push(Moving::Monitor {
                    rect: Shape::Rect {
                        center: center + facing * 0.001,
                        u,
                        v,
                    },
                    color: *color,
                    period_s: *bar_period_s,
                });
            }
            DynamicSpec::Plant {
                at,
                height,
                radius,
                color,
                sway_m,
                period_s,
            } => {
                statics.push(Primitive::new(
                    Shape::Cylinder {
                        x: at[0],
                        y: at[1],
                        z0: 0.0,
                        z1: 0.35,
                        r: radius * 0.5,
                    },
                    Material::flat([150, 80, 50]),
                    0,
                ));
                moving.push(Moving::Plant {
                    base: *at,
                    height: *height,
                    radius: *radius,
                    color: *color,
                    sway_m: *sway_m,
                    period_s: *period_s,
                });
            }
            DynamicSpec::Traffic {
                y,
                x_range,
                speed,
                every_s,
                size,
            } => {
                let mut r = rng::stream(s.scenario.seed, "traffic", session);
                let palette: [Rgb; 6] = [
                    [180, 30, 30],
                    [30, 60, 160],
                    [220, 220, 220],
                    [40, 40, 40],
                    [200, 160, 40],
                    [90, 140, 90],
                ];
                let colors = (0..64)
                    .map(|_| palette[r.random_range(0..palette.len())])
                    .collect();
                moving.push(Moving::Traffic {
                    y: *y,
                    x_range: *x_range,
                    speed: *speed,
                    every_s: *every_s,
                    size: *size,
                    colors,
                });
            }
        }
    }
    moving
}

impl World {
    pub fn build(s: &Scenario, session: u64) -> World {
        let w = &s.world;
        let mut statics = Vec::new();
        let mut obstacles = Vec::new();
        statics.push(Primitive::new(
            Shape::Plane { z: 0.0, up: true },
            Material::textured(w.floor.color, w.floor.texture),
            0,
        ));
        if w.kind == WorldKind::Room {
            push_room(w, &mut statics);
        }
        push_boxes(w, &mut statics, &mut obstacles);
        if let Some(sc) = &w.scatter {
            let r = rng::stream(s.scenario.seed, "scatter", session);
            scatter::push_scatter(sc, w.size, r, &mut statics, &mut obstacles);
        }
        if let Some(c) = &w.clutter {
            let r = rng::stream(s.scenario.seed, "clutter", session);
            clutter::push_clutter(c, r, &mut statics, &mut obstacles);
        }
        let moving = moving_background(s, session, &mut statics);
        let sun = if w.kind == WorldKind::Outdoor {
            Vector3::new(0.4, 0.3, 0.87).normalize()
        } else {
            Vector3::new(0.15, 0.1, 1.0).normalize()
        };
        World {
            statics,
            moving,
            obstacles,
            lighting: Lighting {
                spec: w.light.clone(),
                sun,
                outdoor: w.kind == WorldKind::Outdoor,
            },
            doors: w.doors.iter().map(|d| d.at).collect(),
            size: w.size,
            outdoor: w.kind == WorldKind::Outdoor,
        }
    }

    /// Moving background at time `t`, appended to `out` (object ids 1, 2, ...).
    pub fn moving_at(&self, t: f64, out: &mut Vec<Primitive>) {
        for (k, m) in self.moving.iter().enumerate() {
            let id = 1 + k as u32;
            match m {
                Moving::Monitor {
                    rect,
                    color,
                    period_s,
                } => {
                    let phase = (t / period_s).fract() as f32;
                    out.push(Primitive::new(
                        rect.clone(),
                        Material {
                            albedo: linear(*color),
                            texture: Texture::Screen { phase },
                            emissive: true,
                        },
                        id,
                    ));
                }
                Moving::Plant {
                    base,
                    height,
                    radius,
                    color,
                    sway_m,
                    period_s,
                } => {
                    for j in 0..3 {
                        let jf = j as f64;
                        let w = std::f64::consts::TAU * t / period_s + jf * 1.7;
                        let sway = sway_m * (0.6 + 0.4 * jf / 2.0);
                        let dx = sway * (w.sin() + 0.3 * (2.3 * w).sin());
                        let dy = 0.4 * sway * (1.3 * w).cos();
                        let z = 0.35 + (height - 0.35) * (0.35 + 0.3 * jf);
                        out.push(Primitive::new(
                            Shape::Ellipsoid {
                                center: Point3::new(base[0] + dx, base[1] + dy, z),
                                radii: Vector3::new(*radius, radius * 0.8, radius * 0.7),
                                yaw: jf,
                            },
                            Material::textured(
                                *color,
                                TextureSpec::Noise {
                                    scale: 0.08,
                                    amp: 0.4,
                                },
                            ),
                            id,
                        ));
                    }
                }
                Moving::Traffic {
                    y,
                    x_range,
                    speed,
                    every_s,
                    size,
                    colors,
                } => {
                    let span = x_range[1] - x_range[0];
                    let travel = span / speed.abs();
                    // every vehicle that is on the road now
                    let first = ((t - travel) / every_s).floor().max(0.0) as i64;
                    let last = (t / every_s).floor() as i64;
                    for n in first..=last {
                        let age = t - n as f64 * every_s;
                        if !(0.0..=travel).contains(&age) {
                            continue;
                        }
                        let x = if *speed > 0.0 {
                            x_range[0] + speed * age
                        } else {
                            x_range[1] + speed * age
                        };
                        out.push(Primitive::new(
                            Shape::Box {
                                center: Point3::new(x, *y, size[2] / 2.0),
                                half: Vector3::new(size[0] / 2.0, size[1] / 2.0, size[2] / 2.0),
                                yaw: 0.0,
                            },
                            Material::flat(colors[n.unsigned_abs() as usize % colors.len()]),
                            id,
                        ));
                    }
                }
            }
        }
    }
}

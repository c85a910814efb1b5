//! Trees and bushes scattered at random over an outdoor world (`[world] scatter`), clear of
//! the keep-clear discs and of each other: their shapes for the renderer and the laser, and
//! their footprints for people's paths and the robot's platform.

use nalgebra::{Point3, Vector3};
use rand::RngExt;

use super::{Material, Obstacle, Primitive};
use crate::synth::scenario::{Scatter, TextureSpec};
use crate::synth::shapes::Shape;

/// Trees and bushes scattered at random, clear of the keep-clear discs and of each other.
pub(super) fn push_scatter(
    sc: &Scatter,
    size: [f64; 2],
    mut r: rand_chacha::ChaCha8Rng,
    statics: &mut Vec<Primitive>,
    obstacles: &mut Vec<Obstacle>,
) {
    let (sx, sy) = (size[0], size[1]);
    let clear = |x: f64, y: f64, obstacles: &[Obstacle]| {
        sc.keep_clear
            .iter()
            .all(|[cx, cy, cr]| (x - cx).hypot(y - cy) > *cr)
            && obstacles.iter().all(|o| o.distance(x, y) > 2.0)
    };
    let place = |n: u32, r: &mut rand_chacha::ChaCha8Rng, obstacles: &mut Vec<Obstacle>| {
        let mut out = Vec::new();
        let mut tries = 0;
        while out.len() < n as usize && tries < 10_000 {
            tries += 1;
            let (x, y) = (r.random::<f64>() * sx, r.random::<f64>() * sy);
            if clear(x, y, obstacles) {
                out.push((x, y));
                obstacles.push(Obstacle::disc(x, y, 0.5));
            }
        }
        out
    };
    for (x, y) in place(sc.trees, &mut r, obstacles) {
        let trunk = 0.12 + 0.15 * r.random::<f64>();
        let crown_z = 2.2 + 1.5 * r.random::<f64>();
        let crown_r = 1.2 + 1.2 * r.random::<f64>();
        statics.push(Primitive::new(
            Shape::Cylinder {
                x,
                y,
                z0: 0.0,
                z1: crown_z + 0.5,
                r: trunk,
            },
            Material::textured(
                [92, 70, 50],
                TextureSpec::Noise {
                    scale: 0.15,
                    amp: 0.25,
                },
            ),
            0,
        ));
        statics.push(Primitive::new(
            Shape::Ellipsoid {
                center: Point3::new(x, y, crown_z + crown_r * 0.8),
                radii: Vector3::new(crown_r, crown_r, crown_r * 0.9),
                yaw: 0.0,
            },
            Material::textured(
                [60, 110, 45],
                TextureSpec::Noise {
                    scale: 0.4,
                    amp: 0.35,
                },
            ),
            0,
        ));
        if let Some(o) = obstacles.last_mut() {
            *o = Obstacle::disc(x, y, trunk);
        }
    }
    for (x, y) in place(sc.bushes, &mut r, obstacles) {
        let br = 0.3 + 0.5 * r.random::<f64>();
        statics.push(Primitive::new(
            Shape::Ellipsoid {
                center: Point3::new(x, y, br * 0.7),
                radii: Vector3::new(br, br * (0.7 + 0.5 * r.random::<f64>()), br * 0.8),
                yaw: r.random::<f64>() * std::f64::consts::PI,
            },
            Material::textured(
                [70, 120, 55],
                TextureSpec::Noise {
                    scale: 0.2,
                    amp: 0.35,
                },
            ),
            0,
        ));
        if let Some(o) = obstacles.last_mut() {
            *o = Obstacle::disc(x, y, br);
        }
    }
}

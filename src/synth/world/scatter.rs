//! Trees and bushes scattered at random over an outdoor world (`[world] scatter`), clear of
//! the keep-clear discs and of each other: their shapes for the renderer and the laser, and
//! their footprints for people's paths and the robot's platform.
//!
//! Footprints: a tree's is its trunk's disc; a bush's is its ellipsoid's widest section, the
//! ellipse of its two horizontal semi-axes at its yaw (the laser at 0.45 m sees a section of
//! it, smaller for a bush whose equator is far above or below the scan plane, as on a real
//! robot). While placing, each takes a 0.5 m disc (spaced 2 m from the others' discs).

use std::f64::consts::PI;

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
                out.push((x, y, obstacles.len()));
                obstacles.push(Obstacle::disc(x, y, 0.5));
            }
        }
        out
    };
    // footprints are set once both are placed (placing spaces each from 0.5 m discs)
    let mut footprints = Vec::new();
    for (x, y, at) in place(sc.trees, &mut r, obstacles) {
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
        footprints.push((at, Obstacle::disc(x, y, trunk)));
    }
    for (x, y, at) in place(sc.bushes, &mut r, obstacles) {
        let br = 0.3 + 0.5 * r.random::<f64>();
        let (ry, yaw) = (br * (0.7 + 0.5 * r.random::<f64>()), r.random::<f64>() * PI);
        statics.push(Primitive::new(
            Shape::Ellipsoid {
                center: Point3::new(x, y, br * 0.7),
                radii: Vector3::new(br, ry, br * 0.8),
                yaw,
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
        footprints.push((at, Obstacle::ellipse(x, y, br, ry, yaw)));
    }
    for (at, o) in footprints {
        obstacles[at] = o;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng;

    /// Every tree's footprint is its trunk and every bush's its ellipsoid's equator, at the
    /// shape's own place (not a placeholder disc left from placing).
    #[test]
    fn each_tree_and_bush_has_its_own_footprint() {
        let sc = Scatter {
            trees: 12,
            bushes: 9,
            keep_clear: vec![],
        };
        let (mut statics, mut obstacles) = (Vec::new(), Vec::new());
        push_scatter(
            &sc,
            [40.0, 40.0],
            rng::stream(7, "scatter", 0),
            &mut statics,
            &mut obstacles,
        );
        assert_eq!(obstacles.len(), 21);
        let (mut trunks, mut bushes) = (0, 0);
        for p in &statics {
            let (x, y, hx, hy, yaw) = match p.shape {
                Shape::Cylinder { x, y, r, .. } => (x, y, r, r, 0.0),
                // a bush stands on the ground (a crown sits above 2 m)
                Shape::Ellipsoid { center, radii, yaw } if center.z < 1.0 => {
                    (center.x, center.y, radii.x, radii.y, yaw)
                }
                _ => continue,
            };
            let o = obstacles
                .iter()
                .find(|o| o.x == x && o.y == y)
                .expect("a footprint at the shape");
            assert_eq!((o.hx, o.hy, o.round), (hx, hy, true));
            if hx == hy {
                trunks += 1;
                assert!(hx < 0.3, "trunk radius {hx}");
            } else {
                bushes += 1;
                assert_eq!(o.yaw, yaw);
            }
        }
        assert_eq!((trunks, bushes), (12, 9));
    }

    #[test]
    fn an_ellipse_distance_is_exact_on_its_axes_and_negative_inside() {
        let o = Obstacle::ellipse(1.0, 2.0, 0.8, 0.4, std::f64::consts::FRAC_PI_2);
        // the long axis runs along y after the quarter turn
        assert!((o.distance(1.0, 3.0) - 0.2).abs() < 1e-12);
        assert!((o.distance(1.6, 2.0) - 0.2).abs() < 1e-12);
        assert!((o.distance(1.0, 2.0) + 0.4).abs() < 1e-12);
        assert!(o.distance(1.0, 2.5) < 0.0 && o.distance(1.3, 2.0) < 0.0);
        // never shorter than the true distance: a point at 45° outside
        let (px, py) = (1.0 + 0.7, 2.0 + 0.7);
        let truth = (0..100_000)
            .map(|k| {
                let a = k as f64 / 100_000.0 * std::f64::consts::TAU;
                (px - (1.0 - 0.4 * a.sin())).hypot(py - (2.0 + 0.8 * a.cos()))
            })
            .fold(f64::INFINITY, f64::min);
        let d = o.distance(px, py);
        assert!(d >= truth - 1e-9 && d < truth + 0.1, "{d} vs {truth}");
    }
}

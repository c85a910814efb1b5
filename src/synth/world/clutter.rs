//! Leg-like clutter for laser scenes (`[world.clutter]`, off unless a scenario asks): thin
//! poles, tables and chairs on thin legs, tree trunks, and walls with gaps — what a laser
//! leg detector must learn to reject in real rooms and parks (the real leg_tracker negatives
//! were recorded among such things). Placed at random over `area`, clear of the `keep_clear`
//! discs, of the world's other obstacles and of each other, from the scenario's own `clutter`
//! stream, so scenarios without clutter draw exactly what they drew before.
//!
//! Sizes (a priori, from furniture and street furniture): chair legs radius 1.2–2 cm on a
//! 0.42 m square; table legs 2–3.5 cm at the corners of a 1.0–1.6 × 0.6–0.9 m top at 0.72 m;
//! poles and trunks as the scenario gives; walls 0.1 m thick, 3–6 m long, with one or two
//! gaps of 0.3–0.9 m.

use nalgebra::{Point3, Vector3};
use rand::RngExt;

use super::{Material, Obstacle, Primitive};
use crate::synth::scenario::Clutter;
use crate::synth::shapes::Shape;

fn leg(x: f64, y: f64, r: f64, z1: f64) -> Primitive {
    Primitive::new(
        Shape::Cylinder {
            x,
            y,
            z0: 0.0,
            z1,
            r,
        },
        Material::flat([90, 85, 80]),
        0,
    )
}

/// Corners of a `w × d` rectangle centred on `(x, y)` turned by `yaw`, inset by `inset`.
fn corners(x: f64, y: f64, w: f64, d: f64, yaw: f64, inset: f64) -> [(f64, f64); 4] {
    let (s, c) = yaw.sin_cos();
    let (hx, hy) = (w / 2.0 - inset, d / 2.0 - inset);
    [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)]
        .map(|(ex, ey)| (x + c * ex * hx - s * ey * hy, y + s * ex * hx + c * ey * hy))
}

/// Add the clutter of `c` to `statics` and its footprints to `obstacles`.
pub fn push_clutter(
    c: &Clutter,
    mut r: rand_chacha::ChaCha8Rng,
    statics: &mut Vec<Primitive>,
    obstacles: &mut Vec<Obstacle>,
) {
    let [x0, y0, x1, y1] = c.area;
    let place = |r: &mut rand_chacha::ChaCha8Rng, obstacles: &mut Vec<Obstacle>, radius: f64| {
        for _ in 0..1000 {
            let (x, y) = (
                x0 + r.random::<f64>() * (x1 - x0),
                y0 + r.random::<f64>() * (y1 - y0),
            );
            let clear = c
                .keep_clear
                .iter()
                .all(|[cx, cy, cr]| (x - cx).hypot(y - cy) > cr + radius)
                && obstacles.iter().all(|o| o.distance(x, y) > radius + 0.6);
            if clear {
                obstacles.push(Obstacle::disc(x, y, radius));
                return Some((x, y));
            }
        }
        None
    };
    let span = |r: &mut rand_chacha::ChaCha8Rng, [a, b]: [f64; 2]| a + (b - a) * r.random::<f64>();
    for _ in 0..c.walls {
        // walls first, while there is room; both ends inside the area
        let inside = |x: f64, y: f64| x >= x0 && x <= x1 && y >= y0 && y <= y1;
        let mut found = None;
        for _ in 0..100 {
            let (len, yaw) = (
                span(&mut r, [3.0, 6.0]),
                r.random::<f64>() * std::f64::consts::PI,
            );
            let Some((x, y)) = place(&mut r, obstacles, 0.3) else {
                break;
            };
            obstacles.pop(); // the placing disc: people walk through the gaps
            let (dx, dy) = (yaw.cos() * len / 2.0, yaw.sin() * len / 2.0);
            if inside(x - dx, y - dy) && inside(x + dx, y + dy) {
                found = Some((x, y, len, yaw));
                break;
            }
        }
        let Some((x, y, len, yaw)) = found else {
            continue;
        };

        // pieces between one or two gaps, along the wall's direction
        let gaps = 1 + usize::from(r.random::<f64>() < 0.5);
        let mut cuts: Vec<(f64, f64)> = (0..gaps)
            .map(|_| {
                let g = span(&mut r, [0.3, 0.9]);
                let at = span(&mut r, [0.2, 0.8]) * len;
                (at - g / 2.0, at + g / 2.0)
            })
            .collect();
        cuts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut start = 0.0;
        let (s, co) = yaw.sin_cos();
        for (a, b) in cuts.into_iter().chain([(len, len)]) {
            if a > start + 0.05 {
                let mid = (start + a) / 2.0 - len / 2.0;
                let (cx, cy) = (x + co * mid, y + s * mid);
                statics.push(Primitive::new(
                    Shape::Box {
                        center: Point3::new(cx, cy, 1.0),
                        half: Vector3::new((a - start) / 2.0, 0.05, 1.0),
                        yaw,
                    },
                    Material::flat([200, 198, 190]),
                    0,
                ));
                obstacles.push(Obstacle {
                    x: cx,
                    y: cy,
                    hx: (a - start) / 2.0,
                    hy: 0.05,
                    yaw,
                    round: false,
                });
            }
            start = start.max(b);
        }
    }
    for _ in 0..c.poles {
        let rad = span(&mut r, c.pole_radius);
        if let Some((x, y)) = place(&mut r, obstacles, rad) {
            statics.push(leg(x, y, rad, 1.0 + r.random::<f64>()));
        }
    }
    for _ in 0..c.trunks {
        let rad = span(&mut r, c.trunk_radius);
        if let Some((x, y)) = place(&mut r, obstacles, rad) {
            statics.push(leg(x, y, rad, 3.0));
        }
    }
    for _ in 0..c.tables {
        let (w, d) = (span(&mut r, [1.0, 1.6]), span(&mut r, [0.6, 0.9]));
        let (yaw, rad) = (
            r.random::<f64>() * std::f64::consts::PI,
            span(&mut r, [0.02, 0.035]),
        );
        if let Some((x, y)) = place(&mut r, obstacles, w.hypot(d) / 2.0) {
            for (lx, ly) in corners(x, y, w, d, yaw, 0.06) {
                statics.push(leg(lx, ly, rad, 0.72));
            }
            statics.push(Primitive::new(
                Shape::Box {
                    center: Point3::new(x, y, 0.74),
                    half: Vector3::new(w / 2.0, d / 2.0, 0.02),
                    yaw,
                },
                Material::flat([150, 120, 90]),
                0,
            ));
        }
    }
    for _ in 0..c.chairs {
        let (yaw, rad) = (
            r.random::<f64>() * std::f64::consts::PI,
            span(&mut r, [0.012, 0.02]),
        );
        if let Some((x, y)) = place(&mut r, obstacles, 0.3) {
            for (lx, ly) in corners(x, y, 0.42, 0.42, yaw, 0.02) {
                statics.push(leg(lx, ly, rad, 0.45));
            }
        }
    }
}

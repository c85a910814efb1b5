//! Analytic primitives the renderer and the laser ray-cast against: horizontal planes, boxes
//! turned about z, vertical cylinders, capsules, ellipsoids turned about z, and rectangles. Each
//! returns the nearest hit in `(t_min, t_max)` with its outward normal, and has a bounding
//! sphere for culling. All in world coordinates (m), z up.

use nalgebra::{Point3, Vector3};

/// A surface hit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    pub t: f64,
    pub normal: Vector3<f64>,
}

#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// The plane z = `z`, facing `up` (+z) or down (ceilings).
    Plane { z: f64, up: bool },
    /// A box turned by `yaw` about the vertical through its centre.
    Box {
        center: Point3<f64>,
        half: Vector3<f64>,
        yaw: f64,
    },
    /// A vertical cylinder with caps.
    Cylinder {
        x: f64,
        y: f64,
        z0: f64,
        z1: f64,
        r: f64,
    },
    /// All points within `r` of the segment `a`–`b`.
    Capsule {
        a: Point3<f64>,
        b: Point3<f64>,
        r: f64,
    },
    /// An ellipsoid with semi-axes `radii` (x, y, z before the yaw turn).
    Ellipsoid {
        center: Point3<f64>,
        radii: Vector3<f64>,
        yaw: f64,
    },
    /// A one-sided rectangle `center ± u ± v` (u, v half-extent vectors), facing `u × v`.
    Rect {
        center: Point3<f64>,
        u: Vector3<f64>,
        v: Vector3<f64>,
    },
}

impl Shape {
    /// Centre and radius of a sphere enclosing the shape (infinite for planes).
    pub fn bounds(&self) -> (Point3<f64>, f64) {
        match self {
            Shape::Plane { z, .. } => (Point3::new(0.0, 0.0, *z), f64::INFINITY),
            Shape::Box { center, half, .. } => (*center, half.norm()),
            Shape::Cylinder { x, y, z0, z1, r } => {
                let h = (z1 - z0) / 2.0;
                (Point3::new(*x, *y, (z0 + z1) / 2.0), (h * h + r * r).sqrt())
            }
            Shape::Capsule { a, b, r } => (nalgebra::center(a, b), (b - a).norm() / 2.0 + r),
            Shape::Ellipsoid { center, radii, .. } => (*center, radii.max()),
            Shape::Rect { center, u, v } => (*center, (u + v).norm().max((u - v).norm())),
        }
    }

    /// Nearest intersection of `o + t d` (d unit) with `t_min < t < t_max`.
    pub fn intersect(
        &self,
        o: &Point3<f64>,
        d: &Vector3<f64>,
        t_min: f64,
        t_max: f64,
    ) -> Option<Hit> {
        let hit = match self {
            Shape::Plane { z, up } => {
                if d.z.abs() < 1e-12 {
                    return None;
                }
                let t = (z - o.z) / d.z;
                let normal = if *up { Vector3::z() } else { -Vector3::z() };
                // one-sided: only from the side it faces
                if normal.dot(d) >= 0.0 {
                    return None;
                }
                Hit { t, normal }
            }
            Shape::Box { center, half, yaw } => hit_box(o, d, t_min, center, half, *yaw)?,
            Shape::Cylinder { x, y, z0, z1, r } => {
                hit_cylinder(o, d, t_min, (*x, *y), (*z0, *z1), *r)?
            }
            Shape::Capsule { a, b, r } => hit_capsule(o, d, t_min, a, b, *r)?,
            Shape::Ellipsoid { center, radii, yaw } => hit_ellipsoid(o, d, center, radii, *yaw)?,
            Shape::Rect { center, u, v } => {
                let n = u.cross(v);
                let denom = n.dot(d);
                if denom >= -1e-15 {
                    return None; // one-sided
                }
                let t = n.dot(&(center - o)) / denom;
                let p = o + d * t - center;
                if p.dot(u).abs() > u.dot(u) || p.dot(v).abs() > v.dot(v) {
                    return None;
                }
                Hit {
                    t,
                    normal: n.normalize(),
                }
            }
        };
        (hit.t > t_min && hit.t < t_max).then_some(hit)
    }

    /// Local 2-D coordinates of a point on a rectangle, each in [−1, 1] (for screen textures).
    pub fn rect_uv(&self, p: &Point3<f64>) -> Option<(f64, f64)> {
        match self {
            Shape::Rect { center, u, v } => {
                let rel = p - center;
                Some((rel.dot(u) / u.dot(u), rel.dot(v) / v.dot(v)))
            }
            _ => None,
        }
    }

    /// Move the shape by `delta` (for swaying plants and passing traffic).
    pub fn translated(&self, delta: &Vector3<f64>) -> Shape {
        match self.clone() {
            Shape::Plane { z, up } => Shape::Plane { z: z + delta.z, up },
            Shape::Box { center, half, yaw } => Shape::Box {
                center: center + delta,
                half,
                yaw,
            },
            Shape::Cylinder { x, y, z0, z1, r } => Shape::Cylinder {
                x: x + delta.x,
                y: y + delta.y,
                z0: z0 + delta.z,
                z1: z1 + delta.z,
                r,
            },
            Shape::Capsule { a, b, r } => Shape::Capsule {
                a: a + delta,
                b: b + delta,
                r,
            },
            Shape::Ellipsoid { center, radii, yaw } => Shape::Ellipsoid {
                center: center + delta,
                radii,
                yaw,
            },
            Shape::Rect { center, u, v } => Shape::Rect {
                center: center + delta,
                u,
                v,
            },
        }
    }
}

/// Ray–box hit, in the box's turned frame (slab test); `None` from inside or behind.
fn hit_box(
    o: &Point3<f64>,
    d: &Vector3<f64>,
    t_min: f64,
    center: &Point3<f64>,
    half: &Vector3<f64>,
    yaw: f64,
) -> Option<Hit> {
    let (s, c) = yaw.sin_cos();
    // into the box frame (rotate by −yaw)
    let rel = o - center;
    let lo = Vector3::new(c * rel.x + s * rel.y, -s * rel.x + c * rel.y, rel.z);
    let ld = Vector3::new(c * d.x + s * d.y, -s * d.x + c * d.y, d.z);
    let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
    let (mut axis0, mut sign0) = (0usize, 1.0f64);
    for k in 0..3 {
        if ld[k].abs() < 1e-15 {
            if lo[k].abs() > half[k] {
                return None;
            }
            continue;
        }
        let inv = 1.0 / ld[k];
        let (mut a, mut b) = ((-half[k] - lo[k]) * inv, (half[k] - lo[k]) * inv);
        let mut sg = -1.0;
        if a > b {
            std::mem::swap(&mut a, &mut b);
            sg = 1.0;
        }
        if a > t0 {
            t0 = a;
            axis0 = k;
            sign0 = sg;
        }
        t1 = t1.min(b);
        if t0 > t1 {
            return None;
        }
    }
    if t0 <= t_min {
        return None; // inside the box, or behind: boxes are solid, seen from outside
    }
    let mut ln = Vector3::zeros();
    ln[axis0] = sign0;
    Some(Hit {
        t: t0,
        normal: Vector3::new(c * ln.x - s * ln.y, s * ln.x + c * ln.y, ln.z),
    })
}

/// Ray–vertical-cylinder hit: the side, then the caps.
fn hit_cylinder(
    o: &Point3<f64>,
    d: &Vector3<f64>,
    t_min: f64,
    (x, y): (f64, f64),
    (z0, z1): (f64, f64),
    r: f64,
) -> Option<Hit> {
    let (ox, oy) = (o.x - x, o.y - y);
    let a = d.x * d.x + d.y * d.y;
    let mut best: Option<Hit> = None;
    if a > 1e-15 {
        let b = ox * d.x + oy * d.y;
        let c = ox * ox + oy * oy - r * r;
        let disc = b * b - a * c;
        if disc >= 0.0 {
            let t = (-b - disc.sqrt()) / a;
            let z = o.z + t * d.z;
            if t > t_min && z >= z0 && z <= z1 {
                best = Some(Hit {
                    t,
                    normal: Vector3::new((ox + t * d.x) / r, (oy + t * d.y) / r, 0.0),
                });
            }
        }
    }
    for (zc, n) in [(z1, 1.0), (z0, -1.0)] {
        if d.z.abs() < 1e-15 {
            continue;
        }
        let t = (zc - o.z) / d.z;
        if t > t_min && best.is_none_or(|h| t < h.t) && n * d.z < 0.0 {
            let (px, py) = (ox + t * d.x, oy + t * d.y);
            if px * px + py * py <= r * r {
                best = Some(Hit {
                    t,
                    normal: Vector3::new(0.0, 0.0, n),
                });
            }
        }
    }
    best
}

/// Ray–capsule hit (Inigo Quilez's capsule intersection).
fn hit_capsule(
    o: &Point3<f64>,
    d: &Vector3<f64>,
    t_min: f64,
    a: &Point3<f64>,
    b: &Point3<f64>,
    r: f64,
) -> Option<Hit> {
    // Inigo Quilez's capsule intersection
    let ba = b - a;
    let oa = o - a;
    let baba = ba.dot(&ba);
    let bard = ba.dot(d);
    let baoa = ba.dot(&oa);
    let rdoa = d.dot(&oa);
    let oaoa = oa.dot(&oa);
    let qa = baba - bard * bard;
    let qb = baba * rdoa - baoa * bard;
    let qc = baba * oaoa - baoa * baoa - r * r * baba;
    let h = qb * qb - qa * qc;
    if h < 0.0 {
        return None;
    }
    let sphere = |c: &Point3<f64>| {
        let oc = o - c;
        let bq = d.dot(&oc);
        let hq = bq * bq - (oc.dot(&oc) - r * r);
        (hq >= 0.0).then(|| -bq - hq.sqrt()).filter(|t| *t > t_min)
    };
    let body = (qa.abs() > 1e-15)
        .then(|| (-qb - h.sqrt()) / qa)
        .filter(|t| {
            let y = baoa + t * bard;
            y > 0.0 && y < baba
        });
    let t = match body {
        Some(t) => t,
        // parallel to the axis, or the body hit lies beyond an end: nearest cap
        None => match (sphere(a), sphere(b)) {
            (Some(x), Some(y)) => x.min(y),
            (Some(x), None) | (None, Some(x)) => x,
            (None, None) => return None,
        },
    };
    let p = o + d * t;
    let pa = p - a;
    let k = (pa.dot(&ba) / baba).clamp(0.0, 1.0);
    let normal = (pa - ba * k) / r;
    Some(Hit { t, normal })
}

/// Ray–ellipsoid hit, in the ellipsoid's turned and scaled frame.
fn hit_ellipsoid(
    o: &Point3<f64>,
    d: &Vector3<f64>,
    center: &Point3<f64>,
    radii: &Vector3<f64>,
    yaw: f64,
) -> Option<Hit> {
    let (s, c) = yaw.sin_cos();
    let rel = o - center;
    let lo =
        Vector3::new(c * rel.x + s * rel.y, -s * rel.x + c * rel.y, rel.z).component_div(radii);
    let ld = Vector3::new(c * d.x + s * d.y, -s * d.x + c * d.y, d.z).component_div(radii);
    let a = ld.dot(&ld);
    let b = lo.dot(&ld);
    let cc = lo.dot(&lo) - 1.0;
    let disc = b * b - a * cc;
    if disc < 0.0 {
        return None;
    }
    let t = (-b - disc.sqrt()) / a;
    let lp = lo + ld * t;
    let ln = lp.component_div(radii); // gradient in the turned frame
    let n = Vector3::new(c * ln.x - s * ln.y, s * ln.x + c * ln.y, ln.z).normalize();
    Some(Hit { t, normal: n })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(shape: &Shape, o: [f64; 3], d: [f64; 3], t: Option<f64>, n: Option<[f64; 3]>) {
        let d = Vector3::from(d).normalize();
        let hit = shape.intersect(&Point3::from(o), &d, 1e-9, 1e9);
        match (hit, t) {
            (None, None) => {}
            (Some(h), Some(t)) => {
                assert!((h.t - t).abs() < 1e-9, "{shape:?}: t {} != {t}", h.t);
                if let Some(n) = n {
                    assert!(
                        (h.normal - Vector3::from(n)).norm() < 1e-9,
                        "{shape:?}: normal {}",
                        h.normal
                    );
                }
            }
            (h, t) => panic!("{shape:?}: got {h:?}, expected t = {t:?}"),
        }
    }

    #[test]
    fn known_intersections() {
        check(
            &Shape::Plane { z: 0.0, up: true },
            [0.0, 0.0, 2.0],
            [1.0, 0.0, -1.0],
            Some(2.0 * 2f64.sqrt()),
            Some([0.0, 0.0, 1.0]),
        );
        check(
            &Shape::Plane { z: 0.0, up: true },
            [0.0, 0.0, -2.0],
            [0.0, 0.0, 1.0],
            None,
            None,
        );
        let cyl = Shape::Cylinder {
            x: 3.0,
            y: 0.0,
            z0: 0.0,
            z1: 1.0,
            r: 0.5,
        };
        check(
            &cyl,
            [0.0, 0.0, 0.5],
            [1.0, 0.0, 0.0],
            Some(2.5),
            Some([-1.0, 0.0, 0.0]),
        );
        check(&cyl, [0.0, 0.0, 1.5], [1.0, 0.0, 0.0], None, None);
        check(
            &cyl,
            [3.0, 0.0, 3.0],
            [0.0, 0.0, -1.0],
            Some(2.0),
            Some([0.0, 0.0, 1.0]),
        );
        let bx = Shape::Box {
            center: Point3::new(5.0, 0.0, 0.5),
            half: Vector3::new(0.5, 1.0, 0.5),
            yaw: std::f64::consts::FRAC_PI_2,
        };
        // turned 90°: the x half-extent is now 1.0
        check(
            &bx,
            [0.0, 0.0, 0.5],
            [1.0, 0.0, 0.0],
            Some(4.0),
            Some([-1.0, 0.0, 0.0]),
        );
        let cap = Shape::Capsule {
            a: Point3::new(2.0, 0.0, 0.0),
            b: Point3::new(2.0, 0.0, 1.0),
            r: 0.1,
        };
        check(
            &cap,
            [0.0, 0.0, 0.5],
            [1.0, 0.0, 0.0],
            Some(1.9),
            Some([-1.0, 0.0, 0.0]),
        );
        check(
            &cap,
            [2.0, 0.0, 5.0],
            [0.0, 0.0, -1.0],
            Some(3.9),
            Some([0.0, 0.0, 1.0]),
        );
        let ell = Shape::Ellipsoid {
            center: Point3::new(0.0, 4.0, 0.0),
            radii: Vector3::new(0.2, 0.5, 1.0),
            yaw: 0.0,
        };
        check(
            &ell,
            [0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            Some(3.5),
            Some([0.0, -1.0, 0.0]),
        );
        let rect = Shape::Rect {
            center: Point3::new(0.0, 0.0, 1.0),
            u: Vector3::new(0.5, 0.0, 0.0),
            v: Vector3::new(0.0, 0.3, 0.0),
        };
        check(
            &rect,
            [0.1, 0.1, 3.0],
            [0.0, 0.0, -1.0],
            Some(2.0),
            Some([0.0, 0.0, 1.0]),
        );
        check(&rect, [0.9, 0.1, 3.0], [0.0, 0.0, -1.0], None, None);
    }
}

//! A person as analytic primitives: two legs that swing with the gait (capsules from hip to
//! ankle, so a laser at shin height sees two moving circles that sometimes occlude each other),
//! shoes, torso, arms swinging against the legs, neck, head with skin and hair, an optional
//! coloured hat, and a soft shadow on the floor. Proportions follow standard anthropometry
//! (hip at 0.52 H, shoulders at 0.82 H, head 0.24 m tall).

use nalgebra::{Point3, Vector3};

use super::scenario::{PersonSpec, Rgb};
use super::shapes::Shape;
use super::world::{Material, PERSON_BASE, Primitive, Texture, linear};

/// Where a person is and how far through a stride.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PersonState {
    pub x: f64,
    pub y: f64,
    pub heading: f64,
    pub speed: f64,
    pub vx: f64,
    pub vy: f64,
    /// Gait phase (rad).
    pub phase: f64,
}

/// A person's body and clothes.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    pub id: u32,
    pub height: f64,
    pub width: f64,
    pub leg_radius: f64,
    pub upper: Rgb,
    pub lower: Rgb,
    pub skin: Rgb,
    pub hair: Rgb,
    pub hat: Option<Rgb>,
    /// Skin-coloured hands at the ends of the arms (opt-in per scenario person, `hands = true`:
    /// seed 002's skin detection; off, the arms end in the sleeve as before).
    pub hands: bool,
}

/// Radius of a hand (a sphere at the end of the arm), m.
pub const HAND_RADIUS: f64 = 0.05;

pub const ANKLE_Z: f64 = 0.07;
pub const HEAD_HALF_HEIGHT: f64 = 0.12;

impl Body {
    pub fn from_spec(p: &PersonSpec) -> Body {
        Body {
            id: p.id,
            height: p.height,
            width: p.width,
            leg_radius: p.leg_radius,
            upper: p.upper,
            lower: p.lower,
            skin: p.skin,
            hair: p.hair,
            hat: p.hat,
            hands: p.hands,
        }
    }

    pub fn object(&self) -> u32 {
        PERSON_BASE + self.id
    }

    fn hip_z(&self) -> f64 {
        0.52 * self.height
    }

    /// Step length at a speed: longer strides when walking faster.
    pub fn stride(speed: f64) -> f64 {
        (0.45 + 0.45 * speed).min(1.6)
    }

    /// Hip joint and ankle of leg `k` (0 left, 1 right).
    fn leg(&self, s: &PersonState, k: usize) -> (Point3<f64>, Point3<f64>) {
        let (sn, cs) = s.heading.sin_cos();
        let fwd = Vector3::new(cs, sn, 0.0);
        let left = Vector3::new(-sn, cs, 0.0);
        let side = if k == 0 { 0.09 } else { -0.09 };
        let walking = (s.speed / 0.3).min(1.0);
        let swing = 0.5
            * Body::stride(s.speed)
            * walking
            * (s.phase + std::f64::consts::PI * k as f64).sin();
        let base = Point3::new(s.x, s.y, 0.0) + left * side;
        let bob = 0.015 * walking * (2.0 * s.phase).cos();
        let hip = base + Vector3::new(0.0, 0.0, self.hip_z() + bob);
        let ankle = base + fwd * swing + Vector3::new(0.0, 0.0, ANKLE_Z);
        (hip, ankle)
    }

    /// Centres of both legs at height `z` (what a laser in that plane sees).
    pub fn legs_at(&self, s: &PersonState, z: f64) -> [[f64; 2]; 2] {
        let mut out = [[0.0; 2]; 2];
        for (k, slot) in out.iter_mut().enumerate() {
            let (hip, ankle) = self.leg(s, k);
            let u = ((hip.z - z) / (hip.z - ankle.z)).clamp(0.0, 1.0);
            let p = hip + (ankle - hip) * u;
            *slot = [p.x, p.y];
        }
        out
    }

    /// Top of the head (without a hat).
    pub fn head_top(&self, s: &PersonState) -> Point3<f64> {
        Point3::new(s.x, s.y, self.height)
    }

    /// Centre of the head.
    pub fn head_center(&self, s: &PersonState) -> Point3<f64> {
        Point3::new(s.x, s.y, self.height - HEAD_HALF_HEIGHT)
    }

    /// Centre of the hat (the coloured target of the webcam measurement system).
    pub fn hat_center(&self, s: &PersonState) -> Option<Point3<f64>> {
        self.hat.map(|_| Point3::new(s.x, s.y, self.height + 0.04))
    }

    /// Append the body's primitives.
    pub fn primitives(&self, s: &PersonState, out: &mut Vec<Primitive>) {
        self.primitives_with_head(s, None, out);
    }

    /// Append the body's primitives with a painted face ([`super::face`]) on a head turned to
    /// `head_yaw` (rad, in the world; the body keeps `s.heading`).
    pub fn primitives_with_face(&self, s: &PersonState, head_yaw: f64, out: &mut Vec<Primitive>) {
        self.primitives_with_head(s, Some((head_yaw, &super::face::DEFAULT_STYLE)), out);
    }

    /// As [`Self::primitives_with_face`] with the face drawn in `style`.
    pub fn primitives_with_face_style(
        &self,
        s: &PersonState,
        head_yaw: f64,
        style: &'static super::face::FaceStyle,
        out: &mut Vec<Primitive>,
    ) {
        self.primitives_with_head(s, Some((head_yaw, style)), out);
    }

    fn primitives_with_head(
        &self,
        s: &PersonState,
        face: Option<(f64, &'static super::face::FaceStyle)>,
        out: &mut Vec<Primitive>,
    ) {
        let id = self.object();
        let h = self.height;
        let (sn, cs) = s.heading.sin_cos();
        let fwd = Vector3::new(cs, sn, 0.0);
        let left = Vector3::new(-sn, cs, 0.0);
        let cloth = |c: Rgb| Material {
            albedo: linear(c),
            texture: Texture::Noise {
                scale: 0.12,
                amp: 0.12,
            },
            emissive: false,
        };
        let walking = (s.speed / 0.3).min(1.0);
        for k in 0..2 {
            let (hip, ankle) = self.leg(s, k);
            out.push(Primitive::new(
                Shape::Capsule {
                    a: hip,
                    b: ankle,
                    r: self.leg_radius,
                },
                cloth(self.lower),
                id,
            ));
            out.push(Primitive::new(
                Shape::Capsule {
                    a: Point3::new(ankle.x, ankle.y, 0.045) - fwd * 0.03,
                    b: Point3::new(ankle.x, ankle.y, 0.045) + fwd * 0.17,
                    r: 0.045,
                },
                Material::flat([35, 32, 30]),
                id,
            ));
        }
        let hip_z = self.hip_z();
        let shoulder_z = 0.82 * h;
        let center = Point3::new(s.x, s.y, 0.0);
        out.push(Primitive::new(
            Shape::Ellipsoid {
                center: center + Vector3::new(0.0, 0.0, (hip_z + shoulder_z) / 2.0),
                radii: Vector3::new(0.13, self.width, (shoulder_z - hip_z) / 2.0 + 0.06),
                yaw: s.heading,
            },
            cloth(self.upper),
            id,
        ));
        for k in 0..2 {
            let side = if k == 0 { 1.0 } else { -1.0 };
            // arms swing opposite to the leg on the same side
            let swing = -0.3
                * Body::stride(s.speed)
                * walking
                * (s.phase + std::f64::consts::PI * k as f64).sin();
            let shoulder = center
                + left * side * (self.width + 0.03)
                + Vector3::new(0.0, 0.0, shoulder_z - 0.03);
            let hand = center
                + left * side * (self.width + 0.06)
                + fwd * swing
                + Vector3::new(0.0, 0.0, hip_z - 0.02);
            out.push(Primitive::new(
                Shape::Capsule {
                    a: shoulder,
                    b: hand,
                    r: 0.045,
                },
                cloth(self.upper),
                id,
            ));
            if self.hands {
                let palm = hand - Vector3::new(0.0, 0.0, HAND_RADIUS);
                out.push(
                    Primitive::new(
                        Shape::Ellipsoid {
                            center: palm,
                            radii: Vector3::new(HAND_RADIUS, HAND_RADIUS, HAND_RADIUS),
                            yaw: 0.0,
                        },
                        Material::flat(self.skin),
                        id,
                    )
                    .skin_below(f64::INFINITY),
                );
            }
        }
        out.push(
            Primitive::new(
                Shape::Cylinder {
                    x: s.x,
                    y: s.y,
                    z0: shoulder_z,
                    z1: h - 2.0 * HEAD_HALF_HEIGHT + 0.03,
                    r: 0.055,
                },
                Material::flat(self.skin),
                id,
            )
            .skin_below(f64::INFINITY),
        );
        let head = self.head_center(s);
        let hairline = head.z + super::face::HAIRLINE_U;
        let texture = self.head_texture(head, hairline, face);
        out.push(
            Primitive::new(
                Shape::Ellipsoid {
                    center: head,
                    radii: Vector3::new(0.1, 0.085, HEAD_HALF_HEIGHT),
                    yaw: face.map_or(s.heading, |f| f.0),
                },
                Material {
                    albedo: linear(self.skin),
                    texture,
                    emissive: false,
                },
                id,
            )
            .skin_below(hairline),
        );
        if let Some((yaw, _)) = face {
            self.face_relief(head, yaw, id, out);
        }
        if let Some(hat) = self.hat {
            out.push(Primitive::new(
                Shape::Cylinder {
                    x: s.x,
                    y: s.y,
                    z0: h - 0.03,
                    z1: h + 0.09,
                    r: 0.105,
                },
                Material::flat(hat),
                id,
            ));
        }
    }

    /// The head's texture: hair above the hairline, or a painted face turned to its yaw.
    fn head_texture(
        &self,
        head: Point3<f64>,
        hairline: f64,
        face: Option<(f64, &'static super::face::FaceStyle)>,
    ) -> Texture {
        match face {
            None => Texture::Split {
                z: hairline as f32,
                above: linear(self.hair),
            },
            Some((yaw, style)) => Texture::Face {
                center: [head.x as f32, head.y as f32, head.z as f32],
                yaw: yaw as f32,
                hair: linear(self.hair),
                style,
            },
        }
    }

    /// A face's relief: the nose (in front of the head centre, 2.5 cm below it) and the ears
    /// (at the sides), small skin ellipsoids that turn with the head's yaw.
    fn face_relief(&self, head: Point3<f64>, yaw: f64, id: u32, out: &mut Vec<Primitive>) {
        let (sn, cs) = yaw.sin_cos();
        let at = |f: f64, s: f64, u: f64| head + Vector3::new(f * cs - s * sn, f * sn + s * cs, u);
        let parts = [
            (at(0.092, 0.0, -0.025), Vector3::new(0.022, 0.011, 0.028)),
            (at(0.0, 0.084, -0.005), Vector3::new(0.012, 0.008, 0.03)),
            (at(0.0, -0.084, -0.005), Vector3::new(0.012, 0.008, 0.03)),
        ];
        for (center, radii) in parts {
            out.push(
                Primitive::new(
                    Shape::Ellipsoid { center, radii, yaw },
                    Material::flat(self.skin),
                    id,
                )
                .skin_below(f64::INFINITY),
            );
        }
    }

    /// Radius of the soft floor shadow.
    pub fn shadow_radius(&self) -> f64 {
        self.width + 0.15
    }
}

/// Darkening of the floor at `(x, y)` by the shadows of people at `shadows` (`[x, y, r]`).
pub fn shadow_factor(x: f64, y: f64, shadows: &[[f64; 3]]) -> f32 {
    let mut f = 1.0f32;
    for [sx, sy, r] in shadows {
        let d2 = (x - sx).powi(2) + (y - sy).powi(2);
        if d2 < 4.0 * r * r {
            f *= 1.0 - 0.45 * (-(d2 / (r * r)) as f32).exp();
        }
    }
    f
}

#[cfg(test)]
mod tests {
    use super::*;

    fn body() -> Body {
        Body {
            id: 3,
            height: 1.8,
            width: 0.2,
            leg_radius: 0.065,
            upper: [200, 0, 0],
            lower: [0, 0, 200],
            skin: [210, 160, 130],
            hair: [40, 30, 20],
            hat: Some([0, 180, 0]),
            hands: false,
        }
    }

    #[test]
    fn legs_swing_apart_when_walking_and_stand_together_when_still() {
        let b = body();
        let mut s = PersonState {
            x: 0.0,
            y: 0.0,
            heading: 0.0,
            speed: 1.2,
            vx: 1.2,
            vy: 0.0,
            phase: std::f64::consts::FRAC_PI_2,
        };
        let [l, r] = b.legs_at(&s, 0.25);
        assert!(
            l[0] - r[0] > 0.5,
            "walking: legs {l:?} {r:?} are a stride apart along x"
        );
        s.speed = 0.0;
        let [l, r] = b.legs_at(&s, 0.25);
        assert!((l[0] - r[0]).abs() < 1e-12 && (l[1] - r[1] - 0.18).abs() < 1e-12);
    }

    #[test]
    fn a_laser_ray_at_shin_height_hits_the_leg_it_aims_at() {
        let b = body();
        let s = PersonState {
            x: 3.0,
            y: 0.0,
            heading: 0.0,
            speed: 0.0,
            vx: 0.0,
            vy: 0.0,
            phase: 0.0,
        };
        let mut prims = Vec::new();
        b.primitives(&s, &mut prims);
        let [l, _] = b.legs_at(&s, 0.25);
        let o = Point3::new(0.0, l[1], 0.25);
        let d = Vector3::new(1.0, 0.0, 0.0);
        let t = prims
            .iter()
            .filter_map(|p| p.shape.intersect(&o, &d, 1e-9, 100.0))
            .map(|h| h.t)
            .fold(f64::INFINITY, f64::min);
        // the leg axis leans from hip to ankle; at 0.25 m it is at x = 3.0 for a standing person
        assert!((t - (3.0 - 0.065)).abs() < 1e-3, "{t}");
    }

    #[test]
    fn hands_are_opt_in_and_skin_is_marked_on_face_neck_and_hands_only() {
        let s = PersonState {
            x: 1.0,
            y: 2.0,
            heading: 0.3,
            speed: 0.0,
            vx: 0.0,
            vy: 0.0,
            phase: 0.0,
        };
        let mut plain = Vec::new();
        body().primitives(&s, &mut plain);
        let mut b = body();
        b.hands = true;
        let mut with = Vec::new();
        b.primitives(&s, &mut with);
        assert_eq!(with.len(), plain.len() + 2);
        let skin: Vec<Option<f64>> = plain.iter().map(|p| p.skin_below).collect();
        // neck (always skin) and head (skin below the hairline, 3.5 cm above the head centre)
        let hairline = 1.8 - HEAD_HALF_HEIGHT + 0.035;
        assert_eq!(skin.iter().filter(|z| z.is_some()).count(), 2);
        assert!(skin.contains(&Some(f64::INFINITY)));
        assert!(skin.contains(&Some(hairline)));
        let hands = with
            .iter()
            .filter(|p| p.skin_below == Some(f64::INFINITY))
            .count();
        assert_eq!(hands, 3, "neck + two hands");
    }
}

//! A face painted on a person's head (the BIRON dataset, seed 003 / issue 33): eye sockets,
//! whites and irises, brows, the shadow under the nose, lips, and hair on the crown, the back
//! and the sides, all in the head's own frame so the face turns with the head's yaw. The head
//! is the ellipsoid of [`super::person`] (semi-axes 0.10 m forward, 0.085 m sideways, 0.12 m
//! up); the features are placed on its front by their sideways (`s`) and upward (`u`) offsets
//! from the head centre ([`FaceStyle`], [`DEFAULT_STYLE`]).
//!
//! Feature edges are soft over [`EDGE_M`] so a face 25–40 px wide (4–7 mm per pixel) does not
//! alias. What a face detector sees is only this albedo under the renderer's shading: no
//! geometry for nose or brows, no specular highlights, no expression.

/// Width of a feature's soft edge (m).
pub const EDGE_M: f64 = 0.003;

/// The proportions and shades of a painted face (m from the head centre, `s` sideways, `u`
/// up; shades as factors of the skin or hair albedo).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaceStyle {
    /// Hairline height at the middle of the forehead.
    pub hairline_u: f64,
    /// Eye centres at ±`eye_s`, height `eye_u`.
    pub eye_s: f64,
    pub eye_u: f64,
    /// Eye socket semi-axes and its darkening.
    pub socket_rs: f64,
    pub socket_ru: f64,
    pub socket_shade: f32,
    /// Eye white semi-axes and its linear albedo.
    pub white_rs: f64,
    pub white_ru: f64,
    pub white: f32,
    pub iris_r: f64,
    /// Brows: height above the eyes, semi-axes, shade of the hair.
    pub brow_du: f64,
    pub brow_rs: f64,
    pub brow_ru: f64,
    pub brow_shade: f32,
    /// Shadow under the nose: height, semi-axes, darkening.
    pub nose_u: f64,
    pub nose_rs: f64,
    pub nose_ru: f64,
    pub nose_shade: f32,
    /// Lips: height and semi-axes.
    pub lips_u: f64,
    pub lips_rs: f64,
    pub lips_ru: f64,
}

/// Adult proportions: eyes on the head's mid-line 6.4 cm apart, brows 2.2 cm above them, the
/// hairline 6.5 cm above them, the nose's shadow 4.5 cm and the mouth 7.5 cm below.
pub const DEFAULT_STYLE: FaceStyle = FaceStyle {
    hairline_u: 0.065,
    eye_s: 0.032,
    eye_u: 0.0,
    socket_rs: 0.022,
    socket_ru: 0.013,
    socket_shade: 0.3,
    white_rs: 0.011,
    white_ru: 0.005,
    white: 0.25,
    iris_r: 0.006,
    brow_du: 0.022,
    brow_rs: 0.02,
    brow_ru: 0.007,
    brow_shade: 0.3,
    nose_u: -0.045,
    nose_rs: 0.016,
    nose_ru: 0.007,
    nose_shade: 0.35,
    lips_u: -0.075,
    lips_rs: 0.026,
    lips_ru: 0.008,
};

/// Hairline above the head centre (m) of the plain (faceless) head of [`super::person`].
pub const HAIRLINE_U: f64 = 0.035;

/// An ellipse feature on the face: centre `(s, u)`, semi-axes `(rs, ru)`, in metres.
struct Ellipse {
    s: f64,
    u: f64,
    rs: f64,
    ru: f64,
}

impl Ellipse {
    /// Coverage in [0, 1] of the point `(s, u)`: 1 inside, 0 outside, soft over the edge.
    fn cover(&self, s: f64, u: f64) -> f32 {
        let r = ((s - self.s) / self.rs).hypot((u - self.u) / self.ru);
        let inside_m = (1.0 - r) * self.rs.min(self.ru);
        (inside_m / EDGE_M + 0.5).clamp(0.0, 1.0) as f32
    }
}

fn mix(a: [f32; 3], b: [f32; 3], k: f32) -> [f32; 3] {
    [
        a[0] + (b[0] - a[0]) * k,
        a[1] + (b[1] - a[1]) * k,
        a[2] + (b[2] - a[2]) * k,
    ]
}

fn scale(a: [f32; 3], k: f32) -> [f32; 3] {
    [a[0] * k, a[1] * k, a[2] * k]
}

/// Linear albedo of a head with a face at the world point `p` (on the head's surface): the
/// head centre is `center`, its yaw `yaw` (rad, the direction the face looks), `skin` and
/// `hair` linear albedos, the face drawn as `st` says.
pub fn albedo(
    p: [f64; 3],
    center: [f64; 3],
    yaw: f64,
    skin: [f32; 3],
    hair: [f32; 3],
    st: &FaceStyle,
) -> [f32; 3] {
    let (dx, dy, u) = (p[0] - center[0], p[1] - center[1], p[2] - center[2]);
    let (sn, cs) = yaw.sin_cos();
    let f = dx * cs + dy * sn; // forward
    let s = -dx * sn + dy * cs; // to the head's left
    // hair: the crown above the hairline, the back of the head, the temples
    let hairline = st.hairline_u + 0.6 * s * s;
    if u > hairline || (f < -0.015 && u > -0.08) || (f < 0.035 && u > st.eye_u + 0.02) {
        return hair;
    }
    if f < 0.04 {
        return skin; // cheeks, ears, jaw seen from the side
    }
    let sa = s.abs();
    let e = |s0: f64, u0: f64, rs: f64, ru: f64| Ellipse {
        s: s0,
        u: u0,
        rs,
        ru,
    };
    let mut a = skin;
    a = mix(
        a,
        scale(skin, st.socket_shade),
        e(st.eye_s, st.eye_u, st.socket_rs, st.socket_ru).cover(sa, u),
    );
    a = mix(
        a,
        [st.white; 3],
        e(st.eye_s, st.eye_u, st.white_rs, st.white_ru).cover(sa, u),
    );
    a = mix(
        a,
        [0.02, 0.015, 0.012],
        e(st.eye_s, st.eye_u, st.iris_r, st.iris_r).cover(sa, u),
    );
    let brow = e(
        st.eye_s + 0.002,
        st.eye_u + st.brow_du,
        st.brow_rs,
        st.brow_ru,
    );
    a = mix(a, scale(hair, st.brow_shade), brow.cover(sa, u));
    a = mix(
        a,
        scale(skin, st.nose_shade),
        e(0.0, st.nose_u, st.nose_rs, st.nose_ru).cover(s, u),
    );
    a = mix(
        a,
        [0.32, 0.08, 0.08],
        e(0.0, st.lips_u, st.lips_rs, st.lips_ru).cover(s, u),
    );
    mix(
        a,
        [0.05, 0.02, 0.02],
        e(0.0, st.lips_u, st.lips_rs * 0.9, 0.0018).cover(s, u),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    const SKIN: [f32; 3] = [0.6, 0.4, 0.3];
    const HAIR: [f32; 3] = [0.05, 0.03, 0.02];

    /// The point on the head surface straight ahead of its centre at `(s, u)` offsets.
    fn front(center: [f64; 3], yaw: f64, s: f64, u: f64) -> [f64; 3] {
        let f = 0.1
            * (1.0 - (s / 0.085).powi(2) - (u / 0.12).powi(2))
                .max(0.0)
                .sqrt();
        let (sn, cs) = yaw.sin_cos();
        [
            center[0] + f * cs - s * sn,
            center[1] + f * sn + s * cs,
            center[2] + u,
        ]
    }

    #[test]
    fn irises_are_dark_cheeks_are_skin_and_the_face_turns_with_the_yaw() {
        let c = [1.0, 2.0, 1.6];
        let st = DEFAULT_STYLE;
        for yaw in [0.0, 1.0, -2.5] {
            for side in [-1.0, 1.0] {
                let eye = albedo(
                    front(c, yaw, side * st.eye_s, st.eye_u),
                    c,
                    yaw,
                    SKIN,
                    HAIR,
                    &st,
                );
                assert!(eye[0] < 0.05, "yaw {yaw}: iris {eye:?}");
            }
            let cheek = albedo(front(c, yaw, 0.04, -0.03), c, yaw, SKIN, HAIR, &st);
            assert_eq!(cheek, SKIN, "yaw {yaw}");
            let crown = albedo(front(c, yaw, 0.0, 0.1), c, yaw, SKIN, HAIR, &st);
            assert_eq!(crown, HAIR);
        }
    }

    #[test]
    fn the_back_of_the_head_is_hair_and_shows_no_eyes() {
        let c = [0.0, 0.0, 1.6];
        // the point behind the centre at eye height
        let back = albedo([-0.1, 0.0, 1.6], c, 0.0, SKIN, HAIR, &DEFAULT_STYLE);
        assert_eq!(back, HAIR);
    }

    #[test]
    fn a_feature_edge_is_soft_over_the_edge_width() {
        let e = Ellipse {
            s: 0.0,
            u: 0.0,
            rs: 0.02,
            ru: 0.02,
        };
        assert_eq!(e.cover(0.0, 0.0), 1.0);
        assert!((e.cover(0.02, 0.0) - 0.5).abs() < 1e-6);
        assert_eq!(e.cover(0.02 + EDGE_M, 0.0), 0.0);
    }
}

//! Probe (development aid, not part of the pipeline): render one person's painted face
//! (`synth::face`) at several distances and yaws with the BIRON camera (320x240, 48.8°, at
//! 1.41 m) and run the frontal face detector (`vision::faces`) on each frame; prints the
//! detections (width, score) per distance and yaw and saves the frontal frames as PNGs.
//!
//! Usage: `cargo run --release --example face_probe -- OUT_DIR [thresh=2.0] [key=value ...]`
//! where each key is a `FaceStyle` field (e.g. `hairline_u=0.07 socket_shade=0.4`).

use nalgebra::{Isometry3, Translation3};
use peopletrack::geometry::{
    self,
    camera::{CameraModel, Pinhole},
};
use peopletrack::synth::face::{DEFAULT_STYLE, FaceStyle};
use peopletrack::synth::person::{Body, PersonState};
use peopletrack::synth::render::{Camera, FrameInput};
use peopletrack::synth::{Scenario, world::World};
use peopletrack::vision::faces::{FaceDetector, FaceParams, grey_from_rgb};
use peopletrack::vision::view::ImageView;

fn set(st: &mut FaceStyle, key: &str, v: f64) -> Result<(), String> {
    let f = v as f32;
    match key {
        "hairline_u" => st.hairline_u = v,
        "eye_s" => st.eye_s = v,
        "eye_u" => st.eye_u = v,
        "socket_rs" => st.socket_rs = v,
        "socket_ru" => st.socket_ru = v,
        "socket_shade" => st.socket_shade = f,
        "white_rs" => st.white_rs = v,
        "white_ru" => st.white_ru = v,
        "white" => st.white = f,
        "iris_r" => st.iris_r = v,
        "brow_du" => st.brow_du = v,
        "brow_rs" => st.brow_rs = v,
        "brow_ru" => st.brow_ru = v,
        "brow_shade" => st.brow_shade = f,
        "nose_u" => st.nose_u = v,
        "nose_rs" => st.nose_rs = v,
        "nose_ru" => st.nose_ru = v,
        "nose_shade" => st.nose_shade = f,
        "lips_u" => st.lips_u = v,
        "lips_rs" => st.lips_rs = v,
        "lips_ru" => st.lips_ru = v,
        _ => return Err(format!("unknown style key {key}")),
    }
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let out = args
        .first()
        .ok_or("usage: face_probe OUT_DIR [thresh=T] [key=value ...]")?;
    std::fs::create_dir_all(out)?;
    let mut style = DEFAULT_STYLE;
    let mut thresh = 2.0;
    let mut width = 320u32;
    let mut min_face = 20u32;
    for a in &args[1..] {
        let (k, v) = a.split_once('=').ok_or("arguments are key=value")?;
        let v: f64 = v.parse()?;
        if k == "thresh" {
            thresh = v;
        } else if k == "width" {
            width = v as u32;
        } else if k == "minface" {
            min_face = v as u32;
        } else {
            set(&mut style, k, v)?;
        }
    }
    let style: &'static FaceStyle = Box::leak(Box::new(style));
    let (s, _) = Scenario::load(
        std::path::Path::new("datasets/biron_home/scenario.toml"),
        "quick",
    )?;
    let world = World::build(&s, 0);
    let height = width * 3 / 4;
    let cam = Camera::new(
        "c",
        CameraModel::Pinhole(Pinhole::from_fov(width, height, 48.8)),
        2.0,
        None,
        0,
    );
    let pose = geometry::pose_xyz_rpy([2.5, 3.0, 1.41], [0.0, 0.0, 0.0])
        * Isometry3::from_parts(Translation3::identity(), geometry::body_from_optical());
    let mut det = FaceDetector::new(FaceParams {
        score_thresh: thresh,
        min_face_px: min_face,
        ..FaceParams::default()
    })?;
    let skins = [[224, 172, 140], [198, 140, 105], [150, 100, 70]];
    for (si, skin) in skins.iter().enumerate() {
        let body = Body {
            id: 1,
            height: 1.75,
            width: 0.2,
            leg_radius: 0.065,
            upper: [40, 90, 160],
            lower: [40, 40, 50],
            skin: *skin,
            hair: [60, 42, 30],
            hat: None,
            hands: false,
        };
        for d in [1.3, 1.8, 2.4, 3.0] {
            let clock = std::time::Instant::now();
            let mut line = format!("skin {si} d {d}:");
            for yaw_deg in [0.0f64, 10.0, 20.0, 30.0, 45.0, 60.0, 90.0, 180.0] {
                let st = PersonState {
                    x: 2.5 + d,
                    y: 3.0,
                    heading: std::f64::consts::PI,
                    speed: 0.0,
                    vx: 0.0,
                    vy: 0.0,
                    phase: 0.0,
                };
                let mut prims = Vec::new();
                body.primitives_with_face_style(
                    &st,
                    std::f64::consts::PI + yaw_deg.to_radians(),
                    style,
                    &mut prims,
                );
                let f = cam.render(&FrameInput {
                    world: &world,
                    dynamic: &prims,
                    shadows: &[],
                    t: 0.0,
                    pose,
                    noise_key: 7,
                });
                let (w, h) = (width as usize, height as usize);
                let grey = grey_from_rgb(ImageView::new(&f.rgb, w, h, 3)?)?;
                let faces = det.detect(ImageView::new(&grey, w, h, 1)?)?;
                line += &format!(
                    " {yaw_deg}:{}",
                    faces
                        .iter()
                        .map(|f| format!("[{:.0}px {:.1}]", f.width, f.score))
                        .collect::<Vec<_>>()
                        .join("")
                );
                if yaw_deg == 0.0 {
                    image::RgbImage::from_raw(width, height, f.rgb.clone())
                        .ok_or("frame")?
                        .save(format!("{out}/face_{si}_{d}.png"))?;
                }
            }
            println!(
                "{line} ({:.2} s per frame)",
                clock.elapsed().as_secs_f64() / 8.0
            );
        }
    }
    Ok(())
}

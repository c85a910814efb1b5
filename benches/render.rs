//! Rendering throughput of the synthesizer: one 352x288 frame of the multicam_office scene
//! (desks, four people) on ONE thread, for a fixed camera (static layer cached) and for a camera
//! on a moving robot (everything ray-cast), with and without JPEG encoding. The goal is
//! at least 1 camera-second at 25 fps per core-second, i.e. <= 40 ms per frame on one thread.

use std::path::PathBuf;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Point3;
use peopletrack::geometry::camera::{CameraModel, Pinhole};
use peopletrack::geometry::look_at;
use peopletrack::synth::person::{Body, PersonState};
use peopletrack::synth::render::{Camera, FrameInput};
use peopletrack::synth::scenario::Scenario;
use peopletrack::synth::world::{Primitive, World};

fn bench(c: &mut Criterion) {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("datasets/multicam_office/scenario.toml");
    let (s, _) = Scenario::load(&path, "quick").expect("scenario");
    let world = World::build(&s, 0);
    let model = CameraModel::Pinhole(Pinhole {
        dist: [-0.24, 0.06, 0.0, 0.0, 0.0],
        ..Pinhole::from_fov(352, 288, 78.0)
    });
    let pose = look_at(Point3::new(0.15, 0.15, 2.85), Point3::new(4.0, 4.25, 0.7));
    let mut dynamic: Vec<Primitive> = Vec::new();
    world.moving_at(3.0, &mut dynamic);
    let mut shadows = Vec::new();
    for (k, p) in s.people.iter().enumerate() {
        let body = Body::from_spec(p);
        let st = PersonState {
            x: 2.0 + 1.2 * k as f64,
            y: 4.4,
            heading: 0.3,
            speed: 1.1,
            vx: 1.0,
            vy: 0.3,
            phase: k as f64,
        };
        body.primitives(&st, &mut dynamic);
        shadows.push([st.x, st.y, body.shadow_radius()]);
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    let fixed = pool.install(|| Camera::new("cam_0", model.clone(), 2.0, Some((pose, &world)), 0));
    let moving = Camera::new("cam_0", model, 2.0, None, 0);
    let input = FrameInput {
        world: &world,
        dynamic: &dynamic,
        shadows: &shadows,
        t: 3.0,
        pose,
        noise_key: 7,
    };
    let mut g = c.benchmark_group("render_352x288_one_thread");
    g.sample_size(20);
    g.bench_function("fixed_camera", |b| {
        b.iter(|| pool.install(|| fixed.render(&input)))
    });
    g.bench_function("moving_camera", |b| {
        b.iter(|| pool.install(|| moving.render(&input)))
    });
    g.bench_function("fixed_camera_with_jpeg", |b| {
        b.iter(|| {
            pool.install(|| {
                let f = fixed.render(&input);
                let mut buf = Vec::new();
                image::codecs::jpeg::JpegEncoder::new_with_quality(&mut buf, 92)
                    .encode(&f.rgb, f.width, f.height, image::ExtendedColorType::Rgb8)
                    .expect("jpeg");
                buf
            })
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

//! Seed 004 throughput (`make bench`): frames per second of the Gabor background stage alone
//! (16 filters + running average + MAD threshold, one 352x288 camera, decoded frames), and of
//! the whole `s004_mohedano_multicam` per-session processing — JPEG decode, Gabor background,
//! template detection, 2-D graph matching for four cameras (cameras in parallel), then the 3-D
//! cylinder stage — reported per camera frame (camera-frames/s: divide by four for
//! multi-camera frames/s).
//!
//! The input is a 2 s session of the `multicam_office` scenario (four 352x288 cameras at
//! 25 fps), synthesized once into `target/bench-data/multicam_office/` when absent. The
//! pipeline runs with the file's parameters except: no ground-truth-box run and no `N_app`
//! sweep (evaluation extras; the configured run and its `E_m` counterpart remain).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use peopletrack::log::msgs::CompressedImage;
use peopletrack::log::{SessionLog, read_topic};
use peopletrack::pipelines::s004_mohedano_multicam::{MulticamCylinders, Params};
use peopletrack::run::config::SessionRef;
use peopletrack::run::{Experiment, Session};
use peopletrack::synth::{SynthOptions, synthesize};
use peopletrack::vision::gabor::{GaborBackground, GaborBank, GaborParams, Mask, Update};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The bench session (synthesized when absent).
fn session() -> PathBuf {
    let dir = root().join("target/bench-data/multicam_office");
    let log = dir.join("multicam_office_00.mcap");
    if log.exists() {
        return log;
    }
    std::fs::create_dir_all(&dir).expect("mkdir");
    let text = std::fs::read_to_string(root().join("datasets/multicam_office/scenario.toml"))
        .expect("scenario");
    let text = text.replace(
        "[profiles.quick]\nsessions = 2\nduration_s = 12.0\n",
        "[profiles.quick]\nsessions = 1\nduration_s = 2.0\n",
    );
    let scenario = dir.join("scenario.toml");
    std::fs::write(&scenario, text).expect("scenario");
    let s = synthesize(
        &scenario,
        &SynthOptions {
            profile: "quick".into(),
            out: Some(dir.clone()),
            progress: None,
        },
    )
    .expect("synthesizes");
    s.sessions[0].clone()
}

fn params() -> Params {
    let text = std::fs::read_to_string(root().join("pipelines/s004_mohedano_multicam.toml"))
        .expect("pipeline");
    let v: toml::Value = toml::from_str(&text).expect("toml");
    let mut p: Params = v
        .get("params")
        .cloned()
        .expect("[params]")
        .try_into()
        .expect("params");
    p.gt_boxes = false;
    p.n_app_sweep = Vec::new();
    p.write_tracks = String::new();
    p
}

fn frames_of(path: &Path, topic: &str) -> Vec<image::RgbImage> {
    let log = SessionLog::open(path).expect("open");
    read_topic::<CompressedImage>(&log, topic)
        .expect("topic")
        .map(|r| {
            let (_, img) = r.expect("decodes");
            peopletrack::log::image::decode_compressed(&img)
                .expect("jpeg")
                .to_rgb8()
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let path = session();
    let p = params();

    // Gabor background alone, one camera, frames decoded beforehand
    let frames = frames_of(&path, "/cam_0/image_raw/compressed");
    let bank = GaborBank::new(GaborParams {
        sigma_px: p.gabor_sigma_px,
        wavelength_px: p.gabor_wavelength_px,
    })
    .expect("bank");
    // eq. 2 as printed (every pixel learns) and the selective update of the default pipeline
    let selective = Update::Selective {
        foreground_alpha: p.foreground_alpha,
        dilate_px: bank.radius() as u32,
    };
    let mut g = c.benchmark_group("multicam_gabor_background");
    g.throughput(Throughput::Elements(1));
    g.sample_size(30);
    for (name, update) in [
        ("352x288_frame_eq2_all", Update::All),
        ("352x288_frame_selective", selective),
    ] {
        let mut model = GaborBackground::new(bank.clone(), p.alpha, p.mad_k)
            .and_then(|m| m.with_update(update))
            .expect("model");
        let mut mask = Mask::default();
        for f in &frames {
            model.apply(f, &mut mask).expect("warm-up");
        }
        let mut k = 0usize;
        g.bench_function(name, |b| {
            b.iter(|| {
                let s = model
                    .apply(&frames[k % frames.len()], &mut mask)
                    .expect("apply");
                k += 1;
                s.foreground
            })
        });
    }
    g.finish();

    // the whole per-session processing (4 cameras)
    let info = SessionRef {
        dataset: "multicam_office".into(),
        name: "bench".into(),
        path: path.clone(),
    };
    let camera_frames: u64 = {
        let log = SessionLog::open(&path).expect("open");
        p.cameras
            .iter()
            .map(|cam| {
                read_topic::<CompressedImage>(&log, &format!("/{cam}/image_raw/compressed"))
                    .expect("topic")
                    .count() as u64
            })
            .sum()
    };
    let mut g = c.benchmark_group("multicam_pipeline");
    g.throughput(Throughput::Elements(camera_frames));
    g.sample_size(10);
    g.bench_function("per_camera_frame", |b| {
        b.iter(|| {
            let s = Session {
                log: SessionLog::open(&path).expect("open"),
                info: info.clone(),
            };
            MulticamCylinders::process(&s, &p, &BTreeMap::new(), &peopletrack::progress::Silent)
                .expect("process")
                .len()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

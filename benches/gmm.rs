//! Adaptive GMM throughput (frames/s), OpenCV MOG2's default parameters, on 1 and 2 threads:
//! the synthetic RGB scene at 320x240 and 640x480 (mostly static: the common case), and the
//! real Wallflower WavingTrees clip (160x120, swaying trees: many components per pixel, many
//! new ones) when `../shared/real` is present. Each measured frame continues a model that
//! has already seen the whole clip once. The clips are written to `target/bench-data/`
//! with an index, `gmm_clips.json`, so `tools/bench_opencv_mog2.py` times OpenCV on the same
//! bytes; `make bench-gmm` prints the ratios.

use std::path::PathBuf;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use peopletrack::vision::synthetic::Scene;
use peopletrack::vision::{AdaptiveGmm, GmmParams, ImageView};
use serde_json::json;

/// Frames per synthetic clip (the benchmark cycles through them).
const CLIP: usize = 64;

struct Clip {
    name: String,
    width: usize,
    height: usize,
    frames: Vec<Vec<u8>>,
}

fn clips() -> Vec<Clip> {
    let mut out: Vec<Clip> = [(320, 240), (640, 480)]
        .into_iter()
        .map(|(width, height)| {
            let scene = Scene {
                width,
                height,
                seed: 2004,
            };
            Clip {
                name: format!("{width}x{height}"),
                width,
                height,
                frames: (0..CLIP).map(|t| scene.frame(t)).collect(),
            }
        })
        .collect();
    let trees = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/real/wallflower_waving_trees/WavingTrees");
    let frames: Vec<Vec<u8>> = (0..)
        .map(|k| trees.join(format!("b{k:05}.bmp")))
        .take_while(|p| p.exists())
        .filter_map(|p| image::open(p).ok().map(|i| i.to_rgb8().into_raw()))
        .collect();
    if frames.len() > 1 {
        out.push(Clip {
            name: "waving_trees".into(),
            width: 160,
            height: 120,
            frames,
        });
    }
    out
}

/// Write every clip's frames and an index for the Python peer.
fn export(clips: &[Clip]) {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/bench-data");
    std::fs::create_dir_all(&dir).expect("bench-data dir");
    let mut index = serde_json::Map::new();
    for c in clips {
        let file = format!("gmm_frames_{}.bin", c.name);
        std::fs::write(dir.join(&file), c.frames.concat()).expect("write frames");
        index.insert(
            c.name.clone(),
            json!({"width": c.width, "height": c.height, "frames": c.frames.len(), "file": file}),
        );
    }
    std::fs::write(
        dir.join("gmm_clips.json"),
        serde_json::to_string_pretty(&index).expect("json"),
    )
    .expect("write index");
}

fn bench(c: &mut Criterion) {
    let clips = clips();
    export(&clips);
    let mut g = c.benchmark_group("gmm");
    g.sample_size(20);
    g.throughput(Throughput::Elements(1));
    for clip in &clips {
        let (w, h) = (clip.width, clip.height);
        let views: Vec<ImageView<'_>> = clip
            .frames
            .iter()
            .map(|f| ImageView::new(f, w, h, 3).expect("frame"))
            .collect();
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            let mut gmm = AdaptiveGmm::new(GmmParams::default()).expect("params");
            let mut mask = vec![0u8; w * h];
            for v in &views {
                pool.install(|| gmm.apply(*v, None, &mut mask))
                    .expect("apply");
            }
            let mut t = 0;
            // Each frame is one `install` on a pool of `threads` (as OpenCV dispatches one
            // parallel_for_ per frame).
            g.bench_function(format!("adaptive_{}_t{threads}", clip.name), |b| {
                b.iter(|| {
                    pool.install(|| gmm.apply(views[t % views.len()], None, &mut mask))
                        .expect("apply");
                    t += 1;
                })
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

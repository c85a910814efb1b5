//! Adaptive GMM throughput (frames/s) on the synthetic RGB scene at 320x240 and 640x480, on
//! 1 and 2 threads. Each measured frame continues a model that has already seen the whole
//! clip once, so the state is in steady use. The frames are written to
//! `target/bench-data/gmm_frames_WxH.bin` so `tools/bench_opencv_mog2.py` times OpenCV's
//! MOG2 on the same bytes; `make bench-gmm` prints the ratios.

use std::path::PathBuf;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use peopletrack::vision::synthetic::Scene;
use peopletrack::vision::{AdaptiveGmm, GmmParams, ImageView};

/// Frames per clip (the benchmark cycles through them).
const CLIP: usize = 64;

fn clip(width: usize, height: usize) -> Vec<Vec<u8>> {
    let scene = Scene {
        width,
        height,
        seed: 2004,
    };
    let frames: Vec<Vec<u8>> = (0..CLIP).map(|t| scene.frame(t)).collect();
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/bench-data");
    std::fs::create_dir_all(&dir).expect("bench-data dir");
    std::fs::write(
        dir.join(format!("gmm_frames_{width}x{height}.bin")),
        frames.concat(),
    )
    .expect("write frames");
    frames
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("gmm");
    g.sample_size(20);
    g.throughput(Throughput::Elements(1));
    for (w, h) in [(320, 240), (640, 480)] {
        let frames = clip(w, h);
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            pool.install(|| {
                let mut gmm = AdaptiveGmm::new(GmmParams::default()).expect("params");
                let mut mask = vec![0u8; w * h];
                let views: Vec<ImageView<'_>> = frames
                    .iter()
                    .map(|f| ImageView::new(f, w, h, 3).expect("frame"))
                    .collect();
                for v in &views {
                    gmm.apply(*v, None, &mut mask).expect("apply");
                }
                let mut t = 0;
                g.bench_function(format!("adaptive_{w}x{h}_t{threads}"), |b| {
                    b.iter(|| {
                        gmm.apply(views[t % CLIP], None, &mut mask).expect("apply");
                        t += 1;
                    })
                });
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

//! Appearance-model training (seed 000, section 6.1): the paper's protocol of 10 random 30/70
//! splits, a 3-4-1 network trained by online back-propagation at learning rate 0.3, on 684
//! frames (the paper's count) of depth-cue-like features. Epochs are cut to 200 (the pipeline
//! uses 2000) so scikit-learn, which runs the same per-sample SGD loop in Python, finishes in
//! seconds. The data and the training indices of every split go to
//! `target/bench-data/mlp/` so `tools/bench_sklearn_mlp.py` trains MLPRegressor on the same
//! rows; `make bench-mlp` prints the ratio and both models' test errors.

use criterion::{Criterion, criterion_group, criterion_main};
use peopletrack::learn::mlp::{Regressor, TrainSpec};
use peopletrack::synth::rng::stream;
use rand::RngExt;
use rand::seq::SliceRandom;
use rayon::prelude::*;
use serde_json::json;

const FRAMES: usize = 684;
const SPLITS: usize = 10;
const SPEC: TrainSpec = TrainSpec {
    hidden: 4,
    learning_rate: 0.3,
    epochs: 200,
};

/// Features shaped like the omni cues: width and pixels fall with distance, the apparent
/// distance grows with it; all with noise.
fn data() -> (Vec<Vec<f64>>, Vec<f64>) {
    let mut r = stream(2003, "bench-mlp", 0);
    let mut noise = move |s: f64| s * (r.random::<f64>() - 0.5) * 2.0;
    let (mut xs, mut ys) = (Vec::new(), Vec::new());
    for k in 0..FRAMES {
        let d = 0.8 + 4.0 * (k as f64 * 0.618_034).fract();
        xs.push(vec![
            60.0 / d + noise(3.0),
            12.0 * d + noise(4.0),
            3000.0 / (d * d) + noise(80.0),
        ]);
        ys.push(d);
    }
    (xs, ys)
}

fn splits() -> Vec<Vec<usize>> {
    (0..SPLITS)
        .map(|s| {
            let mut v: Vec<usize> = (0..FRAMES).collect();
            v.shuffle(&mut stream(7, "split", s as u64));
            v.truncate((FRAMES as f64 * 0.3).round() as usize);
            v
        })
        .collect()
}

fn train(xs: &[Vec<f64>], ys: &[f64], split: &[usize], s: usize) -> Regressor {
    let tx: Vec<Vec<f64>> = split.iter().map(|i| xs[*i].clone()).collect();
    let ty: Vec<f64> = split.iter().map(|i| ys[*i]).collect();
    Regressor::fit(&tx, &ty, SPEC, &mut stream(7, "net", s as u64)).expect("valid training data")
}

fn test_error(xs: &[Vec<f64>], ys: &[f64], split: &[usize], m: &Regressor) -> f64 {
    let test: Vec<usize> = (0..FRAMES).filter(|i| !split.contains(i)).collect();
    test.iter()
        .map(|i| (m.predict(&xs[*i]) - ys[*i]).abs())
        .sum::<f64>()
        / test.len() as f64
}

fn bench(c: &mut Criterion) {
    let (xs, ys) = data();
    let sp = splits();
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/bench-data/mlp");
    std::fs::create_dir_all(&dir).expect("bench-data dir");
    let mut csv = String::from("width,apparent_distance,pixels,distance\n");
    for (x, y) in xs.iter().zip(&ys) {
        csv.push_str(&format!("{},{},{},{}\n", x[0], x[1], x[2], y));
    }
    std::fs::write(dir.join("data.csv"), csv).expect("write data");
    let errors: Vec<f64> = sp
        .iter()
        .enumerate()
        .map(|(s, split)| test_error(&xs, &ys, split, &train(&xs, &ys, split, s)))
        .collect();
    let meta = json!({
        "splits": sp,
        "hidden": SPEC.hidden,
        "learning_rate": SPEC.learning_rate,
        "epochs": SPEC.epochs,
        "ours_test_mae_per_split": errors,
    });
    std::fs::write(
        dir.join("protocol.json"),
        serde_json::to_vec_pretty(&meta).expect("json"),
    )
    .expect("write protocol");

    let mut g = c.benchmark_group("mlp");
    g.sample_size(10);
    g.bench_function("ten_splits_sequential", |b| {
        b.iter(|| {
            sp.iter()
                .enumerate()
                .map(|(s, split)| train(&xs, &ys, split, s))
                .collect::<Vec<_>>()
        });
    });
    g.bench_function("ten_splits_rayon", |b| {
        b.iter(|| {
            sp.par_iter()
                .enumerate()
                .map(|(s, split)| train(&xs, &ys, split, s))
                .collect::<Vec<_>>()
        });
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

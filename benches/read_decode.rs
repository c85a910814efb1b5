//! Read + decode throughput: every message of a log, fully decoded (dynamic CDR), on the real
//! laser logs and on a large image log; `tools/bench_python_read.py` times Python
//! `mcap-ros2-support` on the same files and `tools/bench_compare.py` prints the ratios.

use std::path::{Path, PathBuf};

use criterion::{Criterion, criterion_group, criterion_main};
use peopletrack::Nanos;
use peopletrack::log::msgs::{Header, Image, LaserScan};
use peopletrack::log::{Decoders, SessionLog, SessionWriter, WriterOptions, read_topic};

fn real(name: &str) -> Option<PathBuf> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join(format!("../shared/real/laser/{name}/{name}.mcap"));
    p.exists().then_some(p)
}

/// 100 frames of 640x480 rgb8 (a smooth scene plus sensor noise), written once.
fn image_log() -> PathBuf {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/bench-data/images_640x480.mcap");
    if path.exists() {
        return path;
    }
    let mut w = SessionWriter::create(&path, &WriterOptions::default()).expect("create");
    let ch = w.add_ros2::<Image>("/cam_0/image_raw").expect("channel");
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    for i in 0..100u64 {
        let mut data = Vec::with_capacity(640 * 480 * 3);
        for y in 0..480u64 {
            for x in 0..640u64 {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                let noise = state >> 61;
                data.push(((x + i * 3) % 256 / 2 + noise) as u8);
                data.push(((y * 2) % 256 / 2 + noise) as u8);
                data.push(((x + y) % 256 / 2 + noise) as u8);
            }
        }
        let t = Nanos(1_700_000_000_000_000_000 + i * 40_000_000);
        let img = Image {
            header: Header::new(t, "cam_0"),
            height: 480,
            width: 640,
            encoding: "rgb8".into(),
            step: 640 * 3,
            data,
            ..Default::default()
        };
        w.write(ch, t, &img).expect("write");
    }
    w.finish().expect("finish")
}

fn decode_all(path: &Path) -> usize {
    let log = SessionLog::open(path).expect("opens");
    let mut dec = Decoders::new();
    let mut n = 0;
    for m in log.messages().expect("stream") {
        let m = m.expect("message");
        std::hint::black_box(dec.value(&log, &m).expect("decodes"));
        n += 1;
    }
    n
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("read_decode");
    g.sample_size(10);
    for name in [
        "general_tracking_moving_1",
        "person_following_outdoor_1",
        "demo_stationary_simple_environment",
    ] {
        if let Some(p) = real(name) {
            g.bench_function(name, |b| b.iter(|| decode_all(&p)));
        }
    }
    let images = image_log();
    g.bench_function("images_640x480", |b| b.iter(|| decode_all(&images)));
    if let Some(p) = real("general_tracking_moving_1") {
        g.bench_function("general_tracking_moving_1_typed_scans", |b| {
            b.iter(|| {
                let log = SessionLog::open(&p).expect("opens");
                read_topic::<LaserScan>(&log, "/scan")
                    .expect("scan")
                    .map(|s| s.expect("ok").1.ranges.len())
                    .sum::<usize>()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

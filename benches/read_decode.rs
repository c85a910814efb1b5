//! Read + decode throughput: every message of a log, fully decoded, on the real laser logs and
//! on a large image log; `tools/bench_python_read.py` times Python `mcap-ros2-support` on the
//! same files and `tools/bench_compare.py` prints the ratios.
//!
//! Rows per log: `NAME` (the typed fast paths where a channel has one, flat decoding of the
//! other CDR types — what `Decoders::decode` does), `NAME_dynamic` (every message through the value
//! tree) and `NAME_limit`: the physical limit, the file read, every chunk decompressed
//! (zstd/lz4) and each message payload copied once, with no ordering, no index and no decoding
//! (a linear walk over the MCAP records written here, independent of `log::reader`).

use std::path::{Path, PathBuf};

use criterion::measurement::WallTime;
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
        std::hint::black_box(dec.decode(&log, &m).expect("decodes"));
        n += 1;
    }
    n
}

fn decode_all_dynamic(path: &Path) -> usize {
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

fn le_u64(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().expect("8 bytes"))
}

/// Copy the payload of every message record in `records` (opcode, u64 length, body) once.
fn copy_messages(records: &[u8], out: &mut Vec<u8>) -> usize {
    let (mut at, mut n) = (0, 0);
    while at + 9 <= records.len() {
        let (op, len) = (records[at], le_u64(records, at + 1) as usize);
        let body = &records[at + 9..at + 9 + len];
        if op == 0x05 {
            // channel u16, sequence u32, log_time u64, publish_time u64, data
            out.clear();
            out.extend_from_slice(&body[22..]);
            std::hint::black_box(&out);
            n += 1;
        }
        at += 9 + len;
    }
    n
}

/// The physical limit of `decode_all`: read the file, decompress every chunk, copy every
/// message payload once.
fn decompress_and_copy(path: &Path) -> usize {
    let file = std::fs::read(path).expect("reads");
    let mut zstd = zstd::bulk::Decompressor::new().expect("zstd");
    let (mut chunk, mut payload) = (Vec::new(), Vec::new());
    let (mut at, mut n) = (8, 0);
    while at + 9 <= file.len() {
        let (op, len) = (file[at], le_u64(&file, at + 1) as usize);
        let body = &file[at + 9..at + 9 + len];
        match op {
            0x05 => n += copy_messages(&file[at..at + 9 + len], &mut payload),
            0x06 => {
                let size = le_u64(body, 16) as usize;
                let clen = u32::from_le_bytes(body[28..32].try_into().expect("4")) as usize;
                let compression = &body[32..32 + clen];
                let rlen = le_u64(body, 32 + clen) as usize;
                let records = &body[40 + clen..40 + clen + rlen];
                chunk.clear();
                chunk.reserve(size);
                match compression {
                    b"" => chunk.extend_from_slice(records),
                    b"zstd" => {
                        zstd.decompress_to_buffer(records, &mut chunk)
                            .expect("zstd");
                    }
                    b"lz4" => {
                        use std::io::Read;
                        lz4::Decoder::new(records)
                            .and_then(|mut d| d.read_to_end(&mut chunk))
                            .expect("lz4");
                    }
                    other => panic!("compression {:?}", String::from_utf8_lossy(other)),
                }
                n += copy_messages(&chunk, &mut payload);
            }
            0x0F | 0x02 => break, // data end, footer
            _ => {}
        }
        at += 9 + len;
    }
    n
}

fn rows(g: &mut criterion::BenchmarkGroup<'_, WallTime>, name: &str, p: &Path) {
    assert_eq!(
        decode_all(p),
        decompress_and_copy(p),
        "{name}: same messages"
    );
    g.bench_function(name, |b| b.iter(|| decode_all(p)));
    g.bench_function(format!("{name}_dynamic"), |b| {
        b.iter(|| decode_all_dynamic(p))
    });
    g.bench_function(format!("{name}_limit"), |b| {
        b.iter(|| decompress_and_copy(p))
    });
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
            rows(&mut g, name, &p);
        }
    }
    rows(&mut g, "images_640x480", &image_log());
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

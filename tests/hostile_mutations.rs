//! Seeded mutation runs (a stable-toolchain stand-in for `cargo fuzz`, which needs nightly and
//! is not set up here): schema texts, CDR payloads and whole MCAP files are mutated thousands
//! of times; every result must be a value or an error — a panic fails the test. Deterministic:
//! one fixed seed, fixed counts (`PEOPLETRACK_MUTATION_ROUNDS=N` runs N times as many, for a
//! longer search by hand).

use std::path::Path;

use peopletrack::Nanos;
use peopletrack::log::ros2msg::Registry;
use peopletrack::log::{Compression, Decoders, SessionLog, SessionWriter, WriterOptions, cdr};

/// How many times the default counts to run (1 unless set by hand).
fn rounds() -> usize {
    std::env::var("PEOPLETRACK_MUTATION_ROUNDS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(1)
}

/// xorshift64*: a fixed, seeded stream.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// One random edit: flip, replace with an interesting byte, insert, delete, or repeat a span.
fn mutate(rng: &mut Rng, data: &mut Vec<u8>, interesting: &[u8]) {
    let at = rng.below(data.len());
    match rng.below(5) {
        0 if !data.is_empty() => data[at] ^= 1 << rng.below(8),
        1 if !data.is_empty() => data[at] = interesting[rng.below(interesting.len())],
        2 => data.insert(
            at.min(data.len()),
            interesting[rng.below(interesting.len())],
        ),
        3 if !data.is_empty() => {
            data.remove(at);
        }
        _ if !data.is_empty() => {
            let len = rng.below(16).min(data.len() - at);
            let span = data[at..at + len].to_vec();
            for (i, b) in span.into_iter().enumerate() {
                data.insert(at + i, b);
            }
        }
        _ => data.push(0),
    }
}

const TYPES: [&str; 6] = [
    "sensor_msgs/msg/LaserScan",
    "sensor_msgs/msg/CameraInfo",
    "tf2_msgs/msg/TFMessage",
    "nav_msgs/msg/Odometry",
    "vision_msgs/msg/Detection2DArray",
    "geometry_msgs/msg/PoseArray",
];

#[test]
fn mutated_schemas_and_cdr_payloads_never_panic() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let schema_bytes = b"[]<=09=#/\n \"'-xMSG:=====_";
    let mut parsed = 0;
    let mut runs = 0;
    for name in TYPES {
        let text = peopletrack::log::definitions::full_definition(name).expect("known");
        let reg = Registry::parse(name, &text).expect("parses");
        let zero = cdr::default_value(
            &reg,
            &peopletrack::log::ros2msg::BaseType::Msg(reg.root),
            peopletrack::log::ros2msg::ArrayKind::Single,
            None,
        );
        let payload = cdr::encode(&reg, &zero, cdr::Endian::Little).expect("encodes");
        for _ in 0..3_000 * rounds() {
            // a mutated schema, and the (mutated) zero message decoded against it
            let mut t = text.clone().into_bytes();
            for _ in 0..1 + rng.below(4) {
                mutate(&mut rng, &mut t, schema_bytes);
            }
            let mut p = payload.clone();
            for _ in 0..rng.below(4) {
                mutate(&mut rng, &mut p, &[0, 0xff, 0x7f, 0x80, 1, 4, 8]);
            }
            runs += 1;
            if let Ok(r) = Registry::parse(name, &String::from_utf8_lossy(&t)) {
                parsed += 1;
                if let Ok(v) = cdr::decode(&r, &p) {
                    let _ = v.to_json(Some(8));
                }
            }
            if let Ok(v) = cdr::decode(&reg, &p) {
                let _ = cdr::encode(&reg, &v, cdr::Endian::Big);
            }
        }
    }
    eprintln!("{runs} mutated schemas ({parsed} parsed) and payloads");
    assert_eq!(runs, 18_000 * rounds());
    assert!(
        parsed > 1_000,
        "mutations must keep some schemas valid: {parsed}"
    );
}

fn read_all(path: &Path, recover: bool) -> usize {
    let log = match if recover {
        SessionLog::open_recovering(path)
    } else {
        SessionLog::open(path)
    } {
        Ok(log) => log,
        Err(_) => return 0,
    };
    let mut dec = Decoders::new();
    let mut n = 0;
    if let Ok(stream) = log.messages() {
        for m in stream.flatten() {
            let _ = dec.value(&log, &m);
            n += 1;
        }
    }
    n
}

#[test]
fn mutated_mcap_files_never_panic_plain_or_recovering() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut rng = Rng(0x51_7cc1_b727_220a);
    let mut total = 0;
    for compression in [Compression::None, Compression::Zstd, Compression::Lz4] {
        let p = dir.path().join("seed.mcap");
        let options = WriterOptions {
            compression,
            chunk_size: 300,
            ..WriterOptions::default()
        };
        let mut w = SessionWriter::create(&p, &options).expect("create");
        let ch = w
            .add_ros2::<peopletrack::log::msgs::LaserScan>("/scan")
            .expect("channel");
        for i in 0..12u64 {
            let scan = peopletrack::log::msgs::LaserScan {
                ranges: (0..8).map(|k| (i + k) as f32).collect(),
                ..Default::default()
            };
            w.write(ch, Nanos(i * 1_000), &scan).expect("write");
        }
        let seed = std::fs::read(w.finish().expect("finish")).expect("read");
        let m = dir.path().join("mutant.mcap");
        for _ in 0..400 * rounds() {
            let mut data = seed.clone();
            for _ in 0..1 + rng.below(3) {
                mutate(&mut rng, &mut data, &[0, 0xff, 0x7f, 0x80, 1, 5, 6, 8]);
            }
            if rng.below(4) == 0 {
                data.truncate(rng.below(data.len()));
            }
            std::fs::write(&m, &data).expect("write");
            total += read_all(&m, false);
            total += read_all(&m, true);
        }
    }
    eprintln!("{} mutated files, {total} messages read", 1200 * rounds());
    assert!(total > 0);
}

//! Seed corpora for the `cargo fuzz` targets in `fuzz/` (`make fuzz` runs this first).
//!
//! `cargo run --example fuzz_seeds -- OUT_DIR LOG...` writes `OUT_DIR/<target>/<name>` for
//! each target from the given logs (the real ones in `../shared/real/laser` and the test
//! fixtures' kind): prefixes of each file (1, 8 and 32 KiB), and small whole logs re-written
//! from the first messages of each channel (zstd, lz4, unchunked without summary); each
//! schema record alone (`ros2msg_schema`); schema + one real payload (`cdr_decode`,
//! `protobuf_decode`). A small Foxglove protobuf log is made here with the Foxglove SDK, so
//! the protobuf target has seeds whatever logs are given. Pipeline-file seeds are copied by
//! the Makefile (`pipelines/*.toml`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use foxglove::Encode;
use foxglove::messages as fg;
use peopletrack::Nanos;
use peopletrack::log::{Compression, SessionLog, SessionWriter, WriterOptions};

/// Payloads over this size are left out of the seeds (images): libFuzzer works best on small
/// inputs, and the decoders' paths are the same.
const MAX_PAYLOAD: usize = 16 * 1024;
/// Messages kept per channel.
const PER_CHANNEL: usize = 3;

fn write(dir: &Path, name: &str, bytes: &[u8]) {
    std::fs::create_dir_all(dir).expect("seed folder");
    std::fs::write(dir.join(name), bytes).expect("write seed");
}

fn foxglove_log(path: &Path) {
    fn put<T: Encode>(w: &mut SessionWriter, topic: &str, msg: &T, t: u64) {
        let schema = T::get_schema().expect("foxglove types carry schemas");
        let ch = w
            .add_raw(
                topic,
                Some((&schema.name, &schema.encoding, &schema.data)),
                &T::get_message_encoding(),
            )
            .expect("channel");
        let mut buf = Vec::new();
        msg.encode(&mut buf).expect("encode");
        w.write_bytes(ch, Nanos(t), &buf).expect("write");
    }
    let ts = Some(fg::Timestamp::new(1_700_000_000, 250));
    let mut w = SessionWriter::create(path, &WriterOptions::default()).expect("create");
    let scan = fg::LaserScan {
        timestamp: ts,
        frame_id: "laser".into(),
        pose: None,
        start_angle: -1.0,
        end_angle: 1.0,
        ranges: vec![1.0, f64::NAN, f64::INFINITY, 2.0, 3.0],
        intensities: vec![],
    };
    put(&mut w, "/scan", &scan, 1);
    let image = fg::RawImage {
        timestamp: ts,
        frame_id: "cam".into(),
        width: 2,
        height: 1,
        encoding: "rgb8".into(),
        step: 6,
        data: vec![1, 2, 3, 4, 5, 6].into(),
    };
    put(&mut w, "/cam/image", &image, 2);
    let v = |x, y| Some(fg::Vector3 { x, y, z: 0.0 });
    let q = Some(fg::Quaternion {
        x: 0.0,
        y: 0.0,
        z: 0.0,
        w: 1.0,
    });
    let tf = fg::FrameTransforms {
        transforms: vec![fg::FrameTransform {
            timestamp: ts,
            parent_frame_id: "map".into(),
            child_frame_id: "base_link".into(),
            translation: v(1.0, 2.0),
            rotation: q,
        }],
    };
    put(&mut w, "/tf", &tf, 3);
    let pose = fg::PoseInFrame {
        timestamp: ts,
        frame_id: "map".into(),
        pose: Some(fg::Pose {
            position: v(3.0, 4.0),
            orientation: q,
        }),
    };
    put(&mut w, "/pose", &pose, 4);
    w.finish().expect("finish");
}

/// The first messages of each channel of `log` (small payloads only), as
/// `(topic, schema, message encoding, [(time, payload)])`.
type Kept = Vec<(
    String,
    Option<(String, String, Vec<u8>)>,
    String,
    Vec<(Nanos, Vec<u8>)>,
)>;

fn first_messages(log: &SessionLog) -> Kept {
    let mut by_channel: BTreeMap<u16, usize> = BTreeMap::new();
    let mut out: Kept = Vec::new();
    let Ok(stream) = log.messages() else {
        return out;
    };
    for m in stream {
        let Ok(m) = m else { break };
        if m.data.len() > MAX_PAYLOAD {
            continue;
        }
        let i = *by_channel.entry(m.channel.id).or_insert_with(|| {
            let ch = &m.channel;
            let schema = ch
                .schema
                .as_ref()
                .map(|s| (s.name.clone(), s.encoding.clone(), s.data.clone()));
            out.push((
                ch.topic.clone(),
                schema,
                ch.message_encoding.clone(),
                Vec::new(),
            ));
            out.len() - 1
        });
        if out[i].3.len() < PER_CHANNEL {
            out[i].3.push((m.log_time, m.data.to_vec()));
        }
    }
    out
}

fn rewrite(kept: &Kept, path: &Path, options: &WriterOptions) {
    let mut w = SessionWriter::create(path, options).expect("create");
    for (topic, schema, encoding, msgs) in kept {
        let schema = schema
            .as_ref()
            .map(|(n, e, d)| (n.as_str(), e.as_str(), d.as_slice()));
        let ch = w.add_raw(topic, schema, encoding).expect("channel");
        for (t, data) in msgs {
            w.write_bytes(ch, *t, data).expect("write");
        }
    }
    w.finish().expect("finish");
}

fn seeds_of(out: &Path, tag: &str, log_path: &Path, scratch: &Path) {
    let bytes = std::fs::read(log_path).expect("read log");
    for kib in [1, 8, 32] {
        let n = (kib * 1024).min(bytes.len());
        write(
            &out.join("mcap_reader"),
            &format!("{tag}-head{kib}k"),
            &bytes[..n],
        );
    }
    let log = match SessionLog::open(log_path) {
        Ok(l) => l,
        Err(e) => {
            eprintln!("fuzz_seeds: {e} (prefixes only)");
            return;
        }
    };
    let kept = first_messages(&log);
    let variants = [
        ("zstd", Compression::Zstd, true, true),
        ("lz4", Compression::Lz4, true, true),
        ("flat", Compression::None, false, false),
    ];
    for (name, compression, chunked, summary) in variants {
        let p = scratch.join(format!("{tag}-{name}.mcap"));
        let options = WriterOptions {
            compression,
            chunk_size: 4096,
            chunked,
            summary,
        };
        rewrite(&kept, &p, &options);
        let small = std::fs::read(&p).expect("read rewritten");
        write(&out.join("mcap_reader"), &format!("{tag}-{name}"), &small);
    }
    for (i, (_, schema, _, msgs)) in kept.iter().enumerate() {
        let Some((name, encoding, data)) = schema else {
            continue;
        };
        let Some((_, payload)) = msgs.first() else {
            continue;
        };
        if encoding == "ros2msg" {
            let mut s = format!("{name}\n").into_bytes();
            s.extend_from_slice(data);
            write(&out.join("ros2msg_schema"), &format!("{tag}-{i}"), &s);
            s.push(0);
            s.extend_from_slice(payload);
            write(&out.join("cdr_decode"), &format!("{tag}-{i}"), &s);
        } else if encoding == "protobuf" {
            let mut s = format!("{name}\0").into_bytes();
            s.extend_from_slice(&(data.len() as u32).to_le_bytes());
            s.extend_from_slice(data);
            s.extend_from_slice(payload);
            write(&out.join("protobuf_decode"), &format!("{tag}-{i}"), &s);
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some((out, logs)) = args.split_first() else {
        eprintln!("usage: fuzz_seeds OUT_DIR LOG...");
        std::process::exit(2);
    };
    let out = PathBuf::from(out);
    let scratch = tempfile::tempdir().expect("tempdir");
    let fox = scratch.path().join("foxglove.mcap");
    foxglove_log(&fox);
    seeds_of(&out, "foxglove", &fox, scratch.path());
    for (i, log) in logs.iter().enumerate() {
        let stem = Path::new(log)
            .file_stem()
            .map_or(String::new(), |s| s.to_string_lossy().into_owned());
        seeds_of(&out, &format!("{i}-{stem}"), Path::new(log), scratch.path());
    }
}

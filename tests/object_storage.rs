//! Object storage end to end against a real S3 server (`make test-s3`; feature `s3`): Garage
//! starts on 127.0.0.1 from a private configuration in a temporary folder, the logs are put
//! into a bucket, and `peopletrack run` reads them there (summary first, range requests) and
//! keeps its cache and tables there (`--out s3://...`). The tables and figures must equal a
//! run on local files byte for byte, unsharded and as two shards plus `--aggregate-only`; a
//! second run must take every session from the store's cache. It also reports how many bytes
//! a one-topic read fetches against the log's size.
//!
//! SKIPPED (with the reason) when no `garage` binary is found: `$GARAGE_BIN`,
//! `target/tools/bin/garage` (where `make test-s3` installs Garage 2.5.0), or `PATH`.

mod common;

use std::collections::BTreeMap;
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use peopletrack::log::msgs::{Header, LaserScan};
use peopletrack::log::{SessionLog, SessionWriter, WriterOptions};
use peopletrack::{Nanos, storage};

const BUCKET: &str = "peopletrack";
/// A fixed test key (Garage key ids are `GK` + 24 hex digits, secrets 64 hex digits).
const KEY_ID: &str = "GK5eed0000000000000000c0de";
const SECRET: &str = "5eed00000000000000000000000000000000000000000000000000000000c0de";

fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .expect("a free port on 127.0.0.1")
}

fn garage_bin() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("GARAGE_BIN") {
        return Some(PathBuf::from(p));
    }
    let tools = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/tools/bin/garage");
    if tools.is_file() {
        return Some(tools);
    }
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|d| d.join("garage"))
        .find(|p| p.is_file())
}

/// A one-node Garage with one bucket and one key; the server is a child, killed on drop.
struct Garage {
    bin: PathBuf,
    config: PathBuf,
    server: Child,
    endpoint: String,
}

impl Garage {
    fn start(dir: &Path) -> Result<Garage, String> {
        let bin = garage_bin().ok_or("no `garage` binary (run `make test-s3`)")?;
        std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
        let (s3, rpc, admin) = (free_port(), free_port(), free_port());
        let d = dir.display();
        let config = dir.join("garage.toml");
        std::fs::write(
            &config,
            format!(
                "metadata_dir = \"{d}/meta\"\ndata_dir = \"{d}/data\"\ndb_engine = \"lmdb\"\n\
                 replication_factor = 1\nrpc_bind_addr = \"127.0.0.1:{rpc}\"\n\
                 rpc_public_addr = \"127.0.0.1:{rpc}\"\nrpc_secret = \"{SECRET}\"\n\n\
                 [s3_api]\ns3_region = \"garage\"\napi_bind_addr = \"127.0.0.1:{s3}\"\n\
                 root_domain = \".s3.garage\"\n\n[admin]\napi_bind_addr = \"127.0.0.1:{admin}\"\n"
            ),
        )
        .map_err(|e| e.to_string())?;
        let log = std::fs::File::create(dir.join("server.log")).map_err(|e| e.to_string())?;
        let server = Command::new(&bin)
            .arg("-c")
            .arg(&config)
            .arg("server")
            .stdout(Stdio::null())
            .stderr(log)
            .spawn()
            .map_err(|e| format!("{}: {e}", bin.display()))?;
        let g = Garage {
            bin,
            config,
            server,
            endpoint: format!("http://127.0.0.1:{s3}"),
        };
        let started = Instant::now();
        let id = loop {
            let o = g.cli(&["node", "id", "-q"]);
            if o.status.success() {
                break String::from_utf8_lossy(&o.stdout).trim().to_string();
            }
            if started.elapsed() > Duration::from_secs(60) {
                return Err(format!(
                    "Garage did not answer within 60 s (log: {d}/server.log)"
                ));
            }
            std::thread::sleep(Duration::from_millis(100));
        };
        let node = id.split('@').next().unwrap_or_default().to_string();
        for args in [
            vec!["layout", "assign", &node, "-c", "1G", "-z", "dc1"],
            vec!["layout", "apply", "--version", "1"],
            vec!["bucket", "create", BUCKET],
            vec![
                "key",
                "import",
                "--yes",
                "-n",
                "peopletrack-test",
                KEY_ID,
                SECRET,
            ],
            vec![
                "bucket", "allow", "--read", "--write", "--owner", BUCKET, "--key", KEY_ID,
            ],
        ] {
            let o = g.cli(&args);
            if !o.status.success() {
                return Err(format!(
                    "garage {}: {}",
                    args.join(" "),
                    String::from_utf8_lossy(&o.stderr)
                ));
            }
        }
        Ok(g)
    }

    fn cli(&self, args: &[&str]) -> Output {
        Command::new(&self.bin)
            .arg("-c")
            .arg(&self.config)
            .args(args)
            .output()
            .expect("garage runs")
    }

    /// The standard `AWS_*` variables that point `object_store` at this server.
    fn env(&self) -> [(&'static str, String); 5] {
        [
            ("AWS_ENDPOINT_URL", self.endpoint.clone()),
            ("AWS_ACCESS_KEY_ID", KEY_ID.to_string()),
            ("AWS_SECRET_ACCESS_KEY", SECRET.to_string()),
            ("AWS_REGION", "garage".to_string()),
            ("AWS_ALLOW_HTTP", "true".to_string()),
        ]
    }
}

impl Drop for Garage {
    fn drop(&mut self) {
        let _ = self.server.kill();
        let _ = self.server.wait();
    }
}

fn pipeline() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("pipelines/dataset_quality.toml")
}

fn run(env: &[(&str, String)], args: &[&str]) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_peopletrack"))
        .envs(env.iter().map(|(k, v)| (*k, v.as_str())))
        .arg("run")
        .arg(pipeline())
        .args(args)
        .output()
        .expect("runs");
    let text = common::output_text(&o);
    assert!(o.status.success(), "run {args:?}: {text}");
    text
}

/// The tables and figures below `<out>/<pipeline>/` in the store, by `tables/...` name.
fn remote_products(out: &str, pipeline: &str) -> BTreeMap<String, Vec<u8>> {
    let mut m = BTreeMap::new();
    for sub in ["tables", "figures"] {
        let prefix = format!("{out}/{pipeline}/{sub}/");
        for url in storage::list(&prefix).expect("list") {
            let bytes = storage::get(&url).expect("get").expect("listed object");
            m.insert(format!("{sub}/{}", &url[prefix.len()..]), bytes);
        }
    }
    m
}

/// What reading `topic` of the log at `url` fetched.
struct Fetched {
    /// Bytes fetched by opening the log (footer, summary section, header).
    opened: u64,
    /// Bytes fetched by streaming the topic.
    read: u64,
    messages: usize,
    /// All chunk bytes, and those of the chunks whose index lists the topic's channel.
    chunk_bytes: u64,
    wanted_chunk_bytes: u64,
}

fn fetched_for(url: &str, topic: &str) -> Fetched {
    let before = storage::bytes_fetched();
    let log = SessionLog::open(url).expect("open");
    let opened = storage::bytes_fetched() - before;
    let messages = log
        .messages_on(&[topic])
        .expect("topic")
        .collect::<Result<Vec<_>, _>>()
        .expect("messages")
        .len();
    let s = log.summary();
    let id = s.channel(topic).expect("channel").id;
    let wanted = |c: &&peopletrack::log::reader::ChunkInfo| {
        c.channels.as_ref().is_none_or(|chs| chs.contains(&id))
    };
    Fetched {
        opened,
        read: storage::bytes_fetched() - before - opened,
        messages,
        chunk_bytes: s.chunks.iter().map(|c| c.length).sum(),
        wanted_chunk_bytes: s.chunks.iter().filter(wanted).map(|c| c.length).sum(),
    }
}

/// A log whose first half has only `/front` and second half only `/rear` scans, in 16 KiB
/// chunks: a one-topic read should fetch about half of it.
fn two_phase_log(path: &Path) {
    let opts = WriterOptions {
        chunk_size: 16 << 10,
        ..WriterOptions::default()
    };
    let mut w = SessionWriter::create(path, &opts).expect("create");
    let front = w.add_ros2::<LaserScan>("/front").expect("front");
    let rear = w.add_ros2::<LaserScan>("/rear").expect("rear");
    for i in 0..400u64 {
        let t = Nanos(1_000_000_000 + i * 50_000_000);
        let msg = LaserScan {
            header: Header::new(t, "laser"),
            ranges: (0..360)
                .map(|k| 1.0 + ((i * 7 + k) % 97) as f32 * 0.05)
                .collect(),
            range_max: 10.0,
            ..Default::default()
        };
        w.write(if i < 200 { front } else { rear }, t, &msg)
            .expect("write");
    }
    w.finish().expect("finish");
}

#[test]
fn a_pipeline_runs_on_logs_and_a_cache_in_object_storage() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let garage = match Garage::start(&tmp.path().join("garage")) {
        Ok(g) => g,
        Err(why) => {
            eprintln!("SKIPPED: no S3 server here: {why}");
            return;
        }
    };
    let env = garage.env();
    for (k, v) in &env {
        // SAFETY: this test binary runs this one test; no other thread reads the environment
        unsafe { std::env::set_var(k, v) };
    }
    let data = tmp.path().join("data");
    let glob = common::runner_sessions(&data);
    let logs = format!("s3://{BUCKET}/logs");
    for dataset in ["lab", "park"] {
        for e in std::fs::read_dir(data.join(dataset)).expect("data") {
            let p = e.expect("entry").path();
            let name = p.file_name().expect("name").to_string_lossy().into_owned();
            let url = format!("{logs}/{dataset}/{name}");
            storage::put(&url, std::fs::read(&p).expect("log")).expect("put");
        }
    }
    let single = tmp.path().join("single");
    let local = single.to_string_lossy().into_owned();
    run(&[], &["--sessions", &glob, "--out", &local]);
    let expected = common::products(&single, "dataset_quality");
    let remote_glob = format!("{logs}/*/*.mcap");

    // unsharded, then again: every session from the store's cache
    let out = format!("s3://{BUCKET}/out");
    let first = run(&env, &["--sessions", &remote_glob, "--out", &out]);
    assert!(first.contains("3 sessions (3 computed"), "{first}");
    assert_eq!(
        remote_products(&out, "dataset_quality"),
        expected,
        "tables and figures from logs and cache in the store differ from the local run's"
    );
    let again = run(&env, &["--sessions", &remote_glob, "--out", &out]);
    assert!(
        again.contains("3 sessions (0 computed, 3 from cache"),
        "{again}"
    );

    // two shards sharing a cache in the store, then the aggregate alone
    let sharded = format!("s3://{BUCKET}/sharded");
    for k in ["1/2", "2/2"] {
        run(
            &env,
            &["--sessions", &remote_glob, "--out", &sharded, "--shard", k],
        );
    }
    run(
        &env,
        &[
            "--sessions",
            &remote_glob,
            "--out",
            &sharded,
            "--aggregate-only",
            "--expect-shards",
            "2",
        ],
    );
    assert_eq!(
        remote_products(&sharded, "dataset_quality"),
        expected,
        "two shards and an aggregate in the store differ from the local run"
    );

    // bytes fetched against size
    let split = tmp.path().join("two_phase.mcap");
    two_phase_log(&split);
    let mut report = vec![("two-phase log, /rear".to_string(), split.clone(), "/rear")];
    if let Some(real) = common::laser_log("general_tracking_moving_1") {
        report.push((
            "general_tracking_moving_1, /scan".to_string(),
            real,
            "/scan",
        ));
    }
    for (what, path, topic) in report {
        let url = format!(
            "s3://{BUCKET}/fetch/{}",
            path.file_name().expect("name").to_string_lossy()
        );
        let bytes = std::fs::read(&path).expect("log");
        let size = bytes.len() as u64;
        storage::put(&url, bytes).expect("put");
        let f = fetched_for(&url, topic);
        let local_n = SessionLog::open(&path)
            .expect("open local")
            .messages_on(&[topic])
            .expect("topic")
            .count();
        assert_eq!(
            f.messages, local_n,
            "{what}: the store gave other messages than the file"
        );
        // opening reads no chunk; the stream reads exactly the chunks that hold the topic
        assert!(
            f.opened <= size - f.chunk_bytes,
            "{what}: opening fetched {} bytes, more than all but the chunks ({})",
            f.opened,
            size - f.chunk_bytes
        );
        assert_eq!(f.read, f.wanted_chunk_bytes, "{what}: bytes streamed");
        eprintln!(
            "FETCHED {what}: open {} B + one-topic read {} B ({} messages) of a {size} B file: {:.1} %",
            f.opened,
            f.read,
            f.messages,
            100.0 * (f.opened + f.read) as f64 / size as f64
        );
        if what.starts_with("two-phase") {
            assert!(
                f.wanted_chunk_bytes * 10 < f.chunk_bytes * 6,
                "{what}: the topic's chunks are {} of {} chunk bytes: the log is not split by topic",
                f.wanted_chunk_bytes,
                f.chunk_bytes
            );
        }
    }
    drop(garage);
}

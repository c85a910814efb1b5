//! Shard equivalence, no cluster needed: five sessions — three good, an empty log and a
//! corrupt one — run as N ∈ {1, 2, 3, 6} shards, two at a time in shuffled order, on one or two
//! threads, into a fresh cache; then `--aggregate-only --expect-shards N` with the logs moved
//! away. The shards' session sets are disjoint and cover all five, every table and figure is
//! byte-identical to the unsharded run's, every cached session is there with the same key, and
//! a missing shard is named by the aggregate.

use crate::common;

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn peopletrack() -> Command {
    Command::new(env!("CARGO_BIN_EXE_peopletrack"))
}

fn pipeline() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("pipelines/dataset_quality.toml")
}

fn check(o: &Output, what: &str) {
    assert!(
        o.status.success(),
        "{what}: {}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}

fn run(out: &Path, sessions: &str, args: &[&str]) -> Output {
    peopletrack()
        .arg("run")
        .arg(pipeline())
        .args(["--sessions", sessions, "--out"])
        .arg(out)
        .args(args)
        .output()
        .expect("runs")
}

/// The three runner sessions plus `lab/empty` (0 bytes) and `park/corrupt` (not MCAP).
fn five_sessions(data: &Path) -> String {
    let glob = common::runner_sessions(data);
    std::fs::write(data.join("lab/empty.mcap"), b"").expect("empty log");
    std::fs::write(data.join("park/corrupt.mcap"), b"\x89MCAP0\r\nnot really").expect("corrupt");
    glob
}

/// Every cached session folder of `out` with its key.
fn cache_keys(out: &Path) -> BTreeMap<String, String> {
    let root = out.join("dataset_quality/sessions");
    let mut keys = BTreeMap::new();
    for d in std::fs::read_dir(&root).into_iter().flatten().flatten() {
        for s in std::fs::read_dir(d.path()).into_iter().flatten().flatten() {
            let key = std::fs::read_to_string(s.path().join("key.txt")).unwrap_or_default();
            let name = format!(
                "{}/{}",
                d.file_name().to_string_lossy(),
                s.file_name().to_string_lossy()
            );
            keys.insert(name, key);
        }
    }
    keys
}

/// The sessions shard `k` of `n` lists in its record.
fn recorded(out: &Path, k: usize, n: usize) -> Vec<String> {
    let p = out.join(format!("dataset_quality/shards/{n}/{k}.json"));
    let text = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    let v: serde_json::Value = serde_json::from_str(&text).expect("json");
    v["sessions"]
        .as_array()
        .expect("sessions")
        .iter()
        .map(|s| {
            format!(
                "{}/{}",
                s["dataset"].as_str().expect("dataset"),
                s["name"].as_str().expect("name")
            )
        })
        .collect()
}

#[test]
fn shards_give_the_tables_of_one_run() {
    let dir = tempfile::tempdir().expect("tempdir");
    let data = dir.path().join("data");
    let sessions = five_sessions(&data);
    let single = dir.path().join("single");
    check(&run(&single, &sessions, &["-j", "2"]), "unsharded run");
    common::assert_schemas_documented(&pipeline(), &single);
    let want = common::products(&single, "dataset_quality");
    let skipped = String::from_utf8(want["tables/skipped_sessions.csv"].clone()).expect("utf8");
    assert!(
        skipped.contains("empty") && skipped.contains("corrupt"),
        "{skipped}"
    );
    let want_keys = cache_keys(&single);
    assert_eq!(want_keys.len(), 3, "{want_keys:?}");

    for n in [1usize, 2, 3, 6] {
        let out = dir.path().join(format!("shards{n}"));
        // shuffled order (a fixed permutation per n), two at a time, threads alternating 1 and 2
        let mut order: Vec<usize> = (1..=n).collect();
        order.rotate_left(n / 2);
        order.reverse();
        for pair in order.chunks(2) {
            let children: Vec<_> = pair
                .iter()
                .map(|&k| {
                    let threads = if k % 2 == 0 { "2" } else { "1" };
                    let shard = format!("{k}/{n}");
                    let mut c = peopletrack();
                    c.args(["-j", threads, "run"])
                        .arg(pipeline())
                        .args(["--sessions", &sessions, "--shard", &shard, "--out"])
                        .arg(&out)
                        .stdout(std::process::Stdio::piped())
                        .stderr(std::process::Stdio::piped());
                    (shard, c.spawn().expect("starts"))
                })
                .collect();
            for (shard, child) in children {
                let o = child.wait_with_output().expect("runs");
                check(&o, &format!("shard {shard}"));
            }
        }
        let mut all = BTreeSet::new();
        for k in 1..=n {
            for s in recorded(&out, k, n) {
                assert!(all.insert(s.clone()), "{s} is in two of {n} shards");
            }
        }
        assert_eq!(all.len(), 5, "{n} shards: {all:?}");
        assert_eq!(cache_keys(&out), want_keys, "{n} shards: cache");
        // the logs go away; the aggregate reads the cache and the shards' records
        let moved = dir.path().join("moved");
        std::fs::rename(&data, &moved).expect("move the logs away");
        let agg = run(
            &out,
            &sessions,
            &["--aggregate-only", "--expect-shards", &n.to_string()],
        );
        std::fs::rename(&moved, &data).expect("move the logs back");
        check(&agg, &format!("aggregate of {n} shards"));
        let got = common::products(&out, "dataset_quality");
        assert_eq!(
            got.keys().collect::<Vec<_>>(),
            want.keys().collect::<Vec<_>>()
        );
        for (name, bytes) in &want {
            assert!(
                got[name] == *bytes,
                "{n} shards: {name} differs from the unsharded run's"
            );
        }
    }
}

#[test]
fn the_aggregate_names_a_missing_shard() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sessions = five_sessions(&dir.path().join("data"));
    let out = dir.path().join("out");
    for k in [1, 3] {
        check(
            &run(&out, &sessions, &["--shard", &format!("{k}/3")]),
            "shard",
        );
    }
    let agg = run(
        &out,
        &sessions,
        &["--aggregate-only", "--expect-shards", "3"],
    );
    let err = String::from_utf8_lossy(&agg.stderr);
    assert!(
        !agg.status.success(),
        "an aggregate over a missing shard must fail"
    );
    assert!(err.contains("shard 2/3 did not finish"), "{err}");
    assert!(
        !out.join("dataset_quality/tables").exists(),
        "no tables from a partial cache"
    );
}

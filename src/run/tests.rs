//! The runner with a tiny test-only experiment: a session whose `process` panics is skipped
//! with its reason, and the other sessions' results are kept (and cached).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use polars::prelude::df;
use serde::{Deserialize, Serialize};

use super::*;
use crate::Nanos;
use crate::log::msgs::{Header, LaserScan};
use crate::log::{SessionWriter, WriterOptions};

#[derive(Debug, Default, Deserialize, Serialize)]
struct NoParams {}

/// Processes every session into a one-row table, except session `b`, where it panics.
struct Flaky;

impl Experiment for Flaky {
    const KIND: &'static str = "flaky";
    const VERSION: u32 = 1;
    type Params = NoParams;

    fn plan(_params: &NoParams, _topics: &BTreeMap<String, String>) -> Vec<Stage> {
        Vec::new()
    }

    fn process(
        session: &Session,
        _params: &NoParams,
        _topics: &BTreeMap<String, String>,
        _progress: &dyn Progress,
    ) -> anyhow::Result<SessionTables> {
        let name = session.info.name.clone();
        assert_ne!(name, "b", "boom");
        let mut tables = SessionTables::new();
        tables.insert("rows".into(), df!("session" => [name])?);
        Ok(tables)
    }

    fn aggregate(ctx: &Aggregate, _params: &NoParams) -> anyhow::Result<Products> {
        Ok(Products {
            summary: ctx.sessions.iter().map(|(s, _)| s.name.clone()).collect(),
            ..Products::default()
        })
    }
}

/// Logs `d/a.mcap`, `d/b.mcap`, `d/c.mcap`, one scan each.
fn logs(dir: &Path) {
    for name in ["a", "b", "c"] {
        let p = dir.join("d").join(format!("{name}.mcap"));
        let mut w = SessionWriter::create(&p, &WriterOptions::default()).expect("create");
        let scan = w.add_ros2::<LaserScan>("/scan").expect("scan");
        let msg = LaserScan {
            header: Header::new(Nanos(1_000), "laser"),
            ranges: vec![1.0; 4],
            range_max: 10.0,
            ..Default::default()
        };
        w.write(scan, Nanos(1_000), &msg).expect("write");
        w.finish().expect("finish");
    }
}

fn options(out: &Path) -> RunOptions {
    RunOptions {
        sessions: None,
        dry_run: false,
        shard: None,
        aggregate_only: false,
        expect_shards: None,
        force: false,
        out: out.to_path_buf(),
        git_commit: "test".into(),
        progress: None,
        write_tracks: None,
        recover: false,
        keep_going: false,
    }
}

#[test]
fn a_panicking_session_is_skipped_with_its_reason_and_the_others_are_kept() {
    let dir = tempfile::tempdir().expect("tempdir");
    logs(dir.path());
    let text = format!(
        "[pipeline]\nname = \"flaky\"\nkind = \"flaky\"\ntitle = \"Flaky\"\n\n[inputs]\nsessions = [\"{}/*/*.mcap\"]\n",
        dir.path().display()
    );
    let path = dir.path().join("flaky.toml");
    let out = dir.path().join("out");

    let first = run_experiment::<Flaky>(&path, &text, &options(&out)).expect("the run goes on");
    assert_eq!(first.sessions, 3);
    assert_eq!((first.computed, first.cached), (2, 0));
    assert_eq!(first.summary, ["a", "c"]);
    assert_eq!(first.skipped.len(), 1);
    assert_eq!(first.skipped[0].0, "d/b");
    assert!(
        first.skipped[0].1.starts_with("panicked: ") && first.skipped[0].1.contains("boom"),
        "{:?}",
        first.skipped
    );

    // the kept sessions were cached; the panicking one is tried (and skipped) again
    let second = run_experiment::<Flaky>(&path, &text, &options(&out)).expect("second run");
    assert_eq!((second.computed, second.cached), (0, 2));
    assert_eq!(second.skipped, first.skipped);
}

#[test]
fn panic_messages_of_both_payload_types() {
    let s: Box<dyn std::any::Any + Send> = Box::new("static");
    assert_eq!(panic_message(&*s), "static");
    let s: Box<dyn std::any::Any + Send> = Box::new(String::from("formatted 7"));
    assert_eq!(panic_message(&*s), "formatted 7");
    let s: Box<dyn std::any::Any + Send> = Box::new(7_u32);
    assert_eq!(panic_message(&*s), "(no message)");
}

#[path = "../../tests/common/raw_mcap.rs"]
#[allow(dead_code)]
mod raw;

/// Reads every message and tables their log times, in the order the log delivers them.
struct Times;

impl Experiment for Times {
    const KIND: &'static str = "times";
    const VERSION: u32 = 1;
    type Params = NoParams;

    fn plan(_params: &NoParams, _topics: &BTreeMap<String, String>) -> Vec<Stage> {
        Vec::new()
    }

    fn process(
        session: &Session,
        _params: &NoParams,
        _topics: &BTreeMap<String, String>,
        _progress: &dyn Progress,
    ) -> anyhow::Result<SessionTables> {
        let mut times = Vec::new();
        for m in session.log.messages()? {
            times.push(m?.log_time.0);
        }
        let mut tables = SessionTables::new();
        tables.insert("times".into(), df!("log_time_ns" => times)?);
        Ok(tables)
    }

    fn aggregate(ctx: &Aggregate, _params: &NoParams) -> anyhow::Result<Products> {
        let mut summary = Vec::new();
        for (s, tables) in ctx.sessions {
            let times = tables["times"].column("log_time_ns")?.u64()?;
            let times: Vec<String> = times.into_no_null_iter().map(|t| t.to_string()).collect();
            summary.push(format!("{}: {}", s.name, times.join(" ")));
        }
        Ok(Products {
            summary,
            ..Products::default()
        })
    }
}

fn times_pipeline(dir: &Path) -> (PathBuf, String) {
    let text = format!(
        "[pipeline]\nname = \"times\"\nkind = \"times\"\ntitle = \"Times\"\n\n[inputs]\nsessions = [\"{}/*/*.mcap\"]\n",
        dir.display()
    );
    (dir.join("times.toml"), text)
}

/// The skipped_sessions table's rows as `status reason` lines.
fn skipped_rows(out: &Path) -> String {
    std::fs::read_to_string(out.join("times/tables/skipped_sessions.csv")).expect("table")
}

#[test]
fn a_log_whose_chunk_index_lies_is_read_again_by_a_linear_scan_in_order_and_flagged() {
    let dir = tempfile::tempdir().expect("tempdir");
    let messages = |times: &[u64]| -> Vec<u8> {
        times
            .iter()
            .enumerate()
            .flat_map(|(i, t)| raw::message(1, i as u32, *t, b"{}"))
            .collect()
    };
    let channel = raw::channel(1, 0, "/x", "json");
    // chunk A says 0..30 and holds 0, 30; chunk B says 40..100 but holds 20, 100
    let a = raw::chunk(0, 30, &messages(&[0, 30]), true);
    let b = raw::chunk(40, 100, &messages(&[20, 100]), true);
    let a_at = 8 + raw::header().len() as u64 + channel.len() as u64;
    let b_at = a_at + a.len() as u64;
    let bytes = raw::file(
        &[&channel, &a, &b],
        &[
            &channel,
            &raw::chunk_index(0, 30, a_at, a.len() as u64, &[1]),
            &raw::chunk_index(40, 100, b_at, b.len() as u64, &[1]),
            &raw::statistics(4, 2, 0, 100),
        ],
    );
    std::fs::create_dir_all(dir.path().join("d")).expect("mkdir");
    std::fs::write(dir.path().join("d/lying.mcap"), bytes).expect("write");
    let (path, text) = times_pipeline(dir.path());
    let out = dir.path().join("out");

    let run = run_experiment::<Times>(&path, &text, &options(&out)).expect("runs");
    assert_eq!(run.summary, ["lying: 0 20 30 100"], "log-time order");
    assert!(run.skipped.is_empty());
    assert_eq!(run.warned.len(), 1);
    let (session, why) = &run.warned[0];
    assert_eq!(session, "d/lying");
    assert!(
        why.starts_with("indexed by a linear scan of the data"),
        "{why}"
    );
    assert!(
        why.contains(&format!("chunk at byte {b_at} declares")),
        "{why}"
    );
    let table = skipped_rows(&out);
    assert!(table.contains(",warned,"), "{table}");

    // the warning survives the cache
    let again = run_experiment::<Times>(&path, &text, &options(&out)).expect("runs");
    assert_eq!((again.computed, again.cached), (0, 1));
    assert_eq!(again.warned, run.warned);
}

#[test]
fn recover_keeps_the_complete_chunks_of_a_cut_log_and_lists_the_loss() {
    let dir = tempfile::tempdir().expect("tempdir");
    let full = dir.path().join("full.mcap");
    let opts = WriterOptions {
        compression: crate::log::Compression::None,
        chunk_size: 200,
        ..WriterOptions::default()
    };
    let mut w = SessionWriter::create(&full, &opts).expect("create");
    let ch = w.add_json("/x", "X", "{}").expect("channel");
    for i in 1..=40u64 {
        w.write_json(ch, Nanos(i), &serde_json::json!({ "i": i }))
            .expect("write");
    }
    let full = w.finish().expect("finish");
    let chunks = SessionLog::open(&full)
        .expect("opens")
        .summary()
        .chunks
        .clone();
    assert!(chunks.len() >= 4, "several chunks: {}", chunks.len());
    let third = chunks[2].offset as usize;
    let data = std::fs::read(&full).expect("read");
    std::fs::create_dir_all(dir.path().join("d")).expect("mkdir");
    std::fs::write(dir.path().join("d/cut.mcap"), &data[..third + 20]).expect("write");
    let (path, text) = times_pipeline(dir.path());
    let out = dir.path().join("out");

    // without --recover the cut log is a failed session, and nothing else is left to aggregate
    let err = run_experiment::<Times>(&path, &text, &options(&out)).expect_err("all skipped");
    assert!(format!("{err:#}").contains("truncated"), "{err:#}");

    let recovering = RunOptions {
        recover: true,
        ..options(&out)
    };
    let run = run_experiment::<Times>(&path, &text, &recovering).expect("recovers");
    let kept: Vec<u64> = (1..=chunks[1].end.0).collect();
    let kept: Vec<String> = kept.iter().map(u64::to_string).collect();
    assert_eq!(run.summary, [format!("cut: {}", kept.join(" "))]);
    assert_eq!(run.warned.len(), 1);
    let why = &run.warned[0].1;
    let lost = format!("bytes {third}..{} (20 bytes) are lost", third + 20);
    assert!(why.contains(&lost), "{why}");
    assert!(skipped_rows(&out).contains(",warned,"));
}

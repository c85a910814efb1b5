//! The runner with a tiny test-only experiment: a session whose `process` panics is skipped
//! with its reason, and the other sessions' results are kept (and cached).

use std::collections::BTreeMap;
use std::path::Path;

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
        force: false,
        out: out.to_path_buf(),
        git_commit: "test".into(),
        progress: None,
        write_tracks: None,
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

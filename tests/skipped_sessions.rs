//! Sessions without results (issue 19, item 7): a session whose processing panics or fails is
//! that session's failure — the others' results are kept — and every pipeline's tables and
//! REPORT.md list it with its status and reason (they were said on stderr only).

use std::collections::BTreeMap;
use std::path::Path;

use assert_cmd::Command;
use peopletrack::Nanos;
use peopletrack::log::msgs::{Header, LaserScan};
use peopletrack::log::{SessionWriter, WriterOptions};
use peopletrack::progress::Progress;
use peopletrack::run::{
    Aggregate, Experiment, Products, RunOptions, Session, SessionTables, Stage, run_experiment,
};
use polars::prelude::df;
use serde::{Deserialize, Serialize};

#[derive(Debug, Default, Deserialize, Serialize)]
struct NoParams {}

/// One-row table per session, except `bug` (panics, as an index out of bounds would) and
/// `bad` (returns an error).
struct Fragile;

impl Experiment for Fragile {
    const KIND: &'static str = "fragile";
    const VERSION: u32 = 1;
    type Params = NoParams;

    fn plan(_params: &NoParams, _topics: &BTreeMap<String, String>) -> Vec<Stage> {
        vec![Stage {
            name: "scans".into(),
            requires: vec!["/scan".into()],
            optional: vec![],
        }]
    }

    fn process(
        session: &Session,
        _params: &NoParams,
        _topics: &BTreeMap<String, String>,
        _progress: &dyn Progress,
    ) -> anyhow::Result<SessionTables> {
        let name = session.info.name.clone();
        let v: Vec<usize> = Vec::new();
        if name == "bug" {
            let _ = v[name.len()];
        }
        if name == "bad" {
            anyhow::bail!("the log holds no person");
        }
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

/// `d/<name>.mcap` with one scan each; `noscan` has another topic only.
fn logs(dir: &Path) {
    for name in ["bad", "bug", "good", "noscan"] {
        let p = dir.join("d").join(format!("{name}.mcap"));
        let mut w = SessionWriter::create(&p, &WriterOptions::default()).expect("create");
        let topic = if name == "noscan" { "/other" } else { "/scan" };
        let scan = w.add_ros2::<LaserScan>(topic).expect("scan");
        let msg = LaserScan {
            header: Header::new(Nanos(1_000), "laser"),
            ranges: vec![1.0; 4],
            range_max: 10.0,
            ..Default::default()
        };
        w.write(scan, Nanos(1_000), &msg).expect("write");
        w.finish().expect("finish");
    }
    std::fs::write(dir.join("d/cut.mcap"), b"\x89MCAP0\r\n truncated").expect("write");
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

/// Rows of a CSV table as cells (no quoting in these tables' first columns).
fn rows(path: &Path) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .map(|c| c.trim_matches('"').to_string())
                .collect()
        })
        .collect()
}

#[test]
fn failed_and_panicking_sessions_are_listed_in_the_table_and_the_others_kept() {
    let dir = tempfile::tempdir().expect("tempdir");
    logs(dir.path());
    let text = format!(
        "[pipeline]\nname = \"fragile\"\nkind = \"fragile\"\ntitle = \"Fragile\"\n\n[inputs]\nsessions = [\"{}/*/*.mcap\"]\n",
        dir.path().display()
    );
    let path = dir.path().join("fragile.toml");
    let out = dir.path().join("out");
    let s = run_experiment::<Fragile>(&path, &text, &options(&out)).expect("the run goes on");
    assert_eq!((s.sessions, s.computed), (5, 1));
    assert_eq!(s.summary, ["good"], "the good session's result is kept");
    assert_eq!(s.skipped_table, "fragile/tables/skipped_sessions.md");

    let table = rows(&out.join("fragile/tables/skipped_sessions.csv"));
    let status: Vec<(&str, &str, &str)> = table
        .iter()
        .map(|r| (r[0].as_str(), r[1].as_str(), r[2].as_str()))
        .collect();
    assert_eq!(
        status,
        [
            ("d", "bad", "failed"),
            ("d", "bug", "panicked"),
            ("d", "cut", "failed"),
            ("d", "noscan", "skipped"),
        ]
    );
    let reason = |name: &str| table.iter().find(|r| r[1] == name).expect("row")[3].clone();
    assert_eq!(reason("bad"), "the log holds no person");
    assert!(
        reason("bug").starts_with("panicked: index out of bounds"),
        "{}",
        reason("bug")
    );
    assert!(reason("cut").contains("cut.mcap"), "{}", reason("cut"));
    assert_eq!(reason("noscan"), "missing topic(s) /scan");
    for f in ["md", "parquet", "tex"] {
        assert!(
            out.join(format!("fragile/tables/skipped_sessions.{f}"))
                .is_file()
        );
    }

    // the report section lists each with its status and links the table
    let md = BTreeMap::new();
    let h = peopletrack::run::report::Header {
        tool_version: "0".into(),
        git_commit: "test".into(),
        rustc: "rustc".into(),
        total_seconds: 0.0,
    };
    let report = peopletrack::run::report::render(std::slice::from_ref(&s), &md, &h);
    assert!(report.contains("### Skipped sessions (4)"), "{report}");
    assert!(
        report.contains("- `d/bug` (panicked): panicked: index out of bounds"),
        "{report}"
    );
    assert!(
        report.contains("- `d/noscan` (skipped): missing topic(s) /scan"),
        "{report}"
    );
    assert!(
        report.contains("[md](fragile/tables/skipped_sessions.md)"),
        "{report}"
    );

    // a later run without the bad sessions leaves an empty table, not the stale list
    let text = text.replace("/*/*.mcap", "/*/good.mcap");
    run_experiment::<Fragile>(&path, &text, &options(&out)).expect("second run");
    assert!(rows(&out.join("fragile/tables/skipped_sessions.csv")).is_empty());
}

/// Through the CLI: `eval` on the shipped dataset_quality pipeline with one good and one
/// truncated log writes the table, and REPORT.md names the truncated log.
#[test]
fn eval_lists_a_truncated_log_in_the_tables_and_the_report() {
    let dir = tempfile::tempdir().expect("tempdir");
    logs(dir.path());
    let pipelines = dir.path().join("pipelines");
    std::fs::create_dir_all(&pipelines).expect("mkdir");
    let shipped = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("pipelines/dataset_quality.toml"),
    )
    .expect("pipeline");
    let sessions = format!("{}/d/[cg]*.mcap", dir.path().display());
    let text = shipped.replace(
        "sessions = [\"datasets/*/*.mcap\", \"../shared/real/laser/*/*.mcap\"]",
        &format!("sessions = [{sessions:?}]"),
    );
    std::fs::write(pipelines.join("dataset_quality.toml"), text).expect("write");
    let out = dir.path().join("out");
    let o = Command::cargo_bin("peopletrack")
        .expect("binary")
        .args(["eval", "--pipelines"])
        .arg(&pipelines)
        .arg("--out")
        .arg(&out)
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let table = rows(&out.join("dataset_quality/tables/skipped_sessions.csv"));
    assert_eq!(table.len(), 1, "{table:?}");
    assert_eq!(
        (table[0][1].as_str(), table[0][2].as_str()),
        ("cut", "failed")
    );
    let report = std::fs::read_to_string(out.join("REPORT.md")).expect("report");
    assert!(report.contains("### Skipped sessions (1)"), "{report}");
    assert!(report.contains("- `d/cut` (failed): "), "{report}");
}

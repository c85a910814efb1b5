//! The pipeline runner end to end through the CLI: caching, byte-identical tables whatever the
//! thread count, no partial files after a crash, config errors with lines, dry runs, REPORT.md.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::common;

use assert_cmd::Command;
use common::runner_sessions as fixtures;

fn peopletrack() -> Command {
    Command::cargo_bin("peopletrack").expect("binary")
}

fn pipeline() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("pipelines/dataset_quality.toml")
}

fn run(out: &Path, sessions: &str, extra: &[&str]) -> std::process::Output {
    peopletrack()
        .args(extra)
        .arg("run")
        .arg(pipeline())
        .args(["--sessions", sessions, "--out"])
        .arg(out)
        .output()
        .expect("runs")
}

/// Every file under out/<pipeline>/tables and figures, with its bytes.
fn outputs(out: &Path) -> BTreeMap<String, Vec<u8>> {
    common::products(out, "dataset_quality")
}

#[test]
fn second_run_uses_the_cache_and_writes_identical_tables() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sessions = fixtures(&dir.path().join("data"));
    let out = dir.path().join("out");
    let first = run(&out, &sessions, &[]);
    assert!(
        first.status.success(),
        "{}",
        String::from_utf8_lossy(&first.stderr)
    );
    assert!(String::from_utf8_lossy(&first.stdout).contains("3 computed, 0 from cache"));
    let a = outputs(&out);
    let second = run(&out, &sessions, &[]);
    assert!(String::from_utf8_lossy(&second.stdout).contains("0 computed, 3 from cache"));
    assert_eq!(a, outputs(&out));
    // the ground truth was read: 40 + 60 + 50 frames at 1 m/s
    let csv = String::from_utf8(a["tables/sessions.csv"].clone()).expect("utf8");
    assert!(
        csv.lines()
            .nth(1)
            .expect("row")
            .contains(",40,0,1,1.0,1.0,"),
        "{csv}"
    );
}

#[test]
fn aggregate_only_needs_no_logs() {
    let dir = tempfile::tempdir().expect("tempdir");
    let data = dir.path().join("data");
    let sessions = fixtures(&data);
    let out = dir.path().join("out");
    let first = run(&out, &sessions, &[]);
    assert!(
        first.status.success(),
        "{}",
        String::from_utf8_lossy(&first.stderr)
    );
    let a = outputs(&out);
    for f in a.keys() {
        std::fs::remove_file(out.join("dataset_quality").join(f)).expect("remove output");
    }
    // the logs go away: a plain run finds nothing, --aggregate-only uses the cache alone
    std::fs::rename(&data, dir.path().join("moved")).expect("move the logs away");
    assert!(!data.exists());
    assert!(!run(&out, &sessions, &[]).status.success());
    let again = peopletrack()
        .arg("run")
        .arg(pipeline())
        .args(["--aggregate-only", "--sessions", &sessions, "--out"])
        .arg(&out)
        .output()
        .expect("runs");
    let stdout = String::from_utf8_lossy(&again.stdout);
    assert!(
        again.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&again.stderr)
    );
    assert!(stdout.contains("0 computed, 3 from cache"), "{stdout}");
    assert_eq!(a, outputs(&out));
}

#[test]
fn tables_do_not_depend_on_the_thread_count() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sessions = fixtures(&dir.path().join("data"));
    let (o1, o2) = (dir.path().join("o1"), dir.path().join("o2"));
    assert!(run(&o1, &sessions, &["-j", "1"]).status.success());
    assert!(run(&o2, &sessions, &["-j", "3"]).status.success());
    let (a, b) = (outputs(&o1), outputs(&o2));
    assert!(a.len() >= 10);
    assert_eq!(a, b);
}

#[test]
fn a_run_killed_midway_leaves_no_partial_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sessions = fixtures(&dir.path().join("data"));
    let reference = dir.path().join("ref");
    assert!(run(&reference, &sessions, &[]).status.success());
    for abort_at in [1, 2, 4, 6, 9] {
        let out = dir.path().join(format!("killed{abort_at}"));
        let killed = run(
            &out,
            &sessions,
            &["--debug-abort-after-writes", &abort_at.to_string()],
        );
        assert!(!killed.status.success(), "the crash hook must stop the run");
        // every file outside the scratch folder is complete: tables parse, figures decode
        for e in walk(&out) {
            let rel = e
                .strip_prefix(&out)
                .expect("inside")
                .to_string_lossy()
                .into_owned();
            // scratch files, and the run's lock files (not outputs)
            if rel.starts_with(".tmp") || rel.ends_with(".lock") || rel.ends_with(".lock.guard") {
                continue;
            }
            let bytes = std::fs::read(&e).expect("read");
            match e.extension().and_then(|x| x.to_str()) {
                Some("parquet") => {
                    peopletrack::report::table::read_parquet(&e)
                        .unwrap_or_else(|err| panic!("{rel}: {err}"));
                }
                Some("png") => {
                    image::load_from_memory(&bytes).unwrap_or_else(|err| panic!("{rel}: {err}"));
                }
                Some("txt") if rel.ends_with("key.txt") => {
                    assert_eq!(bytes.len(), 32, "{rel}: cache key");
                }
                Some("txt") => {
                    // source.txt: the log's hash, then its path
                    let text = String::from_utf8(bytes).expect("utf8");
                    let mut lines = text.lines();
                    assert_eq!(lines.next().map(str::len), Some(32), "{rel}: log hash");
                    assert!(lines.next().is_some_and(|l| l.ends_with(".mcap")), "{rel}");
                }
                _ => assert!(!bytes.is_empty(), "{rel}"),
            }
        }
        // and a rerun completes with the same tables as an uninterrupted run
        assert!(run(&out, &sessions, &[]).status.success());
        assert_eq!(
            outputs(&out),
            outputs(&reference),
            "after abort at write {abort_at}"
        );
    }
}

fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    if let Ok(rd) = std::fs::read_dir(dir) {
        for e in rd.flatten() {
            let p = e.path();
            if p.is_dir() {
                out.extend(walk(&p));
            } else {
                out.push(p);
            }
        }
    }
    out
}

#[test]
fn bad_pipeline_files_name_the_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let text = std::fs::read_to_string(pipeline()).expect("pipeline");
    for (from, to, needle) in [
        ("bin_s = 1.0", "bin_width = 1.0", "bin_width"),
        ("bin_s = 1.0", "bin_s = -2.0", "params.bin_s"),
        (
            "stamp_offsets = true",
            "stamp_offsets = \"yes\"",
            "stamp_offsets",
        ),
        (
            "kind = \"dataset_quality\"",
            "kind = \"nope\"",
            "unknown pipeline kind `nope`",
        ),
    ] {
        let bad = dir.path().join("bad.toml");
        std::fs::write(&bad, text.replace(from, to)).expect("write");
        let line = text
            .replace(from, to)
            .lines()
            .position(|l| l.contains(to))
            .expect("line")
            + 1;
        let o = peopletrack()
            .arg("run")
            .arg(&bad)
            .arg("--dry-run")
            .output()
            .expect("runs");
        assert_eq!(o.status.code(), Some(1));
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(needle) && err.contains("bad.toml"), "{err}");
        if !to.starts_with("kind") {
            assert!(
                err.contains(&format!("line {line}")) || err.contains(&format!(":{line}:")),
                "line {line}: {err}"
            );
        }
    }
}

#[test]
fn dry_run_lists_sessions_stages_and_missing_topics() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sessions = fixtures(&dir.path().join("data"));
    let o = peopletrack()
        .arg("run")
        .arg(pipeline())
        .args(["--dry-run", "--sessions", &sessions])
        .output()
        .expect("runs");
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("sessions (3)") && text.contains("lab/a") && text.contains("park/c"),
        "{text}"
    );
    assert!(
        text.contains("ground truth") && text.contains("/ground_truth/people"),
        "{text}"
    );
}

#[test]
fn eval_writes_a_report_whose_links_exist() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sessions = fixtures(&dir.path().join("data"));
    let pipelines = dir.path().join("pipelines");
    std::fs::create_dir_all(&pipelines).expect("mkdir");
    let text = std::fs::read_to_string(pipeline()).expect("pipeline");
    let text = text.replace(
        "sessions = [\"datasets/*/*.mcap\", \"../shared/real/laser/*/*.mcap\"]",
        &format!("sessions = [{sessions:?}]"),
    );
    std::fs::write(pipelines.join("dataset_quality.toml"), text).expect("write");
    let out = dir.path().join("out");
    let o = peopletrack()
        .args(["eval", "--pipelines"])
        .arg(&pipelines)
        .arg("--out")
        .arg(&out)
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report = std::fs::read_to_string(out.join("REPORT.md")).expect("report");
    let links: Vec<&str> = report
        .split("](")
        .skip(1)
        .filter_map(|s| s.split(')').next())
        .filter(|l| !l.starts_with('#'))
        .collect();
    assert!(links.len() >= 10, "{report}");
    for l in links {
        assert!(out.join(l).exists(), "REPORT.md links to missing {l}");
    }
}

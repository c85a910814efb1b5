//! Runs that share an output folder (issue 36, item 1): two `peopletrack run --force` started
//! together into one folder used to both exit 0 with wrong tables (each swept the other's
//! scratch files). Now each either succeeds with exactly a clean run's tables or fails at once
//! naming the folder and the other run's process id; shards of one pipeline writing their
//! sessions into one folder at the same time go on side by side; nothing is left in the
//! scratch folder. No sleeps and no timing assertions: both processes are started, both are
//! waited for, and whichever of the allowed outcomes happened is checked exactly.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};

use common::{products, runner_sessions};

/// Rounds of two runs started together.
const ROUNDS: usize = 20;

fn pipeline() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("pipelines/dataset_quality.toml")
}

fn binary() -> PathBuf {
    assert_cmd::cargo::cargo_bin("peopletrack")
}

/// `peopletrack -j 1 run dataset_quality.toml --sessions GLOB --out OUT EXTRA...`, started.
fn start(out: &Path, sessions: &str, extra: &[&str]) -> Child {
    Command::new(binary())
        .args(["-j", "1", "run"])
        .arg(pipeline())
        .args(["--sessions", sessions, "--out"])
        .arg(out)
        .args(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("starts")
}

fn finish(child: Child) -> Output {
    child.wait_with_output().expect("runs")
}

/// The scratch folder holds nothing once every run has ended (it may be gone).
fn assert_no_scratch_left(out: &Path) {
    let scratch = out.join(".tmp");
    if let Ok(d) = std::fs::read_dir(&scratch) {
        let left: Vec<_> = d.map(|e| e.expect("entry").path()).collect();
        assert!(left.is_empty(), "scratch left behind: {left:?}");
    }
}

#[test]
fn two_runs_into_one_folder_give_a_clean_runs_tables_or_one_fails_at_once() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sessions = runner_sessions(&dir.path().join("data"));
    let reference = dir.path().join("reference");
    let clean = finish(start(&reference, &sessions, &[]));
    assert!(
        clean.status.success(),
        "{}",
        String::from_utf8_lossy(&clean.stderr)
    );
    let want = products(&reference, "dataset_quality");
    assert!(want.len() >= 10);
    let out = dir.path().join("shared");
    let folder = out.join("dataset_quality");
    let mut refused = 0;
    for round in 0..ROUNDS {
        let (a, b) = (
            start(&out, &sessions, &["--force"]),
            start(&out, &sessions, &["--force"]),
        );
        let ids = [a.id(), b.id()];
        let outputs = [finish(a), finish(b)];
        let mut succeeded = 0;
        for (i, o) in outputs.iter().enumerate() {
            let (stdout, stderr) = (
                String::from_utf8_lossy(&o.stdout),
                String::from_utf8_lossy(&o.stderr),
            );
            if o.status.success() {
                succeeded += 1;
                assert!(
                    stdout.contains("3 sessions (3 computed, 0 from cache, 0 skipped)"),
                    "round {round}: {stdout}{stderr}"
                );
                assert!(!stderr.contains("warning"), "round {round}: {stderr}");
            } else {
                refused += 1;
                let other = ids[1 - i];
                let said = format!(
                    "error: {} is in use by another run (process {other} on {}, holding {}): ",
                    folder.display(),
                    peopletrack::run::lock::host_name(),
                    folder.join(".lock").display()
                );
                assert_eq!(o.status.code(), Some(1), "round {round}: {stderr}");
                assert!(stderr.starts_with(&said), "round {round}: {stderr}");
                assert!(stdout.is_empty(), "round {round}: failed at once: {stdout}");
            }
        }
        assert!(succeeded >= 1, "round {round}: one of them runs");
        assert_eq!(
            products(&out, "dataset_quality"),
            want,
            "round {round}: the folder holds a clean run's tables and figures"
        );
        assert_no_scratch_left(&out);
    }
    eprintln!("{refused} of {ROUNDS} rounds refused the second run");
}

/// Shards of one pipeline writing disjoint sessions into one folder at the same time take no
/// common lock: both succeed, and the aggregation of what they stored is a clean run's.
#[test]
fn shards_into_one_folder_run_side_by_side() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sessions = runner_sessions(&dir.path().join("data"));
    let reference = dir.path().join("reference");
    assert!(finish(start(&reference, &sessions, &[])).status.success());
    let want = products(&reference, "dataset_quality");
    let out = dir.path().join("shared");
    for round in 0..3 {
        let shards = [
            start(&out, &sessions, &["--force", "--shard", "1/2"]),
            start(&out, &sessions, &["--force", "--shard", "2/2"]),
        ];
        for o in shards.map(finish) {
            assert!(
                o.status.success(),
                "round {round}: {}",
                String::from_utf8_lossy(&o.stderr)
            );
        }
        let all = finish(start(&out, &sessions, &["--aggregate-only"]));
        let stdout = String::from_utf8_lossy(&all.stdout);
        assert!(
            all.status.success() && stdout.contains("0 computed, 3 from cache, 0 skipped"),
            "round {round}: {stdout}{}",
            String::from_utf8_lossy(&all.stderr)
        );
        assert_eq!(products(&out, "dataset_quality"), want, "round {round}");
        assert_no_scratch_left(&out);
    }
}

/// A folder held by a live process (here, this test) is refused at once with that process's
/// id, and a run's scratch folder left by a killed run is swept by the next one.
#[test]
fn a_held_folder_names_its_holder_and_a_killed_runs_scratch_is_swept() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sessions = runner_sessions(&dir.path().join("data"));
    let out = dir.path().join("out");
    let folder = out.join("dataset_quality");
    let held = peopletrack::run::lock::FolderLock::acquire(&folder).expect("lock");
    let o = finish(start(&out, &sessions, &[]));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert_eq!(
        stderr.trim_end(),
        format!(
            "error: {} is in use by another run (process {}, holding {}): wait for it to finish, or give this run another --out",
            folder.display(),
            peopletrack::run::lock::holder_id(),
            folder.join(".lock").display()
        )
    );
    drop(held);
    // killed just before its first rename: its scratch folder stays, unlocked ...
    let killed = finish(start(&out, &sessions, &["--debug-abort-after-writes", "1"]));
    assert!(!killed.status.success());
    let left = std::fs::read_dir(out.join(".tmp"))
        .expect("scratch")
        .count();
    assert_eq!(left, 1, "the killed run's scratch folder");
    // ... and the next run sweeps it and leaves nothing
    assert!(finish(start(&out, &sessions, &[])).status.success());
    assert_no_scratch_left(&out);
}

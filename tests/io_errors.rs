//! Where the tool meets the file system (issue 36, items 2–6), each case as a known answer:
//! a session computed but not stored fails the run and is listed with its cache folder and
//! reason (`--keep-going` accepts it); every I/O error names the path and the step, with the
//! system's "(os error N)" once; `cat --recover` on a log cut before its first chunk ends says
//! the channel was lost; a `[topics]` remap no session has and a glob that matches nothing are
//! said; the CDR structure budget has an option that its error names.
//!
//! Failures are made so that they happen for root too (a file where a folder must be); the
//! permission cases (mode 555, an unreadable folder) run only where permissions hold
//! (SKIPPED, with a message, for a privileged user).

use crate::common;

use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};

use assert_cmd::Command;
use common::raw_mcap as raw;
use common::runner_sessions;

fn peopletrack() -> Command {
    Command::cargo_bin("peopletrack").expect("binary")
}

fn pipeline() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("pipelines/dataset_quality.toml")
}

/// `peopletrack run FILE ARGS...`: (exit code, stdout, stderr).
fn run_file(file: &Path, args: &[&str]) -> (Option<i32>, String, String) {
    let o = peopletrack()
        .arg("run")
        .arg(file)
        .args(args)
        .output()
        .expect("runs");
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// `peopletrack run dataset_quality.toml --sessions GLOB --out OUT EXTRA...`.
fn run(out: &Path, sessions: &str, extra: &[&str]) -> (Option<i32>, String, String) {
    let out = out.display().to_string();
    let args = [&["--sessions", sessions, "--out", &out][..], extra].concat();
    run_file(&pipeline(), &args)
}

/// Every line of an error output says the system's error at most once.
fn assert_os_error_once(stderr: &str) {
    for line in stderr.lines() {
        assert!(line.matches("(os error").count() <= 1, "said twice: {line}");
    }
}

/// Whether permissions stop this user (they do not stop root): a folder of mode 555 refuses a
/// new file. Says SKIPPED when they do not.
fn permissions_hold(dir: &Path) -> bool {
    let probe = dir.join("probe");
    std::fs::create_dir(&probe).expect("mkdir");
    std::fs::set_permissions(&probe, std::fs::Permissions::from_mode(0o555)).expect("chmod");
    let held = std::fs::write(probe.join("x"), b"x").is_err();
    std::fs::set_permissions(&probe, std::fs::Permissions::from_mode(0o755)).expect("chmod");
    if !held {
        eprintln!("SKIPPED: this user is not stopped by file permissions (root?)");
    }
    held
}

/// `(session, status, reason, path)` of each row of the `skipped_sessions` table (from its
/// Parquet file: reasons hold commas).
fn skipped_rows(out: &Path) -> Vec<[String; 4]> {
    let df = peopletrack::report::table::read_parquet(
        &out.join("dataset_quality/tables/skipped_sessions.parquet"),
    )
    .expect("table");
    let col = |name: &str| peopletrack::report::columns::strs(&df, name).expect("column");
    let (s, st, r, p) = (col("session"), col("status"), col("reason"), col("path"));
    (0..df.height())
        .map(|i| [s[i].clone(), st[i].clone(), r[i].clone(), p[i].clone()])
        .collect()
}

#[test]
fn a_session_computed_but_not_stored_fails_the_run_and_is_listed() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sessions = runner_sessions(&dir.path().join("data"));
    let clean = dir.path().join("clean");
    assert_eq!(run(&clean, &sessions, &[]).0, Some(0));
    // the cache folder of dataset `lab` cannot be made: a file is in the way
    let out = dir.path().join("out");
    let blocked = out.join("dataset_quality/sessions/dataset=lab");
    std::fs::create_dir_all(blocked.parent().expect("parent")).expect("mkdir");
    std::fs::write(&blocked, b"in the way").expect("write");
    let (code, _, stderr) = run(&out, &sessions, &[]);
    assert_eq!(code, Some(1), "{stderr}");
    let cache_a = blocked.join("session=a");
    let reason = format!(
        "computed, but its results could not be stored in the cache at {}: creating folder {}: File exists (os error 17)",
        cache_a.display(),
        blocked.display()
    );
    let table = out.join("dataset_quality/tables/skipped_sessions.md");
    assert_eq!(
        stderr.trim_end(),
        format!(
            "error: {}: 2 session(s) computed but not stored in the cache (their results are in this run's tables and they are listed in {}, but the next run must compute them again; --keep-going accepts this); first: lab/a: {reason}",
            pipeline().display(),
            table.display()
        )
    );
    let rows = skipped_rows(&out);
    let listed: Vec<(&str, &str)> = rows
        .iter()
        .map(|r| (r[0].as_str(), r[1].as_str()))
        .collect();
    assert_eq!(listed, [("a", "unstored"), ("b", "unstored")]);
    assert_eq!(rows[0][2], reason);
    assert!(rows[0][3].ends_with("lab/a.mcap"), "{:?}", rows[0]);
    // their results are in the tables all the same
    let sessions_table = |o: &Path| {
        std::fs::read(o.join("dataset_quality/tables/sessions.csv")).expect("sessions table")
    };
    assert_eq!(sessions_table(&out), sessions_table(&clean));
    // --keep-going accepts it: exit 0, each said as a warning with its reason
    let (code, stdout, stderr) = run(&out, &sessions, &["--keep-going"]);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(stdout.contains("(2 computed, 1 from cache"), "{stdout}");
    assert!(
        stderr.contains(&format!(
            "warning: lab/a not stored in the cache (results kept): {reason}"
        )),
        "{stderr}"
    );
    assert_os_error_once(&stderr);
}

#[test]
fn outputs_that_cannot_be_written_are_named_with_the_step() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sessions = runner_sessions(&dir.path().join("data"));
    // an --out below a file: the folder lock cannot be made, said before any session runs
    let file = dir.path().join("plain");
    std::fs::write(&file, b"x").expect("write");
    let (code, stdout, stderr) = run(&file.join("out"), &sessions, &[]);
    assert_eq!(code, Some(1));
    assert!(stdout.is_empty());
    let folder = file.join("out/dataset_quality");
    assert_eq!(
        stderr.trim_end(),
        format!(
            "error: locking {0}: creating folder {0}: Not a directory (os error 20)",
            folder.display()
        )
    );
    // a figure whose folder is a file: "writing figure NAME to PATH: …"
    let out = dir.path().join("out");
    let figures = out.join("dataset_quality/figures");
    std::fs::create_dir_all(figures.parent().expect("parent")).expect("mkdir");
    std::fs::write(&figures, b"in the way").expect("write");
    let (code, _, stderr) = run(&out, &sessions, &[]);
    assert_eq!(code, Some(1));
    let png = figures.join("rates_lab.png");
    assert_eq!(
        stderr.trim_end(),
        format!(
            "error: writing figure rates_lab to {}: creating folder {}: File exists (os error 17)",
            png.display(),
            figures.display()
        )
    );
    // a table likewise: "writing table NAME to PATH: …", the system's error once
    std::fs::remove_file(&figures).expect("rm");
    let tables = out.join("dataset_quality/tables");
    std::fs::remove_dir_all(&tables).expect("rm");
    std::fs::write(&tables, b"in the way").expect("write");
    let (code, _, stderr) = run(&out, &sessions, &[]);
    assert_eq!(code, Some(1));
    assert!(
        stderr.starts_with(&format!(
            "error: writing table sessions to {}: creating folder {}: File exists (os error 17)",
            tables.join("sessions.csv").display(),
            tables.display()
        )),
        "{stderr}"
    );
    assert_os_error_once(&stderr);
}

/// Disk full, as the kernel reports it, in the messages a full disk gives while writing a
/// figure or a table: one "(os error 28)", the name and the path.
#[test]
fn a_full_disk_is_said_once_with_the_figure_or_table_and_its_path() {
    use peopletrack::report::figure::FigureError;
    use peopletrack::report::table::TableError;
    let full = || std::io::Error::from_raw_os_error(28);
    let png = Path::new("out/laser_people/figures/rates_general_tracking_moving_1.png");
    let e = anyhow::Error::from(FigureError::io(
        "rates_general_tracking_moving_1",
        png,
        &full(),
    ));
    assert_eq!(
        format!("{e:#}"),
        "writing figure rates_general_tracking_moving_1 to out/laser_people/figures/rates_general_tracking_moving_1.png: No space left on device (os error 28)"
    );
    let e = anyhow::Error::from(TableError::Io {
        table: "sessions".into(),
        path: "out/p/tables/sessions.csv".into(),
        error: full(),
    });
    assert_eq!(
        format!("{e:#}"),
        "writing table sessions to out/p/tables/sessions.csv: No space left on device (os error 28)"
    );
    // and an I/O error inside a log error: once
    let e = anyhow::Error::from(peopletrack::log::LogError::new("x.mcap", full()));
    assert_eq!(
        format!("{e:#}"),
        "x.mcap: No space left on device (os error 28)"
    );
}

/// An output folder of mode 555, and a finished folder made read-only: the error names the
/// folder (not "every session was skipped"); a glob over an unreadable folder names it.
#[test]
fn read_only_folders_and_unreadable_globs_are_named() {
    let dir = tempfile::tempdir().expect("tempdir");
    if !permissions_hold(dir.path()) {
        return;
    }
    let sessions = runner_sessions(&dir.path().join("data"));
    let mode = |p: &Path, m: u32| {
        std::fs::set_permissions(p, std::fs::Permissions::from_mode(m)).expect("chmod")
    };
    let out = dir.path().join("ro");
    std::fs::create_dir(&out).expect("mkdir");
    mode(&out, 0o555);
    let (code, _, stderr) = run(&out, &sessions, &[]);
    mode(&out, 0o755);
    assert_eq!(code, Some(1));
    let folder = out.join("dataset_quality");
    assert_eq!(
        stderr.trim_end(),
        format!(
            "error: locking {0}: creating folder {0}: Permission denied (os error 13)",
            folder.display()
        )
    );
    // finished, then read-only: a rerun names where it could not write
    assert_eq!(run(&out, &sessions, &[]).0, Some(0));
    let all = |m: u32| {
        for p in [&out, &folder] {
            mode(p, m);
        }
    };
    all(0o555);
    let (code, _, stderr) = run(&out, &sessions, &[]);
    all(0o755);
    assert_eq!(code, Some(1));
    // the sessions are cached; the first table needs this run's scratch folder in out/.tmp
    let scratch = format!(
        ": creating folder {}: Permission denied (os error 13)",
        out.join(".tmp").display()
    );
    assert!(
        stderr.starts_with("error: writing table ") && stderr.trim_end().ends_with(&scratch),
        "{stderr}"
    );
    assert_os_error_once(&stderr);
    // a session glob over a folder this user cannot read
    let lab = dir.path().join("data/lab");
    mode(&lab, 0o000);
    let (code, _, stderr) = run(&out, &sessions, &[]);
    mode(&lab, 0o755);
    assert_eq!(code, Some(1));
    assert_eq!(
        stderr.trim_end(),
        format!(
            "error: session glob `{sessions}`: cannot read folder {}: Permission denied (os error 13)",
            lab.display()
        )
    );
}

/// A model file that is not there is refused by `--dry-run` already, naming the pipeline
/// file, the key's line and the path.
#[test]
fn a_missing_model_file_is_refused_by_the_dry_run_with_its_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let shipped =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("pipelines/s000_cielniak_omni.toml");
    let text = std::fs::read_to_string(&shipped).expect("pipeline");
    let from = "model = \"\"";
    assert!(text.contains(from));
    let missing = dir.path().join("gone.json");
    let text = text.replacen(
        from,
        &format!("model = {:?}", missing.display().to_string()),
        1,
    );
    let line = text
        .lines()
        .position(|l| l.starts_with("model = "))
        .expect("line")
        + 1;
    let file = dir.path().join("s000.toml");
    std::fs::write(&file, text).expect("write");
    let (code, _, stderr) = run_file(&file, &["--dry-run"]);
    assert_eq!(code, Some(1));
    assert_eq!(
        stderr.trim_end(),
        format!(
            "error: {}:{line}: `params.model`: cannot read {}: No such file or directory (os error 2)",
            file.display(),
            missing.display()
        )
    );
}

/// A `[topics]` remap that no session has is said (with its line); a glob that matches
/// nothing fails a dry run as it fails a run.
#[test]
fn a_remap_no_session_has_is_a_warning_and_an_empty_glob_an_error() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sessions = runner_sessions(&dir.path().join("data"));
    let text = std::fs::read_to_string(pipeline()).expect("pipeline");
    let from = "ground_truth = \"/ground_truth/people\"";
    let line = text.lines().position(|l| l == from).expect("remap") + 1;
    let file = dir.path().join("dq.toml");
    std::fs::write(
        &file,
        text.replace(from, "ground_truth = \"/groundtruth/people\""),
    )
    .expect("write");
    let said = format!(
        "warning: {}:{line}: `topics.ground_truth`: no session has topic `/groundtruth/people` (none of the 3 that open): what reads `ground_truth` ran without it",
        file.display()
    );
    let out = dir.path().join("out").display().to_string();
    for extra in [&["--dry-run"][..], &[]] {
        let args = [&["--sessions", &sessions, "--out", &out][..], extra].concat();
        let (code, _, stderr) = run_file(&file, &args);
        assert_eq!(code, Some(0), "{stderr}");
        assert!(stderr.lines().any(|l| l == said), "{extra:?}: {stderr}");
    }
    let nothing = format!("{}/none/*.mcap", dir.path().display());
    let (code, _, stderr) = run_file(&pipeline(), &["--dry-run", "--sessions", &nothing]);
    assert_eq!(code, Some(1));
    assert_eq!(
        stderr.trim_end(),
        format!(
            "error: {}: no sessions match [{nothing:?}]",
            pipeline().display()
        )
    );
}

/// A log of one chunk holding the channel and three messages, cut inside that chunk:
/// `cat --recover` says the topic's channel record was in what is lost.
#[test]
fn recover_on_a_log_cut_inside_its_first_chunk_says_the_channel_was_lost() {
    let dir = tempfile::tempdir().expect("tempdir");
    let schema = raw::schema(1, "p/msg/T", "ros2msg", b"uint8 v\n");
    let channel = raw::channel(1, 1, "/scan", "cdr");
    let messages: Vec<u8> = (1..=3u64)
        .flat_map(|t| raw::message(1, t as u32, t, &raw::cdr(&[7])))
        .collect();
    let chunk = raw::chunk(
        1,
        3,
        &[schema.clone(), channel.clone(), messages].concat(),
        true,
    );
    let bytes = raw::file(&[&chunk], &[]);
    let cut_at = raw::header().len() + 8 + chunk.len() / 2;
    let p = dir.path().join("cut.mcap");
    std::fs::write(&p, &bytes[..cut_at]).expect("write");
    let o = peopletrack()
        .args(["cat", "--recover", "--topic", "/scan"])
        .arg(&p)
        .output()
        .expect("runs");
    assert_eq!(o.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&o.stderr);
    let start = raw::header().len() + 8;
    assert!(
        stderr.lines().last().expect("error").starts_with(&format!(
            "error: {}: topic /scan: no topic `/scan` in the part of the log that could be read (its topics: none): its channel record was in what is lost (bytes {start}..{cut_at}), or the log never had it",
            p.display()
        )),
        "{stderr}"
    );
}

/// An array of 300,000 one-byte structs takes ~24 MB of structure for a 300 kB payload: the
/// default budget (16 MiB + 8 B per payload byte) refuses it and says which option raises
/// it; with the option the message prints.
#[test]
fn the_structure_budget_has_an_option_named_in_its_error() {
    const N: usize = 300_000;
    let dir = tempfile::tempdir().expect("tempdir");
    let schema = raw::schema(
        1,
        "p/msg/T0",
        "ros2msg",
        b"p/B[] items\n===\nMSG: p/B\nuint8 v\n",
    );
    let channel = raw::channel(1, 1, "/x", "cdr");
    let mut body = (N as u32).to_le_bytes().to_vec();
    body.resize(4 + N, 1);
    let message = raw::message(1, 1, 5, &raw::cdr(&body));
    let chunk = raw::chunk(
        5,
        5,
        &[schema.clone(), channel.clone(), message].concat(),
        true,
    );
    let p = dir.path().join("structs.mcap");
    std::fs::write(&p, raw::file(&[&schema, &channel, &chunk], &[])).expect("write");
    let cat = |extra: &[&str]| {
        peopletrack()
            .args(extra)
            .args(["cat", "--topic", "/x"])
            .arg(&p)
            .output()
            .expect("runs")
    };
    let refused = cat(&[]);
    assert_eq!(refused.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&refused.stderr);
    let budget = (16 << 20) + 8 * (N + 8);
    assert!(
        stderr.contains(&format!(
            "decoded message would take more than {budget} bytes of structure (payload {} bytes; --max-structure-mib raises this limit)",
            N + 8
        )),
        "{stderr}"
    );
    let fine = cat(&["--max-structure-mib", "64"]);
    assert!(
        fine.status.success(),
        "{}",
        String::from_utf8_lossy(&fine.stderr)
    );
    let line: serde_json::Value = serde_json::from_slice(&fine.stdout).expect("one JSON line");
    let items = line["message"]["items"].as_array().expect("items");
    assert_eq!(items.len(), N);
    assert!(items.iter().all(|i| i["v"] == 1));
}

/// Error types print the error they wrap once: no `#[error]` message displays a field that
/// is also the error's source (`#[from]`, `#[source]` or a field named `source`), which an
/// error chain (`{:#}`) would print a second time.
#[test]
fn no_error_type_prints_its_source_twice() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut found = Vec::new();
    let mut stack = vec![root];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).expect("src") {
            let p = e.expect("entry").path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                let text = std::fs::read_to_string(&p).expect("read");
                found.extend(
                    twice(&text)
                        .into_iter()
                        .map(|l| format!("{}:{l}", p.display())),
                );
            }
        }
    }
    assert!(found.is_empty(), "errors printed twice: {found:?}");
}

/// Lines (1-based) of `#[error("...")]` attributes whose message shows the variant's source.
fn twice(text: &str) -> Vec<usize> {
    let lines: Vec<&str> = text.lines().map(str::trim).collect();
    let mut out = Vec::new();
    for (i, l) in lines.iter().enumerate() {
        if !l.starts_with("#[error(") || l.contains("transparent") {
            continue;
        }
        // the attribute (it may span lines), then the variant up to the next attribute
        let end = (i..lines.len())
            .find(|&k| lines[k].ends_with(")]"))
            .unwrap_or(i);
        let message = lines[i..=end].join(" ");
        let variant = lines[end + 1..]
            .iter()
            .take_while(|l| !l.starts_with("#[") && !l.starts_with('}'))
            .copied()
            .collect::<Vec<_>>()
            .join(" ");
        let shows_0 = message.contains("{0}")
            && (variant.contains("(#[from]") || variant.contains("(#[source]"));
        let shows_source = message.contains("{source}") && variant.contains("source:");
        if shows_0 || shows_source {
            out.push(i + 1);
        }
    }
    out
}

#[test]
fn the_scan_for_sources_printed_twice_finds_them() {
    let bad = "enum E {\n    #[error(\"saved: {0}\")]\n    Io(#[from] std::io::Error),\n    #[error(\n        \"{path}: {source}\"\n    )]\n    Read { path: String, source: std::io::Error },\n}\n";
    assert_eq!(twice(bad), [2, 4]);
    let good = "enum E {\n    #[error(\"saved: {0}\")]\n    Io(std::io::Error),\n    #[error(transparent)]\n    Log(#[from] LogError),\n    #[error(\"{path}: {error}\")]\n    Read { path: String, error: std::io::Error },\n}\n";
    assert!(twice(good).is_empty());
}

/// A session log written to a full disk (its scratch file is `/dev/full`, which refuses every
/// write with ENOSPC, for root too) says the system's error once, with the file; the `mcap`
/// writer's own text ("I/O error from writing…") used to hide it.
#[test]
fn a_log_written_to_a_full_disk_says_so_with_its_path() {
    use peopletrack::log::msgs::{Header, LaserScan};
    use peopletrack::log::{SessionWriter, WriterOptions};
    let dir = tempfile::tempdir().expect("tempdir");
    let p = dir.path().join("full.mcap");
    let tmp = dir.path().join("full.mcap.tmp");
    std::os::unix::fs::symlink("/dev/full", &tmp).expect("symlink");
    let result = (|| {
        let mut w = SessionWriter::create(&p, &WriterOptions::default())?;
        let scan = w.add_ros2::<LaserScan>("/scan")?;
        let msg = LaserScan {
            header: Header::new(peopletrack::Nanos(1), "laser"),
            ranges: vec![1.0; 4],
            ..Default::default()
        };
        w.write(scan, peopletrack::Nanos(1), &msg)?;
        w.finish()
    })();
    let e = result.expect_err("the disk is full");
    assert_eq!(
        format!("{:#}", anyhow::Error::from(e)),
        format!("{}: No space left on device (os error 28)", tmp.display())
    );
    assert!(!p.exists());
}

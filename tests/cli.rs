//! The CLI end to end: `inspect` and `cat` on real logs, errors as exit codes.

use crate::common;

use assert_cmd::Command;

fn peopletrack() -> Command {
    Command::cargo_bin("peopletrack").expect("binary built")
}

#[test]
fn inspect_json_reports_topics_counts_and_tf() {
    let Some(log) = common::laser_log("general_tracking_moving_1") else {
        return;
    };
    let out = peopletrack()
        .arg("inspect")
        .arg(&log)
        .arg("--json")
        .output()
        .expect("runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    let topics = v["topics"].as_array().expect("topics");
    let count = |t: &str| {
        topics
            .iter()
            .find(|x| x["topic"] == t)
            .map(|x| x["count"].as_u64())
    };
    assert_eq!(count("/tf"), Some(Some(21744)));
    assert_eq!(count("/scan"), Some(Some(873)));
    assert!(topics.iter().all(|t| t["decoder"] == "ok"));
    assert!(
        v["tf_tree"]
            .as_array()
            .expect("tree")
            .iter()
            .any(|e| e["parent"] == "base_link" && e["child"] == "left_laser")
    );
    assert_eq!(v["messages"], 34331);
}

#[test]
fn cat_prints_json_lines_with_non_finite_ranges_visible() {
    let Some(log) = common::laser_log("demo_stationary_simple_environment") else {
        return;
    };
    let out = peopletrack()
        .args(["cat", "--topic", "/scan", "--limit", "2"])
        .arg(&log)
        .output()
        .expect("runs");
    assert!(out.status.success());
    let lines: Vec<serde_json::Value> = String::from_utf8(out.stdout)
        .expect("utf8")
        .lines()
        .map(|l| serde_json::from_str(l).expect("each line is JSON"))
        .collect();
    assert_eq!(lines.len(), 2);
    let ranges = lines[0]["message"]["ranges"].as_array().expect("ranges");
    assert_eq!(ranges.len(), 512);
    // verify.txt: the first scan has 341 non-finite beams
    assert_eq!(ranges.iter().filter(|r| r.is_string()).count(), 341);
    assert_eq!(lines[0]["log_time_ns"], 1_403_201_183_687_882_605u64);
}

#[test]
fn errors_exit_1_with_the_file_named_and_usage_errors_exit_2() {
    let dir = tempfile::tempdir().expect("tempdir");
    let bad = dir.path().join("bad.mcap");
    std::fs::write(&bad, b"not a log at all").expect("write");
    let out = peopletrack()
        .arg("inspect")
        .arg(&bad)
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.starts_with("error: ") && err.contains("bad.mcap"),
        "{err}"
    );
    let out = peopletrack().args(["cat"]).output().expect("runs");
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn help_teaches_with_examples() {
    let out = peopletrack().arg("--help").output().expect("runs");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("inspect") && text.contains("cat") && text.contains("Examples:"),
        "{text}"
    );
}

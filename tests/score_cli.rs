//! `peopletrack score` end to end: TUD-Campus (real data), bad files and bad usage as exit
//! codes.

use crate::common;

use assert_cmd::Command;

fn peopletrack() -> Command {
    Command::cargo_bin("peopletrack").expect("binary built")
}

#[test]
fn scores_tud_campus_as_text_and_json() {
    let Some(dir) = common::real("motmetrics/TUD-Campus") else {
        return;
    };
    let args = |extra: &[&str]| {
        let mut c = peopletrack();
        c.arg("score")
            .arg("--gt")
            .arg(dir.join("gt.txt"))
            .arg("--hyp")
            .arg(dir.join("test.txt"))
            .args(["--iou", "0.5"])
            .args(extra);
        c.output().expect("runs")
    };

    let out = args(&[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).expect("utf8");
    for line in [
        "MOTA       52.65 %",
        "MOTP        0.2772",
        "IDF1       55.77 %",
        "IDSW             7",
        "MT/PT/ML     1/6/1",
    ] {
        assert!(text.contains(line), "missing `{line}` in\n{text}");
    }

    let out = args(&["--json"]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    let m = &v["metrics"];
    // py-motmetrics 1.4.0 (expected_metrics.txt).
    let close =
        |x: &serde_json::Value, want: f64| (x.as_f64().expect("number") - want).abs() <= 1e-6;
    assert!(close(&m["clear"]["mota"], 0.526462));
    assert!(close(&m["clear"]["motp"], 0.277201));
    assert!(close(&m["identity"]["idf1"], 0.557659));
    assert_eq!(m["clear"]["num_false_positives"], 13);
    assert_eq!(m["clear"]["num_misses"], 150);
    assert_eq!(m["hota"]["per_alpha"].as_array().expect("array").len(), 19);
    assert_eq!(v["match"]["rule"], "iou");
}

#[test]
fn a_bad_row_fails_naming_file_and_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let gt = dir.path().join("gt.txt");
    let hyp = dir.path().join("hyp.txt");
    std::fs::write(&gt, "1,1,0,0,10,10,1,-1,-1,-1\n").expect("write");
    std::fs::write(
        &hyp,
        "1,1,0,0,10,10,1,-1,-1,-1\n2,1,0,0,ten,10,1,-1,-1,-1\n",
    )
    .expect("write");
    let out = peopletrack()
        .arg("score")
        .arg("--gt")
        .arg(&gt)
        .arg("--hyp")
        .arg(&hyp)
        .args(["--iou", "0.5"])
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(&format!("{}:2: column `bb_width` is `ten`", hyp.display())),
        "{err}"
    );
}

#[test]
fn ground_plane_points_score_in_metres() {
    let dir = tempfile::tempdir().expect("tempdir");
    let gt = dir.path().join("gt.csv");
    let hyp = dir.path().join("hyp.csv");
    std::fs::write(&gt, "1,1,-1,-1,-1,-1,1,0,0,-1\n2,1,-1,-1,-1,-1,1,1,0,-1\n").expect("write");
    std::fs::write(
        &hyp,
        "1,4,-1,-1,-1,-1,1,0.3,0.4,-1\n2,4,-1,-1,-1,-1,1,1,2,-1\n",
    )
    .expect("write");
    let out = peopletrack()
        .arg("score")
        .arg("--gt")
        .arg(&gt)
        .arg("--hyp")
        .arg(&hyp)
        .args(["--dist-m", "0.75", "--json"])
        .output()
        .expect("runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    let c = &v["metrics"]["clear"];
    // Frame 1: 0.5 m, a match; frame 2: 2 m, a miss and a false positive.
    assert_eq!(
        (c["num_matches"].as_u64(), c["num_misses"].as_u64()),
        (Some(1), Some(1))
    );
    assert_eq!(c["motp"].as_f64(), Some(0.5));
}

#[test]
fn needs_exactly_one_matching_rule() {
    for extra in [&[][..], &["--iou", "0.5", "--dist-m", "1"][..]] {
        let out = peopletrack()
            .args(["score", "--gt", "a.csv", "--hyp", "b.csv"])
            .args(extra)
            .output()
            .expect("runs");
        assert_eq!(out.status.code(), Some(2), "{extra:?}");
    }
}

#[test]
fn an_empty_ground_truth_or_a_bad_threshold_is_an_error_naming_it() {
    let dir = tempfile::tempdir().expect("tempdir");
    let gt = dir.path().join("gt.csv");
    let hyp = dir.path().join("hyp.csv");
    std::fs::write(&gt, "").expect("write");
    std::fs::write(&hyp, "1,1,0,0,10,10,1,-1,-1,-1\n").expect("write");
    let out = peopletrack()
        .args(["score", "--iou", "0.5", "--gt"])
        .arg(&gt)
        .arg("--hyp")
        .arg(&hyp)
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("gt.csv") && err.contains("no ground-truth rows"),
        "{err}"
    );
    for (flag, value, says) in [
        ("--dist-m", "-1", "positive number of metres"),
        ("--dist-m", "0", "positive number of metres"),
        ("--iou", "1.5", "(0, 1]"),
        ("--iou", "-0.2", "(0, 1]"),
    ] {
        let out = peopletrack()
            .args(["score", flag, value, "--gt"])
            .arg(&hyp)
            .arg("--hyp")
            .arg(&hyp)
            .output()
            .expect("runs");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{flag} {value}: {err}");
        assert!(
            err.contains(says) && err.contains(value),
            "{flag} {value}: {err}"
        );
    }
}

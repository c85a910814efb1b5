//! Bad pipeline files (issue 19, item 5): every out-of-range value names the file, the line of
//! its key and its full key path — nested tables and arrays of tables included; unknown
//! `[topics]` keys are errors naming them; degenerate values (zero splits, epochs, sweep splits,
//! a panorama of no pixels) are errors naming the parameter before anything runs, through
//! `run` and through `train`. Each test writes the bad file itself from the shipped one.

use std::path::{Path, PathBuf};

use assert_cmd::Command;
use peopletrack::pipelines::run_file;
use peopletrack::run::RunOptions;
use peopletrack::run::config::line_of;

fn shipped(name: &str) -> String {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("pipelines/{name}.toml"));
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn dry_run(out: &Path) -> RunOptions {
    RunOptions {
        sessions: Some(vec![format!("{}/none/*.mcap", out.display())]),
        dry_run: true,
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

/// The 1-based line of the first line of `text` containing `needle`.
fn line(text: &str, needle: &str) -> usize {
    text.lines()
        .position(|l| l.contains(needle))
        .unwrap_or_else(|| panic!("no line with {needle}"))
        + 1
}

/// Write `text` as `bad.toml`, plan it, and return the error.
fn error_of(dir: &Path, text: &str) -> String {
    let path = dir.join("bad.toml");
    std::fs::write(&path, text).expect("write");
    match run_file(&path, &dry_run(dir)) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => format!("{e:#}"),
    }
}

/// Replace `from` (once, exactly) by `to` in the shipped file `name`, and check the error says
/// `bad.toml:<line of to>: \`key\``.
fn check(name: &str, from: &str, to: &str, key: &str) {
    let dir = tempfile::tempdir().expect("tempdir");
    let text = shipped(name);
    assert_eq!(text.matches(from).count(), 1, "{from} in {name}");
    let text = text.replace(from, to);
    let err = error_of(dir.path(), &text);
    let first = to.lines().next().expect("a line");
    let want = format!("bad.toml:{}: `{key}`", line(&text, first));
    assert!(err.contains(&want), "want {want}\n got {err}");
}

/// Regression: `[params.local_eval] min_iou = 1.5` was `…toml:0: 'params.min_iou'`.
#[test]
fn nested_values_out_of_range_name_their_line_and_full_key_path() {
    let s003 = "s003_zivkovic_background";
    check(
        s003,
        "min_iou = 0.5 ",
        "min_iou = 1.5 ",
        "params.local_eval.min_iou",
    );
    check(
        s003,
        "n_mixtures = 4\n",
        "n_mixtures = 0\n",
        "params.roc.baseline.n_mixtures",
    );
    check(
        s003,
        "beta = 1.1677                          # consistent",
        "beta = -1.0 # consistent",
        "params.local.em.beta",
    );
    check(
        s003,
        "epsilon_px = 0.5                       # stop when the boundary",
        "epsilon_px = 0.0 # stop when the boundary",
        "params.colour.em.epsilon_px",
    );
    check(
        s003,
        "still_frames = 15 ",
        "still_frames = 0 ",
        "params.local.still_frames",
    );
    check(
        s003,
        "var_thresholds = [4.0,",
        "var_thresholds = [-4.0,",
        "params.roc.var_thresholds",
    );
}

#[test]
fn arrays_of_tables_name_the_element() {
    let laser = "laser_people";
    check(
        laser,
        "scans = [133, 404]",
        "scans = [404, 133]",
        "params.sequences[0].scans",
    );
    check(
        laser,
        "scan_topic = \"/scan_base2\"",
        "scan_topic = \"\"",
        "params.sequences[1].scan_topic",
    );
    check(
        laser,
        "max_range_m = 5.0\n",
        "max_range_m = -5.0\n",
        "params.synthetic.max_range_m",
    );
}

#[test]
fn a_key_left_at_its_default_points_at_its_table() {
    let text = shipped("s003_zivkovic_background");
    // `history` is written under [params.roc.adaptive]; `nonexistent` is not
    assert_eq!(
        line_of(&text, "params.roc.adaptive.history"),
        Some((line(&text, "[params.roc.adaptive]") + 1, true))
    );
    assert_eq!(
        line_of(&text, "params.roc.adaptive.nonexistent"),
        Some((line(&text, "[params.roc.adaptive]"), false))
    );
    assert_eq!(line_of(&text, "nothing.here"), None);
}

#[test]
fn unknown_topic_keys_are_errors_naming_them() {
    // a pipeline that remaps topics lists the names it knows
    check(
        "s003_zivkovic_background",
        "odom = \"/odom\"",
        "odmo = \"/odom\"",
        "topics.odmo",
    );
    let dir = tempfile::tempdir().expect("tempdir");
    let text = shipped("s003_zivkovic_background").replace("odom = \"/odom\"", "odmo = \"/odom\"");
    let err = error_of(dir.path(), &text);
    assert!(err.contains("image, mask, ground_truth, odom"), "{err}");

    // per-camera names follow `cameras`
    let s004 = shipped("s004_mohedano_multicam");
    let ok = s004.replace(
        "ground_truth = \"/ground_truth/people\"",
        "ground_truth = \"/ground_truth/people\"\ncam_3_image = \"/c3\"",
    );
    // a dry run needs a session to plan (a glob that matches nothing is an error)
    std::fs::create_dir_all(dir.path().join("none")).expect("mkdir");
    std::fs::write(dir.path().join("none/s.mcap"), b"not opened by a dry run").expect("write");
    run_file(&write(dir.path(), "ok.toml", &ok), &dry_run(dir.path())).expect("a known name");
    check(
        "s004_mohedano_multicam",
        "ground_truth = \"/ground_truth/people\"\n\n[params]",
        "cam_9_image = \"/c9\"\n\n[params]",
        "topics.cam_9_image",
    );

    // a pipeline without remaps says so
    let s000 =
        shipped("s000_cielniak_omni").replace("[params]", "[topics]\nomni = \"/o\"\n\n[params]");
    let err = error_of(dir.path(), &s000);
    let want = format!("bad.toml:{}: `topics.omni`", line(&s000, "omni = \"/o\""));
    assert!(
        err.contains(&want) && err.contains("takes no [topics] remaps"),
        "{err}"
    );
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write");
    p
}

/// Regressions: `splits = 0` panicked (index out of bounds), `epochs = 0` wrote an untrained
/// network's table with exit 0, `sweep_splits = 0` wrote NaN tables, a panorama of no pixels
/// ended in "only 0 frames have both omni features ...". Now each is refused before any work.
#[test]
fn degenerate_s000_values_are_errors_naming_the_parameter() {
    let s000 = "s000_cielniak_omni";
    check(s000, "splits = 10 ", "splits = 0 ", "params.splits");
    check(s000, "epochs = 2000 ", "epochs = 0 ", "params.epochs");
    check(
        s000,
        "sweep_splits = 3",
        "sweep_splits = 0",
        "params.sweep_splits",
    );
    check(
        s000,
        "panorama = [480, 120]",
        "panorama = [0, 120]",
        "params.panorama",
    );
    check(
        s000,
        "background_frames = 5 ",
        "background_frames = 1 ",
        "params.background_frames",
    );
    check(
        s000,
        "hidden_units = 4 ",
        "hidden_units = 0 ",
        "params.hidden_units",
    );
    check(
        s000,
        "train_fraction = 0.3 ",
        "train_fraction = 1.0 ",
        "params.train_fraction",
    );
    check(
        s000,
        "sweep_learning_rates = [0.05, 0.1, 0.3, 0.5, 0.8]",
        "sweep_learning_rates = []",
        "params.sweep_learning_rates",
    );
}

/// `pipelines::check_text` (what the `pipeline_file` fuzz target drives) gives the same
/// errors as `run` without any file or session, and accepts every shipped pipeline file.
#[test]
fn check_text_validates_without_running() {
    use peopletrack::pipelines::check_text;
    let path = Path::new("x.toml");
    for name in [
        "dataset_quality",
        "laser_people",
        "s000_cielniak_omni",
        "s003_zivkovic_background",
        "s004_mohedano_multicam",
    ] {
        let text = shipped(name);
        check_text(path, &text).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
    let bad = shipped("s000_cielniak_omni").replace("epochs = 2000 ", "epochs = 0 ");
    let want = format!("x.toml:{}: `params.epochs`", line(&bad, "epochs = 0 "));
    let err = check_text(path, &bad).expect_err("epochs = 0").to_string();
    assert!(err.starts_with(&want), "{err}");
    let err = check_text(path, "[pipeline]\nname = \"a\"\nkind = \"nope\"\n")
        .expect_err("unknown kind")
        .to_string();
    assert!(err.contains("unknown pipeline kind `nope`"), "{err}");
}

#[test]
fn other_pipelines_refuse_degenerate_values() {
    let s004 = "s004_mohedano_multicam";
    check(s004, "n_dis = 5 ", "n_dis = 0 ", "params.n_dis");
    check(
        s004,
        "template_tilts = 4",
        "template_tilts = 0",
        "params.template_tilts",
    );
    check(s004, "nms_iou = 0.3 ", "nms_iou = 1.3 ", "params.nms_iou");
    check(
        s004,
        "accel_sigma_mps2 = 2.0 ",
        "accel_sigma_mps2 = 0.0 ",
        "params.accel_sigma_mps2",
    );
    check(
        "dataset_quality",
        "bin_s = 1.0 ",
        "bin_s = 0.0 ",
        "params.bin_s",
    );
}

/// `peopletrack train` reads the same pipeline file: a degenerate value is the same error,
/// exit 1, before any session is read.
#[test]
fn train_refuses_the_same_degenerate_values() {
    let dir = tempfile::tempdir().expect("tempdir");
    let text = shipped("s000_cielniak_omni").replace("epochs = 2000 ", "epochs = 0 ");
    let config = write(dir.path(), "bad.toml", &text);
    let o = Command::cargo_bin("peopletrack")
        .expect("binary")
        .args(["train", "omni-appearance", "--sessions"])
        .arg(dir.path().join("*.mcap"))
        .arg("--config")
        .arg(&config)
        .arg("--out")
        .arg(dir.path().join("out"))
        .arg("-o")
        .arg(dir.path().join("m.json"))
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    let want = format!("bad.toml:{}: `params.epochs`", line(&text, "epochs = 0 "));
    assert!(err.contains(&want), "{err}");
    assert!(!dir.path().join("m.json").exists());
}

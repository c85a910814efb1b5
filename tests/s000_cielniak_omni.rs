//! E1 (seed 000) end to end on a 50 s omni_lab cut (tests/fixtures/omni_tiny.toml): synthesize,
//! calibrate the webcams, learn the appearance model, track; then load the saved model on the
//! same log without webcams and get the same per-frame estimates; tables identical whatever the
//! thread count.

use std::path::{Path, PathBuf};

use peopletrack::pipelines::run_file;
use peopletrack::run::RunOptions;
use peopletrack::synth::{SynthOptions, synthesize};

fn opts(out: &Path) -> RunOptions {
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

/// Rows of a table's CSV as (first column, second column, rest) strings.
fn csv(path: &Path) -> Vec<Vec<String>> {
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

/// The mean of a "mean ± std" cell.
fn mean(cell: &str) -> f64 {
    cell.split(' ')
        .next()
        .and_then(|m| m.parse().ok())
        .unwrap_or_else(|| panic!("not a mean ± std: {cell}"))
}

fn pipeline(dir: &Path, name: &str, sessions: &str, extra: &str) -> PathBuf {
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(
        &path,
        format!(
            "[pipeline]\nname = \"{name}\"\nkind = \"s000_cielniak_omni\"\ntitle = \"E1 test\"\ndescription = \"test\"\n\
             [inputs]\nsessions = [\"{sessions}\"]\n[params]\nsplits = 3\nepochs = 500\nsweep_hidden = [2, 4]\n\
             sweep_learning_rates = [0.3]\nsweep_splits = 1\n{extra}\n"
        ),
    )
    .expect("write pipeline");
    path
}

#[test]
fn calibrates_learns_tracks_and_the_saved_model_reproduces_its_estimates() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scenario = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/omni_tiny.toml");
    let logs = dir.path().join("logs");
    synthesize(
        &scenario,
        &SynthOptions {
            profile: "quick".into(),
            out: Some(logs.clone()),
            progress: None,
        },
    )
    .expect("synthesizes");
    let glob = format!("{}/*.mcap", logs.display());
    let train = pipeline(dir.path(), "s000_cielniak_omni", &glob, "");

    // the same run on 1 and 2 threads: byte-identical tables
    let outs: Vec<PathBuf> = [1usize, 2]
        .iter()
        .map(|&n| {
            let out = dir.path().join(format!("out{n}"));
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .expect("pool");
            pool.install(|| run_file(&train, &opts(&out)))
                .expect("E1 runs");
            out
        })
        .collect();
    crate::common::assert_schemas_documented(&train, &outs[0]);
    let tables = |out: &Path| outs_dir(out).join("tables");
    for name in [
        "calibration",
        "angle_error",
        "correlations",
        "ann_error",
        "ann_sweep",
        "person_specific",
        "kalman",
        "kalman_noise",
    ] {
        let (a, b) = (
            tables(&outs[0]).join(format!("{name}.csv")),
            tables(&outs[1]).join(format!("{name}.csv")),
        );
        assert!(
            std::fs::read(&a).expect("table") == std::fs::read(&b).expect("table"),
            "{name} differs between 1 and 2 threads"
        );
    }
    let t = tables(&outs[0]);

    // calibration: the fit brings the mean distance to the known marks down to centimetres
    let cal = csv(&t.join("calibration.csv"));
    let dbar = cal.iter().find(|r| r[0] == "all").expect("d̄ row");
    let (before, after): (f64, f64) =
        (dbar[2].parse().expect("num"), dbar[3].parse().expect("num"));
    assert!(
        after < 0.02 && before > 5.0 * after,
        "d̄ {before} -> {after}"
    );
    // ... and the measurement system then agrees with the simulator's truth to a few cm
    let truth = csv(&t.join("truth_check.csv"));
    let ext = mean(
        &truth
            .iter()
            .find(|r| r[0] == "measurement system position")
            .expect("row")[1],
    );
    assert!(ext < 0.08, "measurement system vs truth {ext} m");

    // the omni pre-processing: bearing within a few degrees, features correlated with distance
    let angle = mean(&csv(&t.join("angle_error.csv"))[0][1]);
    assert!(angle < 3.0, "angle error {angle} deg");
    let corr = csv(&t.join("correlations.csv"));
    let r_of = |q: &str| -> f64 {
        corr.iter().find(|r| r[0] == q).expect("row")[1]
            .parse()
            .expect("r")
    };
    assert!(
        r_of("apparent_distance") > 0.8,
        "apparent distance r = {}",
        r_of("apparent_distance")
    );
    assert!(
        r_of("width") < -0.5 && r_of("pixels") < -0.5,
        "width/pixels r = {} / {}",
        r_of("width"),
        r_of("pixels")
    );

    // the ANN: decimetre-level distances, not the ~1 m spread of the distances themselves
    let ann = mean(&csv(&t.join("ann_error.csv"))[0][1]);
    assert!(ann < 0.3, "ANN average error {ann} m");

    // the saved model, loaded on the same log with no measurement system, gives the same
    // per-frame estimates as the run that trained it
    let model = outs_dir(&outs[0]).join("models/omni_appearance.json");
    assert!(model.exists(), "model artefact");
    let est = pipeline(
        dir.path(),
        "omni_estimate",
        &glob,
        &format!("webcams = []\nmodel = \"{}\"", model.display()),
    );
    let out3 = dir.path().join("out3");
    run_file(&est, &opts(&out3)).expect("estimate-only run");
    let a = std::fs::read_to_string(outs_dir(&outs[0]).join("estimates.csv")).expect("estimates");
    let b = std::fs::read_to_string(out3.join("omni_estimate/estimates.csv")).expect("estimates");
    assert!(a.lines().count() > 50, "{} estimates", a.lines().count());
    assert_eq!(a, b);

    // a file that is not an appearance model is refused, naming it
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, "{\"kind\": \"something\"}").expect("write");
    let est_bad = pipeline(
        dir.path(),
        "omni_bad",
        &glob,
        &format!("webcams = []\nmodel = \"{}\"", bad.display()),
    );
    let e = run_file(&est_bad, &opts(&dir.path().join("out4"))).expect_err("bad model");
    assert!(format!("{e:#}").contains("bad.json"), "{e:#}");
}

fn outs_dir(out: &Path) -> PathBuf {
    out.join("s000_cielniak_omni")
}

/// Regressions (issue 19): `train_fraction = 0.001` panicked (index out of bounds when the
/// network was fitted on no frames), and `background_frames` longer than the log ended in
/// "only 0 frames have both omni features and a measured position", naming no parameter.
/// Both depend on the data, so they are met at run time; each is an error naming it.
#[test]
fn degenerate_values_met_at_run_time_name_the_parameter() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scenario = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/omni_tiny.toml");
    let logs = dir.path().join("logs");
    synthesize(
        &scenario,
        &SynthOptions {
            profile: "quick".into(),
            out: Some(logs.clone()),
            progress: None,
        },
    )
    .expect("synthesizes");
    let glob = format!("{}/*.mcap", logs.display());
    let out = dir.path().join("out");

    let tiny = pipeline(dir.path(), "tiny", &glob, "train_fraction = 0.001");
    let err = format!(
        "{:#}",
        run_file(&tiny, &opts(&out)).expect_err("no training frames")
    );
    assert!(
        err.contains("params.train_fraction = 0.001") && err.contains("into 0 training"),
        "{err}"
    );

    let long = pipeline(dir.path(), "long", &glob, "background_frames = 100000");
    let err = format!(
        "{:#}",
        run_file(&long, &opts(&out)).expect_err("no frames left")
    );
    assert!(
        err.contains("params.background_frames = 100000") && err.contains("none left"),
        "{err}"
    );
}

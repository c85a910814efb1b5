//! The `s003_biron_anchoring` pipeline end to end on one short `biron_home` session: the
//! shipped scenario cut to one 15 s session (the user walks in and greets the robot), rendered
//! by the synthesizer (closed loop: the attention system turns the pan-tilt unit), then the
//! shipped pipeline file run on it with 1 and 2 threads. Known answers:
//!
//! - the offline replay of the full system on the logged percepts reproduces the logged
//!   `/attention/state` at every step (the same code drove the closed loop);
//! - in free field at 30 dB a 0.5 s block's direction of arrival errs by well under a degree
//!   (the estimator's known-answer tests give 0.1° on pure delays; the noise adds little);
//! - the ablations: without sound no speech block lands on anyone and no greeting is heard
//!   (no top-down start); without faces nobody is ever "looking", so no top-down start either;
//! - every table and figure is byte-identical whatever the thread count, and every table is
//!   on `docs/schemas.md`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use peopletrack::synth::{SynthOptions, synthesize};

const PIPELINE: &str = "s003_biron_anchoring";

/// The shipped scenario with its quick profile cut to one 15 s session.
fn scenario(dir: &Path) -> PathBuf {
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("datasets/biron_home/scenario.toml");
    let text = std::fs::read_to_string(&shipped).expect("the shipped scenario");
    let quick = "[profiles.quick]\nsessions = 2\nduration_s = 30.0";
    assert!(text.contains(quick), "the scenario's quick profile changed");
    let text = text.replace(quick, "[profiles.quick]\nsessions = 1\nduration_s = 15.0");
    let p = dir.join("biron_home.toml");
    std::fs::write(&p, text).expect("write scenario");
    p
}

fn run(sessions: &str, out: &Path, jobs: &str) {
    let pipeline = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("pipelines")
        .join(format!("{PIPELINE}.toml"));
    let o = crate::common::run_pipeline(&pipeline, sessions, out, jobs);
    assert!(o.status.success(), "{}", crate::common::output_text(&o));
}

fn rows(out: &Path, table: &str) -> Vec<BTreeMap<String, String>> {
    crate::common::csv(
        &out.join(PIPELINE)
            .join("tables")
            .join(format!("{table}.csv")),
    )
}

fn num(r: &BTreeMap<String, String>, col: &str) -> f64 {
    r.get(col)
        .unwrap_or_else(|| panic!("no column {col} in {r:?}"))
        .parse()
        .unwrap_or_else(|e| panic!("{col} = {:?}: {e}", r[col]))
}

#[test]
fn biron_pipeline_end_to_end_on_a_short_session() {
    let dir = tempfile::tempdir().expect("tempdir");
    let data = dir.path().join("data");
    let s = synthesize(
        &scenario(dir.path()),
        &SynthOptions {
            profile: "quick".into(),
            out: Some(data.clone()),
            progress: None,
        },
    )
    .expect("synthesizes");
    assert_eq!(s.sessions.len(), 1);
    let sessions = format!("{}/*.mcap", data.display());
    let (o1, o2) = (dir.path().join("o1"), dir.path().join("o2"));
    run(&sessions, &o1, "1");
    run(&sessions, &o2, "2");
    let pipeline = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("pipelines/{PIPELINE}.toml"));
    crate::common::assert_schemas_documented(&pipeline, &o1);
    let (a, b) = (
        crate::common::products(&o1, PIPELINE),
        crate::common::products(&o2, PIPELINE),
    );
    for name in [
        "tables/doa_grid.csv",
        "tables/variants.csv",
        "tables/replay.csv",
        "tables/faces_by_width.csv",
        "tables/paired_ttests.csv",
    ] {
        assert!(a.contains_key(name), "{name} missing; have {:?}", a.keys());
    }
    assert_eq!(a, b, "tables and figures depend on the thread count");

    // the replay reproduces the closed loop's logged attention at every step
    let replay = rows(&o1, "replay");
    assert_eq!(replay.len(), 1);
    let stem = std::fs::read_dir(&data)
        .expect("data folder")
        .filter_map(|e| {
            let p = e.ok()?.path();
            (p.extension()? == "mcap").then(|| p.file_stem()?.to_str().map(str::to_string))?
        })
        .next()
        .expect("one log");
    assert_eq!(
        replay[0]["session"], stem,
        "the replay row names its session"
    );
    let steps = num(&replay[0], "steps");
    assert!(steps >= 140.0, "{replay:?}");
    assert_eq!(num(&replay[0], "mode_agree"), steps, "{replay:?}");
    assert_eq!(num(&replay[0], "focus_agree"), steps, "{replay:?}");

    // every acoustic condition is scored; free field at 30 dB is accurate
    let grid = rows(&o1, "doa_grid");
    assert_eq!(grid.len(), 9, "{grid:?}");
    let clean = grid
        .iter()
        .find(|r| r["rt60_ms"] == "0" && r["snr_db"] == "30")
        .expect("free field, 30 dB");
    assert!(num(clean, "blocks") >= 1.0, "{clean:?}");
    assert!(num(clean, "median_err_deg") < 1.0, "{clean:?}");

    // the ablations
    let variants: BTreeMap<String, BTreeMap<String, String>> = rows(&o1, "variants")
        .into_iter()
        .map(|r| (r["variant"].clone(), r))
        .collect();
    assert_eq!(
        variants.keys().map(String::as_str).collect::<Vec<_>>(),
        ["full", "no_faces", "no_legs", "no_sound", "no_torso"]
    );
    assert_eq!(num(&variants["full"], "true_top_down_sessions"), 1.0);
    assert!(num(&variants["no_sound"], "speech_blocks") > 0.0);
    assert_eq!(num(&variants["no_sound"], "speaker_id"), 0.0);
    assert_eq!(num(&variants["no_sound"], "top_down_sessions"), 0.0);
    assert_eq!(num(&variants["no_faces"], "top_down_sessions"), 0.0);
}

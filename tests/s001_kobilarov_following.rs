//! `s001_kobilarov_following` end to end through the CLI on a short closed-loop session of the
//! `segway_park` scenario (seed 001): the synthesizer's robot follows the jogger driven by its
//! own PDAF tracker, the pipeline reads the logged tracker output and replays every method on
//! the log. Checks: the replay of the paper's configuration reproduces what the robot logged
//! (same scans, same filter; only the scan poses' source differs), the robot kept the person
//! (Table I's range stays near the following distance), the tables and the log do not depend
//! on the thread count, and the real laser log runs laser-only when `../shared/real` is there.
//!
//! The session is 12 s of the scenario's quick profile (one session) so the debug build stays
//! fast on a 2-core CI machine; `make eval` runs the whole quick dataset.

use crate::common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use assert_cmd::Command;
use common::csv;
use peopletrack::synth::{SynthOptions, synthesize};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The scenario with its quick profile cut to one 12 s session.
fn short_scenario(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(root().join("datasets/segway_park/scenario.toml"))
        .expect("scenario");
    let quick = "[profiles.quick]\nsessions = 2\nduration_s = 40.0\n";
    assert!(
        text.contains(quick),
        "the quick profile changed: update this test"
    );
    let text = text.replace(quick, "[profiles.quick]\nsessions = 1\nduration_s = 12.0\n");
    let d = dir.join("segway_park");
    std::fs::create_dir_all(&d).expect("mkdir");
    let p = d.join("scenario.toml");
    std::fs::write(&p, text).expect("write scenario");
    p
}

struct Fixture {
    _dir: tempfile::TempDir,
    root: PathBuf,
    sessions: String,
    log: PathBuf,
    scenario: PathBuf,
}

fn fixture() -> &'static Fixture {
    static F: OnceLock<Fixture> = OnceLock::new();
    F.get_or_init(|| {
        let dir = tempfile::tempdir().expect("tempdir");
        let base = dir.path().to_path_buf();
        let scenario = short_scenario(&base.join("synth"));
        let s = synthesize(
            &scenario,
            &SynthOptions {
                profile: "quick".into(),
                out: Some(base.join("synth/segway_park/logs")),
                progress: None,
            },
        )
        .expect("synthesizes");
        assert_eq!(s.sessions.len(), 1);
        Fixture {
            sessions: format!("{}/*.mcap", base.join("synth/segway_park/logs").display()),
            log: s.sessions[0].clone(),
            _dir: dir,
            root: base,
            scenario,
        }
    })
}

fn run(f: &Fixture, out: &Path, jobs: &str) -> std::process::Output {
    crate::common::run_pipeline(
        &root().join("pipelines/s001_kobilarov_following.toml"),
        &f.sessions,
        out,
        jobs,
    )
}

fn tables(out: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut m = BTreeMap::new();
    for e in std::fs::read_dir(out.join("s001_kobilarov_following/tables")).expect("tables") {
        let p = e.expect("entry").path();
        m.insert(
            p.file_name().expect("name").to_string_lossy().into_owned(),
            std::fs::read(&p).expect("read"),
        );
    }
    m
}

#[test]
fn the_closed_loop_is_reproduced_by_its_replay_and_the_robot_keeps_the_person() {
    let f = fixture();
    let out = f.root.join("out_j2");
    let o = run(f, &out, "2");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    common::assert_schemas_documented(
        &root().join("pipelines/s001_kobilarov_following.toml"),
        &out,
    );
    let t = out.join("s001_kobilarov_following/tables");
    // the replayed paper configuration is the robot's own tracker on the same scans: the
    // estimates agree to well under the laser's noise-free blob spread (5 cm) on most scans,
    // and do not part (stay apart for 1 s) in the first seconds (poses millimetres apart can
    // tip a blob decided by a hair, after which the two may part: `parted_at_s`)
    let check = csv(&t.join("replay_check.csv"));
    assert_eq!(check.len(), 1, "{check:?}");
    let num = |k: &str| -> f64 { check[0][k].parse().unwrap_or(f64::INFINITY) };
    eprintln!("replay vs loop: {check:?}");
    assert!(num("scans_both") > 60.0, "{check:?}");
    assert!(
        num("parted_at_s") > 5.0,
        "replay and loop part early: {check:?}"
    );
    assert!(num("median_distance_m") < 0.05, "{check:?}");
    // Table I: the robot followed (mean range within 2 m of the desired distance
    // d_follow + v²/(2 a_min), d_follow 3.2 m and a_min 1.4 m/s² in the pipeline file) and moved
    let rows = csv(&t.join("table1.csv"));
    let ours = rows
        .iter()
        .find(|r| r["source"] == "ours" && r["run"] != "mean" && r["run"] != "std")
        .expect("our run");
    let r: f64 = ours["r_avg"].parse().expect("r_avg");
    let v: f64 = ours["v_avg"].parse().expect("v_avg");
    eprintln!("table1: {ours:?}");
    let desired = 3.2 + v * v / (2.0 * 1.4);
    assert!(r > 1.5 && r < desired + 2.0, "r_avg {r}, desired {desired}");
    assert!(v > 0.3, "v_avg {v}");
    assert_eq!(rows.iter().filter(|r| r["source"] == "paper").count(), 14);
    for name in [
        "methods.csv",
        "ttests.csv",
        "rst_events.csv",
        "rst_summary.csv",
        "method1_loss.csv",
        "real.csv",
        "colour_separation.csv",
    ] {
        assert!(t.join(name).exists(), "{name} missing");
    }
    for fig in [
        "fig4_trajectory",
        "fig5_covariance",
        "fig7_following",
        "closed_loop_top_view",
    ] {
        let p = out.join(format!("s001_kobilarov_following/figures/{fig}.png"));
        assert!(p.exists(), "{fig} missing");
    }
}

#[test]
fn tables_do_not_depend_on_the_thread_count() {
    let f = fixture();
    let (a, b) = (f.root.join("j1"), f.root.join("j2"));
    let o = run(f, &a, "1");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = run(f, &b, "2");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (ta, tb) = (tables(&a), tables(&b));
    assert!(ta.len() >= 8, "{:?}", ta.keys());
    let differ: Vec<&String> = ta.keys().filter(|k| ta.get(*k) != tb.get(*k)).collect();
    assert!(
        differ.is_empty(),
        "tables differ between -j 1 and -j 2: {differ:?}"
    );
}

/// The closed loop writes the same bytes whatever rayon's thread count.
#[test]
fn the_closed_loop_log_is_byte_identical_on_one_and_two_threads() {
    let f = fixture();
    let again = |n: usize| -> Vec<u8> {
        let out = f.root.join(format!("synth_t{n}"));
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .expect("pool");
        let s = pool
            .install(|| {
                synthesize(
                    &f.scenario,
                    &SynthOptions {
                        profile: "quick".into(),
                        out: Some(out.clone()),
                        progress: None,
                    },
                )
            })
            .expect("synthesizes");
        std::fs::read(&s.sessions[0]).expect("read")
    };
    let first = std::fs::read(&f.log).expect("read");
    assert!(again(1) == first, "1 thread differs from the fixture");
    assert!(again(2) == first, "2 threads differ from the fixture");
}

/// The real person-following log (laser only) runs when `../shared/real` is present.
///
/// Issue 30: with σ_r = 0.6 m and k = 5 (VERSION 2) the laser-only paper configuration was on
/// the person on 0.29 of the annotated scans. VERSION 3 (σ_r the measured 0.19 m, k = 11.5 from
/// the paper's reset timing) is at 0.293 too: the threshold k σ_r is 2.2 m, the track drifts
/// onto clutter beside the person and, fed measurements there, never resets; the literal k = 5
/// (`ct_colour_rst5`) resets 5 times and is on the person on 0.913. Open (see
/// docs/s001_kobilarov_following.md, "Real data"): this test holds the floor of a follower that
/// starts on the person and keeps it for a while (> 0.2), not the 0.5 a working follower
/// reaches; nothing was chosen on this log.
#[test]
fn the_real_person_following_log_runs_laser_only() {
    let real = root()
        .join("../shared/real/laser/person_following_outdoor_1/person_following_outdoor_1.mcap");
    if !real.exists() {
        eprintln!("SKIPPED: {} is absent", real.display());
        return;
    }
    let f = fixture();
    let out = f.root.join("out_real");
    let o = Command::cargo_bin("peopletrack")
        .expect("binary")
        .args(["run"])
        .arg(root().join("pipelines/s001_kobilarov_following.toml"))
        .args(["--sessions", &real.display().to_string(), "--out"])
        .arg(&out)
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rows = csv(&out.join("s001_kobilarov_following/tables/real.csv"));
    let paper = rows
        .iter()
        .find(|r| r["method"] == "ct_colour")
        .expect("the paper's configuration, laser only");
    let on: f64 = paper["on_target"].parse().expect("on_target");
    eprintln!("real: {rows:?}");
    assert!(paper["annotated_scans"] == "6179", "{paper:?}");
    assert!(on > 0.2, "on target {on}");
}

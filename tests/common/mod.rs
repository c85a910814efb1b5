//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use peopletrack::Nanos;
use peopletrack::groundtruth::{
    PEOPLE_JSON_SCHEMA, PEOPLE_SCHEMA, PEOPLE_TOPIC, PeopleFrame, PersonTruth,
};
use peopletrack::log::msgs::{Header, LaserScan};
use peopletrack::log::{SessionWriter, WriterOptions};

/// `../shared/real/<rel>` beside the project, or `None` (with a clear message on stderr) when
/// that folder is absent. The real data is read in place, never copied into the project.
pub fn real(rel: &str) -> Option<PathBuf> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/real")
        .join(rel);
    if p.exists() {
        Some(p)
    } else {
        eprintln!(
            "SKIPPED: {} is absent; this test needs the real data in ../shared/real beside the project",
            p.display()
        );
        None
    }
}

pub fn laser_log(name: &str) -> Option<PathBuf> {
    real(&format!("laser/{name}/{name}.mcap"))
}

pub mod raw_mcap;

/// Rows of a CSV table as column → value maps (naive split: for tables without quoted commas).
pub fn csv(path: &Path) -> Vec<BTreeMap<String, String>> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let head: Vec<String> = lines
        .next()
        .expect("header")
        .split(',')
        .map(str::to_string)
        .collect();
    lines
        .map(|l| {
            head.iter()
                .cloned()
                .zip(l.split(',').map(str::to_string))
                .collect()
        })
        .collect()
}

/// Three small sessions in two datasets (`lab/a`, `lab/b`, `park/c`), with scans and ground
/// truth, for runs of `pipelines/dataset_quality.toml`; returns the glob that finds them.
pub fn runner_sessions(dir: &Path) -> String {
    for (dataset, name, n) in [("lab", "a", 40u64), ("lab", "b", 60), ("park", "c", 50)] {
        let p = dir.join(dataset).join(format!("{name}.mcap"));
        let mut w = SessionWriter::create(&p, &WriterOptions::default()).expect("create");
        let scan = w.add_ros2::<LaserScan>("/scan").expect("scan");
        let gt = w
            .add_json(PEOPLE_TOPIC, PEOPLE_SCHEMA, PEOPLE_JSON_SCHEMA)
            .expect("gt");
        for i in 0..n {
            let t = Nanos(1_000_000_000 + i * 100_000_000);
            let msg = LaserScan {
                header: Header::new(Nanos(t.0 - 5_000_000), "laser"),
                ranges: vec![1.0; 10],
                range_max: 10.0,
                ..Default::default()
            };
            w.write(scan, t, &msg).expect("scan");
            let frame = PeopleFrame {
                stamp_ns: t.0,
                people: vec![PersonTruth {
                    id: 1,
                    x: i as f64 * 0.1,
                    y: 0.0,
                    vx: 1.0,
                    vy: 0.0,
                    height: 1.8,
                    head_z: 1.7,
                    radius: 0.2,
                    legs: [[0.0, 0.1], [0.0, -0.1]],
                    leg_radius: 0.06,
                    cameras: vec![],
                }],
            };
            w.write_json(gt, t, &frame).expect("gt");
        }
        w.finish().expect("finish");
    }
    format!("{}/*/*.mcap", dir.display())
}

/// `peopletrack -j JOBS run PIPELINE --sessions SESSIONS --out OUT`, its output (not checked).
pub fn run_pipeline(
    pipeline: &Path,
    sessions: &str,
    out: &Path,
    jobs: &str,
) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_peopletrack"))
        .args(["-j", jobs, "run"])
        .arg(pipeline)
        .args(["--sessions", sessions, "--out"])
        .arg(out)
        .output()
        .expect("peopletrack runs")
}

/// A finished command's stdout then stderr, as text (for assertions and their messages).
pub fn output_text(o: &std::process::Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// Every file under `out/<pipeline>/tables` and `figures`, with its bytes.
pub fn products(out: &Path, pipeline: &str) -> BTreeMap<String, Vec<u8>> {
    let mut m = BTreeMap::new();
    for sub in ["tables", "figures"] {
        let d = out.join(pipeline).join(sub);
        for e in std::fs::read_dir(&d).unwrap_or_else(|e| panic!("{}: {e}", d.display())) {
            let p = e.expect("entry").path();
            m.insert(
                format!("{sub}/{}", p.file_name().expect("name").to_string_lossy()),
                std::fs::read(&p).expect("read"),
            );
        }
    }
    m
}

/// `peopletrack schemas PIPELINE --out OUT --check docs/schemas.md` passes: every table the
/// run wrote (per-session and aggregate) is on that page with the same columns, in the same
/// order, of the same types, and no two sessions disagree (issue 34: the page is generated by
/// `make schemas`; this keeps it true for the pipelines the tests run).
pub fn assert_schemas_documented(pipeline: &Path, out: &Path) {
    let page = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/schemas.md");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_peopletrack"))
        .arg("schemas")
        .arg(pipeline)
        .arg("--out")
        .arg(out)
        .arg("--check")
        .arg(&page)
        .output()
        .expect("peopletrack schemas runs");
    assert!(
        o.status.success(),
        "the tables of {} differ from docs/schemas.md:\n{}{}",
        pipeline.display(),
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}

//! `s004_mohedano_multicam` end to end through the CLI on a short session of the `multicam_office`
//! scenario (seed 004): the ground-truth 2-D boxes of the log, written as
//! `vision_msgs/msg/Detection2DArray` per camera, go through the "bring your own detector" path
//! (`detector = "log"`) into the 3-D stage, which must reach MOTA ≥ 0.95; `--write-tracks`
//! writes markers that read back through our reader; tables do not depend on the thread count;
//! a log without one camera's calibration is skipped with a message naming the file and topic;
//! aggregation from the cached per-session tables alone, the logs moved away, gives the same
//! tables and figures (the camera view included).
//!
//! The session is the first of the scenario's quick profile (one 12 s session; the quick profile
//! has two) so that the debug build stays fast on a 2-core CI machine; the full quick dataset
//! is scored by `make eval` (table `clear_mot`, detector `gt_boxes`). A 6 s session was used
//! before: there the N_app = 5 promotion delay of the three people alone costs 12 of 350
//! person-frames, and with the calibrated box head 19 (MOTA 0.946; 0.981 over 12 s, 0.977 on
//! the whole quick dataset).

use crate::common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use assert_cmd::Command;
use common::csv;
use peopletrack::Nanos;
use peopletrack::groundtruth::{PEOPLE_TOPIC, PeopleFrame};
use peopletrack::log::msgs::{Detection2D, Detection2DArray, Header, Marker, MarkerArray};
use peopletrack::log::{SessionLog, SessionWriter, WriterOptions, read_topic};
use peopletrack::synth::{SynthOptions, synthesize};

const CAMERAS: [&str; 4] = ["cam_0", "cam_1", "cam_2", "cam_3"];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The scenario with its quick profile cut to its first 12 s session.
fn short_scenario(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(root().join("datasets/multicam_office/scenario.toml"))
        .expect("scenario");
    let quick = "[profiles.quick]\nsessions = 2\nduration_s = 12.0\n";
    assert!(
        text.contains(quick),
        "the quick profile changed: update this test"
    );
    let text = text.replace(quick, "[profiles.quick]\nsessions = 1\nduration_s = 12.0\n");
    let d = dir.join("multicam_office");
    std::fs::create_dir_all(&d).expect("mkdir");
    let p = d.join("scenario.toml");
    std::fs::write(&p, text).expect("write scenario");
    p
}

/// A copy of `input` without its images, with the ground-truth visible boxes of every camera
/// as `/<cam>/detections` (what a user's detector would log).
fn with_gt_detections(input: &Path, output: &Path, drop_topic: Option<&str>) {
    let log = SessionLog::open(input).expect("open");
    let mut w = SessionWriter::create(output, &WriterOptions::default()).expect("create");
    let mut channels = BTreeMap::new();
    for (id, ch) in &log.summary().channels {
        if ch.topic.contains("/image") || Some(ch.topic.as_str()) == drop_topic {
            continue;
        }
        let schema = ch
            .schema
            .as_deref()
            .map(|s| (s.name.as_str(), s.encoding.as_str(), s.data.as_slice()));
        channels.insert(
            *id,
            w.add_raw(&ch.topic, schema, &ch.message_encoding)
                .expect("channel"),
        );
    }
    let det: Vec<_> = CAMERAS
        .iter()
        .map(|c| {
            w.add_ros2::<Detection2DArray>(&format!("/{c}/detections"))
                .expect("det")
        })
        .collect();
    for m in log.messages().expect("messages") {
        let m = m.expect("message");
        let Some(ch) = channels.get(&m.channel.id) else {
            continue;
        };
        w.write_bytes(*ch, m.log_time, &m.data).expect("copy");
        if m.topic() != PEOPLE_TOPIC {
            continue;
        }
        let gt: PeopleFrame = serde_json::from_slice(&m.data).expect("truth");
        for (c, cam) in CAMERAS.iter().enumerate() {
            let header = Header::new(Nanos(gt.stamp_ns), *cam);
            let detections = gt
                .people
                .iter()
                .filter_map(|p| {
                    let v = p.cameras.iter().find(|v| v.camera == *cam)?;
                    let b = v.bbox?;
                    Some(Detection2D {
                        header: header.clone(),
                        results: vec![("person".into(), 1.0)],
                        center_x: (b[0] + b[2]) / 2.0,
                        center_y: (b[1] + b[3]) / 2.0,
                        size_x: b[2] - b[0],
                        size_y: b[3] - b[1],
                        ..Default::default()
                    })
                })
                .collect();
            w.write(
                det[c],
                m.log_time,
                &Detection2DArray {
                    header: header.clone(),
                    detections,
                },
            )
            .expect("detections");
        }
    }
    w.finish().expect("finish");
}

struct Fixture {
    _dir: tempfile::TempDir,
    root: PathBuf,
    /// Glob of the detection logs.
    sessions: String,
    pipeline: PathBuf,
}

/// Synthesized once for all tests of this file.
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
                out: Some(base.join("synth/multicam_office")),
                progress: None,
            },
        )
        .expect("synthesizes");
        assert_eq!(s.sessions.len(), 1);
        let byod = base.join("byod/multicam_office");
        std::fs::create_dir_all(&byod).expect("mkdir");
        for p in &s.sessions {
            with_gt_detections(p, &byod.join(p.file_name().expect("name")), None);
        }
        let text = std::fs::read_to_string(root().join("pipelines/s004_mohedano_multicam.toml"))
            .expect("pipeline");
        let text = text
            .replace("detector = \"templates\"", "detector = \"log\"")
            .replace("gt_boxes = true", "gt_boxes = false");
        assert!(text.contains("detector = \"log\"") && text.contains("gt_boxes = false"));
        let pipeline = base.join("s004_mohedano_multicam.toml");
        std::fs::write(&pipeline, text).expect("pipeline");
        Fixture {
            sessions: format!("{}/*.mcap", byod.display()),
            _dir: dir,
            root: base,
            pipeline,
        }
    })
}

fn run(
    f: &Fixture,
    out: &Path,
    sessions: &str,
    global: &[&str],
    after: &[&std::ffi::OsStr],
) -> std::process::Output {
    Command::cargo_bin("peopletrack")
        .expect("binary")
        .args(global)
        .arg("run")
        .arg(&f.pipeline)
        .args(["--sessions", sessions, "--out"])
        .arg(out)
        .args(after)
        .output()
        .expect("runs")
}

fn tables(out: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut m = BTreeMap::new();
    let d = out.join("s004_mohedano_multicam/tables");
    for e in std::fs::read_dir(&d).expect("tables exist") {
        let p = e.expect("entry").path();
        m.insert(
            p.file_name().expect("name").to_string_lossy().into_owned(),
            std::fs::read(&p).expect("read"),
        );
    }
    m
}

#[test]
fn ground_truth_boxes_through_the_log_detector_path_reach_mota_095_and_tracks_read_back() {
    let f = fixture();
    let out = f.root.join("out");
    let tracks = f.root.join("tracks");
    // one run, tracks written back with --write-tracks (an option of `run`)
    let o = run(
        f,
        &out,
        &f.sessions,
        &["-j", "2"],
        &["--write-tracks".as_ref(), tracks.as_os_str()],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    common::assert_schemas_documented(&f.pipeline, &out);

    let rows = csv(&out.join("s004_mohedano_multicam/tables/clear_mot.csv"));
    let mut seen = 0;
    for r in rows.iter().filter(|r| r["detector"] == "log") {
        let mota: f64 = r["MOTA"].parse().expect("MOTA");
        let idf1: f64 = r["IDF1"].parse().expect("IDF1");
        eprintln!("match {} m: MOTA {mota:.4}, IDF1 {idf1:.4}", r["match_m"]);
        assert!(mota >= 0.95, "MOTA {mota} at {} m: {r:?}", r["match_m"]);
        seen += 1;
    }
    assert_eq!(seen, 2, "rows at 0.5 m and 1 m: {rows:?}");

    // the markers: one MarkerArray per frame with a track, cylinders in the world frame
    let written: Vec<PathBuf> = glob::glob(&format!("{}/*/*_tracks.mcap", tracks.display()))
        .expect("glob")
        .map(|p| p.expect("path"))
        .collect();
    assert_eq!(written.len(), 1, "{written:?}");
    let log = SessionLog::open(&written[0]).expect("reads back");
    let arrays: Vec<(Nanos, MarkerArray)> = read_topic::<MarkerArray>(&log, "/tracks/cylinders")
        .expect("topic")
        .map(|r| {
            let (t, a) = r.expect("decodes");
            (t, a)
        })
        .collect();
    assert!(arrays.len() > 100, "{} marker messages", arrays.len());
    let cylinders: Vec<&Marker> = arrays
        .iter()
        .flat_map(|(_, a)| &a.markers)
        .filter(|m| m.kind == Marker::CYLINDER)
        .collect();
    assert!(!cylinders.is_empty());
    for m in &cylinders {
        assert_eq!(m.header.frame_id, "map");
        assert!(m.scale.z > 1.0 && m.scale.z < 2.3, "{m:?}");
        assert!(m.scale.x > 0.1 && m.scale.x < 1.5, "{m:?}");
        assert!(m.pose.position.x > -1.0 && m.pose.position.x < 9.0, "{m:?}");
    }
    // everything else of the input is still there
    let input = SessionLog::open(
        glob::glob(&f.sessions)
            .expect("glob")
            .next()
            .expect("one")
            .expect("path"),
    )
    .expect("input");
    for ch in input.summary().channels.values() {
        assert!(
            log.summary().channel(&ch.topic).is_some(),
            "{} lost",
            ch.topic
        );
    }
}

#[test]
fn tables_do_not_depend_on_the_thread_count() {
    let f = fixture();
    let (a, b) = (f.root.join("j1"), f.root.join("j3"));
    let o = run(f, &a, &f.sessions, &["-j", "1"], &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = run(f, &b, &f.sessions, &["-j", "3"], &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // everything but the MEASURED timings (timing_3d) is identical for 1 and 3 threads
    let measured = |t: BTreeMap<String, Vec<u8>>| -> BTreeMap<String, Vec<u8>> {
        t.into_iter()
            .filter(|(k, _)| !k.contains("timing"))
            .collect()
    };
    let (ta, tb) = (measured(tables(&a)), measured(tables(&b)));
    assert!(ta.len() >= 6, "{:?}", ta.keys());
    assert_eq!(ta.keys().collect::<Vec<_>>(), tb.keys().collect::<Vec<_>>());
    let differ: Vec<&String> = ta.keys().filter(|k| ta[*k] != tb[*k]).collect();
    assert!(
        differ.is_empty(),
        "tables differ between -j 1 and -j 3: {differ:?}"
    );
}

#[test]
fn a_log_without_one_cameras_calibration_is_skipped_with_file_and_topic() {
    let f = fixture();
    let bad_dir = f.root.join("bad/multicam_office");
    std::fs::create_dir_all(&bad_dir).expect("mkdir");
    let good = glob::glob(&f.sessions)
        .expect("glob")
        .next()
        .expect("one")
        .expect("path");
    // re-derive from the detection log: drop cam_2's CameraInfo
    let bad = bad_dir.join("no_cam2_info.mcap");
    let log = SessionLog::open(&good).expect("open");
    let mut w = SessionWriter::create(&bad, &WriterOptions::default()).expect("create");
    let mut channels = BTreeMap::new();
    for (id, ch) in &log.summary().channels {
        if ch.topic == "/cam_2/camera_info" {
            continue;
        }
        let schema = ch
            .schema
            .as_deref()
            .map(|s| (s.name.as_str(), s.encoding.as_str(), s.data.as_slice()));
        channels.insert(
            *id,
            w.add_raw(&ch.topic, schema, &ch.message_encoding)
                .expect("ch"),
        );
    }
    for m in log.messages().expect("messages") {
        let m = m.expect("message");
        if let Some(ch) = channels.get(&m.channel.id) {
            w.write_bytes(*ch, m.log_time, &m.data).expect("copy");
        }
    }
    w.finish().expect("finish");
    // alone: the run fails, naming the session and the topic
    let out = f.root.join("bad_out");
    let o = run(f, &out, &format!("{}/*.mcap", bad_dir.display()), &[], &[]);
    let text = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(text.contains("no_cam2_info"), "{text}");
    assert!(text.contains("/cam_2/camera_info"), "{text}");
    assert!(!text.contains("panicked"), "{text}");
    // beside a good log: the good one is processed, the bad one skipped and reported
    std::fs::copy(&good, bad_dir.join("good.mcap")).expect("copy");
    let out = f.root.join("bad_out2");
    let o = run(f, &out, &format!("{}/*.mcap", bad_dir.display()), &[], &[]);
    let text = common::output_text(&o);
    assert!(o.status.success(), "{text}");
    assert!(text.contains("1 computed"), "{text}");
    assert!(text.contains("1 skipped"), "{text}");
    assert!(text.contains("no_cam2_info"), "{text}");
    assert!(text.contains("/cam_2/camera_info"), "{text}");
    assert!(!text.contains("panicked"), "{text}");
}

/// The cached per-session tables of a run, read back as the runner does.
fn cached_tables(out: &Path, dataset: &str, name: &str) -> peopletrack::run::SessionTables {
    let dir = out
        .join("s004_mohedano_multicam/sessions")
        .join(format!("dataset={dataset}"))
        .join(format!("session={name}"));
    let mut t = peopletrack::run::SessionTables::new();
    for e in std::fs::read_dir(&dir).expect("session cache") {
        let p = e.expect("entry").path();
        if p.extension().is_some_and(|x| x == "parquet") {
            let stem = p.file_stem().expect("stem").to_string_lossy().into_owned();
            t.insert(
                stem,
                peopletrack::report::table::read_parquet(&p).expect("parquet"),
            );
        }
    }
    t
}

#[test]
fn aggregation_reads_only_the_cached_tables_and_gives_the_same_tables_and_figures() {
    use peopletrack::pipelines::s004_mohedano_multicam::{MulticamCylinders, Params};
    use peopletrack::run::{Aggregate, Experiment};
    let f = fixture();
    // a private copy of the log, run once through the CLI
    let logs = f.root.join("absent/multicam_office");
    std::fs::create_dir_all(&logs).expect("mkdir");
    let good = glob::glob(&f.sessions)
        .expect("glob")
        .next()
        .expect("one")
        .expect("path");
    let log = logs.join(good.file_name().expect("name"));
    std::fs::copy(&good, &log).expect("copy");
    let out = f.root.join("absent_out");
    let o = run(f, &out, &format!("{}/*.mcap", logs.display()), &[], &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let name = log
        .file_stem()
        .expect("stem")
        .to_string_lossy()
        .into_owned();
    let cached = cached_tables(&out, "multicam_office", &name);
    // the camera view travels with the session's tables
    for t in ["view_frame", "view_image", "view_shapes"] {
        assert!(cached.contains_key(t), "{t}: {:?}", cached.keys());
    }
    // the logs move away; aggregation from the cache alone
    std::fs::rename(&logs, f.root.join("absent/moved")).expect("move the logs away");
    assert!(!log.exists());
    let text = std::fs::read_to_string(&f.pipeline).expect("pipeline");
    let params = peopletrack::run::config::parse::<Params>(&f.pipeline, &text)
        .expect("parses")
        .params;
    let sessions = vec![(
        peopletrack::run::config::SessionRef {
            dataset: "multicam_office".into(),
            name: name.clone(),
            path: log.clone(),
        },
        cached,
    )];
    let products = MulticamCylinders::aggregate(
        &Aggregate {
            sessions: &sessions,
            provenance: Default::default(),
            write_tracks: None,
        },
        &params,
    )
    .expect("aggregates without the logs");
    assert!(
        !products.summary.iter().any(|l| l.contains("not drawn")),
        "{:?}",
        products.summary
    );
    // the same tables (CSV) and figures (PNG) as the run that had the logs
    let dir = out.join("s004_mohedano_multicam");
    assert!(products.tables.len() >= 6);
    for t in &products.tables {
        let before = std::fs::read(dir.join(format!("tables/{}.csv", t.name))).expect("csv");
        assert_eq!(t.to_csv().expect("csv"), before, "table {}", t.name);
    }
    let figs = f.root.join("absent_figures");
    let names: Vec<&str> = products.figures.iter().map(|x| x.name.as_str()).collect();
    assert!(names.contains(&"camera_views"), "{names:?}");
    for fig in &products.figures {
        peopletrack::report::write_figure(&figs, fig, &f.root).expect("figure");
        let png = format!("{}.png", fig.name);
        assert_eq!(
            std::fs::read(figs.join(&png)).expect("new"),
            std::fs::read(dir.join("figures").join(&png)).expect("before"),
            "figure {png}"
        );
    }
}

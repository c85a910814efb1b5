//! The `laser_people` pipeline end to end. Known answer: a hand-made log of two people (leg
//! pairs, noise-free ray-cast circles) walking straight past a laser with their ground truth
//! published: the `legs` detector + tracker scores MOTA exactly 1 on the scans after
//! confirmation, the `nearest` baseline follows only the nearer person (MOTA exactly 0.5), a
//! listed sequence without a log gets SKIPPED rows, and the tracks CSV is written. Then a
//! structural run over the real `general_tracking_moving_1` (SKIPPED when absent): it completes,
//! has its rows, and places the annotations on the scans of the authors' `ground_truth.csv`.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use nalgebra::{Quaternion, Vector3};
use peopletrack::Nanos;
use peopletrack::groundtruth::{
    PEOPLE_JSON_SCHEMA, PEOPLE_SCHEMA, PEOPLE_TOPIC, PeopleFrame, PersonTruth,
};
use peopletrack::log::msgs::{
    Header, LaserScan, Marker, MarkerArray, TfMessage, Transform, TransformStamped,
};
use peopletrack::log::{SessionLog, SessionWriter, Value, WriterOptions, read_topic};
use peopletrack::pipelines::run_file;
use peopletrack::report::columns::i64s;
use peopletrack::report::table::read_parquet;
use peopletrack::run::RunOptions;

const BEAMS: usize = 721;
const INCREMENT: f64 = std::f64::consts::PI / 720.0; // 0.25°
const ANGLE_MIN: f64 = -std::f64::consts::FRAC_PI_2;
const LEG_RADIUS: f64 = 0.06;
const SCANS: u64 = 10;

/// Person `k`'s centre at scan `i`: both walk +x at 0.1 m per scan (1 m/s at 10 Hz).
fn centre(k: usize, i: u64) -> [f64; 2] {
    let x = 0.1 * i as f64;
    if k == 0 {
        [1.5 + x, 0.8]
    } else {
        [2.0 + x, -1.0]
    }
}

/// Leg centres 0.2 m apart across the direction of walking.
fn legs(c: [f64; 2]) -> [[f64; 2]; 2] {
    [[c[0], c[1] + 0.1], [c[0], c[1] - 0.1]]
}

/// Nearest hit of the ray at `angle` from the origin with any leg circle (inf: none).
fn ray(angle: f64, circles: &[[f64; 2]]) -> f32 {
    let d = [angle.cos(), angle.sin()];
    let mut best = f64::INFINITY;
    for c in circles {
        let b = d[0] * c[0] + d[1] * c[1];
        let disc = b * b - (c[0] * c[0] + c[1] * c[1] - LEG_RADIUS * LEG_RADIUS);
        if disc >= 0.0 {
            let t = b - disc.sqrt();
            if t > 0.0 {
                best = best.min(t);
            }
        }
    }
    best as f32
}

fn person(id: u32, c: [f64; 2]) -> PersonTruth {
    PersonTruth {
        id,
        x: c[0],
        y: c[1],
        vx: 1.0,
        vy: 0.0,
        height: 1.75,
        head_z: 1.65,
        radius: 0.22,
        legs: legs(c),
        leg_radius: LEG_RADIUS,
        cameras: vec![],
    }
}

/// The `leg_tracker/msg/Person` definition of the real logs (no header; laser frame).
const PERSON_DEF: &str = "geometry_msgs/Pose pose\nuint32 id\n================================================================================\nMSG: geometry_msgs/Pose\ngeometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n================================================================================\nMSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z\n================================================================================\nMSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w\n";

fn person_msg(id: u32, c: [f64; 2]) -> Value {
    let f = |pairs: Vec<(&str, Value)>| {
        Value::Struct(pairs.into_iter().map(|(k, v)| (Arc::from(k), v)).collect())
    };
    let position = f(vec![
        ("x", Value::F64(c[0])),
        ("y", Value::F64(c[1])),
        ("z", Value::F64(0.0)),
    ]);
    let orientation = f(["x", "y", "z", "w"]
        .into_iter()
        .map(|k| (k, Value::F64(0.0)))
        .collect());
    f(vec![
        (
            "pose",
            f(vec![("position", position), ("orientation", orientation)]),
        ),
        ("id", Value::U32(id)),
    ])
}

/// The hand-made session: ten scans with ground truth per scan, either synthetic-style
/// (`/ground_truth/people` in `map`, a static `map -> laser` identity) or as the real logs
/// have it (`leg_tracker/msg/Person` in the laser frame, logged between a scan and the next,
/// no TF).
fn write_log(path: &Path, leigh_style: bool) {
    write_log_with(path, leigh_style, None);
}

/// [`write_log`], with a straight wall across the scan at `x = wall_x` (m) when given.
fn write_log_with(path: &Path, leigh_style: bool, wall_x: Option<f64>) {
    let mut w = SessionWriter::create(path, &WriterOptions::default()).expect("create");
    let tf = w.add_ros2::<TfMessage>("/tf_static").expect("tf");
    let scan = w.add_ros2::<LaserScan>("/scan").expect("scan");
    let gt = w
        .add_json(PEOPLE_TOPIC, PEOPLE_SCHEMA, PEOPLE_JSON_SCHEMA)
        .expect("gt");
    let person_ch = w
        .add_ros2_dynamic(
            "/ground_truth_people_tracks",
            "leg_tracker/msg/Person",
            PERSON_DEF,
        )
        .expect("person");
    let identity = TransformStamped {
        header: Header::new(Nanos(500_000_000), "map"),
        child_frame_id: "laser".into(),
        transform: Transform {
            translation: Vector3::zeros(),
            rotation: Quaternion::new(1.0, 0.0, 0.0, 0.0),
        },
    };
    if !leigh_style {
        w.write(
            tf,
            Nanos(500_000_000),
            &TfMessage {
                transforms: vec![identity],
            },
        )
        .expect("tf");
    }
    for i in 0..SCANS {
        let t = Nanos(1_000_000_000 + i * 100_000_000);
        let circles: Vec<[f64; 2]> = (0..2).flat_map(|k| legs(centre(k, i))).collect();
        let ranges = (0..BEAMS)
            .map(|b| {
                let a = ANGLE_MIN + b as f64 * INCREMENT;
                let wall = wall_x
                    .filter(|_| a.cos() > 0.2)
                    .map_or(f32::INFINITY, |x| (x / a.cos()) as f32);
                ray(a, &circles).min(wall)
            })
            .collect();
        let msg = LaserScan {
            header: Header::new(t, "laser"),
            angle_min: ANGLE_MIN as f32,
            angle_max: (ANGLE_MIN + (BEAMS - 1) as f64 * INCREMENT) as f32,
            angle_increment: INCREMENT as f32,
            range_min: 0.05,
            range_max: 10.0,
            ranges,
            ..Default::default()
        };
        w.write(scan, t, &msg).expect("scan");
        if leigh_style {
            for k in 0..2 {
                let msg = person_msg(k as u32 + 1, centre(k, i));
                w.write_value(person_ch, Nanos(t.0 + 50_000_000), &msg)
                    .expect("person");
            }
        } else {
            let frame = PeopleFrame {
                stamp_ns: t.0,
                people: vec![person(1, centre(0, i)), person(2, centre(1, i))],
            };
            w.write_json(gt, t, &frame).expect("gt");
        }
    }
    w.finish().expect("finish");
}

fn options(out: &Path, sessions: Vec<String>) -> RunOptions {
    RunOptions {
        sessions: Some(sessions),
        dry_run: false,
        shard: None,
        aggregate_only: false,
        expect_shards: None,
        force: false,
        out: out.to_path_buf(),
        git_commit: String::new(),
        progress: None,
        write_tracks: None,
        recover: false,
        keep_going: false,
    }
}

/// Rows of a CSV without quoted commas, as header → value maps.
fn csv_rows(path: &Path) -> Vec<std::collections::BTreeMap<String, String>> {
    let text = std::fs::read_to_string(path).expect("csv");
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .expect("header")
        .split(',')
        .map(str::to_string)
        .collect();
    lines
        .map(|l| {
            header
                .iter()
                .cloned()
                .zip(l.split(',').map(str::to_string))
                .collect()
        })
        .collect()
}

fn row<'a>(
    rows: &'a [std::collections::BTreeMap<String, String>],
    sequence: &str,
    detector: &str,
) -> &'a std::collections::BTreeMap<String, String> {
    rows.iter()
        .find(|r| r["sequence"] == sequence && r["detector"] == detector)
        .unwrap_or_else(|| panic!("no row {sequence}/{detector} in {rows:?}"))
}

const PIPELINE: &str = r#"
[pipeline]
name = "laser_people"
kind = "laser_people"
title = "laser_people test"

[inputs]
sessions = []

[[params.sequences]]
name = "absent_sequence"
scan_topic = "/scan"
gt_topic = "/ground_truth_people_tracks"

[params.synthetic]
name = ""
scan_topic = "/scan"
gt_topic = "/ground_truth/people"
scans = [2, 9]
wedge_deg = [-90.0, 90.0]
max_range_m = 5.0
"#;

#[test]
fn two_walkers_are_tracked_exactly() {
    let dir = tempfile::tempdir().expect("tempdir");
    let data = dir.path().join("walkers");
    std::fs::create_dir_all(&data).expect("mkdir");
    write_log(&data.join("walkers_00.mcap"), false);
    let toml = dir.path().join("laser_people.toml");
    std::fs::write(&toml, PIPELINE).expect("write pipeline");
    let out = dir.path().join("out");
    let sessions = vec![format!("{}/*.mcap", data.display())];
    let summary = run_file(&toml, &options(&out, sessions)).expect("runs");
    assert!(summary.skipped.is_empty(), "{:?}", summary.skipped);
    crate::common::assert_schemas_documented(&toml, &out);

    let rows = csv_rows(&out.join("laser_people/tables/results.csv"));
    let legs = row(&rows, "walkers_00", "legs");
    assert_eq!(legs["status"], "ok");
    assert_eq!(legs["scored_scans"], "8");
    assert_eq!(legs["gt_count"], "16");
    assert_eq!(legs["mota"].parse::<f64>().expect("mota"), 1.0);
    assert_eq!(
        (
            &*legs["false_positives"],
            &*legs["misses"],
            &*legs["id_switches"]
        ),
        ("0", "0", "0")
    );
    assert!(
        legs["motp_m"].parse::<f64>().expect("motp") < 0.1,
        "{legs:?}"
    );
    assert_eq!(legs["idf1"].parse::<f64>().expect("idf1"), 1.0);
    // the baseline follows the nearer walker only, at the midpoint of its legs
    let nearest = row(&rows, "walkers_00", "nearest");
    assert_eq!(nearest["mota"].parse::<f64>().expect("mota"), 0.5);
    assert_eq!(nearest["misses"], "8");
    assert!(
        nearest["motp_m"].parse::<f64>().expect("motp") < 1e-3,
        "{nearest:?}"
    );
    // a listed sequence without a log
    let absent = row(&rows, "absent_sequence", "legs");
    assert!(absent["status"].starts_with("SKIPPED"), "{absent:?}");
    // tracks: laser and world frames agree (identity TF); ids of the legs tracker
    let tracks = csv_rows(&out.join("laser_people/tracks/walkers_00_legs.csv"));
    assert_eq!(tracks.len(), 16);
    assert!(
        tracks
            .iter()
            .all(|t| t["x"] == t["world_x"] && t["y"] == t["world_y"])
    );
    let mut ids: Vec<&str> = tracks.iter().map(|t| t["id"].as_str()).collect();
    ids.sort();
    ids.dedup();
    assert_eq!(ids, ["1", "2"]);
    assert!(out.join("laser_people/tables/paired_ttest.csv").exists());
}

/// The learned detectors without their training data (`../shared/real` absent, no synthetic
/// logs): their rows say SKIPPED with the reason, the other methods are scored as before, and
/// the `leg_classifier` table has one SKIPPED row per source.
#[test]
fn learned_methods_without_training_data_are_skipped() {
    let dir = tempfile::tempdir().expect("tempdir");
    let data = dir.path().join("walkers");
    std::fs::create_dir_all(&data).expect("mkdir");
    write_log(&data.join("walkers_00.mcap"), false);
    let toml = dir.path().join("laser_people.toml");
    let absent = dir.path().join("no_training");
    let learned = format!(
        "methods = [\"legs\", \"learned\", \"learned_synthetic\"]\n\n[params.learned]\ntraining_dir = \"{}\"\nsynthetic_sessions = [\"{}/*.mcap\"]\n",
        absent.display(),
        absent.display()
    );
    let text = PIPELINE
        .replace(
            "[[params.sequences]]",
            &format!("{learned}\n[[params.sequences]]"),
        )
        .replace(
            "[inputs]\nsessions = []\n",
            "[inputs]\nsessions = []\n\n[params]\n",
        );
    std::fs::write(&toml, text).expect("write pipeline");
    let out = dir.path().join("out");
    let sessions = vec![format!("{}/*.mcap", data.display())];
    let summary = run_file(&toml, &options(&out, sessions)).expect("runs");
    assert!(summary.skipped.is_empty(), "{:?}", summary.skipped);
    let rows = csv_rows(&out.join("laser_people/tables/results.csv"));
    assert_eq!(
        row(&rows, "walkers_00", "legs")["mota"]
            .parse::<f64>()
            .expect("mota"),
        1.0
    );
    for m in ["learned", "learned_synthetic"] {
        let r = row(&rows, "walkers_00", m);
        assert!(r["status"].starts_with("SKIPPED: "), "{r:?}");
        assert!(r["mota"].is_empty(), "{r:?}");
    }
    assert!(row(&rows, "walkers_00", "learned")["status"].contains("no_training absent"));
    let cls = csv_rows(&out.join("laser_people/tables/leg_classifier.csv"));
    assert_eq!(cls.len(), 2, "{cls:?}");
    assert!(
        cls.iter().all(|r| r["fold"].starts_with("SKIPPED: ")),
        "{cls:?}"
    );
}

/// The hand-made Leigh-style session as a listed sequence with a scored-scan window.
const LEIGH_SEQUENCE: &str = "\n[[params.sequences]]\nname = \"leigh_walkers\"\nscan_topic = \"/scan\"\ngt_topic = \"/ground_truth_people_tracks\"\nscans = [2, 9]\nwedge_deg = [-90.0, 90.0]\n";

/// The real logs' ground-truth path on the same walkers: `leg_tracker/msg/Person` messages in
/// the laser frame, each logged after its scan, a listed sequence with a scored-scan window, no
/// TF (tracked in the laser frame): the same exact scores.
#[test]
fn leg_tracker_annotations_score_the_same() {
    let dir = tempfile::tempdir().expect("tempdir");
    let data = dir.path().join("leigh");
    std::fs::create_dir_all(&data).expect("mkdir");
    write_log(&data.join("leigh_walkers.mcap"), true);
    let toml = dir.path().join("laser_people.toml");
    // scored as the paper's Following Outdoor benchmark too (paper_table3)
    let following = "paper_benchmark = \"following_outdoor\"\n";
    std::fs::write(&toml, format!("{PIPELINE}{LEIGH_SEQUENCE}{following}"))
        .expect("write pipeline");
    let out = dir.path().join("out");
    let sessions = vec![format!("{}/*.mcap", data.display())];
    let summary = run_file(&toml, &options(&out, sessions)).expect("runs");
    assert!(summary.skipped.is_empty(), "{:?}", summary.skipped);
    // under the paper's following protocol: counts of the annotated people only, no false
    // positives or MOTA; the baseline holds the nearer walker, so half the objects
    let t3 = csv_rows(&out.join("laser_people/tables/paper_table3.csv"));
    let ours = |tracker: &str| {
        t3.iter()
            .find(|r| r["source"] == "this run: leigh_walkers" && r["tracker"] == tracker)
            .unwrap_or_else(|| panic!("no {tracker} row in {t3:?}"))
    };
    let (legs, nearest) = (ours("legs"), ours("nearest"));
    for (r, valid, misses, accuracy) in [(legs, "16", "0", "1.0"), (nearest, "8", "8", "0.5")] {
        assert_eq!(r["benchmark"], "Following Outdoor");
        assert_eq!((&*r["objects"], &*r["valid"]), ("16", valid), "{r:?}");
        assert_eq!((&*r["id_switches"], &*r["misses"]), ("0", misses), "{r:?}");
        assert_eq!((&*r["false_positives"], &*r["mota"]), ("", ""), "{r:?}");
        assert_eq!(r["target_accuracy"], accuracy, "{r:?}");
    }
    assert_eq!(t3.iter().filter(|r| r["source"] == "paper").count(), 3);
    let rows = csv_rows(&out.join("laser_people/tables/results.csv"));
    let legs = row(&rows, "leigh_walkers", "legs");
    assert_eq!((&*legs["scored_scans"], &*legs["gt_count"]), ("8", "16"));
    assert_eq!(legs["mota"].parse::<f64>().expect("mota"), 1.0);
    let nearest = row(&rows, "leigh_walkers", "nearest");
    assert_eq!(nearest["mota"].parse::<f64>().expect("mota"), 0.5);
    let sessions = csv_rows(&out.join("laser_people/tables/sessions.csv"));
    assert_eq!(sessions[0]["gt_kind"], "leg_tracker");
    assert_eq!(sessions[0]["fixed_frame"], "laser");
    assert_eq!(sessions[0]["gt_rows"], "20");
}

/// A log without `odom`/`map` (the outdoor real log's case): the fixed frame is the scan's own
/// frame and every TF pose the identity, which says nothing about motion. With a wall in view
/// the free-space methods run on scan-matched odometry (`odometry = scan_match`, no failed
/// match); with only the walkers' legs (masked out) every match fails, more than
/// `MAX_FAILED_SHARE`, and they stay in the laser frame (`none_scan_match_unfit`, 9 failed: all
/// but the first scan, which only becomes the keyframe). The other methods keep the laser frame and their exact scores either way. Before
/// the fix the identity poses were taken as odometry and scan matching never ran on such logs.
#[test]
fn a_log_in_the_sensor_frame_gets_scan_matched_odometry_where_it_is_fit() {
    for (wall, odometry, failures) in [
        (Some(6.0), "scan_match", "0"),
        (None, "none_scan_match_unfit", "9"),
    ] {
        let dir = tempfile::tempdir().expect("tempdir");
        let data = dir.path().join("leigh");
        std::fs::create_dir_all(&data).expect("mkdir");
        write_log_with(&data.join("leigh_walkers.mcap"), true, wall);
        let toml = dir.path().join("laser_people.toml");
        let pipeline = PIPELINE.replace(
            "[inputs]",
            "[params]\nmethods = [\"legs\", \"legs_free_space\"]\n\n[inputs]",
        );
        std::fs::write(&toml, format!("{pipeline}{LEIGH_SEQUENCE}")).expect("write pipeline");
        let out = dir.path().join("out");
        let sessions = vec![format!("{}/*.mcap", data.display())];
        let summary = run_file(&toml, &options(&out, sessions)).expect("runs");
        assert!(summary.skipped.is_empty(), "{:?}", summary.skipped);
        let sessions = csv_rows(&out.join("laser_people/tables/sessions.csv"));
        assert_eq!(sessions[0]["fixed_frame"], "laser");
        assert_eq!(
            (
                &*sessions[0]["odometry"],
                &*sessions[0]["scan_match_failures"]
            ),
            (odometry, failures),
            "wall {wall:?}"
        );
        let rows = csv_rows(&out.join("laser_people/tables/results.csv"));
        let legs = row(&rows, "leigh_walkers", "legs");
        assert_eq!(
            legs["mota"].parse::<f64>().expect("mota"),
            1.0,
            "wall {wall:?}"
        );
        row(&rows, "leigh_walkers", "legs_free_space");
    }
}

/// `--write-tracks`: a copy of the two-walker log with one MarkerArray per scan and method on
/// `/peopletrack/laser_people/<method>/markers`, in the scan's frame at its stamp: `DELETEALL`,
/// then a sphere and an id label per track. `legs` has both walkers on the 8 scans after
/// confirmation (16 tracks: 10 + 2 × 16 markers), `nearest` the nearer walker (id 1) on all 10
/// scans at the midpoint of its legs (10 + 2 × 10); the spheres sit where the tracks CSV
/// says, and every message of the original is in the copy unchanged.
#[test]
fn tracks_go_back_into_a_copy_of_the_log_as_markers() {
    let dir = tempfile::tempdir().expect("tempdir");
    let data = dir.path().join("walkers");
    std::fs::create_dir_all(&data).expect("mkdir");
    let input = data.join("walkers_00.mcap");
    write_log(&input, false);
    let toml = dir.path().join("laser_people.toml");
    std::fs::write(&toml, PIPELINE).expect("write pipeline");
    let out = dir.path().join("out");
    let copies = dir.path().join("copies");
    let mut opts = options(&out, vec![format!("{}/*.mcap", data.display())]);
    opts.write_tracks = Some(copies.clone());
    let summary = run_file(&toml, &opts).expect("runs");
    assert!(summary.skipped.is_empty(), "{:?}", summary.skipped);
    let copy = copies.join("walkers/walkers_00_laser_people.mcap");
    let log = SessionLog::open(&copy).expect("the copy reads back");
    let arrays = |method: &str| -> Vec<(Nanos, MarkerArray)> {
        read_topic::<MarkerArray>(&log, &format!("/peopletrack/laser_people/{method}/markers"))
            .expect("marker topic")
            .map(|r| r.expect("decodes"))
            .collect()
    };
    let scan_time = |i: u64| Nanos(1_000_000_000 + i * 100_000_000);
    let legs_csv = csv_rows(&out.join("laser_people/tracks/walkers_00_legs.csv"));
    for (method, per_scan, total) in [("legs", None, 42), ("nearest", Some(1), 30)] {
        let got = arrays(method);
        assert_eq!(got.len(), SCANS as usize, "{method}");
        let markers: usize = got.iter().map(|(_, a)| a.markers.len()).sum();
        assert_eq!(markers, total, "{method}");
        for (i, (t, a)) in got.iter().enumerate() {
            let i = i as u64;
            assert_eq!(*t, scan_time(i), "{method}: logged at the scan's log time");
            assert_eq!(a.markers[0].action, Marker::DELETEALL);
            for m in &a.markers {
                assert_eq!(m.header.frame_id, "laser");
                assert_eq!(m.header.stamp.nanos(), Some(scan_time(i)));
            }
            let spheres: Vec<&Marker> = a.markers.iter().filter(|m| m.ns == "tracks").collect();
            let labels: Vec<&Marker> = a.markers.iter().filter(|m| m.ns == "ids").collect();
            assert!(spheres.iter().all(|m| m.kind == Marker::SPHERE));
            assert!(labels.iter().all(|m| m.kind == Marker::TEXT_VIEW_FACING));
            let ids: Vec<i32> = spheres.iter().map(|m| m.id).collect();
            let texts: Vec<String> = labels.iter().map(|m| m.text.clone()).collect();
            assert_eq!(texts, ids.iter().map(i32::to_string).collect::<Vec<_>>());
            match per_scan {
                // nearest: id 1 at the nearer walker's centre on every scan
                Some(id) => {
                    assert_eq!(ids, [id]);
                    let c = centre(0, i);
                    let p = spheres[0].pose.position;
                    assert!(
                        (p.x - c[0]).hypot(p.y - c[1]) < 1e-3,
                        "{method} scan {i}: {p}"
                    );
                }
                // legs: exactly the rows of the tracks CSV on this scan
                None => {
                    let rows: Vec<_> = legs_csv
                        .iter()
                        .filter(|r| r["scan_idx"] == i.to_string())
                        .collect();
                    assert_eq!(ids.len(), rows.len(), "legs scan {i}");
                    assert_eq!(rows.len(), if i >= 2 { 2 } else { 0 }, "legs scan {i}");
                    for (m, r) in spheres.iter().zip(&rows) {
                        assert_eq!(m.id.to_string(), r["id"]);
                        let x: f64 = r["x"].parse().expect("x");
                        let y: f64 = r["y"].parse().expect("y");
                        let p = m.pose.position;
                        assert!((p.x - x).abs() <= 5e-5 && (p.y - y).abs() <= 5e-5);
                    }
                }
            }
        }
    }
    // every original message, unchanged and in order
    let messages = |path: &Path, skip_markers: bool| -> Vec<(String, u64, Vec<u8>)> {
        SessionLog::open(path)
            .expect("open")
            .messages()
            .expect("messages")
            .map(|m| m.expect("message"))
            .filter(|m| !(skip_markers && m.channel.topic.starts_with("/peopletrack/")))
            .map(|m| (m.channel.topic.clone(), m.log_time.0, m.data.to_vec()))
            .collect()
    };
    let original = messages(&input, false);
    assert_eq!(original.len(), 21); // tf_static + 10 scans + 10 ground-truth frames
    assert_eq!(messages(&copy, true), original);
    assert_eq!(messages(&copy, false).len(), 21 + 2 * SCANS as usize);
}

/// Bad input: a session without its laser topic is a listed skip naming the topic; NaN, ±inf
/// and zero ranges give no detections, and an undecodable scan is counted, not fatal.
#[test]
fn bad_scans_are_counted_and_a_missing_topic_is_a_named_skip() {
    let dir = tempfile::tempdir().expect("tempdir");
    let data = dir.path().join("bad");
    std::fs::create_dir_all(&data).expect("mkdir");
    let mut w = SessionWriter::create(data.join("no_scan.mcap"), &WriterOptions::default())
        .expect("create");
    let gt = w
        .add_json(PEOPLE_TOPIC, PEOPLE_SCHEMA, PEOPLE_JSON_SCHEMA)
        .expect("gt");
    let frame = PeopleFrame {
        stamp_ns: 1_000_000_000,
        people: vec![person(1, centre(0, 0))],
    };
    w.write_json(gt, Nanos(1_000_000_000), &frame).expect("gt");
    w.finish().expect("finish");
    let mut w = SessionWriter::create(data.join("garbage.mcap"), &WriterOptions::default())
        .expect("create");
    let scan = w.add_ros2::<LaserScan>("/scan").expect("scan");
    for i in 0..5u64 {
        let t = Nanos(1_000_000_000 + i * 100_000_000);
        let ranges = (0..BEAMS)
            .map(|b| [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.0, -1.0][b % 5])
            .collect();
        let msg = LaserScan {
            header: Header::new(t, "laser"),
            angle_min: ANGLE_MIN as f32,
            angle_increment: INCREMENT as f32,
            range_min: 0.05,
            range_max: 10.0,
            ranges,
            ..Default::default()
        };
        w.write(scan, t, &msg).expect("scan");
    }
    w.write_bytes(scan, Nanos(2_000_000_000), &[1, 2, 3])
        .expect("garbage");
    w.finish().expect("finish");

    let toml = dir.path().join("laser_people.toml");
    std::fs::write(&toml, PIPELINE).expect("write pipeline");
    let out = dir.path().join("out");
    let sessions = vec![format!("{}/*.mcap", data.display())];
    let summary = run_file(&toml, &options(&out, sessions)).expect("runs");
    assert_eq!(summary.skipped.len(), 1, "{:?}", summary.skipped);
    assert!(
        summary.skipped[0].0.ends_with("no_scan")
            && summary.skipped[0].1.contains("missing laser topic /scan"),
        "{:?}",
        summary.skipped
    );
    let rows = csv_rows(&out.join("laser_people/tables/sessions.csv"));
    let garbage = rows
        .iter()
        .find(|r| r["sequence"] == "garbage")
        .expect("garbage row");
    assert_eq!(
        (&*garbage["scans"], &*garbage["skipped_messages"]),
        ("5", "1")
    );
    let tracks =
        std::fs::read_to_string(out.join("laser_people/tracks/garbage_legs.csv")).expect("tracks");
    assert_eq!(tracks, "scan_idx,id,x,y,world_x,world_y\n");
}

/// The real wheelchair sequence (Leigh et al., ICRA 2015): the pipeline completes and the
/// results table has its rows. No assertion on the numbers. The committed pipeline file with
/// its methods cut to those that train no forest (the learned ones train four; their code is
/// the same on every log and tested on synthetic ones), so the test takes seconds.
#[test]
fn real_general_tracking_moving_1_completes() {
    let rel = "shared/real/laser/general_tracking_moving_1/general_tracking_moving_1.mcap";
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let Some(path) = [root.join("..").join(rel), root.join("../..").join(rel)]
        .into_iter()
        .find(|p| p.exists())
    else {
        println!("SKIPPED: {rel} not found next to the repository");
        return;
    };
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out");
    let committed =
        std::fs::read_to_string(root.join("pipelines/laser_people.toml")).expect("pipeline");
    let methods = committed
        .lines()
        .find(|l| l.starts_with("methods = "))
        .expect("a methods line");
    let text = committed.replace(
        methods,
        r#"methods = ["legs", "legs_free_space", "nearest"]"#,
    );
    let toml = dir.path().join("laser_people.toml");
    std::fs::write(&toml, text).expect("write pipeline");
    let summary = run_file(&toml, &options(&out, vec![path.display().to_string()])).expect("runs");
    assert!(summary.skipped.is_empty(), "{:?}", summary.skipped);
    let rows = csv_rows(&out.join("laser_people/tables/results.csv"));
    for det in ["legs", "legs_free_space", "nearest"] {
        let r = row(&rows, "general_tracking_moving_1", det);
        assert_eq!(r["status"], "ok");
        println!("general_tracking_moving_1 {det}: {r:?}");
    }
    // the other listed sequence was not asked for: SKIPPED
    let r = row(&rows, "person_following_outdoor_1", "legs");
    assert!(r["status"].starts_with("SKIPPED"));
    // beside the paper's Table III: its three trackers on both benchmarks the committed file
    // names, our three methods on the moving one, under CLEAR MOT (every output counts)
    let t3 = csv_rows(&out.join("laser_people/tables/paper_table3.csv"));
    let paper = t3.iter().filter(|r| r["source"] == "paper").count();
    assert_eq!(paper, 6, "{t3:?}");
    let ours: Vec<_> = t3.iter().filter(|r| r["source"] != "paper").collect();
    assert_eq!(ours.len(), 3, "{t3:?}");
    for r in ours {
        assert_eq!(r["benchmark"], "Moving Robot");
        let n = |c: &str| r[c].parse::<i64>().expect(c);
        assert_eq!(n("valid") + n("id_switches") + n("misses"), n("objects"));
        assert!(
            !r["false_positives"].is_empty() && !r["mota"].is_empty(),
            "{r:?}"
        );
        assert!(r["target_accuracy"].is_empty(), "{r:?}");
    }
    // the annotations sit on the scans the authors' ground_truth.csv names
    let cached = out.join(
        "laser_people/sessions/dataset=general_tracking_moving_1/session=general_tracking_moving_1/truth.parquet",
    );
    let df = read_parquet(&cached).expect("cached truth");
    let ours: Vec<(i64, i64)> = i64s(&df, "scan_idx")
        .expect("scan_idx")
        .into_iter()
        .zip(i64s(&df, "id").expect("id"))
        .collect();
    let csv = std::fs::read_to_string(path.with_file_name("ground_truth.csv")).expect("csv");
    let theirs: Vec<(i64, i64)> = csv
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[0].parse().expect("scan_idx"), f[2].parse().expect("id"))
        })
        .collect();
    assert_eq!(ours, theirs);
}

//! The synthesizer end to end on a tiny scenario: deterministic bytes whatever the thread
//! count, logs that read back through our reader with every topic decoding, ground truth that
//! agrees with the images and the laser.

use std::path::{Path, PathBuf};

use peopletrack::groundtruth::PeopleFrame;
use peopletrack::log::msgs::{CompressedImage, Image, LaserScan};
use peopletrack::log::{Decoders, SessionLog, read_topic};
use peopletrack::synth::{SynthOptions, SynthSummary, synthesize, synthesize_sessions};

fn scenario() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/tiny_scenario.toml")
}

fn synth_into(dir: &Path, threads: usize) -> Vec<PathBuf> {
    synth_summary(dir, threads).sessions
}

fn synth_summary(dir: &Path, threads: usize) -> SynthSummary {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool");
    pool.install(|| {
        synthesize(
            &scenario(),
            &SynthOptions {
                profile: "quick".into(),
                out: Some(dir.to_path_buf()),
                progress: None,
            },
        )
        .expect("synthesizes")
    })
}

#[test]
fn same_scenario_and_seed_give_identical_bytes_whatever_the_thread_count() {
    let dir = tempfile::tempdir().expect("tempdir");
    let one = synth_summary(&dir.path().join("one"), 1);
    let a = one.sessions;
    let b = synth_into(&dir.path().join("three"), 3);
    assert_eq!(a.len(), 2);
    for (x, y) in a.iter().zip(&b) {
        let (bx, by) = (
            std::fs::read(x).expect("read"),
            std::fs::read(y).expect("read"),
        );
        assert!(bx.len() > 10_000);
        assert!(bx == by, "{} differs between 1 and 3 threads", x.display());
    }
    // sessions differ from each other (different session seeds)
    assert_ne!(
        std::fs::read(&a[0]).expect("a0"),
        std::fs::read(&a[1]).expect("a1")
    );
    // the synthesizer returns the preview's data; report draws the sheet
    let data = one.preview.expect("preview data of session 0");
    assert_eq!(data.cameras.len(), 3, "one tile per camera");
    let root = dir.path().join("one/preview");
    let sheet = peopletrack::report::preview::write(&root, "tiny", &data).expect("sheet");
    assert_eq!(sheet, root.join("tiny/preview.png"));
    let png = image::open(&sheet).expect("a PNG");
    assert!(png.width() > 100 && png.height() > 100);
}

#[test]
fn logs_read_back_with_every_topic_decoding() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sessions = synth_into(dir.path(), 2);
    let log = SessionLog::open(&sessions[0]).expect("opens");
    let mut dec = Decoders::new();
    let mut counts = std::collections::BTreeMap::new();
    for m in log.messages().expect("stream") {
        let m = m.expect("message");
        dec.value(&log, &m).unwrap_or_else(|e| panic!("{e}"));
        *counts.entry(m.topic().to_string()).or_insert(0) += 1;
    }
    assert_eq!(counts["/cam_0/image_raw"], 10);
    assert_eq!(counts["/cam_0/ground_truth_mask"], 10);
    assert_eq!(counts["/omni_para/image_raw/compressed"], 5);
    assert_eq!(counts["/omni_cone/image_raw/compressed"], 5);
    assert_eq!(counts["/scan"], 10);
    assert_eq!(counts["/odom"], 50);
    assert_eq!(counts["/tf_static"], 1);
    assert!(counts["/ground_truth/people"] >= 10);
    assert_eq!(
        log.summary()
            .metadata
            .iter()
            .find(|m| m.name == "peopletrack.scenario")
            .map(|m| m.entries["seed"].as_str()),
        Some("42")
    );
    // images decode, and the JPEG camera too
    let (_, img) = read_topic::<Image>(&log, "/cam_0/image_raw")
        .expect("t")
        .next()
        .expect("1")
        .expect("ok");
    assert_eq!(
        (img.width, img.height, img.encoding.as_str()),
        (64, 48, "rgb8")
    );
    let (_, jpg) = read_topic::<CompressedImage>(&log, "/omni_cone/image_raw/compressed")
        .expect("t")
        .next()
        .expect("1")
        .expect("ok");
    let decoded = peopletrack::log::image::decode_compressed(&jpg).expect("jpeg decodes");
    assert_eq!((decoded.width(), decoded.height()), (64, 64));
}

#[test]
fn ground_truth_agrees_with_the_mask_and_the_laser() {
    let dir = tempfile::tempdir().expect("tempdir");
    let sessions = synth_into(dir.path(), 2);
    let log = SessionLog::open(&sessions[0]).expect("opens");
    let masks: Vec<_> = read_topic::<Image>(&log, "/cam_0/ground_truth_mask")
        .expect("masks")
        .map(|r| r.expect("ok"))
        .collect();
    let mut gts: Vec<(peopletrack::Nanos, PeopleFrame)> = Vec::new();
    for m in log.messages_on(&["/ground_truth/people"]).expect("gt") {
        let m = m.expect("ok");
        gts.push((
            m.log_time,
            serde_json::from_slice(&m.data).expect("valid ground truth"),
        ));
    }
    let mut checked = 0;
    for (_, mask) in &masks {
        let stamp = mask.header.stamp.nanos().expect("stamp");
        let Some((_, gt)) = gts.iter().find(|(t, _)| *t == stamp) else {
            continue;
        };
        let Some(view) = gt
            .people
            .iter()
            .flat_map(|p| &p.cameras)
            .find(|v| v.camera == "cam_0")
        else {
            continue;
        };
        // the box is the extent of the mask's foreground pixels
        let fg: Vec<(u32, u32)> = mask
            .data
            .iter()
            .enumerate()
            .filter(|(_, v)| **v == 255)
            .map(|(i, _)| ((i % 64) as u32, (i / 64) as u32))
            .collect();
        match view.bbox {
            Some([x0, y0, x1, y1]) => {
                let (mx0, my0) = (
                    fg.iter().map(|p| p.0).min().expect("fg"),
                    fg.iter().map(|p| p.1).min().expect("fg"),
                );
                let (mx1, my1) = (
                    fg.iter().map(|p| p.0).max().expect("fg"),
                    fg.iter().map(|p| p.1).max().expect("fg"),
                );
                assert_eq!(
                    [x0, y0, x1, y1],
                    [
                        f64::from(mx0),
                        f64::from(my0),
                        f64::from(mx1 + 1),
                        f64::from(my1 + 1)
                    ]
                );
                checked += 1;
            }
            None => assert!(fg.is_empty()),
        }
    }
    assert!(
        checked >= 5,
        "only {checked} frames with the person in view"
    );
    // the laser sees the person's legs where the ground truth puts them
    let scans: Vec<_> = read_topic::<LaserScan>(&log, "/scan")
        .expect("scan")
        .map(|r| r.expect("ok"))
        .collect();
    let mut near = 0;
    for (_, s) in &scans {
        let stamp = s.header.stamp.nanos().expect("stamp");
        let Some((_, gt)) = gts.iter().find(|(t, _)| *t == stamp) else {
            continue;
        };
        let Some(p) = gt.people.first() else { continue };
        // laser at (2.5, 0.3) + 0.1 forward (robot faces +y), height 0.3: beam angle 0 is +y
        let (lx, ly) = (2.5, 0.4);
        for leg in p.legs {
            let (dx, dy) = (leg[0] - lx, leg[1] - ly);
            let bearing = -dx.atan2(dy); // angle from +y towards +x is clockwise = negative
            let k = ((bearing - f64::from(s.angle_min)) / f64::from(s.angle_increment)).round()
                as usize;
            let expect = dx.hypot(dy) - p.leg_radius;
            if let Some(r) = s.ranges.get(k)
                && r.is_finite()
                && (f64::from(*r) - expect).abs() < 0.15
            {
                near += 1;
            }
        }
    }
    assert!(near >= 8, "legs seen where expected in only {near} beams");
}

#[test]
fn a_crowd_is_numbered_after_the_scripted_people() {
    // the tiny scenario's scripted person 1 plus a crowd of two (no crossers): every person of
    // a ground-truth frame has their own id, the crowd's being 2 and 3 (it used to restart at 1,
    // so person 1 had two bodies and one union box)
    let dir = tempfile::tempdir().expect("tempdir");
    let text = std::fs::read_to_string(scenario()).expect("fixture")
        + "\n[crowd]\ncount = 2\narea = [1.0, 1.0, 4.0, 3.0]\nstay_s = [5.0, 6.0]\nspeed = [0.8, 1.0]\n";
    let path = dir.path().join("crowd_scenario.toml");
    std::fs::write(&path, text).expect("write");
    let summary = synthesize(
        &path,
        &SynthOptions {
            profile: "quick".into(),
            out: Some(dir.path().join("out")),
            progress: None,
        },
    )
    .expect("synthesizes");
    let log = SessionLog::open(&summary.sessions[0]).expect("opens");
    let mut seen = std::collections::BTreeSet::new();
    for m in log.messages_on(&["/ground_truth/people"]).expect("gt") {
        let frame: PeopleFrame = serde_json::from_slice(&m.expect("ok").data).expect("valid");
        let ids: Vec<u32> = frame.people.iter().map(|p| p.id).collect();
        let unique: std::collections::BTreeSet<u32> = ids.iter().copied().collect();
        assert_eq!(
            unique.len(),
            ids.len(),
            "duplicate ids in one frame: {ids:?}"
        );
        seen.extend(unique);
    }
    assert_eq!(seen.into_iter().collect::<Vec<_>>(), vec![1, 2, 3]);
}

#[test]
fn a_profile_gives_a_person_one_height_per_session_on_the_same_walk() {
    // the tiny scenario as is, and with a profile that makes person 1 1.60 m tall in session 0
    // and 1.95 m in session 1: the ground truth carries those heights (head centre 0.12 m
    // below the top) and the walk is the same, stamp by stamp, as the plain scenario's
    let truth = |path: &Path| -> Vec<(u64, f64, f64, f64, f64)> {
        let log = SessionLog::open(path).expect("opens");
        log.messages_on(&["/ground_truth/people"])
            .expect("gt")
            .map(|m| {
                let m = m.expect("ok");
                let f: PeopleFrame = serde_json::from_slice(&m.data).expect("valid");
                let p = &f.people[0];
                (m.log_time.0, p.x, p.y, p.height, p.head_z)
            })
            .collect()
    };
    let dir = tempfile::tempdir().expect("tempdir");
    let plain = synth_into(&dir.path().join("plain"), 1);
    let text = std::fs::read_to_string(scenario()).expect("fixture")
        + "\n[[profiles.quick.people]]\nid = 1\nheights = [1.60, 1.95]\n";
    let path = dir.path().join("heights_scenario.toml");
    std::fs::write(&path, &text).expect("write");
    let opts = |out: &str| SynthOptions {
        profile: "quick".into(),
        out: Some(dir.path().join(out)),
        progress: None,
    };
    let tall = synthesize(&path, &opts("heights")).expect("synthesizes");
    for (k, want) in [(0, 1.60), (1, 1.95)] {
        let (a, b) = (truth(&plain[k]), truth(&tall.sessions[k]));
        assert!(!a.is_empty() && a.len() == b.len());
        for (x, y) in a.iter().zip(&b) {
            assert_eq!((x.0, x.1, x.2), (y.0, y.1, y.2), "session {k}: same walk");
            assert!((x.3 - 1.8).abs() < 1e-12 && (y.3 - want).abs() < 1e-12);
            assert!(
                (y.3 - y.4 - 0.12).abs() < 1e-9,
                "head centre follows the height"
            );
        }
    }
    // an override naming no person is an error that names its key
    let bad = text.replace("id = 1\nheights", "id = 7\nheights");
    std::fs::write(&path, bad).expect("write");
    let err = synthesize(&path, &opts("bad")).err().expect("refused");
    assert!(
        format!("{err:#}").contains("profiles.quick.people[0].id"),
        "{err:#}"
    );
}

#[test]
fn the_id_mask_names_each_persons_pixels_and_a_profile_can_start_at_any_session() {
    // the tiny scenario with the per-person id mask on cam_0 and a profile of one session
    // starting at session 7
    let dir = tempfile::tempdir().expect("tempdir");
    let text = std::fs::read_to_string(scenario())
        .expect("fixture")
        .replace("mask = true\n", "mask = true\nid_mask = true\n")
        .replace(
            "[profiles.quick]\n",
            "[profiles.later]\nsessions = 1\nfirst_session = 7\n\n[profiles.quick]\n",
        );
    let path = dir.path().join("ids_scenario.toml");
    std::fs::write(&path, text).expect("write");
    let summary = synthesize(
        &path,
        &SynthOptions {
            profile: "later".into(),
            out: Some(dir.path().join("out")),
            progress: None,
        },
    )
    .expect("synthesizes");
    assert_eq!(summary.sessions.len(), 1);
    assert!(summary.sessions[0].ends_with("tiny_07.mcap"));
    let log = SessionLog::open(&summary.sessions[0]).expect("opens");
    let read = |topic: &str| -> Vec<Image> {
        read_topic::<Image>(&log, topic)
            .expect("topic")
            .map(|r| r.expect("ok").1)
            .collect()
    };
    let (masks, ids) = (
        read("/cam_0/ground_truth_mask"),
        read("/cam_0/ground_truth_ids"),
    );
    assert_eq!(masks.len(), ids.len());
    let mut person_pixels = 0;
    for (m, i) in masks.iter().zip(&ids) {
        assert_eq!(m.header.stamp, i.header.stamp);
        assert_eq!((i.encoding.as_str(), i.width, i.height), ("mono8", 64, 48));
        for (&u, &id) in m.data.iter().zip(&i.data) {
            // person 1 is the only person: its id exactly where the union mask is set
            assert_eq!(id, if u == 255 { 1 } else { 0 });
        }
        person_pixels += i.data.iter().filter(|v| **v == 1).count();
    }
    assert!(person_pixels > 100, "only {person_pixels} person pixels");
    // session 7's own seed: unlike session 0 of the quick profile
    let quick = synthesize(
        &path,
        &SynthOptions {
            profile: "quick".into(),
            out: Some(dir.path().join("quick")),
            progress: None,
        },
    )
    .expect("synthesizes");
    assert!(quick.sessions[0].ends_with("tiny_00.mcap"));
    assert_ne!(
        std::fs::read(&quick.sessions[0]).expect("00"),
        std::fs::read(&summary.sessions[0]).expect("07")
    );
}

/// `synth --missing-only` finishes an interrupted render: only the absent session is written,
/// and it is byte for byte the one a whole render writes.
#[test]
fn an_interrupted_render_is_finished_with_the_same_bytes() {
    let dir = tempfile::tempdir().expect("tempdir");
    let whole = synth_into(&dir.path().join("whole"), 1);
    assert!(whole.len() >= 2, "the fixture has several sessions");
    let part = dir.path().join("part");
    std::fs::create_dir_all(&part).expect("mkdir");
    // the render was cut after every session but the last
    for p in &whole[..whole.len() - 1] {
        std::fs::copy(p, part.join(p.file_name().expect("name"))).expect("copy");
    }
    let opts = SynthOptions {
        profile: "quick".into(),
        out: Some(part.clone()),
        progress: None,
    };
    let done = synthesize_sessions(&scenario(), &opts, true).expect("synthesizes");
    let last = whole.last().expect("a session");
    assert_eq!(done.sessions, [part.join(last.file_name().expect("name"))]);
    assert!(
        std::fs::read(last).expect("whole") == std::fs::read(&done.sessions[0]).expect("part"),
        "the finished session differs from the whole render's"
    );
}

/// `synth --if-absent` keeps logs only when they are what the scenario renders now: logs
/// rendered from this very file are current; after the file changes (one comment added) they
/// are named stale; a log without our metadata is named too.
#[test]
fn logs_from_another_version_of_the_scenario_are_stale() {
    use peopletrack::synth::stale_logs;
    let dir = tempfile::tempdir().expect("tempdir");
    let logs = dir.path().join("logs");
    synth_into(&logs, 2);
    assert_eq!(
        stale_logs(&scenario(), "quick", &logs).expect("checks"),
        None
    );
    let edited = dir.path().join("tiny_scenario.toml");
    let text = std::fs::read_to_string(scenario()).expect("fixture");
    std::fs::write(&edited, format!("{text}\n# edited\n")).expect("write");
    let why = stale_logs(&edited, "quick", &logs)
        .expect("checks")
        .expect("stale after an edit");
    assert!(why.contains("another version"), "{why}");
    // an empty folder has nothing stale
    let empty = dir.path().join("empty");
    std::fs::create_dir_all(&empty).expect("mkdir");
    assert_eq!(
        stale_logs(&scenario(), "quick", &empty).expect("checks"),
        None
    );
}

//! The closed following loop end to end (`[robot.follow] closed_loop = true`): the log's
//! bytes do not depend on the thread count, `/follower/state` carries one state per scan,
//! the robot follows the walker, and an open-loop copy of the scenario has no follower channel.

use std::path::{Path, PathBuf};

use peopletrack::groundtruth::{FollowerState, PeopleFrame};
use peopletrack::log::SessionLog;
use peopletrack::log::msgs::{LaserScan, Odometry};
use peopletrack::log::read_topic;
use peopletrack::synth::{SynthOptions, synthesize};

fn scenario() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/follow_scenario.toml")
}

fn synth(scenario: &Path, dir: &Path, threads: usize) -> Vec<PathBuf> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool");
    pool.install(|| {
        synthesize(
            scenario,
            &SynthOptions {
                profile: "quick".into(),
                out: Some(dir.to_path_buf()),
                progress: None,
            },
        )
        .expect("synthesizes")
        .sessions
    })
}

fn json<T: serde::de::DeserializeOwned>(log: &SessionLog, topic: &str) -> Vec<T> {
    log.messages_on(&[topic])
        .expect("topic")
        .map(|m| serde_json::from_slice(&m.expect("ok").data).expect("valid json"))
        .collect()
}

#[test]
fn closed_loop_logs_are_identical_on_one_and_two_threads_and_follow_the_walker() {
    let dir = tempfile::tempdir().expect("tempdir");
    let a = synth(&scenario(), &dir.path().join("one"), 1);
    let b = synth(&scenario(), &dir.path().join("two"), 2);
    assert_eq!(a.len(), 2);
    for (x, y) in a.iter().zip(&b) {
        let (bx, by) = (
            std::fs::read(x).expect("read"),
            std::fs::read(y).expect("read"),
        );
        assert!(bx == by, "{} differs between 1 and 2 threads", x.display());
    }
    for (k, path) in a.iter().enumerate() {
        let log = SessionLog::open(path).expect("opens");
        let states: Vec<FollowerState> = json(&log, "/follower/state");
        let scans: Vec<_> = read_topic::<LaserScan>(&log, "/scan")
            .expect("scans")
            .map(|r| r.expect("ok").1)
            .collect();
        assert_eq!(states.len(), scans.len(), "one state per scan");
        for (s, scan) in states.iter().zip(&scans) {
            assert_eq!(Some(s.stamp_ns), scan.header.stamp.nanos().map(|n| n.0));
            assert_eq!(s.frame_id, "odom");
        }
        // controllers alternate by session
        let expected = ["pursuit", "direct"][k];
        assert!(states.iter().all(|s| s.controller == expected));
        let tracked = states.iter().filter(|s| s.position.is_some()).count();
        assert!(
            tracked * 10 >= states.len() * 9,
            "{tracked} of {}",
            states.len()
        );
        // the estimate is near the walker's true position (odom = map shifted to the start)
        let people: Vec<PeopleFrame> = json(&log, "/ground_truth/people");
        let mut errors = Vec::new();
        for s in &states {
            let (Some(p), Some(gt)) =
                (s.position, people.iter().find(|g| g.stamp_ns == s.stamp_ns))
            else {
                continue;
            };
            let Some(walker) = gt.people.iter().find(|q| q.id == 1) else {
                continue;
            };
            // the robot starts at (5.5, 10) facing +x: odom = map − (5.5, 10); odometry
            // drifts a few centimetres in 4 s; the laser sees the legs' near surfaces and the
            // baseline's smoothed velocity lags a walker who starts or turns
            errors.push((p[0] + 5.5 - walker.x).hypot(p[1] + 10.0 - walker.y));
        }
        assert!(errors.len() > 30);
        // while the robot accelerates its pitch puts the laser on the ground (seed 001's
        // "gnd"): the baseline then coasts or sits on ground returns for a few scans; and the
        // comparison is in odom, which drifts from map by the odometry's 2 % speed bias
        let mut sorted = errors.clone();
        sorted.sort_by(f64::total_cmp);
        let median = sorted[sorted.len() / 2];
        let p90 = sorted[sorted.len() * 9 / 10];
        eprintln!("session {k}: estimate error median {median:.3} p90 {p90:.3} m");
        assert!(
            median < 0.3 && p90 < 0.8,
            "median {median} p90 {p90}: {errors:.2?}"
        );
        // the robot drove after the walker
        let odom: Vec<_> = read_topic::<Odometry>(&log, "/odom")
            .expect("odom")
            .map(|r| r.expect("ok").1)
            .collect();
        let last = odom.last().expect("odometry");
        assert!(
            last.pose.position.x > 2.0,
            "odom x {}",
            last.pose.position.x
        );
    }
}

#[test]
fn an_open_loop_copy_has_no_follower_channel() {
    let dir = tempfile::tempdir().expect("tempdir");
    let text = std::fs::read_to_string(scenario()).expect("scenario");
    let open = text.replace("closed_loop = true", "closed_loop = false");
    assert_ne!(open, text);
    let path = dir.path().join("open.toml");
    std::fs::write(&path, open).expect("write");
    let sessions = synth(&path, &dir.path().join("out"), 1);
    let log = SessionLog::open(&sessions[0]).expect("opens");
    assert!(log.messages_on(&["/scan"]).is_ok());
    assert!(
        log.messages_on(&["/follower/state"]).is_err(),
        "no follower channel"
    );
}

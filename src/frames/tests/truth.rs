use super::{open, s, writer};
use crate::frames::truth;
use crate::groundtruth::{
    PEOPLE_JSON_SCHEMA, PEOPLE_SCHEMA, PEOPLE_TOPIC, PeopleFrame, TARGETS_JSON_SCHEMA,
    TARGETS_SCHEMA, TARGETS_TOPIC, Target, TargetsFrame,
};

const TOL_NS: u64 = 20_000_000;

fn frame(stamp_ms: u64) -> PeopleFrame {
    PeopleFrame {
        stamp_ns: stamp_ms * 1_000_000,
        people: Vec::new(),
    }
}

/// People frames at 1000, 1100 (written first), 1200 ms and one bad JSON message; one target.
fn truth_log(dir: &std::path::Path) -> std::path::PathBuf {
    let (mut w, _) = writer(dir, "truth");
    let ch = w
        .add_json(PEOPLE_TOPIC, PEOPLE_SCHEMA, PEOPLE_JSON_SCHEMA)
        .expect("ch");
    let tg = w
        .add_json(TARGETS_TOPIC, TARGETS_SCHEMA, TARGETS_JSON_SCHEMA)
        .expect("ch");
    w.write_json(ch, s(1000), &frame(1100)).expect("w");
    w.write_json(ch, s(1001), &frame(1000)).expect("w");
    w.write_bytes(ch, s(1150), b"{\"stamp_ns\": 1").expect("w");
    w.write_json(ch, s(1200), &frame(1200)).expect("w");
    let target = TargetsFrame {
        stamp_ns: 5,
        targets: vec![Target {
            id: 1,
            x: 1.0,
            y: 2.0,
            z: 3.0,
        }],
    };
    w.write_json(tg, s(1300), &target).expect("w");
    w.finish().expect("finish")
}

#[test]
fn people_sorted_bad_counted_and_nearest_within_tolerance() {
    let dir = tempfile::tempdir().expect("tmp");
    let path = truth_log(dir.path());
    let log = open(&path);
    let (gt, skips) = truth::people(&log, PEOPLE_TOPIC).expect("truth");
    assert_eq!(gt.stamps(), &[s(1000), s(1100), s(1200)]);
    assert_eq!(skips.count(PEOPLE_TOPIC), 1);
    assert_eq!(
        skips.first_error(),
        Some(
            format!(
                "{}: topic {PEOPLE_TOPIC} at log time 1.150000000 s: EOF while parsing an object at line 1 column 14",
                path.display()
            )
            .as_str()
        )
    );
    let at = |ms: u64, extra_ns: u64| {
        gt.nearest(crate::time::Nanos(ms * 1_000_000 + extra_ns), TOL_NS)
            .map(|f| f.stamp_ns / 1_000_000)
    };
    assert_eq!(at(1020, 0), Some(1000), "exactly at the tolerance");
    assert_eq!(at(1020, 1), None, "1 ns beyond it");
    assert_eq!(at(980, 0), Some(1000));
    assert_eq!(at(979, 999_999), None);
    assert_eq!(at(1150, 0), None, "50 ms from both");
    assert_eq!(
        gt.nearest(s(1150), 50_000_000).map(|f| f.stamp_ns),
        Some(1_100_000_000),
        "a tie goes to the earlier stamp"
    );
    assert_eq!(
        gt.nearest_with_stamp(s(1210), TOL_NS).map(|(t, _)| t),
        Some(s(1200))
    );
    let (targets, tskips) = truth::targets(&log, TARGETS_TOPIC).expect("targets");
    assert_eq!(targets.len(), 1);
    assert_eq!(targets.items()[0].targets[0].z, 3.0);
    assert!(tskips.is_empty());
    // no ground truth in the log: empty, not an error
    let (none, _) = truth::people(&log, "/ground_truth/none").expect("absent");
    assert!(none.is_empty());
}

const PERSON_DEF: &str = "geometry_msgs/Pose pose\nuint32 id\n===\nMSG: geometry_msgs/Pose\n\
    geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n===\n\
    MSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z\n===\n\
    MSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w";

/// A `leg_tracker/msg/Person` as rosbags writes it (little-endian CDR, no header field).
fn person_cdr(x: f64, y: f64, id: u32) -> Vec<u8> {
    let mut b = vec![0, 1, 0, 0];
    for v in [x, y, 0.0, 0.0, 0.0, 0.0, 1.0] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.extend_from_slice(&id.to_le_bytes());
    b
}

/// The flat-decoded CDR channel and a JSON channel of the same fields (the tree path) give
/// the same rows; a truncated payload and a NaN position are skipped and counted, the first
/// with the tree decoder's error naming the field.
#[test]
fn person_positions_read_cdr_flat_and_json_alike() {
    let dir = tempfile::tempdir().expect("tmp");
    let (mut w, path) = writer(dir.path(), "people");
    let cdr = w
        .add_ros2_dynamic("/gt", "leg_tracker/msg/Person", PERSON_DEF)
        .expect("ch");
    let json = w.add_json("/gt_json", "Person", "{}").expect("ch");
    w.write_bytes(cdr, s(10), &person_cdr(1.5, -2.0, 7))
        .expect("w");
    w.write_bytes(cdr, s(20), &person_cdr(1.5, -2.0, 7)[..40])
        .expect("w");
    w.write_bytes(cdr, s(30), &person_cdr(f64::NAN, 0.0, 8))
        .expect("w");
    w.write_bytes(cdr, s(40), &person_cdr(-0.25, 3.0, 9))
        .expect("w");
    for (t, x, y, id) in [(10, 1.5, -2.0, 7), (40, -0.25, 3.0, 9)] {
        let m = serde_json::json!({"pose": {"position": {"x": x, "y": y}}, "id": id});
        w.write_json(json, s(t), &m).expect("w");
    }
    w.finish().expect("finish");
    let log = open(&path);
    let (rows, skips) = truth::person_positions(&log, "/gt").expect("reads");
    let (json_rows, json_skips) = truth::person_positions(&log, "/gt_json").expect("reads");
    let got: Vec<_> = rows.iter().map(|p| (p.log_time, p.id, p.x, p.y)).collect();
    assert_eq!(got, [(s(10), 7, 1.5, -2.0), (s(40), 9, -0.25, 3.0)]);
    assert_eq!(json_rows, rows);
    assert!(json_skips.is_empty());
    assert_eq!(skips.count("/gt"), 2);
    let first = skips.first_error_on("/gt").expect("an error");
    assert!(
        first.contains("at log time 0.020000000 s") && first.contains("pose.orientation.y"),
        "{first}"
    );
    let (none, _) = truth::person_positions(&log, "/absent").expect("reads");
    assert!(none.is_empty());
}

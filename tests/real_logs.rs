//! Known answers from real ROS 2 logs written by rosbags (not by us): counts, schema names,
//! no-return markers, the custom `leg_tracker/msg/Person` type and TF, as recorded in each
//! folder's `verify.txt` under `../shared/real/laser/`.

use crate::common;

use std::collections::BTreeMap;

use peopletrack::Nanos;
use peopletrack::log::msgs::LaserScan;
use peopletrack::log::sync::header_stamp;
use peopletrack::log::{Decoders, SessionLog, TfBuffer, read_topic};

fn counts(log: &SessionLog) -> BTreeMap<String, (String, u64)> {
    let mut out = BTreeMap::new();
    for m in log.messages().expect("stream") {
        let m = m.expect("message");
        out.entry(m.topic().to_string())
            .or_insert_with(|| (m.channel.schema_name().to_string(), 0))
            .1 += 1;
    }
    out
}

#[test]
fn general_tracking_topics_schemas_and_counts() {
    let Some(path) = common::laser_log("general_tracking_moving_1") else {
        return;
    };
    let log = SessionLog::open(&path).expect("opens");
    let c = counts(&log);
    let expect = [
        ("/tf", "tf2_msgs/msg/TFMessage", 21744),
        ("/odom", "nav_msgs/msg/Odometry", 11561),
        ("/scan", "sensor_msgs/msg/LaserScan", 873),
        ("/ground_truth_people_tracks", "leg_tracker/msg/Person", 153),
    ];
    assert_eq!(c.len(), expect.len());
    for (topic, schema, n) in expect {
        assert_eq!(c[topic], (schema.to_string(), n), "{topic}");
    }
    // the summary's statistics agree with what we read
    let stats = log.summary().statistics.clone().expect("statistics");
    assert_eq!(stats.message_count, 34331);
    assert_eq!(stats.start, Nanos(1_403_024_474_605_089_680));
    assert_eq!(stats.end, Nanos(1_403_024_590_842_192_446));
}

/// Counts of (beams, exact 0.0, NaN, +inf) over all scans of a topic.
fn no_return_counts(
    log: &SessionLog,
    topic: &str,
    beams: usize,
) -> (usize, usize, usize, usize, usize) {
    let (mut n, mut total, mut zero, mut nan, mut inf) = (0, 0, 0, 0, 0);
    for item in read_topic::<LaserScan>(log, topic).expect("topic") {
        let (_, scan) = item.expect("scan decodes");
        assert_eq!(scan.ranges.len(), beams);
        n += 1;
        total += scan.ranges.len();
        zero += scan.ranges.iter().filter(|r| **r == 0.0).count();
        nan += scan.ranges.iter().filter(|r| r.is_nan()).count();
        inf += scan.ranges.iter().filter(|r| **r == f32::INFINITY).count();
    }
    (n, total, zero, nan, inf)
}

#[test]
fn every_scan_decodes_with_no_returns_preserved() {
    // verify.txt: "beams=670464 zero=31428 nan=40048 +inf=267584"
    if let Some(p) = common::laser_log("general_tracking_moving_1") {
        let log = SessionLog::open(&p).expect("opens");
        assert_eq!(
            no_return_counts(&log, "/scan", 768),
            (873, 670_464, 31_428, 40_048, 267_584)
        );
    }
    // "beams=1756650 zero=0 nan=210281 +inf=1165270"
    if let Some(p) = common::laser_log("person_following_outdoor_1") {
        let log = SessionLog::open(&p).expect("opens");
        assert_eq!(
            no_return_counts(&log, "/scan_base2", 245),
            (7170, 1_756_650, 0, 210_281, 1_165_270)
        );
    }
}

#[test]
fn first_scan_fields_match_verify_txt() {
    let Some(p) = common::laser_log("general_tracking_moving_1") else {
        return;
    };
    let log = SessionLog::open(&p).expect("opens");
    let (t, scan) = read_topic::<LaserScan>(&log, "/scan")
        .expect("topic")
        .next()
        .expect("one")
        .expect("ok");
    assert_eq!(t, Nanos(1_403_024_474_695_328_780));
    assert_eq!(scan.header.frame_id, "left_laser");
    assert_eq!(
        scan.header.stamp.nanos(),
        Some(Nanos(1_403_024_474_631_777_750))
    );
    assert_eq!(scan.angle_min, -2.356_194_5_f32);
    assert_eq!(scan.angle_max, 2.350_058_6_f32);
    assert!((scan.angle_increment - 0.006_135_923).abs() < 1e-9); // printed rounded in verify.txt
    assert_eq!(scan.range_max, 11.0);
    assert!(scan.intensities.is_empty());
}

#[test]
fn custom_person_type_decodes_dynamically_and_equals_ground_truth_csv() {
    let Some(p) = common::laser_log("general_tracking_moving_1") else {
        return;
    };
    let Some(csv) = common::real("laser/general_tracking_moving_1/ground_truth.csv") else {
        return;
    };
    let log = SessionLog::open(&p).expect("opens");
    let rows: Vec<(f64, u32, f64, f64)> = std::fs::read_to_string(csv)
        .expect("csv")
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (
                f[1].parse().expect("t"),
                f[2].parse().expect("id"),
                f[3].parse().expect("x"),
                f[4].parse().expect("y"),
            )
        })
        .collect();
    assert_eq!(rows.len(), 153);
    let mut dec = Decoders::new();
    let mut n = 0;
    for (m, (t, id, x, y)) in log
        .messages_on(&["/ground_truth_people_tracks"])
        .expect("topic")
        .zip(&rows)
    {
        let m = m.expect("message");
        let v = dec
            .value(&log, &m)
            .expect("dynamic decode of leg_tracker/msg/Person");
        let pos = v
            .get("pose")
            .and_then(|p| p.get("position"))
            .expect("pose.position");
        assert_eq!(v.get("id").and_then(|i| i.as_u32()), Ok(*id));
        // the CSV rounds to 0.1 mm and to the microsecond
        assert!((pos.get("x").and_then(|v| v.as_f64()).expect("x") - x).abs() <= 5.1e-5);
        assert!((pos.get("y").and_then(|v| v.as_f64()).expect("y") - y).abs() <= 5.1e-5);
        assert!((m.log_time.as_secs_f64() - t).abs() < 1e-6);
        n += 1;
    }
    assert_eq!(n, 153);
}

#[test]
fn tf_lookup_gives_the_static_laser_mount() {
    let Some(p) = common::laser_log("general_tracking_moving_1") else {
        return;
    };
    let log = SessionLog::open(&p).expect("opens");
    let tf = TfBuffer::from_log(&log, 0.5).expect("tf");
    let at = Nanos(1_403_024_500_000_000_000);
    let m = tf
        .lookup("base_link", "left_laser", at)
        .expect("base_link <- left_laser");
    let t = m.translation.vector;
    assert!(
        (t.x - 0.850326).abs() < 1e-6 && (t.y - 0.235214).abs() < 1e-6 && t.z.abs() < 1e-9,
        "{t}"
    );
    // verify.txt: q=(0.0,0.0,0.35919389439271154,0.9332629566370871)
    let q = m.rotation.quaternion();
    assert!(
        (q.k - 0.359_193_894_392_711_54).abs() < 1e-12
            && (q.w - 0.933_262_956_637_087_1).abs() < 1e-12,
        "{q}"
    );
    // `/odom` -> `/base_link` is written with leading slashes; lookups work without them
    let m = tf
        .lookup("odom", "left_laser", at)
        .expect("odom <- left_laser through base_link");
    assert!(m.translation.vector.iter().all(|v| v.is_finite()));
}

#[test]
fn uncompressed_variant_reads_the_same_as_zstd() {
    let Some(z) = common::laser_log("demo_stationary_simple_environment") else {
        return;
    };
    let u = z.with_file_name("demo_stationary_simple_environment.uncompressed.mcap");
    let (lz, lu) = (
        SessionLog::open(&z).expect("zstd"),
        SessionLog::open(&u).expect("none"),
    );
    assert_eq!(lz.summary().chunks[0].compression, "zstd");
    assert_eq!(lu.summary().chunks[0].compression, "");
    let a: Vec<_> = read_topic::<LaserScan>(&lz, "/scan")
        .expect("scan")
        .map(|r| r.expect("ok"))
        .collect();
    let b: Vec<_> = read_topic::<LaserScan>(&lu, "/scan")
        .expect("scan")
        .map(|r| r.expect("ok"))
        .collect();
    assert_eq!(a.len(), 1265);
    assert_eq!(a.len(), b.len());
    for ((ta, sa), (tb, sb)) in a.iter().zip(&b) {
        assert_eq!(ta, tb);
        let bits = |s: &LaserScan| s.ranges.iter().map(|r| r.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(sa), bits(sb)); // NaN payloads included
        assert_eq!(sa.header, sb.header);
    }
}

#[test]
fn stamps_run_130_s_ahead_of_log_time_outdoors() {
    let Some(p) = common::laser_log("person_following_outdoor_1") else {
        return;
    };
    let log = SessionLog::open(&p).expect("opens");
    let mut dec = Decoders::new();
    let mut offsets: Vec<f64> = log
        .messages_on(&["/scan_base2"])
        .expect("topic")
        .map(|m| {
            let m = m.expect("message");
            let stamp = header_stamp(&dec.value(&log, &m).expect("decodes")).expect("stamp");
            stamp.signed_sub(m.log_time) as f64 * 1e-9
        })
        .collect();
    offsets.sort_by(f64::total_cmp);
    // verify.txt: header.stamp - log_time: min=130.2332 median=130.2810 max=130.2964 s
    assert!((offsets[0] - 130.2332).abs() < 1e-4);
    assert!((offsets[offsets.len() / 2] - 130.2810).abs() < 1e-4);
    assert!((offsets[offsets.len() - 1] - 130.2964).abs() < 1e-4);
}

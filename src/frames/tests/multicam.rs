use super::{open, raw_rgb, s, writer};
use crate::frames::multicam::{self, MultiFrame};
use crate::frames::{ImageMsg, Skips};
use crate::log::msgs::{Detection2D, Detection2DArray, Header, Image};
use crate::time::Nanos;

const TOL_NS: u64 = 10_000_000;

fn topics() -> Vec<String> {
    (0..3).map(|c| format!("/c{c}/image_raw")).collect()
}

/// Three cameras; (log ms, camera, stamp ms):
/// frame 1000: (1000, c0, 1000), (1001, c1, 1002), (1002, c2, 1004)
/// frame 1100: (1100, c0, 1100), (1101, c2, 1101) — c1 misses it; (1102) garbage on c1
/// frame 1199: (1200, c2, 1199), (1201, c1, 1200), (1202, c0, 1209)
/// frame 1300 and 1305: (1300, c0, 1300), (1301, c0, 1305): c0 twice closes the frame
/// frame 1400 and 1420: (1400, c1, 1400), (1401, c2, 1420): beyond the tolerance; (1402, c0, 1418)
fn multicam_log(dir: &std::path::Path) -> std::path::PathBuf {
    let (mut w, _) = writer(dir, "multicam");
    let ch: Vec<_> = topics()
        .iter()
        .map(|t| w.add_ros2::<Image>(t).expect("ch"))
        .collect();
    let msgs: [(u64, usize, u64); 13] = [
        (1000, 0, 1000),
        (1001, 1, 1002),
        (1002, 2, 1004),
        (1100, 0, 1100),
        (1101, 2, 1101),
        (1200, 2, 1199),
        (1201, 1, 1200),
        (1202, 0, 1209),
        (1300, 0, 1300),
        (1301, 0, 1305),
        (1400, 1, 1400),
        (1401, 2, 1420),
        (1402, 0, 1418),
    ];
    for (log_ms, c, stamp_ms) in msgs {
        w.write(ch[c], s(log_ms), &raw_rgb(s(stamp_ms), 2, 2, c as u8))
            .expect("w");
        if log_ms == 1101 {
            w.write_bytes(ch[1], s(1102), &[9, 9]).expect("w");
        }
    }
    w.finish().expect("finish")
}

fn shape<P>(f: &MultiFrame<P>) -> (u64, Vec<bool>) {
    (
        f.stamp.0 / 1_000_000,
        f.cameras.iter().map(Option::is_some).collect(),
    )
}

#[test]
fn cameras_group_by_stamp_within_tolerance() {
    let dir = tempfile::tempdir().expect("tmp");
    let path = multicam_log(dir.path());
    let log = open(&path);
    let mut frames = multicam::group::<ImageMsg>(&log, &topics(), TOL_NS).expect("group");
    let got: Vec<MultiFrame<ImageMsg>> = frames.by_ref().map(|f| f.expect("frame")).collect();
    let (t, f) = (true, false);
    assert_eq!(
        got.iter().map(shape).collect::<Vec<_>>(),
        vec![
            (1000, vec![t, t, t]),
            (1100, vec![t, f, t]),
            (1199, vec![t, t, t]),
            (1300, vec![t, f, f]),
            (1305, vec![t, f, f]),
            (1400, vec![f, t, f]),
            (1420, vec![t, f, t]),
        ]
    );
    assert_eq!(got.iter().map(MultiFrame::missing).sum::<usize>(), 8);
    // each camera's own message: the tag is the camera index, the stamp its own
    let f0 = &got[2];
    for (c, m) in f0.cameras.iter().enumerate() {
        let m = m.as_ref().expect("present");
        assert_eq!(m.decode().expect("rgb").get_pixel(1, 1).0, [1, 1, c as u8]);
    }
    assert_eq!(
        f0.cameras[0].as_ref().map(|m| m.header().stamp.nanos()),
        Some(Some(s(1209)))
    );
    let skips: Skips = frames.into_skips();
    assert_eq!(skips.count("/c1/image_raw"), 1);
    let text = skips.first_error().expect("one");
    assert!(
        text.starts_with(&format!(
            "{}: topic /c1/image_raw at log time 1.102000000 s: ",
            path.display()
        )),
        "{text}"
    );
}

#[test]
fn detections_group_the_same_way() {
    let dir = tempfile::tempdir().expect("tmp");
    let (mut w, path) = writer(dir.path(), "detections");
    let topics = vec!["/c0/detections".to_string(), "/c1/detections".to_string()];
    let ch: Vec<_> = topics
        .iter()
        .map(|t| w.add_ros2::<Detection2DArray>(t).expect("ch"))
        .collect();
    let det = |stamp: Nanos, n: usize| Detection2DArray {
        header: Header::new(stamp, "cam"),
        detections: (0..n)
            .map(|i| Detection2D {
                center_x: i as f64,
                ..Default::default()
            })
            .collect(),
    };
    // c1's second array is unstamped: its log time (2003 ms) stands in
    w.write(ch[0], s(1000), &det(s(1000), 1)).expect("w");
    w.write(ch[1], s(1001), &det(s(1005), 2)).expect("w");
    w.write(ch[0], s(2000), &det(s(2000), 0)).expect("w");
    w.write(ch[1], s(2003), &det(Nanos(0), 3)).expect("w");
    w.write(ch[1], s(3000), &det(s(3000), 4)).expect("w");
    w.finish().expect("finish");
    let log = open(&path);
    let got: Vec<(u64, Vec<Option<usize>>)> =
        multicam::group::<Detection2DArray>(&log, &topics, TOL_NS)
            .expect("group")
            .map(|f| {
                let f = f.expect("frame");
                (
                    f.stamp.0 / 1_000_000,
                    f.cameras
                        .iter()
                        .map(|d| d.as_ref().map(|d| d.detections.len()))
                        .collect(),
                )
            })
            .collect();
    assert_eq!(
        got,
        vec![
            (1000, vec![Some(1), Some(2)]),
            (2000, vec![Some(0), Some(3)]),
            (3000, vec![None, Some(4)]),
        ]
    );
}

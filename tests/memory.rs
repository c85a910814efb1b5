//! Reading is streaming: the peak heap while reading every message of a log ten times longer
//! stays flat. Measured with a counting global allocator (exact and deterministic, unlike RSS).

use std::sync::atomic::Ordering::Relaxed;

use crate::support::counting_alloc::{CURRENT, PEAK};

use peopletrack::Nanos;
use peopletrack::log::msgs::{Header, Image};
use peopletrack::log::{SessionLog, SessionWriter, WriterOptions, read_topic};

fn write_log(path: &std::path::Path, frames: u64) {
    let mut w = SessionWriter::create(path, &WriterOptions::default()).expect("create");
    let ch = w.add_ros2::<Image>("/cam/image_raw").expect("channel");
    let mut state = 0x2545_f491_4f6c_dd1du64;
    for i in 0..frames {
        // 128x128 mono8 with noise, so chunks really hold ~1 MB each
        let data: Vec<u8> = (0..128 * 128)
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 56) as u8
            })
            .collect();
        let img = Image {
            header: Header::new(Nanos(i * 40_000_000), "cam"),
            height: 128,
            width: 128,
            encoding: "mono8".into(),
            step: 128,
            data,
            ..Default::default()
        };
        w.write(ch, Nanos(i * 40_000_000), &img).expect("write");
    }
    w.finish().expect("finish");
}

/// Peak heap growth (bytes) while reading and decoding every image of the log.
fn peak_while_reading(path: &std::path::Path) -> (usize, u64) {
    let log = SessionLog::open(path).expect("opens");
    let base = CURRENT.load(Relaxed);
    PEAK.store(base, Relaxed);
    let mut n = 0;
    let mut checksum = 0u64;
    for item in read_topic::<Image>(&log, "/cam/image_raw").expect("topic") {
        let (_, img) = item.expect("image");
        checksum = checksum.wrapping_add(u64::from(img.data[0]));
        n += 1;
    }
    std::hint::black_box(checksum);
    (PEAK.load(Relaxed) - base, n)
}

#[test]
fn peak_heap_is_flat_for_a_ten_times_longer_log() {
    let _alone = crate::support::counting_alloc::alone();
    let dir = tempfile::tempdir().expect("tempdir");
    let (short, long) = (dir.path().join("short.mcap"), dir.path().join("long.mcap"));
    write_log(&short, 150);
    write_log(&long, 1500);
    let long_bytes = std::fs::metadata(&long).expect("size").len();
    let (peak_short, n_short) = peak_while_reading(&short);
    let (peak_long, n_long) = peak_while_reading(&long);
    assert_eq!((n_short, n_long), (150, 1500));
    eprintln!(
        "peak heap while reading: {:.2} MB (150 frames), {:.2} MB (1500 frames, file {:.1} MB)",
        peak_short as f64 / 1e6,
        peak_long as f64 / 1e6,
        long_bytes as f64 / 1e6
    );
    assert!(
        peak_long as f64 <= 1.25 * peak_short as f64 + 256e3,
        "peak grew from {peak_short} to {peak_long} bytes"
    );
    assert!(
        (peak_long as u64) < long_bytes / 5,
        "reading must not hold the file in memory"
    );
}

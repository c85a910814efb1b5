//! Nearest-stamp joins between topics, with a stated tolerance.
//!
//! Real logs differ in which clock is trustworthy: header stamps can sit 130 s ahead of log
//! time (a robot whose clock was never synchronised), or lag it by the driver's latency. So
//! every join says which [`TimeBase`] it uses; [`header_stamp`] reads the stamp of any decoded
//! message (ROS `header.stamp` or Foxglove `timestamp`).

use super::value::Value;
use crate::time::Nanos;

/// Which time a join compares.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TimeBase {
    /// MCAP log time (when the recorder received the message).
    LogTime,
    /// The message's own header stamp (when the sensor measured).
    HeaderStamp,
}

/// Index into `sorted` of the time nearest to `t`, if it is within `tolerance_ns`.
/// Ties go to the earlier time. `sorted` must be non-decreasing.
pub fn nearest(sorted: &[Nanos], t: Nanos, tolerance_ns: u64) -> Option<usize> {
    debug_assert!(
        sorted.windows(2).all(|w| w[0] <= w[1]),
        "times must be sorted"
    );
    let i = sorted.partition_point(|s| *s < t);
    let before = i.checked_sub(1);
    let after = (i < sorted.len()).then_some(i);
    let best = match (before, after) {
        (Some(b), Some(a)) => {
            if t.abs_diff(sorted[b]) <= sorted[a].abs_diff(t) {
                b
            } else {
                a
            }
        }
        (Some(b), None) => b,
        (None, Some(a)) => a,
        (None, None) => return None,
    };
    (sorted[best].abs_diff(t) <= tolerance_ns).then_some(best)
}

/// For each time in `left`, the index of the nearest time in `right` within `tolerance_ns`.
pub fn join_nearest(left: &[Nanos], right: &[Nanos], tolerance_ns: u64) -> Vec<Option<usize>> {
    left.iter()
        .map(|t| nearest(right, *t, tolerance_ns))
        .collect()
}

/// The stamp of a decoded message: `header.stamp` (ROS) or `timestamp` (Foxglove).
pub fn header_stamp(v: &Value) -> Option<Nanos> {
    let stamp = v
        .get("header")
        .and_then(|h| h.get("stamp"))
        .or_else(|_| v.get("timestamp"))
        .ok()?;
    let sec = stamp
        .get("sec")
        .or_else(|_| stamp.get("seconds"))
        .ok()?
        .as_i128()
        .ok()?;
    let nsec = stamp
        .get("nanosec")
        .or_else(|_| stamp.get("nanos"))
        .or_else(|_| stamp.get("nsec"))
        .ok()?
        .as_i128()
        .ok()?;
    Nanos::from_stamp(i32::try_from(sec).ok()?, u32::try_from(nsec).ok()?)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ns(v: &[u64]) -> Vec<Nanos> {
        v.iter().map(|x| Nanos(*x)).collect()
    }

    #[test]
    fn nearest_respects_tolerance_and_ties() {
        let right = ns(&[10, 20, 30]);
        assert_eq!(nearest(&right, Nanos(14), 5), Some(0));
        assert_eq!(nearest(&right, Nanos(15), 5), Some(0)); // tie -> earlier
        assert_eq!(nearest(&right, Nanos(16), 5), Some(1));
        assert_eq!(nearest(&right, Nanos(36), 5), None);
        assert_eq!(nearest(&right, Nanos(0), 10), Some(0));
        assert_eq!(nearest(&[], Nanos(0), 10), None);
        assert_eq!(
            join_nearest(&ns(&[9, 25, 100]), &right, 4),
            vec![Some(0), None, None]
        );
    }

    #[test]
    fn header_stamp_reads_ros_and_foxglove_shapes() {
        use crate::log::value::record;
        let ros = record([(
            "header",
            record([(
                "stamp",
                record([("sec", Value::I32(2)), ("nanosec", Value::U32(5))]),
            )]),
        )]);
        assert_eq!(header_stamp(&ros), Some(Nanos(2_000_000_005)));
        let fox = record([(
            "timestamp",
            record([("seconds", Value::I64(1)), ("nanos", Value::I32(7))]),
        )]);
        assert_eq!(header_stamp(&fox), Some(Nanos(1_000_000_007)));
        assert_eq!(header_stamp(&Value::I32(1)), None);
    }
}

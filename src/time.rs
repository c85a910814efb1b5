//! Time as the logs carry it: `u64` nanoseconds since the Unix epoch (MCAP log and publish
//! times), and conversions from ROS `builtin_interfaces/Time` stamps.

use std::fmt;

use serde::{Deserialize, Serialize};

/// A point in time in nanoseconds (MCAP log time, or a header stamp converted).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize,
)]
#[serde(transparent)]
pub struct Nanos(pub u64);

impl Nanos {
    pub const NANOS_PER_SEC: u64 = 1_000_000_000;

    pub fn as_secs_f64(self) -> f64 {
        (self.0 / Self::NANOS_PER_SEC) as f64 + (self.0 % Self::NANOS_PER_SEC) as f64 * 1e-9
    }

    /// Nearest nanosecond; negative and non-finite inputs give zero.
    pub fn from_secs_f64(s: f64) -> Nanos {
        if s.is_finite() && s > 0.0 {
            let whole = s.trunc();
            Nanos(whole as u64 * Self::NANOS_PER_SEC + ((s - whole) * 1e9).round() as u64)
        } else {
            Nanos(0)
        }
    }

    /// `self - other` in nanoseconds, signed.
    pub fn signed_sub(self, other: Nanos) -> i64 {
        (i128::from(self.0) - i128::from(other.0)).clamp(i64::MIN.into(), i64::MAX.into()) as i64
    }

    pub fn abs_diff(self, other: Nanos) -> u64 {
        self.0.abs_diff(other.0)
    }

    /// From a ROS stamp (`sec`, `nanosec`); `None` for stamps before the epoch or with
    /// `nanosec` ≥ 10⁹.
    pub fn from_stamp(sec: i32, nanosec: u32) -> Option<Nanos> {
        if sec < 0 || u64::from(nanosec) >= Self::NANOS_PER_SEC {
            return None;
        }
        Some(Nanos(sec as u64 * Self::NANOS_PER_SEC + u64::from(nanosec)))
    }

    /// As a ROS stamp; saturates at the largest `int32` second.
    pub fn to_stamp(self) -> (i32, u32) {
        let sec = (self.0 / Self::NANOS_PER_SEC).min(i32::MAX as u64) as i32;
        (sec, (self.0 % Self::NANOS_PER_SEC) as u32)
    }
}

impl fmt::Display for Nanos {
    /// Seconds with all nine decimals, e.g. `1403024474.605089680`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}.{:09}",
            self.0 / Self::NANOS_PER_SEC,
            self.0 % Self::NANOS_PER_SEC
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_and_conversions() {
        let t = Nanos(1_403_024_474_605_089_680);
        assert_eq!(t.to_string(), "1403024474.605089680");
        assert_eq!(Nanos::from_stamp(1_403_024_474, 605_089_680), Some(t));
        assert_eq!(t.to_stamp(), (1_403_024_474, 605_089_680));
        assert_eq!(Nanos::from_stamp(-1, 0), None);
        assert_eq!(Nanos::from_secs_f64(1.5), Nanos(1_500_000_000));
        assert_eq!(Nanos(5).signed_sub(Nanos(7)), -2);
    }
}

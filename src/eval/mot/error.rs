//! The one error type of the `mot` module. File errors name the file and the 1-based line;
//! errors in observations handed over in memory name the side, the frame and the id.

use std::fmt;
use std::path::PathBuf;

/// Which of the two inputs an observation came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    GroundTruth,
    Hypothesis,
}

impl fmt::Display for Side {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Side::GroundTruth => "ground truth",
            Side::Hypothesis => "hypothesis",
        })
    }
}

/// What went wrong while reading tracks or scoring them.
#[derive(Debug, thiserror::Error)]
pub enum MotError {
    #[error(
        "{}:{line}: {found} columns; a MOTChallenge row has {expected} (frame,id,bb_left,bb_top,bb_width,bb_height,conf,x,y,z)",
        path.display()
    )]
    ColumnCount {
        path: PathBuf,
        line: usize,
        found: usize,
        expected: &'static str,
    },
    #[error("{}:{line}: column `{column}` is `{value}`, not {wanted}", path.display())]
    BadNumber {
        path: PathBuf,
        line: usize,
        column: &'static str,
        value: String,
        wanted: &'static str,
    },
    #[error("{}:{line}: `{column}` is {value}; a box size cannot be negative", path.display())]
    NegativeSize {
        path: PathBuf,
        line: usize,
        column: &'static str,
        value: f64,
    },
    #[error("{}:{line}: frame {frame} has id {id} a second time (first on line {first_line})", path.display())]
    DuplicateRow {
        path: PathBuf,
        line: usize,
        first_line: usize,
        frame: i64,
        id: i64,
    },
    #[error(
        "{}: no row has ground-plane coordinates (x and y are -1 on every row); metre matching reads x,y in metres from columns 8 and 9",
        path.display()
    )]
    NoGroundPlane { path: PathBuf },
    #[error("{side} frame {frame}: id {id} appears more than once")]
    DuplicateId { side: Side, frame: i64, id: i64 },
    #[error("{side} frame {frame} id {id}: {rule} matching needs {expected}, not {found}")]
    WrongGeometry {
        side: Side,
        frame: i64,
        id: i64,
        rule: &'static str,
        expected: &'static str,
        found: &'static str,
    },
    #[error("{side} frame {frame} id {id}: a coordinate or the confidence is not finite")]
    NonFinite { side: Side, frame: i64, id: i64 },
    #[error("{side}: more than 2³² − 1 observations")]
    TooLarge { side: Side },
    #[error("{rule} threshold {value} is out of range: {allowed}")]
    BadThreshold {
        rule: &'static str,
        value: f64,
        allowed: &'static str,
    },
}

//! MOTChallenge CSV text: `frame,id,bb_left,bb_top,bb_width,bb_height,conf,x,y,z`, one row
//! per object per frame (Milan et al., "MOT16", arXiv:1603.00831, §3.3).
//!
//! - Boxes ([`GeometryKind::Box`]): columns 3–6 in pixels; 6 to 10 columns are accepted
//!   (a missing `conf` reads as 1). Other columns are ignored, so MOT16/17 ground truth
//!   (`conf, class, visibility` in 7–9) reads too, unfiltered.
//! - Ground-plane points ([`GeometryKind::Point`]): columns 8 and 9 (`x`, `y`) in metres, as
//!   in MOT15's 3-D files; 9 or 10 columns; the box columns are ignored (may be −1). A file in
//!   which every row has x = y = −1 (the 2-D files' "unused") is refused.
//! - Fields are separated by commas (spaces around them allowed) or, in a row without
//!   commas, by whitespace, as motmetrics reads them. `frame` and `id` are integers
//!   (`12` or `12.0`). Blank lines are skipped. Any other bad row is an error naming the
//!   file and 1-based line, as is a second row for the same frame and id.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;

use super::{BoxPx, Geometry, GeometryKind, GroundPoint, MotError, Observation};

const COLUMNS: [&str; 10] = [
    "frame",
    "id",
    "bb_left",
    "bb_top",
    "bb_width",
    "bb_height",
    "conf",
    "x",
    "y",
    "z",
];

/// Parse MOTChallenge CSV text; `path` only names the source in errors.
///
/// Rows in the canonical form (comma-separated, no spaces, plain decimal numbers, finite and
/// valid) take a byte-level path that never splits a row into strings; any other row takes
/// the general path, which accepts exactly what the module doc says and names the file,
/// line and column of what it refuses. Both paths give the same values (numbers are
/// correctly rounded either way).
pub fn parse_motchallenge(
    text: &str,
    path: &Path,
    kind: GeometryKind,
) -> Result<Vec<Observation>, MotError> {
    let min_cols = match kind {
        GeometryKind::Box => 6,
        GeometryKind::Point => 9,
    };
    // A rough row count, to grow the table once or twice rather than a dozen times.
    let mut out = Vec::with_capacity(text.len() / 48);
    let mut any_ground_plane = false;
    let bytes = text.as_bytes();
    let (mut pos, mut line) = (0, 0);
    while pos < bytes.len() {
        line += 1;
        let parsed = match fast_row(bytes, pos, kind, min_cols) {
            Some((o, next)) => {
                pos = next;
                Some(o)
            }
            None => {
                let end = bytes[pos..]
                    .iter()
                    .position(|&b| b == b'\n')
                    .map_or(bytes.len(), |k| pos + k);
                let raw = &text[pos..end];
                pos = end + 1;
                match parse_row(raw.strip_suffix('\r').unwrap_or(raw), path, line, kind) {
                    Ok(o) => o,
                    // A duplicate on an earlier line is the first error in the file.
                    Err(e) => return Err(duplicate_error(&out, text, path).unwrap_or(e)),
                }
            }
        };
        if let Some(o) = parsed {
            if let Geometry::Point(p) = o.geometry {
                any_ground_plane |= !(p.x_m == -1.0 && p.y_m == -1.0);
            }
            out.push(o);
        }
    }
    if has_duplicates(&out)
        && let Some(e) = duplicate_error(&out, text, path)
    {
        return Err(e);
    }
    if kind == GeometryKind::Point && !out.is_empty() && !any_ground_plane {
        return Err(MotError::NoGroundPlane {
            path: path.to_path_buf(),
        });
    }
    Ok(out)
}

/// What a column holds for one kind of file.
#[derive(Clone, Copy, PartialEq)]
enum Role {
    Integer,
    Number,
    Ignored,
}

fn role(kind: GeometryKind, column: usize) -> Role {
    match (kind, column) {
        (_, 0 | 1) => Role::Integer,
        (_, 6) | (GeometryKind::Box, 2..=5) | (GeometryKind::Point, 7 | 8) => Role::Number,
        _ => Role::Ignored,
    }
}

/// The row starting at `pos` if it is in the canonical form, and where the next row starts;
/// `None` sends the row to [`parse_row`] (anything unusual, including every error).
fn fast_row(
    bytes: &[u8],
    mut pos: usize,
    kind: GeometryKind,
    min_cols: usize,
) -> Option<(Observation, usize)> {
    let mut ints = [0i64; 2];
    let mut nums = [0.0f64; COLUMNS.len()];
    let mut n = 0;
    loop {
        if n == COLUMNS.len() {
            return None;
        }
        match role(kind, n) {
            Role::Integer => {
                let (v, next) = fast_integer(bytes, pos)?;
                ints[n] = v;
                pos = next;
            }
            Role::Number => {
                // '+', '.', "inf", "nan" and the like go the general way.
                if !matches!(bytes.get(pos), Some(b'-' | b'0'..=b'9')) {
                    return None;
                }
                let (v, used) = fast_float2::parse_partial::<f64, _>(&bytes[pos..]).ok()?;
                if used == 0 || !v.is_finite() {
                    return None;
                }
                nums[n] = v;
                pos += used;
            }
            Role::Ignored => {
                while !matches!(bytes.get(pos), None | Some(b',' | b'\n')) {
                    pos += 1;
                }
            }
        }
        n += 1;
        match bytes.get(pos) {
            Some(b',') => pos += 1,
            Some(b'\n') => {
                pos += 1;
                break;
            }
            Some(b'\r') if bytes.get(pos + 1) == Some(&b'\n') => {
                pos += 2;
                break;
            }
            None => break,
            Some(_) => return None,
        }
    }
    if n < min_cols {
        return None;
    }
    let geometry = match kind {
        GeometryKind::Box => {
            if nums[4] < 0.0 || nums[5] < 0.0 {
                return None;
            }
            Geometry::Box(BoxPx {
                left_px: nums[2],
                top_px: nums[3],
                width_px: nums[4],
                height_px: nums[5],
            })
        }
        GeometryKind::Point => Geometry::Point(GroundPoint {
            x_m: nums[7],
            y_m: nums[8],
        }),
    };
    let o = Observation {
        frame: ints[0],
        id: ints[1],
        geometry,
        confidence: if n > 6 { nums[6] } else { 1.0 },
    };
    Some((o, pos))
}

/// `-?[0-9]{1,18}` at `pos` (anything else, such as `12.0`, goes the general way).
fn fast_integer(bytes: &[u8], mut pos: usize) -> Option<(i64, usize)> {
    let negative = bytes.get(pos) == Some(&b'-');
    pos += negative as usize;
    let start = pos;
    let mut v: i64 = 0;
    while let Some(&b @ b'0'..=b'9') = bytes.get(pos) {
        if pos - start == 18 {
            return None;
        }
        v = v * 10 + (b - b'0') as i64;
        pos += 1;
    }
    (pos > start).then_some((if negative { -v } else { v }, pos))
}

/// One row by the general rules (`raw` without its line break): `None` for a blank line.
fn parse_row<'a>(
    raw: &'a str,
    path: &Path,
    line: usize,
    kind: GeometryKind,
) -> Result<Option<Observation>, MotError> {
    let (min_cols, expected) = match kind {
        GeometryKind::Box => (6, "6 to 10"),
        GeometryKind::Point => (9, "9 or 10 for ground-plane points"),
    };
    let row = raw.trim();
    if row.is_empty() {
        return Ok(None);
    }
    let mut fields = [""; COLUMNS.len()];
    let mut n = 0;
    let mut take = |f: &'a str| {
        if let Some(slot) = fields.get_mut(n) {
            *slot = f;
        }
        n += 1;
    };
    if row.contains(',') {
        row.split(',').map(str::trim).for_each(&mut take);
    } else {
        row.split_whitespace().for_each(&mut take);
    }
    if n < min_cols || n > COLUMNS.len() {
        return Err(MotError::ColumnCount {
            path: path.to_path_buf(),
            line,
            found: n,
            expected,
        });
    }
    let integer = |c: usize| {
        parse_integer(fields[c]).ok_or_else(|| bad(path, line, c, fields[c], "an integer"))
    };
    let number = |c: usize| {
        parse_finite(fields[c]).ok_or_else(|| bad(path, line, c, fields[c], "a finite number"))
    };
    let frame = integer(0)?;
    let id = integer(1)?;
    let confidence = if n > 6 { number(6)? } else { 1.0 };
    let geometry = match kind {
        GeometryKind::Box => {
            let (width_px, height_px) = (number(4)?, number(5)?);
            for (c, v) in [(4, width_px), (5, height_px)] {
                if v < 0.0 {
                    return Err(MotError::NegativeSize {
                        path: path.to_path_buf(),
                        line,
                        column: COLUMNS[c],
                        value: v,
                    });
                }
            }
            Geometry::Box(BoxPx {
                left_px: number(2)?,
                top_px: number(3)?,
                width_px,
                height_px,
            })
        }
        GeometryKind::Point => Geometry::Point(GroundPoint {
            x_m: number(7)?,
            y_m: number(8)?,
        }),
    };
    Ok(Some(Observation {
        frame,
        id,
        geometry,
        confidence,
    }))
}

/// Whether some (frame, id) occurs twice. Files are usually in frame order: then each
/// frame's ids are checked on their own; otherwise all keys are sorted.
fn has_duplicates(rows: &[Observation]) -> bool {
    let mut ids: Vec<i64> = Vec::new();
    if rows.is_sorted_by_key(|o| o.frame) {
        rows.chunk_by(|a, b| a.frame == b.frame).any(|run| {
            // ids written in ascending order (as most writers do) cannot repeat
            if run.is_sorted_by(|a, b| a.id < b.id) {
                return false;
            }
            ids.clear();
            ids.extend(run.iter().map(|o| o.id));
            ids.sort_unstable();
            ids.windows(2).any(|w| w[0] == w[1])
        })
    } else {
        let mut keys: Vec<(i64, i64)> = rows.iter().map(|o| (o.frame, o.id)).collect();
        keys.sort_unstable();
        keys.windows(2).any(|w| w[0] == w[1])
    }
}

/// The 1-based lines of the rows of `text`: its lines that are not blank (every other line
/// is a row or an error), found again only when an error needs them.
fn row_lines(text: &str) -> impl Iterator<Item = usize> + '_ {
    text.split('\n')
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(k, _)| k + 1)
}

/// The first line (in file order) that repeats an earlier row's (frame, id), if any, among
/// `rows`, the first rows of `text`.
fn duplicate_error(rows: &[Observation], text: &str, path: &Path) -> Option<MotError> {
    let mut first_line: HashMap<(i64, i64), usize> = HashMap::with_capacity(rows.len());
    for (o, line) in rows.iter().zip(row_lines(text)) {
        if let Some(&first) = first_line.get(&(o.frame, o.id)) {
            return Some(MotError::DuplicateRow {
                path: path.to_path_buf(),
                line,
                first_line: first,
                frame: o.frame,
                id: o.id,
            });
        }
        first_line.insert((o.frame, o.id), line);
    }
    None
}

/// MOTChallenge CSV text, one row per observation in the given order; unused columns are
/// −1 (boxes: x, y, z; points: the box and z). Numbers are written in Rust's shortest
/// round-trip form, so [`parse_motchallenge`] reads back the same values.
pub fn write_motchallenge(observations: &[Observation]) -> String {
    let mut s = String::with_capacity(observations.len() * 48);
    for o in observations {
        // Writing to a String cannot fail.
        let _ = match o.geometry {
            Geometry::Box(b) => writeln!(
                s,
                "{},{},{},{},{},{},{},-1,-1,-1",
                o.frame, o.id, b.left_px, b.top_px, b.width_px, b.height_px, o.confidence
            ),
            Geometry::Point(p) => writeln!(
                s,
                "{},{},-1,-1,-1,-1,{},{},{},-1",
                o.frame, o.id, o.confidence, p.x_m, p.y_m
            ),
        };
    }
    s
}

fn bad(path: &Path, line: usize, column: usize, value: &str, wanted: &'static str) -> MotError {
    MotError::BadNumber {
        path: path.to_path_buf(),
        line,
        column: COLUMNS[column],
        value: value.to_string(),
        wanted,
    }
}

fn parse_finite(s: &str) -> Option<f64> {
    s.parse::<f64>().ok().filter(|v| v.is_finite())
}

/// `12`, or a float with no fractional part such as `12.0` (some trackers write ids so).
fn parse_integer(s: &str) -> Option<i64> {
    if let Ok(v) = s.parse::<i64>() {
        return Some(v);
    }
    let v = parse_finite(s)?;
    // 2^63 as f64; anything at or beyond it does not fit an i64.
    const LIMIT: f64 = 9_223_372_036_854_775_808.0;
    (v.fract() == 0.0 && v.abs() < LIMIT).then_some(v as i64)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str, kind: GeometryKind) -> Result<Vec<Observation>, MotError> {
        parse_motchallenge(text, Path::new("runs/hyp.txt"), kind)
    }

    /// The error message, which must name the file and the line.
    fn err(text: &str, kind: GeometryKind) -> String {
        match parse(text, kind) {
            Ok(v) => panic!("parsed {v:?}"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn reads_2d_rows_in_both_separators() {
        let text = "1,3,113.84,274.5,57.307,130.05,-1,-1,-1,-1\n\n2 4 1 2 3 4 0.5 -1 -1 -1\n";
        let v = parse(text, GeometryKind::Box).expect("valid test input");
        assert_eq!(v.len(), 2);
        assert_eq!((v[0].frame, v[0].id, v[0].confidence), (1, 3, -1.0));
        assert_eq!(
            v[0].geometry,
            Geometry::Box(BoxPx {
                left_px: 113.84,
                top_px: 274.5,
                width_px: 57.307,
                height_px: 130.05
            })
        );
        assert_eq!((v[1].frame, v[1].id, v[1].confidence), (2, 4, 0.5));
    }

    #[test]
    fn short_rows_and_float_ids() {
        let v = parse("7.0, 2.0, 1, 2, 3, 4\n", GeometryKind::Box).expect("valid test input");
        assert_eq!((v[0].frame, v[0].id, v[0].confidence), (7, 2, 1.0));
    }

    #[test]
    fn reads_ground_plane_points_from_x_y() {
        let v = parse("1,1,-1,-1,-1,-1,1,2.5,-0.75,0\n", GeometryKind::Point)
            .expect("valid test input");
        assert_eq!(
            v[0].geometry,
            Geometry::Point(GroundPoint {
                x_m: 2.5,
                y_m: -0.75
            })
        );
    }

    #[test]
    fn errors_name_file_and_line() {
        let ok = "1,1,0,0,10,10,1,-1,-1,-1\n";
        let cases: &[(String, GeometryKind, &str)] = &[
            (
                format!("{ok}1,2,0,0,10\n"),
                GeometryKind::Box,
                "runs/hyp.txt:2: 5 columns",
            ),
            (
                format!("{ok}{ok}"),
                GeometryKind::Box,
                "runs/hyp.txt:2: frame 1 has id 1 a second time (first on line 1)",
            ),
            (
                format!("{ok}\n1,x,0,0,10,10\n"),
                GeometryKind::Box,
                "runs/hyp.txt:3: column `id` is `x`, not an integer",
            ),
            (
                "1,1.5,0,0,1,1\n".into(),
                GeometryKind::Box,
                "runs/hyp.txt:1: column `id` is `1.5`",
            ),
            (
                "1,1,0,0,NaN,1\n".into(),
                GeometryKind::Box,
                "runs/hyp.txt:1: column `bb_width` is `NaN`, not a finite number",
            ),
            (
                "1,1,0,0,1,inf\n".into(),
                GeometryKind::Box,
                "column `bb_height` is `inf`",
            ),
            (
                "1,1,0,0,-3,1\n".into(),
                GeometryKind::Box,
                "runs/hyp.txt:1: `bb_width` is -3; a box size cannot be negative",
            ),
            (
                "1,1,0,0,1,1,,-1,-1,-1\n".into(),
                GeometryKind::Box,
                "runs/hyp.txt:1: column `conf` is ``",
            ),
            (
                "1,1,0,0,1,1,1,2,3,4,5\n".into(),
                GeometryKind::Box,
                "runs/hyp.txt:1: 11 columns",
            ),
            (
                "1,1,0,0,1,1,1\n".into(),
                GeometryKind::Point,
                "runs/hyp.txt:1: 7 columns; a MOTChallenge row has 9 or 10",
            ),
            (
                "1,1,0,0,1,1,1,a,0\n".into(),
                GeometryKind::Point,
                "runs/hyp.txt:1: column `x` is `a`",
            ),
            (
                "1,1,0,0,9,9,1,-1,-1,-1\n2,1,0,0,9,9,1,-1,-1,-1\n".into(),
                GeometryKind::Point,
                "runs/hyp.txt: no row has ground-plane coordinates",
            ),
            (
                "99999999999999999999,1,0,0,1,1\n".into(),
                GeometryKind::Box,
                "column `frame` is `99999999999999999999`",
            ),
        ];
        for (text, kind, want) in cases {
            let got = err(text, *kind);
            assert!(got.contains(want), "{text:?}: got `{got}`, want `{want}`");
        }
    }

    /// Every row the byte-level path accepts, the general path reads to the same bits.
    #[test]
    fn fast_rows_equal_general_rows() {
        let rows = [
            "1,3,113.84,274.5,57.307,130.05,-1,-1,-1,-1",
            "2,-4,0.1,2,3,4",
            "2,4,1e3,-2.5E-3,0.30000000000000004,1.7976931348623157e308,0.5",
            "7,1,-0,5.,1.e2,00012.5000,1,a,b,c",
            "999999999999999999,-999999999999999999,1,1,1,1,1,,,",
            "3,1,-1,-1,-1,-1,1,2.5,-0.75,0",
            "3,1,1,1,1,1,1,2.5,-0.75",
        ];
        let mut fast = 0;
        for kind in [GeometryKind::Box, GeometryKind::Point] {
            let min_cols = if kind == GeometryKind::Box { 6 } else { 9 };
            for row in rows {
                for end in ["", "\n", "\r\n"] {
                    let text = format!("{row}{end}");
                    let general = parse_row(row, Path::new("x"), 1, kind);
                    let Some((o, next)) = fast_row(text.as_bytes(), 0, kind, min_cols) else {
                        continue;
                    };
                    fast += 1;
                    assert_eq!(next, text.len(), "{text:?}");
                    let g = general.expect("the general path reads it").expect("a row");
                    assert_eq!(format!("{o:?}"), format!("{g:?}"), "{text:?}");
                }
            }
        }
        assert!(fast >= 15, "{fast} rows took the fast path");
        // Not canonical: the general path decides (and may accept).
        for row in [
            "1, 2,0,0,1,1",
            "1 2 0 0 1 1",
            "+1,2,0,0,1,1",
            "1,2,.5,0,1,1",
            "1,2.0,0,0,1,1",
        ] {
            assert!(
                fast_row(row.as_bytes(), 0, GeometryKind::Box, 6).is_none(),
                "{row}"
            );
            assert!(parse(row, GeometryKind::Box).is_ok(), "{row}");
        }
    }

    #[test]
    fn the_first_error_in_the_file_is_reported() {
        // A duplicate on line 2 comes before a bad number on line 3 ...
        let text = "1,1,0,0,1,1\n1,1,0,0,1,1\n1,2,0,0,x,1\n";
        assert!(err(text, GeometryKind::Box).contains("hyp.txt:2: frame 1 has id 1 a second time"));
        // ... and, in a file out of frame order, the earliest repeat names its first line.
        let text = "2,5,0,0,1,1\n1,7,0,0,1,1\n1,8,0,0,1,1\n2,5,0,0,1,1\n1,7,0,0,1,1\n";
        assert!(
            err(text, GeometryKind::Box)
                .contains("hyp.txt:4: frame 2 has id 5 a second time (first on line 1)")
        );
        // Blank and \r\n lines keep the line count.
        let text = "1,1,0,0,1,1\r\n\n  \n1,2,0,0,1,y\n";
        assert!(err(text, GeometryKind::Box).contains("hyp.txt:4: column `bb_height` is `y`"));
    }

    #[test]
    fn write_then_parse_round_trips() {
        let obs = vec![
            Observation {
                frame: 3,
                id: -2,
                geometry: Geometry::Box(BoxPx {
                    left_px: 0.1 + 0.2,
                    top_px: -5.0,
                    width_px: 1e-300,
                    height_px: 123456.789,
                }),
                confidence: 0.25,
            },
            Observation {
                frame: 4,
                id: 7,
                geometry: Geometry::Box(BoxPx {
                    left_px: 1.0,
                    top_px: 2.0,
                    width_px: 3.0,
                    height_px: 4.0,
                }),
                confidence: 1.0,
            },
        ];
        let text = write_motchallenge(&obs);
        assert_eq!(
            parse(&text, GeometryKind::Box).expect("valid test input"),
            obs
        );
        let pts = vec![Observation {
            frame: 1,
            id: 1,
            geometry: Geometry::Point(GroundPoint {
                x_m: 1.0 / 3.0,
                y_m: -2.0,
            }),
            confidence: 1.0,
        }];
        let text = write_motchallenge(&pts);
        assert_eq!(text, "1,1,-1,-1,-1,-1,1,0.3333333333333333,-2,-1\n");
        assert_eq!(
            parse(&text, GeometryKind::Point).expect("valid test input"),
            pts
        );
    }
}

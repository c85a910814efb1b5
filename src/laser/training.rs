//! Training samples for a learned leg detector: scans → segments ([`super::segment`], the
//! default options) → feature vectors ([`super::features`] plus the centroid's range) with a
//! leg / not-leg label.
//!
//! **Real data**: the leg_tracker training CSVs (Leigh et al., ICRA 2015;
//! `../shared/real/laser/leg_training/`), parsed here from text (the caller reads the files):
//! `positive_K_scans.csv` (one scan per line: `scan_idx,bag_time_s,stamp_s,frame_id,
//! angle_min_rad,angle_increment_rad,range_min_m,range_max_m,n,r_0..r_{n-1}`),
//! `positive_K_legs.csv` (`scan_idx,x_m,y_m`: labelled leg-cluster centroids in the scan frame)
//! and `negative_K_scans.csv` (people-free scans). Lines starting with `#` are headers.
//!
//! What carries over from leg_tracker's `train_leg_detector.cpp` (read, not copied):
//!
//! - **positives** are the clusters of a positive scan whose centroid coincides with a label
//!   (leg_tracker: within 0.1 mm, because its labels are the centroids of its own clusters —
//!   Euclidean clustering at 0.13 m, ≥ 3 points). Our segments (jump distance 0.1 m) can cut a
//!   cluster slightly differently, so here each label takes the **nearest** segment whose
//!   centroid lies within [`LABEL_MATCH_M`] of it;
//! - the **other segments of positive scans are not used** (leg_tracker ignores them: its
//!   labels only cover a ±15° wedge within 5 m, so an unlabelled cluster may still be a leg);
//! - **negatives** are all segments of the people-free scans, under-sampled: leg_tracker keeps
//!   each cluster with probability 1/50 (`undersample_negative_factor`, `rand()`); here every
//!   `keep_every`-th segment in file order is kept (deterministic, the same rate).
//!
//! **Synthetic data** ([`label_synthetic`]): a segment is a leg when its centroid lies within
//! the leg radius + [`LABEL_MATCH_M`] of a ground-truth leg centre (the nearest segment per
//! leg), not a leg when it lies farther than [`PERSON_CLEAR_M`] from every leg and within the
//! range limit (5 m, the range of the real labels); segments in between are left out.

use nalgebra::Point2;

use serde::{Deserialize, Serialize};

use super::features::{self, FEATURE_NAMES, LEG_TRACKER_FEATURE_NAMES};
use super::points::{self, ScanGeometry, ScanPoint};
use super::segment::{self, Segment, SegmentOptions};

/// Most distance (m) between a label and the centroid of the segment it labels: below half
/// the spacing of two legs side by side (≈ 0.2 m centre to centre), above the shift of a
/// centroid when a segment gains or loses an end point.
pub const LABEL_MATCH_M: f64 = 0.1;

/// Synthetic negatives lie farther than this (m) from every ground-truth leg centre.
pub const PERSON_CLEAR_M: f64 = 0.5;

/// Feature names of a sample: [`FEATURE_NAMES`] then the centroid's range.
pub fn sample_feature_names() -> Vec<&'static str> {
    let mut v = FEATURE_NAMES.to_vec();
    v.push("range");
    v
}

/// Which features a sample carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FeatureSet {
    /// The 11 features of [`features::compute`] and the centroid's range (12).
    #[default]
    Segment,
    /// leg_tracker's 17 cluster features ([`features::leg_tracker_features`]).
    LegTracker,
}

impl FeatureSet {
    /// The names, in vector order.
    pub fn names(self) -> Vec<&'static str> {
        match self {
            FeatureSet::Segment => sample_feature_names(),
            FeatureSet::LegTracker => LEG_TRACKER_FEATURE_NAMES.to_vec(),
        }
    }

    /// The feature vector of segment `i` of a segmented scan (`None`: the set is undefined on
    /// it, e.g. leg_tracker's on fewer than 3 points).
    pub fn of(self, s: &Segmented, i: usize) -> Option<Vec<f64>> {
        match self {
            FeatureSet::Segment => Some(sample_features(s, i)),
            FeatureSet::LegTracker => {
                features::leg_tracker_features(&s.points, &s.segments[i], &s.geometry, &s.ranges)
                    .map(|f| f.to_vec())
            }
        }
    }
}

/// Why a training file does not parse.
#[derive(Debug, thiserror::Error)]
pub enum TrainingError {
    #[error("{file}:{line}: {why}")]
    Line {
        file: String,
        line: usize,
        why: String,
    },
}

/// One scan of a training file.
#[derive(Debug, Clone, PartialEq)]
pub struct ScanRecord {
    pub scan_idx: usize,
    pub frame_id: String,
    pub geometry: ScanGeometry,
    pub ranges: Vec<f32>,
}

/// A labelled segment.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// The file (or file and laser) it comes from: the unit of cross-validation.
    pub group: String,
    pub scan_idx: usize,
    /// In [`sample_feature_names`] order.
    pub features: Vec<f64>,
    pub range_m: f64,
    pub leg: bool,
}

fn bad(file: &str, line: usize, why: impl Into<String>) -> TrainingError {
    TrainingError::Line {
        file: file.to_string(),
        line,
        why: why.into(),
    }
}

/// Data lines of a CSV text: `(1-based line number, fields)`, headers and blank lines skipped.
fn data_lines(text: &str) -> impl Iterator<Item = (usize, Vec<&str>)> {
    text.lines().enumerate().filter_map(|(i, l)| {
        let l = l.trim();
        (!l.is_empty() && !l.starts_with('#'))
            .then(|| (i + 1, l.split(',').map(str::trim).collect()))
    })
}

fn num<T: std::str::FromStr>(
    file: &str,
    line: usize,
    what: &str,
    s: &str,
) -> Result<T, TrainingError> {
    s.parse()
        .map_err(|_| bad(file, line, format!("{what} {s:?} is not a number")))
}

/// The scans of a `*_scans.csv` text (`file` names it in errors).
pub fn parse_scans(text: &str, file: &str) -> Result<Vec<ScanRecord>, TrainingError> {
    data_lines(text)
        .map(|(line, f)| {
            if f.len() < 9 {
                return Err(bad(
                    file,
                    line,
                    format!("{} fields, expected at least 9", f.len()),
                ));
            }
            let n: usize = num(file, line, "n", f[8])?;
            if f.len() != 9 + n {
                return Err(bad(
                    file,
                    line,
                    format!("n = {n} but {} ranges", f.len() - 9),
                ));
            }
            let ranges = f[9..]
                .iter()
                .map(|s| num::<f32>(file, line, "range", s))
                .collect::<Result<Vec<f32>, _>>()?;
            Ok(ScanRecord {
                scan_idx: num(file, line, "scan_idx", f[0])?,
                frame_id: f[3].to_string(),
                geometry: ScanGeometry {
                    angle_min: num(file, line, "angle_min", f[4])?,
                    angle_increment: num(file, line, "angle_increment", f[5])?,
                    range_min: num(file, line, "range_min", f[6])?,
                    range_max: num(file, line, "range_max", f[7])?,
                },
                ranges,
            })
        })
        .collect()
}

/// The labels of a `*_legs.csv` text: `(scan_idx, centroid in the scan frame)`.
pub fn parse_legs(text: &str, file: &str) -> Result<Vec<(usize, Point2<f64>)>, TrainingError> {
    data_lines(text)
        .map(|(line, f)| {
            if f.len() != 3 {
                return Err(bad(file, line, format!("{} fields, expected 3", f.len())));
            }
            Ok((
                num(file, line, "scan_idx", f[0])?,
                Point2::new(num(file, line, "x", f[1])?, num(file, line, "y", f[2])?),
            ))
        })
        .collect()
}

/// A scan's returns, segments (default options) and each segment's sensor-frame centroid,
/// with the ranges and beam geometry they came from.
pub struct Segmented {
    pub points: Vec<ScanPoint>,
    pub segments: Vec<Segment>,
    pub centroids: Vec<Point2<f64>>,
    pub geometry: ScanGeometry,
    pub ranges: Vec<f32>,
}

/// Project and segment one scan (sensor frame).
pub fn segment_scan(ranges: &[f32], geometry: &ScanGeometry) -> Segmented {
    let points = points::project(ranges, geometry, None);
    let segments = segment::segment(&points, &SegmentOptions::default());
    let centroids = segments.iter().map(|s| centroid(&points, s)).collect();
    Segmented {
        points,
        segments,
        centroids,
        geometry: *geometry,
        ranges: ranges.to_vec(),
    }
}

/// The mean of a segment's sensor-frame points (origin for an empty one).
pub fn centroid(points: &[ScanPoint], s: &Segment) -> Point2<f64> {
    let seg = points.get(s.points.clone()).unwrap_or(&[]);
    if seg.is_empty() {
        return Point2::origin();
    }
    Point2::from(
        seg.iter()
            .map(|p| p.sensor.coords)
            .sum::<nalgebra::Vector2<f64>>()
            / seg.len() as f64,
    )
}

/// The feature vector of segment `i` of a segmented scan.
pub fn sample_features(s: &Segmented, i: usize) -> Vec<f64> {
    let mut v = features::compute(&s.points, &s.segments[i]).to_vec();
    v.push(s.centroids[i].coords.norm());
    v
}

/// Which segments the labels mark: each label takes the nearest centroid within `max_m`
/// (ties: the first segment).
pub fn match_labels(centroids: &[Point2<f64>], labels: &[Point2<f64>], max_m: f64) -> Vec<bool> {
    let mut hit = vec![false; centroids.len()];
    for l in labels {
        let best = centroids
            .iter()
            .enumerate()
            .map(|(i, c)| ((c - l).norm(), i))
            .filter(|(d, _)| *d <= max_m)
            .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        if let Some((_, i)) = best {
            hit[i] = true;
        }
    }
    hit
}

/// Positive samples of one labelled file: the segments its labels mark ([`match_labels`] at
/// [`LABEL_MATCH_M`]); the other segments are not used. Returns the samples and how many
/// labels found no segment.
pub fn positive_samples(
    group: &str,
    scans: &[ScanRecord],
    labels: &[(usize, Point2<f64>)],
    set: FeatureSet,
) -> (Vec<Sample>, usize) {
    let mut out = Vec::new();
    let mut unmatched = 0;
    for scan in scans {
        let mine: Vec<Point2<f64>> = labels
            .iter()
            .filter(|(k, _)| *k == scan.scan_idx)
            .map(|(_, p)| *p)
            .collect();
        if mine.is_empty() {
            continue;
        }
        let s = segment_scan(&scan.ranges, &scan.geometry);
        let hit = match_labels(&s.centroids, &mine, LABEL_MATCH_M);
        unmatched += mine
            .len()
            .saturating_sub(hit.iter().filter(|&&h| h).count());
        for (i, _) in hit.iter().enumerate().filter(|(_, h)| **h) {
            let Some(features) = set.of(&s, i) else {
                continue;
            };
            out.push(Sample {
                group: group.to_string(),
                scan_idx: scan.scan_idx,
                features,
                range_m: s.centroids[i].coords.norm(),
                leg: true,
            });
        }
    }
    (out, unmatched)
}

/// Negative samples of a people-free file: every `keep_every`-th segment in file order (≥ 1),
/// grouped by file and laser (`group/frame_id`).
pub fn negative_samples(
    group: &str,
    scans: &[ScanRecord],
    keep_every: usize,
    set: FeatureSet,
) -> Vec<Sample> {
    let mut out = Vec::new();
    let mut k = 0usize;
    for scan in scans {
        let s = segment_scan(&scan.ranges, &scan.geometry);
        for i in 0..s.segments.len() {
            if k.is_multiple_of(keep_every.max(1))
                && let Some(features) = set.of(&s, i)
            {
                out.push(Sample {
                    group: format!("{group}/{}", scan.frame_id),
                    scan_idx: scan.scan_idx,
                    features,
                    range_m: s.centroids[i].coords.norm(),
                    leg: false,
                });
            }
            k += 1;
        }
    }
    out
}

/// Labels of a synthetic scan's segments from ground-truth legs `(centre, radius)` in the
/// sensor frame (see the module doc): `Some(true)` leg, `Some(false)` not a leg, `None` left
/// out.
pub fn label_synthetic(
    centroids: &[Point2<f64>],
    legs: &[(Point2<f64>, f64)],
    max_range_m: f64,
) -> Vec<Option<bool>> {
    let mut out: Vec<Option<bool>> = centroids
        .iter()
        .map(|c| {
            let clear = legs.iter().all(|(l, _)| (c - l).norm() > PERSON_CLEAR_M);
            (clear && c.coords.norm() <= max_range_m).then_some(false)
        })
        .collect();
    for (l, r) in legs {
        let hit = match_labels(centroids, &[*l], r + LABEL_MATCH_M);
        if let Some(i) = hit.iter().position(|&h| h) {
            out[i] = Some(true);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCANS: &str = "# scan_idx,bag_time_s,stamp_s,frame_id,angle_min_rad,angle_increment_rad,range_min_m,range_max_m,n,ranges_m[n]\n\
        0,1.0,2.0,right_laser,-0.5,0.25,0.03,11,3,1.0,0.0,2.5\n\
        \n\
        4,1.1,2.1,left_laser,0,0.1,0.03,11,2,nan,3\n";

    #[test]
    fn scans_csv_gives_exact_records() {
        let s = parse_scans(SCANS, "t.csv").expect("parse");
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].scan_idx, 0);
        assert_eq!(s[0].frame_id, "right_laser");
        assert_eq!(
            s[0].geometry,
            ScanGeometry {
                angle_min: -0.5,
                angle_increment: 0.25,
                range_min: 0.03,
                range_max: 11.0
            }
        );
        assert_eq!(s[0].ranges, vec![1.0, 0.0, 2.5]);
        assert_eq!(s[1].scan_idx, 4);
        assert!(s[1].ranges[0].is_nan() && s[1].ranges[1] == 3.0);
    }

    #[test]
    fn bad_lines_name_file_and_line() {
        let e = parse_scans("# h\n0,1,2,l,0,0.1,0,11,3,1,2\n", "x.csv").expect_err("short");
        assert_eq!(e.to_string(), "x.csv:2: n = 3 but 2 ranges");
        let e = parse_legs("0,1.0\n", "l.csv").expect_err("fields");
        assert_eq!(e.to_string(), "l.csv:1: 2 fields, expected 3");
        let e = parse_legs("0,a,1\n", "l.csv").expect_err("number");
        assert_eq!(e.to_string(), "l.csv:1: x \"a\" is not a number");
    }

    #[test]
    fn legs_csv_gives_exact_labels() {
        let l =
            parse_legs("# scan_idx,x_m,y_m\n0,1.5,-0.25\n0,2,0.5\n3,0.5,0\n", "l").expect("parse");
        assert_eq!(
            l,
            vec![
                (0, Point2::new(1.5, -0.25)),
                (0, Point2::new(2.0, 0.5)),
                (3, Point2::new(0.5, 0.0))
            ]
        );
    }

    /// A hand-made scan: a wall at 3 m across beams 0..=9 and a 4-beam object at 1 m on beams
    /// 12..=15 (no return on 10, 11). Two segments; a label at the object's centroid marks it,
    /// a label 0.2 m away from everything marks nothing.
    #[test]
    fn labels_match_the_nearest_segment_within_the_distance() {
        let g = ScanGeometry {
            angle_min: -0.08,
            angle_increment: 0.01,
            range_min: 0.03,
            range_max: 11.0,
        };
        let mut ranges = vec![3.0f32; 10];
        ranges.extend([0.0, 0.0, 1.0, 1.0, 1.0, 1.0]);
        let s = segment_scan(&ranges, &g);
        assert_eq!(s.segments.len(), 2);
        let obj = s.centroids[1];
        let expect_x: f64 = (12..16)
            .map(|k| (-0.08 + f64::from(k) * 0.01).cos())
            .sum::<f64>()
            / 4.0;
        assert!((obj.x - expect_x).abs() < 1e-6, "{obj}");
        let label = obj + nalgebra::Vector2::new(0.05, 0.0);
        assert_eq!(
            match_labels(&s.centroids, &[label], LABEL_MATCH_M),
            vec![false, true]
        );
        let far = obj + nalgebra::Vector2::new(0.2, 0.0);
        assert_eq!(
            match_labels(&s.centroids, &[far], LABEL_MATCH_M),
            vec![false, false]
        );
        // one file's samples: the object is the positive, the wall is not used
        let scans = vec![ScanRecord {
            scan_idx: 7,
            frame_id: "l".into(),
            geometry: g,
            ranges: ranges.clone(),
        }];
        let (pos, unmatched) = positive_samples(
            "p1",
            &scans,
            &[(7, label), (7, far), (8, label)],
            FeatureSet::Segment,
        );
        assert_eq!(unmatched, 1);
        assert_eq!(pos.len(), 1);
        assert_eq!(pos[0].features[0], 4.0); // four points
        assert_eq!(pos[0].features.len(), sample_feature_names().len());
        // negatives: both segments, then every second one
        assert_eq!(
            negative_samples("n", &scans, 1, FeatureSet::Segment).len(),
            2
        );
        let half = negative_samples("n", &scans, 2, FeatureSet::Segment);
        assert_eq!(half.len(), 1);
        assert_eq!(half[0].group, "n/l");
        assert_eq!(half[0].features[0], 10.0); // the wall came first
        // leg_tracker's set: 17 features, the point count first
        let lt = negative_samples("n", &scans, 1, FeatureSet::LegTracker);
        assert_eq!(lt.len(), 2);
        assert_eq!(lt[1].features.len(), 17);
        assert_eq!(lt[1].features[0], 4.0);
    }

    #[test]
    fn synthetic_labels_leg_near_unknown_and_far_negative() {
        let c = [
            Point2::new(2.0, 0.0), // at a leg's surface (0.06 from its centre)
            Point2::new(2.3, 0.0), // 0.24 from the leg: neither
            Point2::new(2.0, 2.0), // clear
            Point2::new(6.0, 0.0), // clear but beyond 5 m
        ];
        let legs = [(Point2::new(2.06, 0.0), 0.06)];
        assert_eq!(
            label_synthetic(&c, &legs, 5.0),
            vec![Some(true), None, Some(false), None]
        );
    }
}

//! `[params]` of `pipelines/laser_people.toml`: the scoring protocol of each sequence and its
//! validation. The detector and tracker run at the defaults of [`crate::laser`] (chosen on
//! synthetic data; nothing here tunes them).

use serde::{Deserialize, Serialize};

use super::learned::LearnedParams;
use super::methods::Method;
use crate::groundtruth::PEOPLE_TOPIC;
use crate::laser::training::FeatureSet;
use crate::run::config::Invalid;

/// The benchmarks of Leigh et al. (ICRA 2015, Table II), for `paper_table3` ([`super::paper`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PaperBenchmark {
    /// General multi-person tracking, stationary robot (7 min 11 s, 45 tracks).
    StationaryRobot,
    /// General multi-person tracking, moving robot (5 min 1 s, 37 tracks).
    MovingRobot,
    /// Tracking for following, indoors (21 min 24 s, one person).
    FollowingIndoor,
    /// Tracking for following, outdoors (12 min, one person).
    FollowingOutdoor,
}

impl PaperBenchmark {
    /// Table III's name of the benchmark.
    pub fn title(self) -> &'static str {
        match self {
            PaperBenchmark::StationaryRobot => "Stationary Robot",
            PaperBenchmark::MovingRobot => "Moving Robot",
            PaperBenchmark::FollowingIndoor => "Following Indoor",
            PaperBenchmark::FollowingOutdoor => "Following Outdoor",
        }
    }

    /// Whether only the followed person is annotated (false positives and MOTA undefined).
    pub fn following(self) -> bool {
        matches!(
            self,
            PaperBenchmark::FollowingIndoor | PaperBenchmark::FollowingOutdoor
        )
    }
}

/// How one sequence (a session, by name) is read and scored.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sequence {
    /// Session name (the log's file name without `.mcap`).
    pub name: String,
    pub scan_topic: String,
    /// Ground truth: a `leg_tracker/msg/Person` topic (positions in the laser frame, each
    /// belonging to the last scan logged before it) or a synthetic `/ground_truth/people` JSON
    /// topic (map frame, joined to the scan by nearest stamp).
    pub gt_topic: String,
    /// First and last scored scan index (inclusive, 0-based in log order); absent: all.
    #[serde(default)]
    pub scans: Option<[i64; 2]>,
    /// Ground truth and hypotheses are scored only when their bearing `atan2(y, x)` in the
    /// laser frame lies in `[min, max]` degrees (both kept when equal to a bound, as the
    /// authors' `clear_mot.py` removes only `angle < min` or `angle > max`).
    #[serde(default)]
    pub wedge_deg: Option<[f64; 2]>,
    /// Ground truth and hypotheses farther than this from the laser are not scored (m).
    #[serde(default)]
    pub max_range_m: Option<f64>,
    /// The methods do not see the log's TF (the ground truth still uses it): the free-space
    /// methods run on scan-matched odometry, the others in the laser frame, as on a log without
    /// odometry (issue 35: the synthetic logs made to look like `person_following_outdoor_1`).
    #[serde(default)]
    pub withhold_odometry: bool,
    /// The free-space methods report people not matched on the current scan (leg_tracker's
    /// `publish_occluded`; its default true, false in the authors' launch file of
    /// `general_tracking_moving_1`).
    #[serde(default = "yes")]
    pub publish_occluded: bool,
    /// The benchmark of Leigh et al. (ICRA 2015, Table II) this sequence belongs to: its
    /// rows of Table III and this run's rows under its protocol go into `paper_table3`
    /// ([`super::paper`]); absent: none.
    #[serde(default)]
    pub paper_benchmark: Option<PaperBenchmark>,
}

fn yes() -> bool {
    true
}

/// `[params]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Params {
    /// CLEAR MOT / IDF1 match threshold and HOTA's half zero-similarity distance (m).
    pub match_m: f64,
    /// Largest stamp difference between a scan and the synthetic ground-truth frame joined to
    /// it (s).
    pub gt_tolerance_s: f64,
    /// Confidence level of the paired t-test.
    pub level: f64,
    /// The real sequences, by session name; a listed sequence whose log is absent gets
    /// SKIPPED rows.
    pub sequences: Vec<Sequence>,
    /// How every other session (the synthetic datasets) is read and scored (`name` unused).
    pub synthetic: Sequence,
    /// The methods run on every scan, in table order (see [`super::methods`]).
    pub methods: Vec<Method>,
    /// Training of the learned leg detectors (`learned`, `learned_synthetic`).
    pub learned: LearnedParams,
    /// Training of the free-space methods' detectors (`learned_free_space`,
    /// `learned_synthetic_free_space`): leg_tracker's features by default.
    pub learned_free_space: LearnedParams,
}

/// The default `[params.learned_free_space]`: leg_tracker's 17 features; real negatives
/// every 10th segment (5 times leg_tracker's share, each standing for 10 in the CV precision);
/// the synthetic logs with `laser_clutter` (legs of many widths among trees, chair and table
/// legs and walls with gaps).
pub fn learned_free_space_default() -> LearnedParams {
    let mut p = LearnedParams {
        feature_set: FeatureSet::LegTracker,
        negative_keep_every: 10,
        ..LearnedParams::default()
    };
    p.synthetic_sessions
        .push("datasets/laser_clutter/*.mcap".into());
    p
}

impl Default for Params {
    fn default() -> Self {
        Params {
            match_m: 0.75,
            gt_tolerance_s: 0.05,
            level: 0.95,
            sequences: Vec::new(),
            synthetic: Sequence {
                name: String::new(),
                scan_topic: "/scan".into(),
                gt_topic: PEOPLE_TOPIC.into(),
                scans: None,
                wedge_deg: None,
                max_range_m: None,
                withhold_odometry: false,
                publish_occluded: true,
                paper_benchmark: None,
            },
            methods: vec![Method::Legs, Method::Nearest],
            learned: LearnedParams::default(),
            learned_free_space: learned_free_space_default(),
        }
    }
}

impl Params {
    /// The protocol of session `name`: its listed sequence, else the synthetic one.
    pub fn sequence(&self, name: &str) -> &Sequence {
        self.sequences
            .iter()
            .find(|s| s.name == name)
            .unwrap_or(&self.synthetic)
    }

    /// The training settings of `method`'s detector.
    pub fn learned_for(&self, method: Method) -> &LearnedParams {
        if method.free_space() {
            &self.learned_free_space
        } else {
            &self.learned
        }
    }

    /// Whether `name` is one of the listed (real) sequences.
    pub fn is_listed(&self, name: &str) -> bool {
        self.sequences.iter().any(|s| s.name == name)
    }
}

impl Sequence {
    /// Whether scan `idx` is scored.
    pub fn scores_scan(&self, idx: i64) -> bool {
        self.scans.is_none_or(|[a, b]| idx >= a && idx <= b)
    }

    /// Whether a position in the laser frame is scored (wedge and range).
    pub fn scores_point(&self, x: f64, y: f64) -> bool {
        if !(x.is_finite() && y.is_finite()) {
            return false;
        }
        let in_wedge = self.wedge_deg.is_none_or(|[lo, hi]| {
            let a = y.atan2(x);
            !(a < lo.to_radians() || a > hi.to_radians())
        });
        let in_range = self.max_range_m.is_none_or(|r| x.hypot(y) <= r);
        in_wedge && in_range
    }
}

fn check_sequence(key: &str, s: &Sequence, out: &mut Vec<Invalid>) {
    for (field, topic) in [("scan_topic", &s.scan_topic), ("gt_topic", &s.gt_topic)] {
        if topic.is_empty() {
            out.push((format!("{key}.{field}"), "must be set".into()));
        }
    }
    if let Some([a, b]) = s.scans
        && !(a >= 0 && a <= b)
    {
        out.push((
            format!("{key}.scans"),
            format!("[{a}, {b}] needs 0 ≤ first ≤ last"),
        ));
    }
    if let Some([lo, hi]) = s.wedge_deg
        && !(lo.is_finite() && hi.is_finite() && lo <= hi)
    {
        out.push((
            format!("{key}.wedge_deg"),
            format!("[{lo}, {hi}] needs min ≤ max"),
        ));
    }
    if let Some(r) = s.max_range_m
        && !(r.is_finite() && r > 0.0)
    {
        out.push((
            format!("{key}.max_range_m"),
            format!("{r} must be finite and > 0"),
        ));
    }
}

pub(super) fn validate(p: &Params) -> Vec<Invalid> {
    let mut out = Vec::new();
    if !(p.match_m.is_finite() && p.match_m > 0.0) {
        out.push((
            "match_m".into(),
            format!("{} must be finite and > 0", p.match_m),
        ));
    }
    if !(p.gt_tolerance_s.is_finite() && p.gt_tolerance_s >= 0.0 && p.gt_tolerance_s <= 10.0) {
        out.push((
            "gt_tolerance_s".into(),
            format!("{} is not in [0, 10] s", p.gt_tolerance_s),
        ));
    }
    if !(p.level > 0.0 && p.level < 1.0) {
        out.push(("level".into(), format!("{} is not in (0, 1)", p.level)));
    }
    for (i, s) in p.sequences.iter().enumerate() {
        let key = format!("sequences[{i}]");
        if s.name.is_empty() {
            out.push((format!("{key}.name"), "every sequence needs a name".into()));
        } else if p.sequences[..i].iter().any(|o| o.name == s.name) {
            out.push((
                format!("{key}.name"),
                format!("`{}` is listed twice", s.name),
            ));
        }
        check_sequence(&key, s, &mut out);
    }
    check_sequence("synthetic", &p.synthetic, &mut out);
    for (key, l) in [
        ("learned", &p.learned),
        ("learned_free_space", &p.learned_free_space),
    ] {
        if l.folds < 2
            || l.n_trees == 0
            || l.negative_keep_every == 0
            || l.synthetic_scan_every == 0
            || l.synthetic_negative_keep_every == 0
        {
            out.push((
                key.into(),
                "folds ≥ 2 and n_trees, negative_keep_every, synthetic_scan_every, synthetic_negative_keep_every ≥ 1".into(),
            ));
        }
        if !(l.max_range_m.is_finite() && l.max_range_m > 0.0) {
            out.push((
                key.into(),
                format!("max_range_m {} must be finite and > 0", l.max_range_m),
            ));
        }
    }
    if p.methods.is_empty() {
        out.push(("methods".into(), "needs at least one method".into()));
    }
    let mut sorted = p.methods.clone();
    sorted.sort();
    if sorted.windows(2).any(|w| w[0] == w[1]) {
        out.push(("methods".into(), "lists a method twice".into()));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_wedge_keeps_its_bounds_and_drops_what_lies_outside() {
        let s = Sequence {
            wedge_deg: Some([-80.0, 12.0]),
            max_range_m: Some(5.0),
            scans: Some([133, 404]),
            ..Params::default().synthetic
        };
        assert!(s.scores_point(1.0, 0.0));
        assert!(s.scores_point(0.2, -1.0)); // −78.7°
        assert!(!s.scores_point(0.1, -1.0)); // −84.3°
        assert!(!s.scores_point(1.0, 0.25)); // 14.0°
        assert!(!s.scores_point(6.0, 0.0)); // beyond 5 m
        assert!(!s.scores_point(f64::NAN, 0.0));
        assert!(s.scores_scan(133) && s.scores_scan(404));
        assert!(!s.scores_scan(132) && !s.scores_scan(405));
    }

    #[test]
    fn bad_values_are_named() {
        let mut p = Params {
            match_m: f64::NAN,
            ..Params::default()
        };
        p.synthetic.scans = Some([5, 2]);
        p.sequences = vec![p.synthetic.clone(), p.synthetic.clone()];
        p.sequences[0].name = "a".into();
        p.sequences[0].scans = None;
        p.sequences[1].name = "a".into();
        p.sequences[1].scans = None;
        p.sequences[1].wedge_deg = Some([10.0, -10.0]);
        let keys: Vec<String> = validate(&p).into_iter().map(|(k, _)| k).collect();
        assert_eq!(
            keys,
            [
                "match_m",
                "sequences[1].name",
                "sequences[1].wedge_deg",
                "synthetic.scans"
            ]
        );
        let p = Params {
            methods: vec![Method::Nearest, Method::Legs, Method::Nearest],
            ..Params::default()
        };
        let keys: Vec<String> = validate(&p).into_iter().map(|(k, _)| k).collect();
        assert_eq!(keys, ["methods"]);
        let p = Params {
            methods: vec![],
            ..Params::default()
        };
        let keys: Vec<String> = validate(&p).into_iter().map(|(k, _)| k).collect();
        assert_eq!(keys, ["methods"]);
    }
}

//! The learned leg detectors: a random forest ([`crate::learn::forest`]) over the segment
//! features of [`crate::laser::training`], trained on the real leg_tracker training CSVs
//! (`learned`) or on the synthetic laser datasets (`learned_synthetic`), with grouped
//! cross-validation and the probability threshold chosen on it.
//!
//! **Where the model comes from.** The pipeline trains it itself, deterministically, the first
//! time a session (or the aggregation) asks for it in a run, and keeps it in memory for the
//! rest of the run ([`model`]): a fresh machine's `make eval` needs no extra step, and the
//! model cannot drift from the training files or code the run uses. The alternative — a model
//! file as a parameter, written first by `peopletrack train leg-detector` — would key the
//! per-session cache by the file's path, not its contents. The training inputs (the real
//! folder, the synthetic session globs) are listed in the plan (`external_inputs`); the cache
//! key has the training settings (they are parameters) but not the training files' bytes:
//! the real CSVs are fixed read-only data and the synthetic logs are deterministic from their
//! scenario; after changing either, run with `--force`. `peopletrack train leg-detector`
//! trains the same model and writes it as JSON with its cross-validation table.
//!
//! **Cross-validation** is k-fold grouped by file (real positives: one group per
//! `positive_K` file; real negatives: one group per laser of `negative_2`, whose three lasers
//! drove the same rooms; synthetic: one group per session), so neighbouring scans never
//! straddle training and test. Groups with positives are dealt to the folds round-robin in
//! name order, then the negative-only groups. The probability threshold is the one of
//! `0.05, 0.10, …, 0.95` with the best F1 on the pooled out-of-fold probabilities (ties: the
//! lower): chosen on the training data, never on the test logs. Precision (and so F1) counts
//! each kept negative as the `negative_keep_every` segments it was drawn from, so it
//! estimates precision on whole scans rather than on the thinned sample (the first version
//! counted each once, which put the threshold at 0.40 and let clutter through: see README). The final model is trained on
//! all samples.
//!
//! Training runs sequentially (no rayon inside): sessions wait on one lock while the first one
//! trains, and a rayon worker holding the lock must not pick up another session's job.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use anyhow::Context;
use nalgebra::{Point2, Point3};
use serde::{Deserialize, Serialize};

use crate::frames::laser::{self as laser_frames, LaserOptions};
use crate::frames::truth;
use crate::laser::points::ScanGeometry;
use crate::laser::training::{self, FeatureSet, Sample, Segmented};
use crate::learn::forest::{Forest, ForestParams};
use crate::log::SessionLog;

/// `[params.learned]`: where the learned leg detectors' training data is and how they are
/// trained (see the module doc).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LearnedParams {
    /// The leg_tracker training CSVs (`positive_K_{scans,legs}.csv`, `negative_K_scans.csv`).
    pub training_dir: String,
    /// Real negatives: every n-th segment of the people-free scans (leg_tracker: 1 in 50).
    pub negative_keep_every: usize,
    /// Synthetic training logs (globs).
    pub synthetic_sessions: Vec<String>,
    /// Synthetic: every n-th scan of a log (neighbouring scans are near copies).
    pub synthetic_scan_every: usize,
    /// Synthetic negatives: every n-th non-leg segment (1: all; the synthetic scenes have
    /// few segments within 5 m besides the legs: about as many as legs).
    pub synthetic_negative_keep_every: usize,
    /// Synthetic samples farther than this from the laser are not used (m; the real labels
    /// lie within 5 m).
    pub max_range_m: f64,
    /// Cross-validation folds (grouped by file).
    pub folds: usize,
    pub n_trees: u16,
    pub seed: u64,
    /// The segment features the forest sees (`segment`: ours, 12; `leg_tracker`: its 17).
    pub feature_set: FeatureSet,
    /// A model file written by `peopletrack train leg-detector`: the method of this block
    /// whose training source matches the file's `source` loads it instead of training (its
    /// feature set and threshold come from the file). Absent: train.
    pub model: Option<String>,
}

impl Default for LearnedParams {
    fn default() -> Self {
        LearnedParams {
            training_dir: "../shared/real/laser/leg_training".into(),
            negative_keep_every: 50,
            synthetic_sessions: vec![
                "datasets/segway_park/*.mcap".into(),
                "datasets/office_network/*.mcap".into(),
            ],
            synthetic_scan_every: 2,
            synthetic_negative_keep_every: 1,
            max_range_m: 5.0,
            folds: 3,
            n_trees: 100,
            seed: 1,
            feature_set: FeatureSet::Segment,
            model: None,
        }
    }
}

/// Which training data.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Source {
    Real,
    Synthetic,
}

impl Source {
    pub fn name(self) -> &'static str {
        match self {
            Source::Real => "real",
            Source::Synthetic => "synthetic",
        }
    }
}

/// Precision / recall at the threshold of one fold (or of all folds pooled).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FoldScore {
    /// `fold k` or `pooled`.
    pub fold: String,
    /// The test groups.
    pub groups: Vec<String>,
    pub positives: usize,
    pub negatives: usize,
    pub precision: f64,
    pub recall: f64,
    pub f1: f64,
}

/// A trained leg detector with its evaluation (the model file's contents).
#[derive(Debug, Serialize, Deserialize)]
pub struct LegModel {
    pub source: Source,
    /// Which features (files written before this field: `segment`).
    #[serde(default)]
    pub feature_set: FeatureSet,
    pub features: Vec<String>,
    pub threshold: f64,
    pub positives: usize,
    pub negatives: usize,
    /// Labels that found no segment (real data).
    pub unmatched_labels: usize,
    pub cv: Vec<FoldScore>,
    pub training: LearnedParams,
    pub forest: Forest,
    /// The samples it was trained on, legs and non-legs (for the feature figures; not
    /// saved).
    #[serde(skip)]
    pub samples: Vec<Sample>,
}

impl LegModel {
    /// The model's feature vector of segment `i` (`None`: undefined on it).
    pub fn features_of(&self, s: &Segmented, i: usize) -> Option<Vec<f64>> {
        self.feature_set.of(s, i)
    }

    /// Leg probability of each feature row.
    pub fn probability(&self, x: &[Vec<f64>]) -> anyhow::Result<Vec<f64>> {
        Ok(self.forest.probability(x)?)
    }
}

/// Labelled samples and how many labels found no segment.
pub struct TrainingSet {
    pub samples: Vec<Sample>,
    pub unmatched_labels: usize,
}

fn read(path: &Path) -> anyhow::Result<String> {
    std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))
}

/// The real training set of folder `dir` (see [`crate::laser::training`]).
pub fn real_samples(
    dir: &Path,
    keep_every: usize,
    features: FeatureSet,
) -> anyhow::Result<TrainingSet> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .with_context(|| format!("reading {}", dir.display()))?
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with("_scans.csv"))
        .collect();
    names.sort();
    let mut set = TrainingSet {
        samples: Vec::new(),
        unmatched_labels: 0,
    };
    for name in names {
        let stem = name.trim_end_matches("_scans.csv").to_string();
        let path = dir.join(&name);
        let scans = training::parse_scans(&read(&path)?, &path.display().to_string())?;
        if stem.starts_with("positive") {
            let lp = dir.join(format!("{stem}_legs.csv"));
            let labels = training::parse_legs(&read(&lp)?, &lp.display().to_string())?;
            let (s, unmatched) = training::positive_samples(&stem, &scans, &labels, features);
            set.samples.extend(s);
            set.unmatched_labels += unmatched;
        } else if stem.starts_with("negative") {
            set.samples.extend(training::negative_samples(
                &stem, &scans, keep_every, features,
            ));
        }
    }
    Ok(set)
}

/// The synthetic training set: every `scan_every`-th scan of each session matching `globs`.
pub fn synthetic_samples(
    p: &LearnedParams,
    scan_topic: &str,
    gt_topic: &str,
) -> anyhow::Result<TrainingSet> {
    let mut paths: Vec<PathBuf> = Vec::new();
    for g in &p.synthetic_sessions {
        for e in glob::glob(g).with_context(|| format!("bad glob {g}"))? {
            paths.push(e?);
        }
    }
    paths.sort();
    paths.dedup();
    let mut samples = Vec::new();
    let mut negatives = 0usize;
    for path in &paths {
        let group = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let log = SessionLog::open(path)?;
        let (people, _) = truth::people(&log, gt_topic)?;
        let options = LaserOptions {
            fixed_frame: Some("map".into()),
            ..LaserOptions::default()
        };
        let frames = laser_frames::scans(&log, scan_topic, &options)?;
        for (idx, f) in frames.enumerate() {
            let Ok(f) = f else { continue };
            if idx % p.synthetic_scan_every.max(1) != 0 {
                continue;
            }
            let (Some(pose), Some(gt)) = (f.pose.as_ref(), people.nearest(f.stamp, 50_000_000))
            else {
                continue;
            };
            let geometry = ScanGeometry::of(&f.scan);
            let s = training::segment_scan(&f.scan.ranges, &geometry);
            let legs: Vec<(Point2<f64>, f64)> = gt
                .people
                .iter()
                .flat_map(|person| {
                    person.legs.iter().map(move |l| {
                        let q = pose.inverse_transform_point(&Point3::new(l[0], l[1], 0.0));
                        (Point2::new(q.x, q.y), person.leg_radius)
                    })
                })
                .collect();
            let labels = training::label_synthetic(&s.centroids, &legs, p.max_range_m);
            for (i, l) in labels.iter().enumerate() {
                let Some(leg) = *l else { continue };
                let Some(features) = p.feature_set.of(&s, i) else {
                    continue;
                };
                if !leg {
                    negatives += 1;
                    if !(negatives - 1).is_multiple_of(p.synthetic_negative_keep_every.max(1)) {
                        continue;
                    }
                }
                samples.push(Sample {
                    group: group.clone(),
                    scan_idx: idx,
                    features,
                    range_m: s.centroids[i].coords.norm(),
                    leg,
                });
            }
        }
    }
    Ok(TrainingSet {
        samples,
        unmatched_labels: 0,
    })
}

/// Fold of each group: groups with positives round-robin in name order, then the others.
pub fn assign_folds(samples: &[Sample], folds: usize) -> BTreeMap<String, usize> {
    let mut with_pos: Vec<&str> = Vec::new();
    let mut neg_only: Vec<&str> = Vec::new();
    let mut groups: BTreeMap<&str, bool> = BTreeMap::new();
    for s in samples {
        *groups.entry(&s.group).or_insert(false) |= s.leg;
    }
    for (g, pos) in groups {
        if pos {
            with_pos.push(g)
        } else {
            neg_only.push(g)
        }
    }
    let k = folds.max(1);
    let mut out = BTreeMap::new();
    for (i, g) in with_pos.iter().enumerate() {
        out.insert(g.to_string(), i % k);
    }
    for (i, g) in neg_only.iter().enumerate() {
        out.insert(g.to_string(), i % k);
    }
    out
}

/// Precision and recall of `p >= threshold` against `y`; each negative counts
/// `negative_weight` times (the under-sampling factor of the negatives: precision is then an
/// estimate for the scans the negatives were drawn from, not for the thinned sample).
fn score(
    fold: String,
    groups: Vec<String>,
    p: &[f64],
    y: &[bool],
    threshold: f64,
    negative_weight: f64,
) -> FoldScore {
    let (mut tp, mut fp, mut fnn) = (0.0f64, 0.0f64, 0.0f64);
    for (pi, yi) in p.iter().zip(y) {
        match (*pi >= threshold, *yi) {
            (true, true) => tp += 1.0,
            (true, false) => fp += negative_weight,
            (false, true) => fnn += 1.0,
            _ => {}
        }
    }
    let ratio = |a: f64, b: f64| {
        if a + b == 0.0 { f64::NAN } else { a / (a + b) }
    };
    let (precision, recall) = (ratio(tp, fp), ratio(tp, fnn));
    FoldScore {
        fold,
        groups,
        positives: y.iter().filter(|&&v| v).count(),
        negatives: y.iter().filter(|&&v| !v).count(),
        precision,
        recall,
        f1: 2.0 * precision * recall / (precision + recall),
    }
}

/// How many segments of the people-free scans each kept negative stands for.
fn negative_weight(source: Source, p: &LearnedParams) -> f64 {
    let every = match source {
        Source::Real => p.negative_keep_every,
        Source::Synthetic => p.synthetic_negative_keep_every,
    };
    every.max(1) as f64
}

/// Train with grouped cross-validation; the threshold from the out-of-fold probabilities.
pub fn train(source: Source, set: TrainingSet, p: &LearnedParams) -> anyhow::Result<LegModel> {
    let samples = &set.samples;
    let forest_params = ForestParams {
        n_trees: p.n_trees,
        seed: p.seed,
        ..ForestParams::default()
    };
    let folds = assign_folds(samples, p.folds);
    let k = p.folds.max(1);
    let mut oof = vec![f64::NAN; samples.len()];
    for fold in 0..k {
        let test: Vec<usize> = (0..samples.len())
            .filter(|&i| folds[&samples[i].group] == fold)
            .collect();
        let (x, y): (Vec<Vec<f64>>, Vec<bool>) = samples
            .iter()
            .filter(|s| folds[&s.group] != fold)
            .map(|s| (s.features.clone(), s.leg))
            .unzip();
        let forest = Forest::fit(&x, &y, forest_params)
            .with_context(|| format!("{} fold {fold}", source.name()))?;
        let xt: Vec<Vec<f64>> = test.iter().map(|&i| samples[i].features.clone()).collect();
        for (i, pr) in test.iter().zip(forest.probability(&xt)?) {
            oof[*i] = pr;
        }
    }
    let y: Vec<bool> = samples.iter().map(|s| s.leg).collect();
    let w = negative_weight(source, p);
    let threshold = (1..20)
        .map(|i| f64::from(i) * 0.05)
        .map(|t| (t, score(String::new(), vec![], &oof, &y, t, w).f1))
        .fold((0.5, f64::NEG_INFINITY), |best, (t, f)| {
            if f > best.1 { (t, f) } else { best }
        })
        .0;
    let mut cv = Vec::new();
    for fold in 0..k {
        let idx: Vec<usize> = (0..samples.len())
            .filter(|&i| folds[&samples[i].group] == fold)
            .collect();
        let groups = folds
            .iter()
            .filter(|(_, f)| **f == fold)
            .map(|(g, _)| g.clone())
            .collect();
        let pf: Vec<f64> = idx.iter().map(|&i| oof[i]).collect();
        let yf: Vec<bool> = idx.iter().map(|&i| y[i]).collect();
        cv.push(score(
            format!("fold {}", fold + 1),
            groups,
            &pf,
            &yf,
            threshold,
            w,
        ));
    }
    cv.push(score(
        "pooled".into(),
        folds.keys().cloned().collect(),
        &oof,
        &y,
        threshold,
        w,
    ));
    let (x, _): (Vec<Vec<f64>>, Vec<()>) = samples.iter().map(|s| (s.features.clone(), ())).unzip();
    let forest = Forest::fit(&x, &y, forest_params)?;
    Ok(LegModel {
        source,
        feature_set: p.feature_set,
        features: p
            .feature_set
            .names()
            .iter()
            .map(|s| s.to_string())
            .collect(),
        threshold,
        positives: y.iter().filter(|&&v| v).count(),
        negatives: y.iter().filter(|&&v| !v).count(),
        unmatched_labels: set.unmatched_labels,
        cv,
        training: p.clone(),
        forest,
        samples: set.samples.clone(),
    })
}

/// Why a model is not available: the training data is absent (SKIPPED) or failed.
#[derive(Debug, Clone)]
pub enum Unavailable {
    Absent(String),
    Failed(String),
}

type Cached = Result<Arc<LegModel>, Unavailable>;

static MODELS: Mutex<BTreeMap<String, Cached>> = Mutex::new(BTreeMap::new());

/// The training data of `source` is absent (the reason), or present (`None`).
pub fn absent(source: Source, p: &LearnedParams) -> Option<String> {
    match source {
        Source::Real => {
            (!Path::new(&p.training_dir).is_dir()).then(|| format!("{} absent", p.training_dir))
        }
        Source::Synthetic => {
            let any = p
                .synthetic_sessions
                .iter()
                .any(|g| glob::glob(g).is_ok_and(|mut it| it.any(|e| e.is_ok())));
            (!any).then(|| {
                format!(
                    "no synthetic training logs ({})",
                    p.synthetic_sessions.join(", ")
                )
            })
        }
    }
}

/// Train `source`'s model from scratch (no cache).
pub fn train_source(source: Source, p: &LearnedParams, scan_topic: &str, gt_topic: &str) -> Cached {
    if let Some(why) = absent(source, p) {
        return Err(Unavailable::Absent(why));
    }
    let set = match source {
        Source::Real => real_samples(
            Path::new(&p.training_dir),
            p.negative_keep_every,
            p.feature_set,
        ),
        Source::Synthetic => synthetic_samples(p, scan_topic, gt_topic),
    };
    set.and_then(|s| train(source, s, p))
        .map(Arc::new)
        .map_err(|e| Unavailable::Failed(format!("{e:#}")))
}

/// `source`'s model for settings `p`, trained once per process (see the module doc).
pub fn model(source: Source, p: &LearnedParams, scan_topic: &str, gt_topic: &str) -> Cached {
    let key = format!(
        "{}|{}|{scan_topic}|{gt_topic}",
        source.name(),
        serde_json::to_string(p).unwrap_or_default()
    );
    let mut cache = MODELS
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    cache
        .entry(key)
        .or_insert_with(|| match loaded(source, p) {
            Some(m) => m,
            None => train_source(source, p, scan_topic, gt_topic),
        })
        .clone()
}

/// The model file of `p.model` when it was trained on `source` (see [`LearnedParams::model`]);
/// `None` when no file is named or it holds the other source's model.
fn loaded(source: Source, p: &LearnedParams) -> Option<Cached> {
    let path = p.model.as_deref()?;
    let m = std::fs::read(path)
        .with_context(|| format!("reading leg model {path}"))
        .and_then(|b| {
            serde_json::from_slice::<LegModel>(&b)
                .with_context(|| format!("leg model {path} is not a model file"))
        });
    match m {
        Ok(m) if m.source == source => Some(Ok(Arc::new(m))),
        Ok(_) => None,
        Err(e) => Some(Err(Unavailable::Failed(format!("{e:#}")))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(group: &str, leg: bool) -> Sample {
        Sample {
            group: group.into(),
            scan_idx: 0,
            features: vec![],
            range_m: 1.0,
            leg,
        }
    }

    /// No group's samples ever sit in two folds; positive groups are spread over the folds
    /// first, then the negative-only ones.
    #[test]
    fn folds_never_split_a_file() {
        let samples = vec![
            s("positive_1", true),
            s("positive_2", true),
            s("positive_1", true),
            s("positive_3", true),
            s("negative_2/left", false),
            s("negative_2/right", false),
            s("positive_4", true),
            s("negative_2/rear", false),
            s("positive_2", false),
        ];
        let f = assign_folds(&samples, 3);
        assert_eq!(f["positive_1"], 0);
        assert_eq!(f["positive_2"], 1);
        assert_eq!(f["positive_3"], 2);
        assert_eq!(f["positive_4"], 0);
        assert_eq!(f["negative_2/left"], 0);
        assert_eq!(f["negative_2/rear"], 1);
        assert_eq!(f["negative_2/right"], 2);
        // every sample of a group is in that group's single fold
        for a in &samples {
            for b in &samples {
                if a.group == b.group {
                    assert_eq!(f[&a.group], f[&b.group]);
                }
            }
        }
    }

    /// A model saved as `train leg-detector` saves it is what the pipeline uses when
    /// `model` names the file (same source): same threshold, feature set and probabilities;
    /// a file of the other source is ignored (that source trains, here: absent data).
    #[test]
    fn a_saved_model_file_is_loaded_for_its_source() {
        let mut samples = Vec::new();
        for k in 0..12 {
            let x = f64::from(k);
            for (g, leg) in [
                ("positive_1", true),
                ("positive_2", true),
                ("negative_2/l", false),
                ("negative_2/r", false),
            ] {
                samples.push(Sample {
                    group: g.into(),
                    scan_idx: k as usize,
                    features: vec![if leg { 1.0 + x } else { -1.0 - x }; 17],
                    range_m: 1.0,
                    leg,
                });
            }
        }
        let p = LearnedParams {
            feature_set: FeatureSet::LegTracker,
            folds: 2,
            n_trees: 5,
            training_dir: "/nonexistent/leg_training".into(),
            synthetic_sessions: vec!["/nonexistent/*.mcap".into()],
            ..LearnedParams::default()
        };
        let set = TrainingSet {
            samples,
            unmatched_labels: 0,
        };
        let trained = train(Source::Real, set, &p).expect("trains");
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("legs.json");
        std::fs::write(&path, serde_json::to_vec(&trained).expect("json")).expect("write");
        let with_file = LearnedParams {
            model: Some(path.display().to_string()),
            ..p
        };
        let got = model(Source::Real, &with_file, "/scan", "/gt").expect("loaded");
        assert_eq!(got.feature_set, FeatureSet::LegTracker);
        assert_eq!(got.threshold, trained.threshold);
        let x = vec![vec![3.0; 17], vec![-3.0; 17]];
        assert_eq!(
            got.probability(&x).expect("p"),
            trained.probability(&x).expect("p")
        );
        assert!(matches!(
            model(Source::Synthetic, &with_file, "/scan", "/gt"),
            Err(Unavailable::Absent(_))
        ));
    }

    #[test]
    fn fold_score_counts() {
        let p = [0.9, 0.8, 0.2, 0.6, 0.1];
        let y = [true, true, true, false, false];
        let sc = score("x".into(), vec![], &p, &y, 0.5, 1.0);
        assert_eq!((sc.positives, sc.negatives), (3, 2));
        assert!((sc.precision - 2.0 / 3.0).abs() < 1e-12);
        assert!((sc.recall - 2.0 / 3.0).abs() < 1e-12);
        assert!((sc.f1 - 2.0 / 3.0).abs() < 1e-12);
        // each negative standing for 10: tp 2, fp 10 → precision 2/12, recall unchanged
        let sc = score("x".into(), vec![], &p, &y, 0.5, 10.0);
        assert_eq!((sc.positives, sc.negatives), (3, 2));
        assert!((sc.precision - 2.0 / 12.0).abs() < 1e-12);
        assert!((sc.recall - 2.0 / 3.0).abs() < 1e-12);
        let f1 = 2.0 * (2.0 / 12.0) * (2.0 / 3.0) / (2.0 / 12.0 + 2.0 / 3.0);
        assert!((sc.f1 - f1).abs() < 1e-12);
    }
}

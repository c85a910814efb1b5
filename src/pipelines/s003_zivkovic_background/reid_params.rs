//! `[params.reid]` of `pipelines/s003_zivkovic_background.toml`: re-identification across local
//! tracks (Zajdel, Zivkovic & Kröse, ICRA 2005, inside seed 003) — which datasets are scored
//! and which are the training split, how local tracks become observations, the clips, and
//! their validation.

use serde::{Deserialize, Serialize};

/// One clip of `[params.reid]`: the observations that ended by `until_s` (seconds since the
/// session's first frame; absent: the whole session), as the paper's clips cover one or more
/// places of the tour.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ClipParams {
    pub name: String,
    #[serde(default)]
    pub until_s: Option<f64>,
}

/// `[params.reid]`: re-identification across local tracks (Zajdel et al., ICRA 2005).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ReidParams {
    /// Datasets whose sessions are re-identified and scored (a touring robot with several
    /// people).
    pub datasets: Vec<String>,
    /// Datasets whose sessions are the training split: never scored; the prior values moved
    /// to the features' units and the nearest-neighbour threshold are fitted on their
    /// ground-truth local tracks. Absent from a run: the rows that need them are left out.
    pub train_datasets: Vec<String>,
    /// Ground-truth boxes less visible than this are left out of the features.
    pub min_visibility: f64,
    /// A local track breaks where its person or track is unseen for longer than this (s).
    pub max_gap_s: f64,
    /// Local tracks with fewer frames than this are no observation.
    pub min_frames: usize,
    /// The nearest-neighbour baseline's a-priori distance threshold on the channel-normalised
    /// 9-D feature (its other row takes the threshold fitted on the training split).
    pub nn_threshold: f64,
    pub clips: Vec<ClipParams>,
    /// Confidence level of the t-tests.
    pub level: f64,
    /// Figs. 5–6: the session keeps the frame with the most people of every window this long
    /// (s); the figures draw four of them per clip.
    pub snapshot_window_s: f64,
}

impl Default for ReidParams {
    fn default() -> Self {
        Self {
            datasets: vec!["home_tour".into()],
            train_datasets: vec!["home_tour_train".into()],
            min_visibility: 0.5,
            max_gap_s: 1.0,
            min_frames: 5,
            nn_threshold: 0.15,
            clips: vec![
                ClipParams {
                    name: "similar light".into(),
                    until_s: Some(95.0),
                },
                ClipParams {
                    name: "across light".into(),
                    until_s: None,
                },
            ],
            level: 0.95,
            snapshot_window_s: 5.0,
        }
    }
}

/// Every `[params.reid]` problem, named by its key path below `[params]`.
pub(super) fn validate_reid(r: &ReidParams, bad: &mut impl FnMut(&str, String)) {
    if !(0.0..=1.0).contains(&r.min_visibility) {
        bad(
            "reid.min_visibility",
            format!("{} is not in [0, 1]", r.min_visibility),
        );
    }
    for (key, v) in [
        ("reid.max_gap_s", r.max_gap_s),
        ("reid.nn_threshold", r.nn_threshold),
    ] {
        if !(v.is_finite() && v > 0.0) {
            bad(key, format!("{v} must be finite and positive"));
        }
    }
    if r.min_frames == 0 {
        bad("reid.min_frames", "must be at least 1".into());
    }
    if !(r.level > 0.0 && r.level < 1.0) {
        bad("reid.level", format!("{} is not in (0, 1)", r.level));
    }
    if r.clips.is_empty() {
        bad("reid.clips", "needs at least one clip".into());
    }
    for (i, c) in r.clips.iter().enumerate() {
        if let Some(t) = c.until_s
            && !(t.is_finite() && t > 0.0)
        {
            bad(
                &format!("reid.clips[{i}].until_s"),
                format!("{t} must be finite and > 0"),
            );
        }
    }
    if let Some(d) = r.train_datasets.iter().find(|d| r.datasets.contains(d)) {
        bad(
            "reid.train_datasets",
            format!("`{d}` is also scored (reid.datasets): a training split must be apart"),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_training_dataset_that_is_also_scored_is_refused() {
        let mut problems = Vec::new();
        let ok = ReidParams::default();
        validate_reid(&ok, &mut |k, r| problems.push((k.to_string(), r)));
        assert!(problems.is_empty(), "{problems:?}");
        let both = ReidParams {
            train_datasets: vec!["home_tour".into()],
            ..ReidParams::default()
        };
        validate_reid(&both, &mut |k, r| problems.push((k.to_string(), r)));
        assert_eq!(problems.len(), 1);
        assert_eq!(problems[0].0, "reid.train_datasets");
    }
}

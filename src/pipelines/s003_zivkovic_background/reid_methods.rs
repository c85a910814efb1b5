//! Re-identification methods compared (seed 003 §IV–V): the paper's model — the assumed-density
//! filter of `track::reid` on the person's pixels in the channel-normalised space, with the
//! printed prior and P_δ — beside variants that change one thing each, the nearest-neighbour
//! baseline, and what the training split fits for them.
//!
//! **The training split** (`reid.train_datasets`, never scored): on its sessions' ground-truth
//! local tracks (every observation of a session, the whole tour) it fits, per feature variant,
//! the prior moved to the features' units ([`Prior::moved`]: a₀ at the mean look, κ₀ at the
//! ratio of the between- to the within-person spread, C₀ at the within-person spread; η₀ as
//! printed) and the nearest-neighbour threshold (the one of
//! [`NN_GRID`] with the fewest mis-identified observations over its sessions, the smallest on
//! a tie). Without a training session in the run the rows that need them are left out.

use std::collections::BTreeMap;

use super::reid_features::{Feature, Observation, PixelSet, Space};
use crate::eval::reid::score;
use crate::track::reid::{Moved, Prior, ReidFilter, Terms};

/// Which prior the filter starts from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum PriorKind {
    /// As printed: a₀ = 0, κ₀ = 100, η₀ = 9, C₀ = 10⁻³·I.
    Printed,
    /// Moved to the features' units on the training split.
    Trained,
}

/// Where the nearest-neighbour threshold comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Threshold {
    /// `reid.nn_threshold`.
    APriori,
    /// Fitted on the training split.
    Trained,
}

/// How labels are found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Model {
    Adf {
        prior: PriorKind,
        spatio_temporal: bool,
    },
    Nearest(Threshold),
}

/// One compared method: a model on a feature variant.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Method {
    pub name: &'static str,
    pub feature: Feature,
    pub model: Model,
}

const PAPER_ADF: Model = Model::Adf {
    prior: PriorKind::Printed,
    spatio_temporal: true,
};
const TRAINED_ADF: Model = Model::Adf {
    prior: PriorKind::Trained,
    spatio_temporal: true,
};
const NORMALISED: Space = Space::Normalised;

/// The paper's model as the paper describes it: the default, first.
pub(super) const PAPER: Method = Method {
    name: "paper (ADF)",
    feature: (PixelSet::Person, NORMALISED),
    model: PAPER_ADF,
};

/// Every method, the paper's first; each row of `reid` and `reid_ttests` is one of them.
pub(super) const METHODS: [Method; 14] = [
    PAPER,
    Method {
        name: "paper, prior moved (training split)",
        feature: (PixelSet::Person, NORMALISED),
        model: TRAINED_ADF,
    },
    Method {
        name: "without spatio-temporal term",
        feature: (PixelSet::Person, NORMALISED),
        model: Model::Adf {
            prior: PriorKind::Printed,
            spatio_temporal: false,
        },
    },
    Method {
        name: "raw RGB",
        feature: (PixelSet::Person, Space::Raw),
        model: PAPER_ADF,
    },
    Method {
        name: "ln space",
        feature: (PixelSet::Person, Space::Ln),
        model: PAPER_ADF,
    },
    Method {
        name: "nearest neighbour (a priori)",
        feature: (PixelSet::Person, NORMALISED),
        model: Model::Nearest(Threshold::APriori),
    },
    Method {
        name: "nearest neighbour (threshold from training)",
        feature: (PixelSet::Person, NORMALISED),
        model: Model::Nearest(Threshold::Trained),
    },
    Method {
        name: "ceiling: exact masks",
        feature: (PixelSet::Exact, NORMALISED),
        model: PAPER_ADF,
    },
    Method {
        name: "ceiling: exact masks, prior moved",
        feature: (PixelSet::Exact, NORMALISED),
        model: TRAINED_ADF,
    },
    Method {
        name: "whole box, ln (before issue 31)",
        feature: (PixelSet::Box, Space::Ln),
        model: PAPER_ADF,
    },
    Method {
        name: "filled silhouettes, prior moved",
        feature: (PixelSet::Filled, NORMALISED),
        model: TRAINED_ADF,
    },
    Method {
        name: "chromaticity",
        feature: (PixelSet::Person, Space::Chromaticity),
        model: PAPER_ADF,
    },
    Method {
        name: "chromaticity, prior moved",
        feature: (PixelSet::Person, Space::Chromaticity),
        model: TRAINED_ADF,
    },
    Method {
        name: "ceiling: exact masks, chromaticity, prior moved",
        feature: (PixelSet::Exact, Space::Chromaticity),
        model: TRAINED_ADF,
    },
];

/// Candidate nearest-neighbour thresholds (channel-normalised units): 0.01 to 2.00 by 0.01.
pub(super) const NN_GRID: std::ops::RangeInclusive<u32> = 1..=200;

/// What the training split fitted: the moved prior per feature variant and the
/// nearest-neighbour threshold per feature variant.
#[derive(Debug, Clone, Default)]
pub(super) struct Training {
    /// Session names of the split.
    pub sessions: Vec<String>,
    pub priors: BTreeMap<Feature, Moved>,
    pub thresholds: BTreeMap<Feature, f64>,
}

impl Training {
    /// Fit on `sessions`: each session's ground-truth observations (the whole tour).
    pub fn fit(sessions: &[(String, Vec<Observation>)]) -> anyhow::Result<Training> {
        let mut out = Training {
            sessions: sessions.iter().map(|(n, _)| n.clone()).collect(),
            ..Training::default()
        };
        if sessions.is_empty() {
            return Ok(out);
        }
        let features: Vec<Feature> = METHODS.iter().map(|m| m.feature).collect();
        for f in features {
            if out.priors.contains_key(&f) {
                continue;
            }
            // looks grouped by (session, person)
            let mut people: BTreeMap<(usize, i64), Vec<Vec<f64>>> = BTreeMap::new();
            for (k, (_, obs)) in sessions.iter().enumerate() {
                for o in obs {
                    if let (Some(t), Some(x)) = (o.truth, o.feature(f)) {
                        people.entry((k, t)).or_default().push(x.to_vec());
                    }
                }
            }
            let groups: Vec<Vec<Vec<f64>>> = people.into_values().collect();
            if let Some(m) = Prior::paper(9).moved(&groups) {
                out.priors.insert(f, m);
            }
        }
        for m in METHODS {
            if m.model == Model::Nearest(Threshold::Trained)
                && !out.thresholds.contains_key(&m.feature)
            {
                let mut best: Option<(usize, f64)> = None;
                for k in NN_GRID {
                    let t = f64::from(k) / 100.0;
                    let mut errors = 0;
                    for (_, obs) in sessions {
                        let seen: Vec<&Observation> = obs
                            .iter()
                            .filter(|o| o.truth.is_some() && o.feature(m.feature).is_some())
                            .collect();
                        let got = nearest(&seen, m.feature, t);
                        let truth: Vec<i64> = seen.iter().filter_map(|o| o.truth).collect();
                        errors += score(&truth, &got).misidentified;
                    }
                    if best.is_none_or(|(e, _)| errors < e) {
                        best = Some((errors, t));
                    }
                }
                if let Some((_, t)) = best {
                    out.thresholds.insert(m.feature, t);
                }
            }
        }
        Ok(out)
    }
}

/// The label each observation gets from method `m` (in order); `None` when the method needs a
/// fitted value the training split did not give. Every observation must carry the method's
/// feature (the caller keeps those that do).
pub(super) fn labels(
    obs: &[&Observation],
    m: &Method,
    nn_threshold: f64,
    training: &Training,
) -> anyhow::Result<Option<Vec<usize>>> {
    let prior = match m.model {
        Model::Nearest(Threshold::APriori) => {
            return Ok(Some(nearest(obs, m.feature, nn_threshold)));
        }
        Model::Nearest(Threshold::Trained) => {
            return Ok(training
                .thresholds
                .get(&m.feature)
                .map(|t| nearest(obs, m.feature, *t)));
        }
        Model::Adf {
            prior: PriorKind::Printed,
            ..
        } => Prior::paper(9),
        Model::Adf {
            prior: PriorKind::Trained,
            ..
        } => match training.priors.get(&m.feature) {
            Some(moved) => moved.prior.clone(),
            None => return Ok(None),
        },
    };
    let terms = Terms {
        appearance: true,
        spatio_temporal: matches!(
            m.model,
            Model::Adf {
                spatio_temporal: true,
                ..
            }
        ),
    };
    let mut filter = ReidFilter::new(&prior, terms);
    let mut out = Vec::with_capacity(obs.len());
    for o in obs {
        let Some(x) = o.feature(m.feature) else {
            anyhow::bail!("observation {} has no {:?} feature", o.id, m.feature);
        };
        out.push(filter.observe(x, o.span)?.label);
    }
    Ok(Some(out))
}

/// The baseline: each observation joins the person whose mean feature is nearest (Euclidean)
/// if closer than `threshold` and their last track ended before it started; else it is a new
/// person. Observations without the feature are new people.
pub(super) fn nearest(obs: &[&Observation], feature: Feature, threshold: f64) -> Vec<usize> {
    // (sum of features, count, last leave time)
    let mut people: Vec<([f64; 9], f64, f64)> = Vec::new();
    let mut out = Vec::with_capacity(obs.len());
    for o in obs {
        let x = o.feature(feature).copied().unwrap_or([f64::NAN; 9]);
        let best = people
            .iter()
            .enumerate()
            .filter(|(_, (_, _, leave))| o.span.enter > *leave)
            .map(|(i, (sum, n, _))| {
                let d: f64 = (0..9).map(|j| (sum[j] / n - x[j]).powi(2)).sum();
                (i, d.sqrt())
            })
            .filter(|(_, d)| *d < threshold)
            .min_by(|a, b| a.1.total_cmp(&b.1));
        let i = match best {
            Some((i, _)) => i,
            None => {
                people.push(([0.0; 9], 0.0, f64::NEG_INFINITY));
                people.len() - 1
            }
        };
        let person = &mut people[i];
        for (acc, v) in person.0.iter_mut().zip(x) {
            *acc += v;
        }
        person.1 += 1.0;
        person.2 = person.2.max(o.span.leave);
        out.push(i + 1);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::track::reid::Span;

    const F: Feature = (PixelSet::Person, Space::Normalised);

    fn o(truth: i64, enter: f64, leave: f64, f: f64) -> Observation {
        let mut x = [1.0; 9];
        x[0] = f;
        Observation {
            id: truth,
            truth: Some(truth),
            span: Span { enter, leave },
            frames: 5,
            features: BTreeMap::from([(F, (x, 5))]),
        }
    }

    #[test]
    fn nearest_neighbour_joins_within_the_threshold_and_never_overlapping_tracks() {
        let obs = [
            o(1, 0.0, 1.0, 0.0),
            o(1, 2.0, 3.0, 0.05),
            o(2, 2.5, 4.0, 0.0),
            o(3, 5.0, 6.0, 1.0),
        ];
        let refs: Vec<&Observation> = obs.iter().collect();
        // the third overlaps the second (same person, mean 0.025): new; the fourth is far
        assert_eq!(nearest(&refs, F, 0.1), [1, 1, 2, 3]);
    }

    #[test]
    fn training_fits_the_threshold_with_fewest_errors_and_the_moved_prior() {
        // one training session: person 1 at 0.0 and 0.305, person 2 at 1.0 and 1.205, all
        // apart in time. Thresholds up to 0.20 split both (2 errors), 0.21–0.30 split person 1
        // (1 error), from 0.31 on both are right (until 1.01 joins person 2 to person 1)
        let session = vec![
            o(1, 0.0, 1.0, 0.0),
            o(2, 2.0, 3.0, 1.0),
            o(1, 4.0, 5.0, 0.305),
            o(2, 6.0, 7.0, 1.205),
        ];
        let t = Training::fit(&[("s".into(), session)]).expect("fit");
        assert_eq!(t.sessions, ["s"]);
        assert_eq!(t.thresholds.get(&F), Some(&0.31));
        let m = t.priors.get(&F).expect("moved prior");
        assert!((m.prior.a0[0] - 2.51 / 4.0).abs() < 1e-12 && m.prior.a0[1] == 1.0);
        // within: one dimension of nine varies, two people seen twice each
        let within = 2.0 * 0.1525f64.powi(2) + 2.0 * 0.1025f64.powi(2);
        assert!((m.within_sd - (within / 18.0).sqrt()).abs() < 1e-12);
        // without training sessions nothing is fitted, and the trained rows are left out
        let none = Training::fit(&[]).expect("fit");
        let refs: Vec<&Observation> = Vec::new();
        assert_eq!(labels(&refs, &METHODS[1], 0.15, &none).expect("ok"), None);
        assert_eq!(labels(&refs, &METHODS[6], 0.15, &none).expect("ok"), None);
    }

    #[test]
    fn the_paper_is_first_and_every_method_name_is_unique() {
        assert_eq!(METHODS[0], PAPER);
        let mut names: Vec<&str> = METHODS.iter().map(|m| m.name).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), METHODS.len());
    }
}

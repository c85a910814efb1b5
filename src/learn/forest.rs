//! A binary random forest (Breiman 2001) with a class probability: the fraction of trees that
//! vote for the positive class. Used by the learned leg detector
//! (`pipelines::laser_people::learned`).
//!
//! **Crate: `smartcore`** (0.7, `RandomForestClassifier`), chosen over `linfa-ensemble`:
//!
//! - it is one crate with few dependencies (`num`, `ordered-float`, `approx`; `typetag` for
//!   serde) and needs no BLAS or `ndarray`; `linfa-ensemble` pulls `linfa`, `linfa-trees`,
//!   `ndarray` 0.16, `ndarray-rand` and a second `rand` (0.8), a longer cold build;
//! - it draws a fresh subset of `m` features at **every split** (the classic random forest,
//!   as OpenCV's `RTrees` that leg_tracker trains: `ActiveVarCount = 2`), where
//!   `linfa-ensemble` draws one feature subset per tree;
//! - it is deterministic given a seed (each tree's bootstrap and feature draws come from the
//!   seed), and its models serialise with serde.
//!
//! What smartcore's forest lacks is a probability (it returns the majority class only, and its
//! trees are private). So the forest here is a list of one-tree smartcore forests with seeds
//! `seed, seed + 1, …` — each one a bootstrap sample and per-split feature draws, exactly one
//! tree of a random forest — and the probability is their vote fraction. That bagging loop
//! (a few lines) is the only hand-written part. Trees are fitted one after another: the same
//! seed gives the same forest, and a caller may train while holding a lock inside a rayon job
//! (a rayon join inside could run another job of the same thread that waits on that lock).

use serde::{Deserialize, Serialize};
use smartcore::ensemble::random_forest_classifier::{
    RandomForestClassifier, RandomForestClassifierParameters,
};
use smartcore::linalg::basic::arrays::Array;
use smartcore::linalg::basic::matrix::DenseMatrix;

type Tree = RandomForestClassifier<f64, i32, DenseMatrix<f64>, Vec<i32>>;

/// Why training or prediction failed.
#[derive(Debug, thiserror::Error)]
pub enum ForestError {
    #[error("training needs both classes: {positives} positive and {negatives} negative samples")]
    OneClass { positives: usize, negatives: usize },
    #[error("sample {row} has {got} features, expected {expected}")]
    Width {
        row: usize,
        got: usize,
        expected: usize,
    },
    #[error("random forest: {0}")]
    Crate(String),
}

/// Training settings (defaults: leg_tracker's `train_leg_detector.cpp`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ForestParams {
    pub n_trees: u16,
    pub max_depth: u16,
    pub min_samples_split: usize,
    /// Features drawn at each split.
    pub features_per_split: usize,
    pub seed: u64,
}

impl Default for ForestParams {
    /// 100 trees, depth ≤ 20, split nodes of ≥ 2 samples, 2 features per split: the settings
    /// of leg_tracker's OpenCV random forest. Seed 1.
    fn default() -> Self {
        ForestParams {
            n_trees: 100,
            max_depth: 20,
            min_samples_split: 2,
            features_per_split: 2,
            seed: 1,
        }
    }
}

/// A trained forest.
#[derive(Debug, Serialize, Deserialize)]
pub struct Forest {
    pub params: ForestParams,
    pub features: usize,
    trees: Vec<Tree>,
}

fn matrix(x: &[Vec<f64>], width: usize) -> Result<DenseMatrix<f64>, ForestError> {
    for (row, r) in x.iter().enumerate() {
        if r.len() != width {
            return Err(ForestError::Width {
                row,
                got: r.len(),
                expected: width,
            });
        }
    }
    DenseMatrix::from_2d_vec(&x.to_vec()).map_err(|e| ForestError::Crate(e.to_string()))
}

impl Forest {
    /// Fit on samples `x` (rows of equal width) with labels `y` (true = positive).
    pub fn fit(x: &[Vec<f64>], y: &[bool], params: ForestParams) -> Result<Forest, ForestError> {
        let positives = y.iter().filter(|&&v| v).count();
        let negatives = y.len() - positives;
        if positives == 0 || negatives == 0 || x.len() != y.len() {
            return Err(ForestError::OneClass {
                positives,
                negatives,
            });
        }
        let features = x[0].len();
        let m = matrix(x, features)?;
        let labels: Vec<i32> = y.iter().map(|&v| i32::from(v)).collect();
        let trees = (0..params.n_trees)
            .map(|i| {
                let p = RandomForestClassifierParameters::default()
                    .with_n_trees(1)
                    .with_max_depth(params.max_depth)
                    .with_min_samples_split(params.min_samples_split)
                    .with_m(params.features_per_split.clamp(1, features))
                    .with_seed(params.seed.wrapping_add(u64::from(i)));
                Tree::fit(&m, &labels, p).map_err(|e| ForestError::Crate(e.to_string()))
            })
            .collect::<Result<Vec<Tree>, ForestError>>()?;
        Ok(Forest {
            params,
            features,
            trees,
        })
    }

    /// The positive-class probability (fraction of trees voting positive) of each row.
    pub fn probability(&self, x: &[Vec<f64>]) -> Result<Vec<f64>, ForestError> {
        if x.is_empty() {
            return Ok(Vec::new());
        }
        let m = matrix(x, self.features)?;
        let mut votes = vec![0u32; m.shape().0];
        for t in &self.trees {
            let p = t
                .predict(&m)
                .map_err(|e| ForestError::Crate(e.to_string()))?;
            for (v, c) in votes.iter_mut().zip(p) {
                *v += u32::from(c == 1);
            }
        }
        let n = self.trees.len().max(1) as f64;
        Ok(votes.into_iter().map(|v| f64::from(v) / n).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small() -> ForestParams {
        ForestParams {
            n_trees: 15,
            ..ForestParams::default()
        }
    }

    /// Two classes apart on the first feature (second feature noise-free junk): every
    /// training and held-out point is classified with probability exactly 1 or 0.
    #[test]
    fn separable_set_is_separated_perfectly() {
        let mut x = Vec::new();
        let mut y = Vec::new();
        for i in 0..20 {
            let f = f64::from(i);
            x.push(vec![f * 0.1, (f * 7.0) % 3.0]);
            y.push(false);
            x.push(vec![10.0 + f * 0.1, (f * 5.0) % 3.0]);
            y.push(true);
        }
        let forest = Forest::fit(&x, &y, small()).expect("fit");
        let p = forest.probability(&x).expect("predict");
        for (pi, yi) in p.iter().zip(&y) {
            assert_eq!(*pi, if *yi { 1.0 } else { 0.0 });
        }
        let held = forest
            .probability(&[vec![0.5, 1.0], vec![11.0, 2.0]])
            .expect("predict");
        assert_eq!(held, vec![0.0, 1.0]);
    }

    fn overlapping() -> (Vec<Vec<f64>>, Vec<bool>) {
        let mut x = Vec::new();
        let mut y = Vec::new();
        for i in 0..60 {
            let f = f64::from(i);
            x.push(vec![(f * 0.37) % 5.0, (f * 0.61) % 3.0, f % 4.0]);
            y.push((f * 0.37) % 5.0 + (f * 0.61) % 3.0 > 3.5);
        }
        (x, y)
    }

    #[test]
    fn same_seed_same_forest_and_json_round_trip_predicts_the_same() {
        let (x, y) = overlapping();
        let a = Forest::fit(&x, &y, small()).expect("fit");
        let b = Forest::fit(&x, &y, small()).expect("fit");
        let pa = a.probability(&x).expect("p");
        assert_eq!(pa, b.probability(&x).expect("p"));
        let json = serde_json::to_string(&a).expect("save");
        let c: Forest = serde_json::from_str(&json).expect("load");
        assert_eq!(pa, c.probability(&x).expect("p"));
        // a different seed gives other trees (a check that the seed reaches them)
        let d = Forest::fit(
            &x,
            &y,
            ForestParams {
                seed: 99,
                ..small()
            },
        )
        .expect("fit");
        assert_ne!(
            serde_json::to_string(&d).expect("save"),
            json,
            "seed ignored"
        );
    }

    #[test]
    fn one_class_and_ragged_rows_are_errors() {
        let x = vec![vec![1.0], vec![2.0]];
        assert!(matches!(
            Forest::fit(&x, &[true, true], small()),
            Err(ForestError::OneClass { .. })
        ));
        let ragged = vec![vec![1.0], vec![2.0, 3.0]];
        assert!(matches!(
            Forest::fit(&ragged, &[true, false], small()),
            Err(ForestError::Width { row: 1, .. })
        ));
    }
}

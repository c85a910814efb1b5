//! The learning protocol the sub-experiments share (section 4.4): seeded random train/test
//! splits of the frames, and the 3-H-1 network fitted on a training set — or the loaded model.

use rand::seq::SliceRandom;

use super::dataset::Dataset;
use super::params::Params;
use crate::learn::mlp::{Regressor, TrainSpec};
use crate::rng;

/// Split `idx` with the seeded stream `(seed, "split", s)`: a shuffled training part of
/// `round(n · fraction)` indices and the rest for testing.
pub fn split(seed: u64, fraction: f64, s: usize, idx: &[usize]) -> (Vec<usize>, Vec<usize>) {
    let mut r = rng::stream(seed, "split", s as u64);
    let mut v = idx.to_vec();
    v.shuffle(&mut r);
    let n_train = ((v.len() as f64) * fraction).round() as usize;
    let test = v.split_off(n_train);
    (v, test)
}

/// Fewest training frames a split may leave: from one frame min–max scaling maps every
/// input to 0.5 and the network learns a constant.
pub const MIN_TRAIN: usize = 2;

/// Features and distances of the dataset with the protocol's parameters.
pub struct Learner<'a> {
    pub xs: Vec<Vec<f64>>,
    pub dist: Vec<f64>,
    pub spec: TrainSpec,
    seed: u64,
    fraction: f64,
    /// A loaded model replaces every fit of the main protocol.
    pub loaded: Option<&'a Regressor>,
}

impl<'a> Learner<'a> {
    /// The learner of `data` (see [`Learner::of`]).
    pub fn new(data: &Dataset, p: &Params, loaded: Option<&'a Regressor>) -> Learner<'a> {
        Learner::of(data.xs(), data.distances(), p, loaded)
    }

    /// The learner of feature vectors `xs` and distances `dist`.
    pub fn of(
        xs: Vec<Vec<f64>>,
        dist: Vec<f64>,
        p: &Params,
        loaded: Option<&'a Regressor>,
    ) -> Learner<'a> {
        Learner {
            xs,
            dist,
            spec: p.spec(),
            seed: p.seed,
            fraction: p.train_fraction,
            loaded,
        }
    }

    /// Every frame's index.
    pub fn all(&self) -> Vec<usize> {
        (0..self.xs.len()).collect()
    }

    pub fn split(&self, s: usize, idx: &[usize]) -> (Vec<usize>, Vec<usize>) {
        split(self.seed, self.fraction, s, idx)
    }

    /// A network fitted on `train` with the seeded stream `(seed, "net", label)`.
    pub fn fit(&self, train: &[usize], label: u64, spec: TrainSpec) -> anyhow::Result<Regressor> {
        let tx: Vec<Vec<f64>> = train.iter().map(|i| self.xs[*i].clone()).collect();
        let ty: Vec<f64> = train.iter().map(|i| self.dist[*i]).collect();
        Regressor::fit(&tx, &ty, spec, &mut rng::stream(self.seed, "net", label)).map_err(|e| {
            anyhow::anyhow!(
                "training a network on {} frames: {e} (see params.train_fraction, params.epochs, params.hidden_units)",
                train.len()
            )
        })
    }

    /// The loaded model, or the main protocol's network fitted on `train`.
    pub fn model(&self, train: &[usize], label: u64) -> anyhow::Result<Regressor> {
        match self.loaded {
            Some(m) => Ok(m.clone()),
            None => self.fit(train, label, self.spec),
        }
    }

    /// Check that `params.train_fraction` leaves at least [`MIN_TRAIN`] training frames and one
    /// test frame of `n` frames (`what` names them in the error: "the 684 frames").
    pub fn check_fraction(&self, n: usize, what: &str) -> anyhow::Result<()> {
        let n_train = ((n as f64) * self.fraction).round() as usize;
        if n_train < MIN_TRAIN || n_train >= n {
            anyhow::bail!(
                "params.train_fraction = {} splits {what} ({n}) into {n_train} training and {} test frames; \
                 need at least {MIN_TRAIN} to train and 1 to test",
                self.fraction,
                n - n_train.min(n)
            );
        }
        Ok(())
    }

    /// Absolute distance errors of `m` on the frames `idx`.
    pub fn errors(&self, m: &Regressor, idx: &[usize]) -> Vec<f64> {
        idx.iter()
            .map(|i| (m.predict(&self.xs[*i]) - self.dist[*i]).abs())
            .collect()
    }
}

/// Split 0 and its model, used by the correlations (fig. 5) and the Kalman experiment.
pub struct Split0 {
    pub train: Vec<usize>,
    pub test: Vec<usize>,
    pub model: Regressor,
}

impl Split0 {
    pub fn new(l: &Learner) -> anyhow::Result<Split0> {
        let (train, test) = l.split(0, &l.all());
        let model = l.model(&train, 0)?;
        Ok(Split0 { train, test, model })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_split_partitions_the_indices_with_the_rounded_fraction_and_is_seeded() {
        let idx: Vec<usize> = (10..30).collect();
        let (train, test) = split(7, 0.3, 0, &idx);
        assert_eq!((train.len(), test.len()), (6, 14));
        let mut both: Vec<usize> = train.iter().chain(&test).copied().collect();
        both.sort_unstable();
        assert_eq!(both, idx);
        assert_eq!(split(7, 0.3, 0, &idx), (train.clone(), test));
        assert_ne!(
            split(7, 0.3, 1, &idx).0,
            train,
            "another split, another draw"
        );
        assert_eq!(split(7, 0.25, 0, &[1, 2]).0.len(), 1, "0.5 rounds up");
    }
}

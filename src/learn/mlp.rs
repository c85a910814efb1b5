//! A small multi-layer feed-forward network trained by back-propagation, as seed 000 uses it to
//! map depth-cue features to distance (section 4.4): inputs → one hidden layer of logistic
//! units → one linear output, squared error, online (per-sample) gradient descent with a fixed
//! learning rate, samples shuffled every epoch by a seeded generator.
//!
//! Written here rather than taken from a crate: the deep-learning crates (burn, candle, tch)
//! are heavy to build and make the paper's exact protocol (plain online back-propagation, one
//! learning rate, no momentum) harder to state; this network has a few dozen weights.
//!
//! [`Normalizer`] maps each input (and the target) to [0, 1] using the training data's range,
//! so one learning rate suits features of different units.

use rand::RngExt;
use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

fn sigmoid(x: f64) -> f64 {
    1.0 / (1.0 + (-x).exp())
}

/// Inputs → `hidden` logistic units → one linear output.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Mlp {
    pub inputs: usize,
    pub hidden: usize,
    /// `hidden × (inputs + 1)`, bias last in each row.
    pub w1: Vec<f64>,
    /// `hidden + 1`, bias last.
    pub w2: Vec<f64>,
}

impl Mlp {
    /// Weights uniform in ±0.5 from `rng`.
    pub fn new(inputs: usize, hidden: usize, rng: &mut ChaCha8Rng) -> Mlp {
        let mut w = |n: usize| {
            (0..n)
                .map(|_| rng.random::<f64>() - 0.5)
                .collect::<Vec<_>>()
        };
        Mlp {
            inputs,
            hidden,
            w1: w(hidden * (inputs + 1)),
            w2: w(hidden + 1),
        }
    }

    fn hidden_out(&self, x: &[f64], h: &mut [f64]) {
        for (j, hj) in h.iter_mut().enumerate() {
            let row = &self.w1[j * (self.inputs + 1)..(j + 1) * (self.inputs + 1)];
            let a: f64 = row[..self.inputs]
                .iter()
                .zip(x)
                .map(|(w, v)| w * v)
                .sum::<f64>()
                + row[self.inputs];
            *hj = sigmoid(a);
        }
    }

    pub fn forward(&self, x: &[f64]) -> f64 {
        let mut h = vec![0.0; self.hidden];
        self.hidden_out(x, &mut h);
        h.iter().zip(&self.w2).map(|(a, w)| a * w).sum::<f64>() + self.w2[self.hidden]
    }

    /// One gradient step on one sample (loss ½(y − ŷ)²).
    #[allow(clippy::needless_range_loop)] // j indexes w1 rows, w2 and h together
    pub fn step(&mut self, x: &[f64], y: f64, lr: f64) {
        let mut h = vec![0.0; self.hidden];
        self.hidden_out(x, &mut h);
        let out: f64 =
            h.iter().zip(&self.w2).map(|(a, w)| a * w).sum::<f64>() + self.w2[self.hidden];
        let err = out - y;
        for j in 0..self.hidden {
            let delta = err * self.w2[j] * h[j] * (1.0 - h[j]);
            let row = &mut self.w1[j * (self.inputs + 1)..(j + 1) * (self.inputs + 1)];
            for (w, v) in row[..self.inputs].iter_mut().zip(x) {
                *w -= lr * delta * v;
            }
            row[self.inputs] -= lr * delta;
        }
        for j in 0..self.hidden {
            self.w2[j] -= lr * err * h[j];
        }
        self.w2[self.hidden] -= lr * err;
    }

    /// `epochs` passes over the samples in a fresh random order each time.
    pub fn train(
        &mut self,
        xs: &[Vec<f64>],
        ys: &[f64],
        lr: f64,
        epochs: usize,
        rng: &mut ChaCha8Rng,
    ) {
        let mut order: Vec<usize> = (0..xs.len()).collect();
        for _ in 0..epochs {
            order.shuffle(rng);
            for &i in &order {
                self.step(&xs[i], ys[i], lr);
            }
        }
    }
}

/// Min–max scaling to [0, 1] per input, fitted on training data (constant inputs map to 0.5).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Normalizer {
    pub min: Vec<f64>,
    pub max: Vec<f64>,
}

impl Normalizer {
    pub fn fit(rows: &[Vec<f64>]) -> Normalizer {
        let n = rows.first().map_or(0, Vec::len);
        let mut min = vec![f64::INFINITY; n];
        let mut max = vec![f64::NEG_INFINITY; n];
        for r in rows {
            for k in 0..n {
                min[k] = min[k].min(r[k]);
                max[k] = max[k].max(r[k]);
            }
        }
        Normalizer { min, max }
    }

    pub fn apply(&self, row: &[f64]) -> Vec<f64> {
        row.iter()
            .zip(self.min.iter().zip(&self.max))
            .map(|(v, (lo, hi))| if hi > lo { (v - lo) / (hi - lo) } else { 0.5 })
            .collect()
    }

    pub fn invert1(&self, v: f64) -> f64 {
        self.min[0] + v * (self.max[0] - self.min[0])
    }
}

/// A trained regressor: input and target scaling around the network.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Regressor {
    pub input: Normalizer,
    pub target: Normalizer,
    pub net: Mlp,
}

/// Training settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TrainSpec {
    pub hidden: usize,
    pub learning_rate: f64,
    pub epochs: usize,
}

/// Why a network cannot be trained: degenerate data or settings (never a panic).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MlpError {
    #[error("no training rows")]
    NoRows,
    #[error("{xs} feature rows but {ys} targets")]
    LengthMismatch { xs: usize, ys: usize },
    #[error("feature row {row} has {len} values, row 0 has {first}")]
    Ragged {
        row: usize,
        len: usize,
        first: usize,
    },
    #[error("rows have no features")]
    NoFeatures,
    #[error("zero epochs leave the network untrained")]
    NoEpochs,
    #[error("a network needs at least one hidden unit")]
    NoHidden,
    #[error("learning rate {0} is not a finite positive number")]
    BadLearningRate(f64),
}

impl TrainSpec {
    /// Check the settings: at least one hidden unit and one epoch, a finite positive rate.
    pub fn validate(&self) -> Result<(), MlpError> {
        if self.hidden == 0 {
            return Err(MlpError::NoHidden);
        }
        if self.epochs == 0 {
            return Err(MlpError::NoEpochs);
        }
        if !(self.learning_rate.is_finite() && self.learning_rate > 0.0) {
            return Err(MlpError::BadLearningRate(self.learning_rate));
        }
        Ok(())
    }
}

impl Regressor {
    /// Fit on `(xs, ys)` with a seeded generator (initial weights and sample order). Empty or
    /// ragged data and degenerate settings are errors.
    pub fn fit(
        xs: &[Vec<f64>],
        ys: &[f64],
        spec: TrainSpec,
        rng: &mut ChaCha8Rng,
    ) -> Result<Regressor, MlpError> {
        spec.validate()?;
        if xs.len() != ys.len() {
            return Err(MlpError::LengthMismatch {
                xs: xs.len(),
                ys: ys.len(),
            });
        }
        let first = xs.first().ok_or(MlpError::NoRows)?.len();
        if first == 0 {
            return Err(MlpError::NoFeatures);
        }
        if let Some((row, r)) = xs.iter().enumerate().find(|(_, r)| r.len() != first) {
            return Err(MlpError::Ragged {
                row,
                len: r.len(),
                first,
            });
        }
        let input = Normalizer::fit(xs);
        let target = Normalizer::fit(&ys.iter().map(|y| vec![*y]).collect::<Vec<_>>());
        let xn: Vec<Vec<f64>> = xs.iter().map(|x| input.apply(x)).collect();
        let yn: Vec<f64> = ys.iter().map(|y| target.apply(&[*y])[0]).collect();
        let mut net = Mlp::new(input.min.len(), spec.hidden, rng);
        net.train(&xn, &yn, spec.learning_rate, spec.epochs, rng);
        Ok(Regressor { input, target, net })
    }

    pub fn predict(&self, x: &[f64]) -> f64 {
        self.target.invert1(self.net.forward(&self.input.apply(x)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng;

    /// Regression (issue 19): no rows, zero epochs and ragged rows were an index out of
    /// bounds or an untrained network; now each is its error.
    #[test]
    fn degenerate_training_is_an_error() {
        let mut r = rng::stream(3, "t", 0);
        let spec = TrainSpec {
            hidden: 2,
            learning_rate: 0.3,
            epochs: 5,
        };
        let fit = |xs: &[Vec<f64>], ys: &[f64], spec, r: &mut ChaCha8Rng| {
            Regressor::fit(xs, ys, spec, r).map(|_| ())
        };
        assert_eq!(fit(&[], &[], spec, &mut r), Err(MlpError::NoRows));
        let zero = TrainSpec { epochs: 0, ..spec };
        assert_eq!(
            fit(&[vec![1.0]], &[1.0], zero, &mut r),
            Err(MlpError::NoEpochs)
        );
        let ragged = [vec![1.0, 2.0], vec![1.0]];
        assert_eq!(
            fit(&ragged, &[1.0, 2.0], spec, &mut r),
            Err(MlpError::Ragged {
                row: 1,
                len: 1,
                first: 2
            })
        );
        assert_eq!(
            fit(&[vec![1.0]], &[1.0, 2.0], spec, &mut r),
            Err(MlpError::LengthMismatch { xs: 1, ys: 2 })
        );
        assert_eq!(fit(&[vec![1.0]], &[1.0], spec, &mut r), Ok(()));
    }

    #[test]
    fn gradient_matches_finite_differences() {
        let mut r = rng::stream(1, "t", 0);
        let net = Mlp::new(3, 4, &mut r);
        let (x, y) = ([0.2, -0.4, 0.9], 0.3);
        let loss = |n: &Mlp| 0.5 * (n.forward(&x) - y).powi(2);
        // a step of lr on each weight equals −lr × gradient; compare with central differences
        let lr = 1e-6;
        let mut stepped = net.clone();
        stepped.step(&x, y, lr);
        for k in 0..net.w1.len() {
            let g_bp = (net.w1[k] - stepped.w1[k]) / lr;
            let (mut a, mut b) = (net.clone(), net.clone());
            a.w1[k] += 1e-6;
            b.w1[k] -= 1e-6;
            let g_fd = (loss(&a) - loss(&b)) / 2e-6;
            assert!((g_bp - g_fd).abs() < 1e-6, "w1[{k}]: {g_bp} vs {g_fd}");
        }
        for k in 0..net.w2.len() {
            let g_bp = (net.w2[k] - stepped.w2[k]) / lr;
            let (mut a, mut b) = (net.clone(), net.clone());
            a.w2[k] += 1e-6;
            b.w2[k] -= 1e-6;
            assert!((g_bp - (loss(&a) - loss(&b)) / 2e-6).abs() < 1e-6);
        }
    }

    /// The network learns a smooth function of three inputs to a stated error: RMSE below
    /// 0.03 on held-out points of y = sin(2x₁) + 0.5 x₂² − 0.3 x₃ over [0, 1]³ (range ≈ 1.4).
    #[test]
    fn learns_a_known_smooth_function() {
        let mut r = rng::stream(2, "t", 0);
        let f = |x: &[f64]| (2.0 * x[0]).sin() + 0.5 * x[1] * x[1] - 0.3 * x[2];
        let pts: Vec<Vec<f64>> = (0..600)
            .map(|_| (0..3).map(|_| r.random::<f64>()).collect())
            .collect();
        let ys: Vec<f64> = pts.iter().map(|p| f(p)).collect();
        let model = Regressor::fit(
            &pts[..400],
            &ys[..400],
            TrainSpec {
                hidden: 6,
                learning_rate: 0.3,
                epochs: 1500,
            },
            &mut r,
        )
        .expect("valid data");
        let mse: f64 = pts[400..]
            .iter()
            .zip(&ys[400..])
            .map(|(p, y)| (model.predict(p) - y).powi(2))
            .sum::<f64>()
            / 200.0;
        assert!(mse.sqrt() < 0.03, "rmse {}", mse.sqrt());
    }
}

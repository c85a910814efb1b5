//! Bayesian re-identification of people from local tracks (seed 003 §IV, Zajdel, Zivkovic &
//! Kröse, "Keeping track of humans: have I seen this person before?").
//!
//! Each local track is one observation y_k = {o_k, d_k}: o_k an r-D appearance feature, d_k
//! when the person entered and left the view. The generative model (eqs. 1–9): a label s_k
//! uniform over the c_{k−1} people seen so far and one new person (eq. 2); counter and
//! pointers z_k^{(n)} to each person's last observation, updated deterministically (eqs. 3–5);
//! the person's kernel x = {m, V} copied from their last observation or drawn from the
//! Normal–Inverse-Wishart prior π(x) = N(m; a₀, κ₀V)·IW(V; η₀, C₀) (eqs. 1, 6–7); o_k ~ N(m, V)
//! and d_k ~ P_δ(d_k | d_{last}) (eqs. 8–9), with the paper's P_δ = 0 when a track starts
//! before the person's previous track ended.
//!
//! Inference is the paper's assumed-density filter (eqs. 10–12): the filtered density is kept
//! as q(s_k, c_k)·∏ q_k(x_i)·q(z_k^{(i)}), and after each observation the exact one-step
//! posterior is projected back onto that family by its marginals. The paper leaves the
//! marginals to its reference [20] (not available here); what is derived and written by hand
//! in this module, and why:
//!
//! - The joint over (c_{k−1}, s_k, z_k^{(s_k)}) is enumerated with the predicted pointers and
//!   the consistency of the model: a known person (s_k ≤ c_{k−1}) has been seen (z > 0), a new
//!   one (s_k = c_{k−1} + 1) has not (z = 0).
//! - A kernel that observation k may share becomes a mixture of "updated with o_k" and
//!   "unchanged"; its projection onto the NIW family in the KL sense matches the expected
//!   sufficient statistics E[V⁻¹], E[V⁻¹m], E[mᵀV⁻¹m] and E[log|V|] (the last one solved for
//!   the degrees of freedom by bisection). [`Niw::project`] does this; no crate offers it.
//! - The NIW posterior update and its Student-t predictive are the closed forms of Gelman et
//!   al., *Bayesian Data Analysis*, §3.6; the Student-t density itself is `statrs`'
//!   `MultivariateStudent`.
//!
//! κ₀ in the paper scales the covariance of m (N(m; a₀, κ₀V)), so Gelman's prior
//! "number of observations" is λ₀ = 1/κ₀; the inverse-Wishart follows Gelman's convention
//! (E[V] = C/(η − r − 1)).

use nalgebra::{DMatrix, DVector};
use statrs::distribution::{Continuous, MultivariateStudent};
use statrs::function::gamma::digamma;

#[cfg(test)]
mod tests;

/// A Normal–Inverse-Wishart density over a kernel {m, V} (Gelman's parameters): m | V ~
/// N(mean, V/lambda), V ~ IW(nu, psi).
#[derive(Debug, Clone, PartialEq)]
pub struct Niw {
    pub mean: DVector<f64>,
    pub lambda: f64,
    pub nu: f64,
    pub psi: DMatrix<f64>,
}

/// The prior of seed 003 §V: a₀ = 0, κ₀ = 100, η₀ = r, C₀ = 10⁻³·I (r = 9 in the paper).
#[derive(Debug, Clone, PartialEq)]
pub struct Prior {
    pub a0: Vec<f64>,
    pub kappa0: f64,
    pub eta0: f64,
    /// C₀ = c0·I.
    pub c0: f64,
}

impl Prior {
    /// The paper's values for `r`-dimensional features.
    pub fn paper(r: usize) -> Prior {
        Prior {
            a0: vec![0.0; r],
            kappa0: 100.0,
            eta0: r as f64,
            c0: 1e-3,
        }
    }

    /// The prior moved to the units of the features (our addition, not in the paper), fitted
    /// on `people` (looks grouped by person); η₀ stays, r = the looks' dimension:
    /// - a₀ at the mean of every look;
    /// - κ₀ = s_b²/s_w² (at least [`KAPPA0_MIN`]): the printed prior draws a person's mean as
    ///   m ~ N(a₀, κ₀V), so κ₀ is the spread of people's means over the spread of one person's
    ///   looks. s_w² is the pooled within-person variance per dimension (a person seen once
    ///   adds nothing to it), s_b² the variance of the people's mean looks per dimension less
    ///   the part their own looks' noise explains (s_w² times the mean of 1/looks);
    /// - C₀ = c·I with c such that a kernel seen once predicts the person's next look with the
    ///   spread of the difference of two looks: its Student-t scale ψ₁(λ₁ + 1)/(λ₁·ν), λ₁ =
    ///   1/κ₀ + 1 and ν = η₀ − r + 2, equal to 2·s_w² along every direction the one look does
    ///   not fix, i.e. c = 2·s_w²·λ₁·ν/(λ₁ + 1).
    ///
    /// `None` without two looks of one person or two people, or with looks of another
    /// dimension.
    pub fn moved(&self, people: &[Vec<Vec<f64>>]) -> Option<Moved> {
        let r = self.a0.len();
        let all: Vec<&Vec<f64>> = people.iter().flatten().collect();
        if all.is_empty() || all.iter().any(|o| o.len() != r) || people.len() < 2 {
            return None;
        }
        let mean_of = |looks: &[&Vec<f64>]| -> Vec<f64> {
            (0..r)
                .map(|j| looks.iter().map(|o| o[j]).sum::<f64>() / looks.len() as f64)
                .collect()
        };
        let a0 = mean_of(&all);
        let means: Vec<Vec<f64>> = people
            .iter()
            .filter(|l| !l.is_empty())
            .map(|l| mean_of(&l.iter().collect::<Vec<_>>()))
            .collect();
        let (mut sum, mut dof) = (0.0, 0usize);
        for (looks, m) in people.iter().filter(|l| !l.is_empty()).zip(&means) {
            for j in 0..r {
                sum += looks.iter().map(|o| (o[j] - m[j]).powi(2)).sum::<f64>();
            }
            dof += looks.len() - 1;
        }
        if dof == 0 || means.len() < 2 {
            return None;
        }
        let within_var = sum / (dof * r) as f64;
        let centre = mean_of(&means.iter().collect::<Vec<_>>());
        let spread: f64 = means
            .iter()
            .map(|m| (0..r).map(|j| (m[j] - centre[j]).powi(2)).sum::<f64>())
            .sum::<f64>()
            / (r * (means.len() - 1)) as f64;
        let noise = within_var
            * people
                .iter()
                .filter(|l| !l.is_empty())
                .map(|l| 1.0 / l.len() as f64)
                .sum::<f64>()
            / means.len() as f64;
        let between_var = (spread - noise).max(0.0);
        let kappa0 = (between_var / within_var).max(KAPPA0_MIN);
        let (lambda1, nu) = (1.0 / kappa0 + 1.0, self.eta0 - r as f64 + 2.0);
        Some(Moved {
            prior: Prior {
                a0,
                kappa0,
                eta0: self.eta0,
                c0: 2.0 * within_var * lambda1 * nu / (lambda1 + 1.0),
            },
            within_sd: within_var.sqrt(),
            between_sd: between_var.sqrt(),
            observations: all.len(),
            people: means.len(),
        })
    }

    pub fn niw(&self) -> Niw {
        let r = self.a0.len();
        Niw {
            mean: DVector::from_column_slice(&self.a0),
            lambda: 1.0 / self.kappa0,
            nu: self.eta0,
            psi: DMatrix::identity(r, r) * self.c0,
        }
    }
}

/// The smallest κ₀ a moved prior takes: people's means spread at least as much as one
/// person's looks (a priori: with less, appearance could not tell people apart at all).
pub const KAPPA0_MIN: f64 = 1.0;

/// A prior moved to the features' units ([`Prior::moved`]) and what it was fitted on.
#[derive(Debug, Clone, PartialEq)]
pub struct Moved {
    pub prior: Prior,
    /// s_w, the pooled within-person standard deviation per dimension.
    pub within_sd: f64,
    /// s_b, the standard deviation of the people's means per dimension (noise removed).
    pub between_sd: f64,
    pub observations: usize,
    pub people: usize,
}

/// Why a kernel cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReidError {
    #[error("feature of dimension {got}, the prior has {want}")]
    Dimension { want: usize, got: usize },
    #[error("feature holds a NaN or infinite value")]
    NotFinite,
    #[error("the kernel's scale matrix is not positive definite (degenerate features?)")]
    Degenerate,
}

impl Niw {
    pub fn dim(&self) -> usize {
        self.mean.len()
    }

    /// The posterior after one more observation `o` (Gelman et al. §3.6).
    pub fn updated(&self, o: &DVector<f64>) -> Niw {
        let diff = o - &self.mean;
        let lambda = self.lambda + 1.0;
        let psi = &self.psi + (&diff * diff.transpose()) * (self.lambda / lambda);
        Niw {
            mean: (&self.mean * self.lambda + o) / lambda,
            lambda,
            nu: self.nu + 1.0,
            psi: symmetric(psi),
        }
    }

    /// The Student-t predictive density of one more observation: t_{ν−r+1}(mean,
    /// ψ(λ+1)/(λ(ν−r+1))), as its log.
    pub fn ln_predictive(&self, o: &DVector<f64>) -> Result<f64, ReidError> {
        let r = self.dim() as f64;
        let dof = self.nu - r + 1.0;
        let scale = &self.psi * ((self.lambda + 1.0) / (self.lambda * dof));
        let t = MultivariateStudent::new_from_nalgebra(self.mean.clone(), symmetric(scale), dof)
            .map_err(|_| ReidError::Degenerate)?;
        Ok(t.ln_pdf(o))
    }

    /// E[log|V|] under IW(ν, ψ): log|ψ| − Σᵢ ψ((ν − i + 1)/2) − r·log 2.
    fn expected_ln_det(&self) -> Option<f64> {
        let chol = self.psi.clone().cholesky()?;
        let ln_det: f64 = chol.l().diagonal().iter().map(|d| 2.0 * d.ln()).sum();
        Some(ln_det - digamma_sum(self.nu, self.dim()) - self.dim() as f64 * 2f64.ln())
    }

    /// The member of the NIW family nearest in KL to the mixture Σ wᵢ·NIWᵢ (weights
    /// normalised here): it matches the mixture's expected sufficient statistics.
    pub fn project(mixture: &[(f64, &Niw)]) -> Result<Niw, ReidError> {
        let total: f64 = mixture.iter().map(|(w, _)| w).sum();
        let parts: Vec<(f64, &Niw)> = mixture
            .iter()
            .filter(|(w, _)| *w > 0.0)
            .map(|&(w, n)| (w / total, n))
            .collect();
        if let [(_, only)] = parts.as_slice() {
            return Ok((*only).clone());
        }
        let r = parts.first().map_or(0, |(_, n)| n.dim());
        let (mut a, mut b) = (DMatrix::zeros(r, r), DVector::zeros(r));
        let (mut s, mut l) = (0.0, 0.0);
        for &(w, n) in &parts {
            let prec = n.psi.clone().try_inverse().ok_or(ReidError::Degenerate)? * n.nu;
            let pm = &prec * &n.mean;
            s += w * (r as f64 / n.lambda + n.mean.dot(&pm));
            a += prec * w;
            b += pm * w;
            l += w * n.expected_ln_det().ok_or(ReidError::Degenerate)?;
        }
        let a = symmetric(a);
        let a_inv = a.clone().try_inverse().ok_or(ReidError::Degenerate)?;
        let mean = &a_inv * &b;
        let spread = s - b.dot(&mean);
        if spread.is_nan() || spread <= 0.0 {
            return Err(ReidError::Degenerate);
        }
        let lambda = r as f64 / spread;
        // E[log|V|] = r·log ν − log|A| − Σψ(·) − r·log 2 with ψ = ν·A⁻¹: decreasing in ν
        let ln_det_a: f64 = a
            .clone()
            .cholesky()
            .ok_or(ReidError::Degenerate)?
            .l()
            .diagonal()
            .iter()
            .map(|d| 2.0 * d.ln())
            .sum();
        let f =
            |nu: f64| r as f64 * nu.ln() - ln_det_a - digamma_sum(nu, r) - r as f64 * 2f64.ln() - l;
        let (mut lo, mut hi) = (r as f64 - 1.0 + 1e-9, 1e9);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if f(mid) > 0.0 { lo = mid } else { hi = mid }
        }
        let nu = 0.5 * (lo + hi);
        Ok(Niw {
            mean,
            lambda,
            nu,
            psi: symmetric(a_inv * nu),
        })
    }
}

/// Σᵢ₌₁ʳ ψ((ν − i + 1)/2).
fn digamma_sum(nu: f64, r: usize) -> f64 {
    (1..=r).map(|i| digamma((nu - i as f64 + 1.0) / 2.0)).sum()
}

fn symmetric(m: DMatrix<f64>) -> DMatrix<f64> {
    (&m + m.transpose()) * 0.5
}

/// When a local track was seen: entered and left the view (seconds).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Span {
    pub enter: f64,
    pub leave: f64,
}

/// The paper's spatio-temporal transition P_δ(d_k | d_i): 0 when track k starts before the
/// person's previous track i ended, 1 otherwise.
pub fn transition(previous: Span, next: Span) -> f64 {
    if next.enter <= previous.leave {
        0.0
    } else {
        1.0
    }
}

/// The ADF filter's answer for one observation.
#[derive(Debug, Clone, PartialEq)]
pub struct Labelled {
    /// The most likely label (1-based person slot, the paper's s_k).
    pub label: usize,
    /// q(s_k = n) for n = 1..=k (index n − 1).
    pub label_marginal: Vec<f64>,
    /// The most likely number of distinct people so far (c_k).
    pub people: usize,
}

/// Whether the filter uses the appearance and the spatio-temporal terms (for baselines).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Terms {
    pub appearance: bool,
    pub spatio_temporal: bool,
}

impl Default for Terms {
    fn default() -> Terms {
        Terms {
            appearance: true,
            spatio_temporal: true,
        }
    }
}

/// The assumed-density filter over observations in order (eqs. 10–12).
#[derive(Debug, Clone)]
pub struct ReidFilter {
    prior: Niw,
    terms: Terms,
    /// q(s_{k−1} = n, c_{k−1} = c) at `joint[c][n]` (0-based: c people ↔ index c − 1).
    joint: Vec<Vec<f64>>,
    /// q(z_{k−1}^{(n)} = i), i = 0 (not seen) or 1..k−1.
    pointers: Vec<Vec<f64>>,
    /// q(x_i) of each observation so far.
    kernels: Vec<Niw>,
    spans: Vec<Span>,
}

impl ReidFilter {
    pub fn new(prior: &Prior, terms: Terms) -> ReidFilter {
        ReidFilter {
            prior: prior.niw(),
            terms,
            joint: Vec::new(),
            pointers: Vec::new(),
            kernels: Vec::new(),
            spans: Vec::new(),
        }
    }

    /// Observations filtered so far.
    pub fn len(&self) -> usize {
        self.kernels.len()
    }

    pub fn is_empty(&self) -> bool {
        self.kernels.is_empty()
    }

    /// The pointers predicted for slice k (eqs. 4–5): person n's last observation becomes
    /// k − 1 with probability q(s_{k−1} = n).
    fn predicted_pointers(&self) -> Vec<Vec<f64>> {
        let k = self.len() + 1;
        let last_label = self.label_marginal();
        let mut out: Vec<Vec<f64>> = Vec::with_capacity(k);
        for n in 0..k {
            let mut z = vec![0.0; k];
            if n + 1 < k {
                let p = last_label.get(n).copied().unwrap_or(0.0);
                for (i, q) in self.pointers[n].iter().enumerate() {
                    z[i] = (1.0 - p) * q;
                }
                z[k - 1] += p;
            } else {
                z[0] = 1.0; // eq. 4: person k has not been seen before slice k
            }
            out.push(z);
        }
        out
    }

    /// q(s_{k−1} = n) for n = 1..=k−1.
    fn label_marginal(&self) -> Vec<f64> {
        let k = self.len();
        let mut m = vec![0.0; k];
        for row in &self.joint {
            for (n, p) in row.iter().enumerate() {
                m[n] += p;
            }
        }
        m
    }

    /// q(c_{k−1} = c) for c = 1..=k−1 (index c − 1); c₀ = 0 before the first observation.
    fn count_marginal(&self) -> Vec<(usize, f64)> {
        if self.joint.is_empty() {
            return vec![(0, 1.0)];
        }
        self.joint
            .iter()
            .enumerate()
            .map(|(c, row)| (c + 1, row.iter().sum()))
            .collect()
    }

    /// Filter one observation: appearance `o` and when it was seen.
    pub fn observe(&mut self, o: &[f64], span: Span) -> Result<Labelled, ReidError> {
        let r = self.prior.dim();
        if o.len() != r {
            return Err(ReidError::Dimension {
                want: r,
                got: o.len(),
            });
        }
        if o.iter().any(|v| !v.is_finite()) {
            return Err(ReidError::NotFinite);
        }
        let o = DVector::from_column_slice(o);
        let k = self.len() + 1;
        let z_pred = self.predicted_pointers();
        // log-likelihood of o_k and d_k if it continues observation i (0: a new kernel)
        let mut ln_like = vec![f64::NEG_INFINITY; k];
        for (i, slot) in ln_like.iter_mut().enumerate() {
            let kernel = if i == 0 {
                &self.prior
            } else {
                &self.kernels[i - 1]
            };
            let st = if i == 0 || !self.terms.spatio_temporal {
                1.0
            } else {
                transition(self.spans[i - 1], span)
            };
            if st > 0.0 {
                let app = if self.terms.appearance {
                    kernel.ln_predictive(&o)?
                } else {
                    0.0
                };
                *slot = app + st.ln();
            }
        }
        let shift = ln_like
            .iter()
            .copied()
            .filter(|v| v.is_finite())
            .fold(f64::NEG_INFINITY, f64::max);
        let like: Vec<f64> = ln_like.iter().map(|v| (v - shift).exp()).collect();
        // weight[c][n][i] of (c_{k−1} = c, s_k = n + 1, z_k^{(n+1)} = i), consistent only
        let counts = self.count_marginal();
        let mut joint_new = vec![vec![0.0; k]; k]; // q(s_k = n, c_k = c)
        let mut link = vec![vec![0.0; k]; k]; // Σ_c weight at [n][i]
        for &(c, qc) in &counts {
            for n in 0..=c {
                let new_person = n == c;
                for i in 0..k {
                    if (i == 0) != new_person {
                        continue;
                    }
                    let w = qc / (c as f64 + 1.0) * z_pred[n][i] * like[i];
                    if w > 0.0 {
                        let c_k = if new_person { c + 1 } else { c };
                        joint_new[c_k - 1][n] += w;
                        link[n][i] += w;
                    }
                }
            }
        }
        let total: f64 = joint_new.iter().flatten().sum();
        if !(total > 0.0 && total.is_finite()) {
            return Err(ReidError::Degenerate);
        }
        for row in joint_new.iter_mut() {
            for p in row.iter_mut() {
                *p /= total;
            }
        }
        for row in link.iter_mut() {
            for p in row.iter_mut() {
                *p /= total;
            }
        }
        self.update_kernels(&o, &link)?;
        // pointer marginals: person n's pointer is the link when s_k = n, else as predicted
        let label_post: Vec<f64> = link.iter().map(|row| row.iter().sum()).collect();
        self.pointers = (0..k)
            .map(|n| {
                (0..k)
                    .map(|i| link[n][i] + (1.0 - label_post[n]) * z_pred[n][i])
                    .collect()
            })
            .collect();
        self.joint = joint_new;
        self.spans.push(span);
        let label = argmax(&label_post) + 1;
        let people = argmax(
            &self
                .count_marginal()
                .iter()
                .map(|c| c.1)
                .collect::<Vec<_>>(),
        ) + 1;
        Ok(Labelled {
            label,
            label_marginal: label_post,
            people,
        })
    }

    /// Each earlier kernel i becomes "updated with o_k" with the probability that k links to
    /// it, and the new kernel is the mixture over what it links to; both projected (ADF).
    fn update_kernels(&mut self, o: &DVector<f64>, link: &[Vec<f64>]) -> Result<(), ReidError> {
        let k = self.len() + 1;
        let to: Vec<f64> = (0..k)
            .map(|i| link.iter().map(|row| row[i]).sum())
            .collect();
        let updated: Vec<Niw> = (0..k)
            .map(|i| {
                if i == 0 {
                    self.prior.updated(o)
                } else {
                    self.kernels[i - 1].updated(o)
                }
            })
            .collect();
        let new_kernel = Niw::project(
            &to.iter()
                .zip(&updated)
                .map(|(w, n)| (*w, n))
                .collect::<Vec<_>>(),
        )?;
        for i in 1..k {
            let w = to[i];
            if w > 0.0 {
                let kept = self.kernels[i - 1].clone();
                self.kernels[i - 1] = Niw::project(&[(w, &updated[i]), (1.0 - w, &kept)])?;
            }
        }
        self.kernels.push(new_kernel);
        Ok(())
    }
}

/// Index of the largest value (the first of ties).
fn argmax(v: &[f64]) -> usize {
    let mut best = 0;
    for (i, x) in v.iter().enumerate() {
        if *x > v[best] {
            best = i;
        }
    }
    best
}

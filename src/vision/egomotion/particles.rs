//! Seed 001 §IV (after Jung & Sukhatme, IAS 2004): a particle filter over the compensated
//! difference images and EM clustering of its particles.
//!
//! State: a particle is a direction `(θ, φ)` — azimuth and elevation in the omni camera frame.
//! The directions are chosen over the views' pixels because they are continuous across the
//! seams between neighbouring views (a person walking round the robot moves from one view to
//! the next without the filter noticing) and because the detection is a bearing, which is what
//! the caller compares with the truth and what the laser needs to find the range.
//!
//! One step: (1) prediction — a Gaussian random walk (σ_θ, σ_φ per frame), elevation clamped to
//! the band the views cover, and a fraction of particles redrawn uniformly over the band so
//! that new motion anywhere can be picked up; (2) weighting — each particle's weight is the
//! measurement's value at its direction (the thresholded difference averaged over a small
//! window, see `DiffField`); (3) EM clustering of the weighted particles (a 2-D Gaussian
//! mixture with azimuth differences wrapped to (−π, π]); the component with the largest mixing
//! weight is the detection; (4) systematic resampling from a seeded stream.
//!
//! Number of clusters: EM is run for `k = 1..=k_max` and the `k` with the smallest BIC wins,
//! the sample size being the particles' effective number `1/Σw²` (weights normalised). When
//! every particle weighs zero (no difference above the threshold anywhere a particle looks)
//! there is no detection and the particles are left as predicted.

use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use super::views::wrap_angle;

/// What the particles are weighed against: a non-negative value per direction.
pub trait DiffField {
    /// Value at azimuth `θ`, elevation `φ` (rad, omni camera frame); 0 where nothing is seen.
    fn value(&self, azimuth: f64, elevation: f64) -> f64;
}

/// Particle filter and EM settings.
#[derive(Debug, Clone, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct ParticleParams {
    pub particles: usize,
    /// Random-walk standard deviation of the azimuth per frame (rad).
    pub sigma_azimuth_rad: f64,
    /// Random-walk standard deviation of the elevation per frame (rad).
    pub sigma_elevation_rad: f64,
    /// Fraction of particles redrawn uniformly each frame.
    pub uniform_fraction: f64,
    /// Largest number of EM components tried.
    pub em_max_components: usize,
    /// EM iterations per `k`.
    pub em_iterations: usize,
}

impl Default for ParticleParams {
    fn default() -> Self {
        Self {
            particles: 1000,
            sigma_azimuth_rad: 0.05,
            sigma_elevation_rad: 0.03,
            uniform_fraction: 0.1,
            em_max_components: 3,
            em_iterations: 30,
        }
    }
}

/// One particle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Particle {
    pub azimuth: f64,
    pub elevation: f64,
    pub weight: f64,
}

/// One Gaussian component of the particle mixture.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cluster {
    /// Mean azimuth, wrapped to (−π, π] (rad).
    pub azimuth: f64,
    pub elevation: f64,
    /// Mixing weight: the share of the particles' total weight.
    pub weight: f64,
    /// Covariance of (azimuth, elevation), rad².
    pub cov: [[f64; 2]; 2],
}

/// Smallest variance a component may shrink to (rad²), so that EM never divides by zero.
const MIN_VARIANCE: f64 = 1e-6;

/// The filter.
#[derive(Debug, Clone)]
pub struct ParticleFilter {
    p: ParticleParams,
    elevation_band: (f64, f64),
    particles: Vec<Particle>,
    rng: ChaCha8Rng,
}

impl ParticleFilter {
    /// Particles spread uniformly over all azimuths and the elevation band `[lo, hi]` (rad).
    pub fn new(p: &ParticleParams, elevation_band: (f64, f64), seed: u64) -> ParticleFilter {
        let mut rng = crate::rng::stream(seed, "egomotion_particles", 0);
        let n = p.particles.max(1);
        let particles = (0..n).map(|_| uniform(&mut rng, elevation_band)).collect();
        ParticleFilter {
            p: p.clone(),
            elevation_band,
            particles,
            rng,
        }
    }

    pub fn particles(&self) -> &[Particle] {
        &self.particles
    }

    /// Predict, weigh against `field`, cluster, resample; the strongest cluster, if any
    /// particle weighs anything.
    pub fn step(&mut self, field: &dyn DiffField) -> Option<Cluster> {
        self.predict();
        let mut total = 0.0;
        for q in &mut self.particles {
            let v = field.value(q.azimuth, q.elevation);
            q.weight = if v.is_finite() && v > 0.0 { v } else { 0.0 };
            total += q.weight;
        }
        if total.is_nan() || total <= 0.0 {
            let w = 1.0 / self.particles.len() as f64;
            self.particles.iter_mut().for_each(|q| q.weight = w);
            return None;
        }
        self.particles.iter_mut().for_each(|q| q.weight /= total);
        let best = em_clusters(
            &self.particles,
            self.p.em_max_components,
            self.p.em_iterations,
        )
        .into_iter()
        .max_by(|a, b| a.weight.total_cmp(&b.weight));
        self.resample();
        best
    }

    fn predict(&mut self) {
        let (lo, hi) = self.elevation_band;
        let n = self.particles.len();
        let redraw = ((self.p.uniform_fraction.clamp(0.0, 1.0)) * n as f64).round() as usize;
        for (i, q) in self.particles.iter_mut().enumerate() {
            if i < redraw {
                *q = uniform(&mut self.rng, self.elevation_band);
            } else {
                q.azimuth =
                    wrap_angle(q.azimuth + self.p.sigma_azimuth_rad * normal(&mut self.rng));
                q.elevation = (q.elevation + self.p.sigma_elevation_rad * normal(&mut self.rng))
                    .clamp(lo, hi);
            }
        }
    }

    /// Systematic resampling of the normalised weights.
    fn resample(&mut self) {
        let n = self.particles.len();
        let step = 1.0 / n as f64;
        let mut u = self.rng.random::<f64>() * step;
        let mut out = Vec::with_capacity(n);
        let mut cum = 0.0;
        for q in &self.particles {
            cum += q.weight;
            while u < cum && out.len() < n {
                out.push(Particle { weight: step, ..*q });
                u += step;
            }
        }
        // rounding can leave the last slots unfilled: repeat the last particle
        let last = self.particles[n - 1];
        out.resize(
            n,
            Particle {
                weight: step,
                ..last
            },
        );
        self.particles = out;
    }
}

fn uniform(rng: &mut ChaCha8Rng, (lo, hi): (f64, f64)) -> Particle {
    let az = (rng.random::<f64>() * 2.0 - 1.0) * std::f64::consts::PI;
    Particle {
        azimuth: wrap_angle(az),
        elevation: lo + (hi - lo) * rng.random::<f64>(),
        weight: 0.0,
    }
}

/// Standard normal draw (Box–Muller).
fn normal(rng: &mut ChaCha8Rng) -> f64 {
    let u1 = 1.0 - rng.random::<f64>(); // (0, 1]
    let u2 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// A fitted mixture and its weighted log-likelihood.
struct Mixture {
    clusters: Vec<Cluster>,
    log_likelihood: f64,
}

/// EM over weighted particles for `k = 1..=k_max`, keeping the `k` with the smallest BIC
/// (`−2 ln L + p ln N_eff`, `p = 6k − 1` free parameters, `N_eff = 1/Σw²`). Weights need not be
/// normalised; particles of zero weight are ignored. Empty when no particle weighs anything.
pub fn em_clusters(particles: &[Particle], k_max: usize, iterations: usize) -> Vec<Cluster> {
    let total: f64 = particles.iter().map(|q| q.weight.max(0.0)).sum();
    if total.is_nan() || total <= 0.0 {
        return Vec::new();
    }
    let pts: Vec<Particle> = particles
        .iter()
        .filter(|q| q.weight > 0.0)
        .map(|q| Particle {
            weight: q.weight / total,
            ..*q
        })
        .collect();
    let n_eff = 1.0 / pts.iter().map(|q| q.weight * q.weight).sum::<f64>();
    let mut best: Option<(f64, Vec<Cluster>)> = None;
    for k in 1..=k_max.max(1).min(pts.len()) {
        let m = em(&pts, k, iterations);
        let params = (6 * k - 1) as f64;
        // the likelihood of N_eff samples: the weighted mean log-density times N_eff
        let bic = -2.0 * n_eff * m.log_likelihood + params * n_eff.ln();
        if best.as_ref().is_none_or(|(b, _)| bic < *b) {
            best = Some((bic, m.clusters));
        }
    }
    best.map(|(_, c)| c).unwrap_or_default()
}

/// EM for a `k`-component mixture; initial means by weighted farthest-point picking (the
/// heaviest particle first), which is deterministic. `pts` weights sum to one.
fn em(pts: &[Particle], k: usize, iterations: usize) -> Mixture {
    let mut clusters = init(pts, k);
    let mut resp = vec![0.0; pts.len() * k];
    let mut log_likelihood = f64::NEG_INFINITY;
    for _ in 0..iterations.max(1) {
        // E step: responsibilities and the weighted mean log-density
        log_likelihood = 0.0;
        for (i, q) in pts.iter().enumerate() {
            let r = &mut resp[i * k..(i + 1) * k];
            let mut sum = 0.0;
            for (rj, c) in r.iter_mut().zip(&clusters) {
                *rj = c.weight * density(c, q);
                sum += *rj;
            }
            if sum > 0.0 {
                r.iter_mut().for_each(|x| *x /= sum);
                log_likelihood += q.weight * sum.ln();
            } else {
                r.iter_mut().for_each(|x| *x = 1.0 / k as f64);
                log_likelihood += q.weight * f64::MIN_POSITIVE.ln();
            }
        }
        // M step
        for (j, c) in clusters.iter_mut().enumerate() {
            let mass: f64 = pts
                .iter()
                .enumerate()
                .map(|(i, q)| q.weight * resp[i * k + j])
                .sum();
            if mass.is_nan() || mass <= 1e-12 {
                c.weight = 0.0;
                continue;
            }
            let (mut da, mut de) = (0.0, 0.0);
            for (i, q) in pts.iter().enumerate() {
                let w = q.weight * resp[i * k + j];
                da += w * wrap_angle(q.azimuth - c.azimuth);
                de += w * q.elevation;
            }
            let az = wrap_angle(c.azimuth + da / mass);
            let el = de / mass;
            let (mut saa, mut sae, mut see) = (0.0, 0.0, 0.0);
            for (i, q) in pts.iter().enumerate() {
                let w = q.weight * resp[i * k + j];
                let (a, e) = (wrap_angle(q.azimuth - az), q.elevation - el);
                saa += w * a * a;
                sae += w * a * e;
                see += w * e * e;
            }
            *c = Cluster {
                azimuth: az,
                elevation: el,
                weight: mass,
                cov: [
                    [saa / mass + MIN_VARIANCE, sae / mass],
                    [sae / mass, see / mass + MIN_VARIANCE],
                ],
            };
        }
    }
    Mixture {
        clusters: clusters.into_iter().filter(|c| c.weight > 0.0).collect(),
        log_likelihood,
    }
}

/// Gaussian density of a particle's direction under a component (azimuth difference wrapped).
fn density(c: &Cluster, q: &Particle) -> f64 {
    let [[a, b], [_, d]] = c.cov;
    let det = a * d - b * b;
    if det.is_nan() || det <= 0.0 {
        return 0.0;
    }
    let (x, y) = (wrap_angle(q.azimuth - c.azimuth), q.elevation - c.elevation);
    let m = (d * x * x - 2.0 * b * x * y + a * y * y) / det;
    (-0.5 * m).exp() / (std::f64::consts::TAU * det.sqrt())
}

/// Initial components: weighted farthest-point picking, a broad common covariance.
fn init(pts: &[Particle], k: usize) -> Vec<Cluster> {
    let dist2 = |p: &Particle, c: &Cluster| {
        let a = wrap_angle(p.azimuth - c.azimuth);
        let e = p.elevation - c.elevation;
        a * a + e * e
    };
    let mut out: Vec<Cluster> = Vec::with_capacity(k);
    // spread of the whole cloud about its heaviest particle sets the initial covariance
    let first = pts
        .iter()
        .max_by(|a, b| a.weight.total_cmp(&b.weight))
        .copied()
        .unwrap_or(Particle {
            azimuth: 0.0,
            elevation: 0.0,
            weight: 1.0,
        });
    let seed = |p: &Particle| Cluster {
        azimuth: p.azimuth,
        elevation: p.elevation,
        weight: 1.0 / k as f64,
        cov: [[0.0, 0.0], [0.0, 0.0]],
    };
    out.push(seed(&first));
    while out.len() < k {
        let next = pts
            .iter()
            .max_by(|a, b| {
                let da = a.weight
                    * out
                        .iter()
                        .map(|c| dist2(a, c))
                        .fold(f64::INFINITY, f64::min);
                let db = b.weight
                    * out
                        .iter()
                        .map(|c| dist2(b, c))
                        .fold(f64::INFINITY, f64::min);
                da.total_cmp(&db)
            })
            .copied()
            .unwrap_or(first);
        out.push(seed(&next));
    }
    let var = pts
        .iter()
        .map(|p| p.weight * dist2(p, &out[0]))
        .sum::<f64>()
        .max(MIN_VARIANCE * 100.0)
        / 2.0;
    for c in &mut out {
        c.cov = [[var, 0.0], [0.0, var]];
    }
    out
}

#[cfg(test)]
mod tests;

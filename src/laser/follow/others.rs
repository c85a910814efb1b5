//! The other people (our addition, off in the paper's configuration:
//! `FollowParams::others`). Seed 001's tracker follows one target and treats every other blob
//! as clutter of uniform density λ. A person running beside the target is not uniform
//! clutter: when the target's own blob is missing for a scan and theirs is in the gate, the
//! PDAF gives it nearly all the weight whatever its colour (issue 30's error analysis). Here
//! the follower also keeps a simple track of every blob the target did not take, and a blob
//! that one of those tracks predicts well counts less as the target's.
//!
//! **The weight** is the target's marginal association probability of a JPDA over the target
//! and the other tracks (Bar-Shalom & Li §6.2; [`crate::track::jpda`]) when no two *other*
//! tracks share a measurement: summing out each other track `o` with pair weights
//! `w_ok = P_D · N(z_k; ẑ_o, S_o)` over its gated blobs and missed weight
//! `m_o = λ (1 − P_D P_G)`, the joint event "target ← blob j" keeps the factor
//!
//! ```text
//! f_j = Π_o (m_o + Σ_{k ≠ j} w_ok) / (m_o + Σ_k w_ok)
//! ```
//!
//! relative to "target missed", so the target's PDAF with likelihood ratios `lr_j · f_j`
//! gives exactly the JPDA's `β_tj` ([`discount`]; the test checks it against
//! [`crate::track::jpda::joint_marginals`]). Where other tracks do share blobs it is the usual
//! independence approximation. A blob no other track gates keeps `f_j = 1`.
//!
//! **The other tracks** are constant-velocity Kalman filters ([`crate::track::kalman`]) on
//! `[x, y, vx, vy]` with the follower's `σ_r` as measurement noise and a white-noise
//! acceleration of `accel_sigma`; each scan they are assigned by global nearest neighbour
//! ([`crate::assign::min_cost_max_pairs`], Mahalanobis distance within the follower's χ² gate)
//! to the blobs the target did not take (the target's most probable blob when it is more
//! probable than "none", [`Others::update`]); a blob left over starts a tentative track,
//! confirmed after `confirm_hits` hits; a track without a hit for `max_coast_s` is deleted.
//! Only confirmed tracks discount. Static clutter (tree trunks) becomes tracks too, which is
//! what it is: something that is not the target. When the target is (re-)initialised on a
//! blob, the track that blob belongs to is deleted ([`Others::forget_near`]). Values are a
//! priori (`OthersParams::default`).
//!
//! **Colour on the other tracks** (`OthersParams::colour`, round 6 of issue 30): each track
//! holds the hue–saturation histogram of its first blob that had one as its template, and its
//! pair weights become `w_ok = P_D · N(z_k; ẑ_o, S_o) · lr_ok`, with `lr_ok` the same
//! likelihood ratio of blob `k` against track `o`'s template as the target's (`lr = 1` where
//! a histogram or the template is missing). That is the JPDA with every track's own colour
//! likelihood against uniform clutter, the algebra above unchanged. Without it a companion's
//! track that drifts next to the target discounts the target's own blob whatever its colour
//! (round 5's "other" resets). What it does not do: no track of the target's identity among
//! the others, no joint update of the other tracks.

use nalgebra::{Matrix2, SMatrix, Vector2, Vector4};

use crate::assign;
use crate::track::jpda::gaussian_2d;
use crate::track::kalman::{Kalman, constant_velocity_2d};

/// Settings of the other-people tracks.
#[derive(Debug, Clone, PartialEq)]
pub struct OthersParams {
    /// White-noise acceleration of the other tracks (m/s²).
    pub accel_sigma: f64,
    /// Initial speed standard deviation of a new track (m/s).
    pub init_speed_sigma: f64,
    /// Hits before a track discounts blobs.
    pub confirm_hits: usize,
    /// A track without a hit for longer than this is deleted (s).
    pub max_coast_s: f64,
    /// A track whose position lies within this squared Mahalanobis distance of the target's
    /// (under the sum of both position covariances) is the target itself and is deleted.
    pub coalesce_d2: f64,
    /// Each track's colour likelihood in its pair weights (module doc); false: position only
    /// (round 5).
    pub colour: bool,
}

impl Default for OthersParams {
    /// A priori: people change speed or direction by up to ~2 m/s² (a runner turning at
    /// speed), move at up to ~3 m/s from rest (speed sd 1.5 m/s at birth), are believed after
    /// three scans in a row (0.3 s at 10 Hz) and forgotten after 1 s without a blob; a track
    /// within one standard deviation of the target (d² ≤ 1, about 0.2 m for settled tracks,
    /// closer than two people's centres can be) is the target; every track weighs blobs by
    /// its own colour as the target does.
    fn default() -> Self {
        OthersParams {
            accel_sigma: 2.0,
            init_speed_sigma: 1.5,
            confirm_hits: 3,
            max_coast_s: 1.0,
            coalesce_d2: 1.0,
            colour: true,
        }
    }
}

/// The follower's values the other tracks share with the target's filter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shared {
    pub sigma_r: f64,
    pub p_d: f64,
    /// The χ² gate on the squared Mahalanobis distance.
    pub gate: f64,
    /// The clutter density λ (1/m²).
    pub clutter_density: f64,
}

impl Shared {
    fn p_g(&self) -> f64 {
        1.0 - (-0.5 * self.gate.max(0.0)).exp()
    }
}

#[derive(Debug, Clone)]
struct Track {
    kf: Kalman<4>,
    hits: usize,
    last_hit: f64,
    /// The histogram of the track's first blob that had one (`OthersParams::colour`).
    template: Option<Vec<f64>>,
}

impl Track {
    fn confirmed(&self, p: &OthersParams) -> bool {
        self.hits >= p.confirm_hits
    }

    /// Innovation covariance and squared Mahalanobis distance of `z`; `None` when `S` is not
    /// positive definite.
    fn innovation(&self, z: [f64; 2], sigma_r: f64) -> Option<(f64, f64)> {
        let s = self.kf.p.fixed_view::<2, 2>(0, 0) + Matrix2::identity() * sigma_r * sigma_r;
        let det = s.determinant();
        let inv = s.try_inverse()?;
        if !(det > 0.0 && det.is_finite()) {
            return None;
        }
        let nu = Vector2::new(z[0] - self.kf.x[0], z[1] - self.kf.x[1]);
        Some(((nu.transpose() * inv * nu)[(0, 0)], det))
    }
}

/// What colour says about one scan's blobs, for the other tracks.
pub struct BlobColour<'a> {
    /// Each blob's histogram (`None`: no image or no region).
    pub hists: &'a [Option<Vec<f64>>],
    /// The likelihood ratio of a histogram (first) against a template (second), the
    /// target's own form.
    pub lr: &'a dyn Fn(&[f64], &[f64]) -> f64,
}

impl BlobColour<'_> {
    /// No colour: every ratio 1.
    pub fn none() -> BlobColour<'static> {
        BlobColour {
            hists: &[],
            lr: &|_, _| 1.0,
        }
    }
}

/// The other tracks of one follower.
#[derive(Debug, Clone)]
pub struct Others {
    params: OthersParams,
    tracks: Vec<Track>,
    t: Option<f64>,
}

impl Others {
    pub fn new(params: &OthersParams) -> Others {
        Others {
            params: params.clone(),
            tracks: Vec::new(),
            t: None,
        }
    }

    /// Confirmed tracks' positions (for diagnostics and tests).
    pub fn confirmed(&self) -> Vec<[f64; 2]> {
        self.tracks
            .iter()
            .filter(|t| t.confirmed(&self.params))
            .map(|t| [t.kf.x[0], t.kf.x[1]])
            .collect()
    }

    /// Predicts every track to time `t` (no-op backwards or at the same time).
    pub fn predict(&mut self, t: f64) {
        let dt = self.t.map_or(0.0, |t0| t - t0);
        if dt > 0.0 {
            let (f, q) = constant_velocity_2d(dt, self.params.accel_sigma);
            for tr in &mut self.tracks {
                tr.kf.predict(&f, &q);
            }
        }
        if self.t.is_none_or(|t0| t > t0) {
            self.t = Some(t);
        }
    }

    /// The factor `f_j` of the module doc for every blob `z` (after [`Self::predict`]);
    /// `seen` gives each blob's histogram and the likelihood ratio of a histogram against a
    /// template (used when `OthersParams::colour` is on).
    pub fn discount(&self, z: &[[f64; 2]], seen: &BlobColour<'_>, sh: &Shared) -> Vec<f64> {
        let miss = sh.clutter_density * (1.0 - sh.p_d * sh.p_g()).max(0.0);
        let mut f = vec![1.0; z.len()];
        for tr in self.tracks.iter().filter(|t| t.confirmed(&self.params)) {
            let w: Vec<f64> = z
                .iter()
                .enumerate()
                .map(|(j, &zj)| match tr.innovation(zj, sh.sigma_r) {
                    Some((d2, det)) if d2 <= sh.gate => {
                        sh.p_d * gaussian_2d(d2, det) * self.colour_lr(tr, seen, j)
                    }
                    _ => 0.0,
                })
                .collect();
            let total = miss + w.iter().sum::<f64>();
            if !(total > 0.0 && total.is_finite()) {
                continue;
            }
            for (fj, wj) in f.iter_mut().zip(&w) {
                *fj *= (total - wj).max(0.0) / total;
            }
        }
        f
    }

    /// Track `tr`'s colour likelihood ratio for blob `j` (1 with colour off, without a
    /// template or without the blob's histogram).
    fn colour_lr(&self, tr: &Track, seen: &BlobColour<'_>, j: usize) -> f64 {
        if !self.params.colour {
            return 1.0;
        }
        match (
            tr.template.as_deref(),
            seen.hists.get(j).and_then(Option::as_deref),
        ) {
            (Some(t), Some(h)) => (seen.lr)(h, t),
            _ => 1.0,
        }
    }

    /// Assigns the blobs other than `taken` (the target's) to the tracks, starts tracks on
    /// the blobs left over and deletes those without a hit for `max_coast_s` (see the module
    /// doc); a track without a template takes its blob's histogram. Call after
    /// [`Self::predict`] to the scan's time `t`.
    pub fn update(
        &mut self,
        t: f64,
        z: &[[f64; 2]],
        hists: &[Option<Vec<f64>>],
        taken: Option<usize>,
        sh: &Shared,
    ) {
        let hist = |j: usize| hists.get(j).cloned().flatten();
        let free: Vec<usize> = (0..z.len()).filter(|&j| Some(j) != taken).collect();
        let tracks = &self.tracks;
        let pairs = assign::min_cost_max_pairs(tracks.len(), free.len(), |i, k| {
            match tracks[i].innovation(z[free[k]], sh.sigma_r) {
                Some((d2, _)) if d2 <= sh.gate => d2,
                _ => f64::INFINITY,
            }
        });
        let r = Matrix2::identity() * sh.sigma_r * sh.sigma_r;
        let h = SMatrix::<f64, 2, 4>::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0);
        let mut used = vec![false; free.len()];
        for &(i, k) in &pairs {
            let zj = z[free[k]];
            let tr = &mut self.tracks[i];
            if tr.kf.update(&h, &r, &Vector2::new(zj[0], zj[1])).is_ok() {
                tr.hits += 1;
                tr.last_hit = t;
                used[k] = true;
                if tr.template.is_none() {
                    tr.template = hist(free[k]);
                }
            }
        }
        let max_coast = self.params.max_coast_s;
        self.tracks.retain(|tr| t - tr.last_hit <= max_coast);
        let (sr, sv) = (sh.sigma_r, self.params.init_speed_sigma);
        for (k, &j) in free.iter().enumerate() {
            let zj = z[j];
            if used[k] || !(zj[0].is_finite() && zj[1].is_finite()) {
                continue;
            }
            let p = SMatrix::<f64, 4, 4>::from_diagonal(&Vector4::new(
                sr * sr,
                sr * sr,
                sv * sv,
                sv * sv,
            ));
            self.tracks.push(Track {
                kf: Kalman::new(Vector4::new(zj[0], zj[1], 0.0, 0.0), p),
                hits: 1,
                last_hit: t,
                template: hist(j),
            });
        }
    }

    /// Deletes the tracks that are the target (module doc): within `coalesce_d2` of the
    /// target's `position` under the sum of the position covariances.
    pub fn coalesce(&mut self, position: [f64; 2], covariance: [[f64; 2]; 2]) {
        let pt = Matrix2::new(
            covariance[0][0],
            covariance[0][1],
            covariance[1][0],
            covariance[1][1],
        );
        let limit = self.params.coalesce_d2;
        self.tracks.retain(|tr| {
            let s = tr.kf.p.fixed_view::<2, 2>(0, 0) + pt;
            let nu = Vector2::new(tr.kf.x[0] - position[0], tr.kf.x[1] - position[1]);
            match s.try_inverse() {
                Some(inv) => (nu.transpose() * inv * nu)[(0, 0)] > limit,
                None => true,
            }
        });
    }

    /// Deletes the track (confirmed or not) that gates `z` most closely: the target was
    /// (re-)initialised on that blob.
    pub fn forget_near(&mut self, z: [f64; 2], sh: &Shared) {
        let best = self
            .tracks
            .iter()
            .enumerate()
            .filter_map(|(i, tr)| {
                let (d2, _) = tr.innovation(z, sh.sigma_r)?;
                (d2 <= sh.gate).then_some((i, d2))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((i, _)) = best {
            self.tracks.remove(i);
        }
    }
}

#[cfg(test)]
mod tests;

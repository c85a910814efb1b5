//! The careful restart of the background model and the colour tracker's random
//! initialisations (Zajdel, Zivkovic & Kröse, ICRA 2005, sections III-A and III-C; see the
//! parent module's hand-over step).

use super::{COLOUR_BOX_SIGMA, LocalError, LocalParams, LocalTracker};
use crate::rng;
use crate::vision::ellipse::Ellipse;
use crate::vision::gmm::BACKGROUND;
use crate::vision::view::ImageView;

/// Whether a colour-tracked `region` has collapsed: its size (√ of its ellipse's area) below
/// `min_scale` of the `body` it was handed over with (never without a body or with
/// `min_scale` 0).
pub(super) fn collapsed(region: &Ellipse, body: Option<&Ellipse>, min_scale: f64) -> bool {
    body.is_some_and(|b| region.area(1.0) < min_scale * min_scale * b.area(1.0))
}

/// Seed of the colour tracker's random initialisations (hashed with track, frame and draw).
const RANDOM_START_SEED: u64 = 0x5a6a_de1c_0003;

/// Random initialisation `k` of track `id` on frame `frame`: `region` shifted by a uniform
/// draw within ±`random_start_sigma` σ per axis (same shape).
pub(super) fn random_start(
    region: &Ellipse,
    id: u32,
    frame: u64,
    k: u32,
    p: &LocalParams,
) -> Ellipse {
    let draw = rng::hash(RANDOM_START_SEED, &[u64::from(id), frame, u64::from(k)]);
    let ux = f64::from(rng::unit(draw)) * 2.0 - 1.0;
    let uy = f64::from(rng::unit(rng::mix(draw))) * 2.0 - 1.0;
    let sx = region.cov[(0, 0)].max(0.0).sqrt();
    let sy = region.cov[(1, 1)].max(0.0).sqrt();
    let shift = nalgebra::Vector2::new(ux * sx, uy * sy) * p.random_start_sigma;
    Ellipse::new(region.center + shift, region.cov)
}

impl LocalTracker {
    /// The background model's learning rate for this frame: OpenCV's bootstrap
    /// α = 1/min(2n, T) during the warm-up after a (re)start, then the steady α = 1/T (with
    /// `steady_after_warmup`; else the bootstrap throughout, as OpenCV).
    pub(super) fn learning_rate(&self) -> Option<f32> {
        (self.params.steady_after_warmup && self.since_reset >= self.params.warmup_frames)
            .then(|| 1.0 / self.params.gmm.history as f32)
    }

    /// Update the background model and its mask, not learning the protected tracks' body
    /// boxes (see the module doc); pixels without a model are not foreground.
    pub(super) fn learn_selectively(&mut self, frame: ImageView<'_>) -> Result<(), LocalError> {
        let (w, h) = (frame.width(), frame.height());
        if self.since_reset >= self.params.protect_frames {
            for t in &mut self.tracks {
                t.protected = false;
            }
        }
        self.learn.fill(true);
        let mut protecting = false;
        for t in self.tracks.iter().filter(|t| t.protected && !t.ended) {
            let Some(body) = t.body else {
                continue;
            };
            let b = Ellipse::new(t.region.center, body.cov)
                .bbox(COLOUR_BOX_SIGMA * self.params.protect_scale);
            let clamp = |v: f64, n: usize| v.clamp(0.0, n as f64) as usize;
            let (x0, x1) = (clamp(b[0].floor(), w), clamp(b[2].ceil() + 1.0, w));
            let (y0, y1) = (clamp(b[1].floor(), h), clamp(b[3].ceil() + 1.0, h));
            for y in y0..y1 {
                self.learn[y * w + x0..y * w + x1].fill(false);
                protecting |= x1 > x0;
            }
        }
        let before = self.unmodelled.then(|| self.gmm.components_per_pixel());
        let rate = self.learning_rate();
        if protecting {
            self.stats.protected_frames += 1;
            self.gmm
                .apply_selective(frame, rate, &self.learn, &mut self.mask)?;
        } else {
            self.gmm.apply(frame, rate, &mut self.mask)?;
        }
        if let Some(before) = before {
            for (i, m) in self.mask.iter_mut().enumerate() {
                if before.get(i).is_none_or(|&n| n == 0) {
                    *m = BACKGROUND;
                }
            }
        }
        // frozen pixels of a fresh model have no component; once nothing is frozen, every
        // pixel has learned this frame
        self.unmodelled = protecting;
        Ok(())
    }
}

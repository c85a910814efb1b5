//! Probing a foreground mask where a person is known to be: what the detector of the parent
//! module could have found there, and how the mask fills one template placed on them. This is
//! the measuring side of the seed 004 chain's error analysis (issue 32): a missed person is
//! told apart as "the mask does not hold their silhouette", "no template of the set fits it",
//! "the calibration's per-position choice picked another template" or "a candidate was there
//! but suppressed", in the chain's order.
//!
//! [`Probe::best_near`] visits exactly the head positions [`super::detect_with`] visits (the
//! same stride grid per template, the same border rules, the per-position template map) within
//! a radius of a given head point, without the detector's threshold. [`Probe::fill_at`] splits
//! one placement's matching error into the silhouette's missing foreground and the window
//! margin's extra foreground (and how much of that extra lies in the window's lower quarter,
//! where a person's floor shadow falls).
//!
//! What it does not do: no search over shapes beyond the given templates; no NMS.

use super::{Mask, Silhouette, Sums, TemplateMap, score_at};

/// One placement found near a head point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fit {
    /// Matching score `1 − MSE`.
    pub score: f64,
    /// Index of the template.
    pub template: usize,
    /// Head position (pixels, on the detector's grid).
    pub head: (i64, i64),
    /// The silhouette's box `[x0, y0, x1, y1]` as a detection would report it.
    pub bbox: [f64; 4],
}

/// How the mask fills one template placement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fill {
    /// Matching score `1 − MSE` (as the detector computes it).
    pub score: f64,
    /// Fraction of the silhouette's pixels (inside the image) that are foreground.
    pub inside: f64,
    /// Fraction of the window's margin (window minus silhouette, inside the image) that is
    /// foreground.
    pub margin: f64,
    /// Share of the margin's foreground that lies in the window's lower quarter (0 when the
    /// margin holds none).
    pub margin_low: f64,
    /// Matching error from missing silhouette pixels, `(|T| − Σ T·S) / A`, and from extra
    /// margin pixels, `(Σ S − Σ T·S) / A`: they add up to `1 − score`.
    pub missing: f64,
    pub extra: f64,
}

/// A mask's prefix sums, ready for probing.
pub struct Probe {
    sums: Sums,
    /// Fraction of a template window that must lie inside the image (as the detector's).
    min_inside: f64,
}

impl Probe {
    pub fn new(mask: &Mask, min_inside: f64) -> Probe {
        Probe {
            sums: Sums::new(mask),
            min_inside,
        }
    }

    /// The best placement on the detector's grid (`stride_px`) whose head lies within
    /// `radius_px` of `head`, over `templates` (only the one `map` chooses at each head
    /// position, as the detector), whatever its score; `None` when no placement is allowed
    /// there. Ties: the first template, then the lowest row, then the leftmost column.
    pub fn best_near(
        &self,
        templates: &[Silhouette],
        map: Option<&TemplateMap>,
        head: [f64; 2],
        radius_px: f64,
        stride_px: u32,
    ) -> Option<Fit> {
        let (w, h) = (self.sums.w as i64, self.sums.h as i64);
        let stride = i64::from(stride_px.max(1));
        let mut best: Option<Fit> = None;
        for (ti, t) in templates.iter().enumerate() {
            let tw = i64::from(t.width);
            let (hx, hy) = (t.head.0.round() as i64, t.head.1.round() as i64);
            // the detector's grid: rows 0, s, 2s, …; columns −tw/2 + hx + k·s
            let x_start = -tw / 2 + hx;
            let y_lo = ((head[1] - radius_px).max(0.0) / stride as f64).ceil() as i64 * stride;
            let k_lo = ((head[0] - radius_px - x_start as f64) / stride as f64).ceil() as i64;
            let mut yh = y_lo;
            while yh < h && (yh as f64) <= head[1] + radius_px {
                let mut xh = x_start + k_lo.max(0) * stride;
                while xh < w + tw / 2 && (xh as f64) <= head[0] + radius_px {
                    let d = (xh as f64 - head[0]).hypot(yh as f64 - head[1]);
                    let allowed = map.is_none_or(|m| m.at(xh, yh) == Some(ti));
                    let (x, y) = (xh - hx, yh - hy);
                    if d <= radius_px
                        && allowed
                        && x + tw > 0
                        && let Some(s) =
                            score_at(&self.sums, t, x, y, f64::NEG_INFINITY, self.min_inside)
                        && best.is_none_or(|b| s > b.score)
                    {
                        let b = t.body.map(f64::from);
                        let (xf, yf) = (x as f64, y as f64);
                        best = Some(Fit {
                            score: s,
                            template: ti,
                            head: (xh, yh),
                            bbox: [xf + b[0], yf + b[1], xf + b[2], yf + b[3]],
                        });
                    }
                    xh += stride;
                }
                yh += stride;
            }
        }
        best
    }

    /// `t` with its head at `head` (rounded), moved by up to `search_px` pixels each way: the
    /// best-scoring placement's fill; `None` when no placement is allowed (border rules).
    pub fn fill_at(&self, t: &Silhouette, head: [f64; 2], search_px: i64) -> Option<Fill> {
        let x0 = (head[0] - t.head.0).round() as i64;
        let y0 = (head[1] - t.head.1).round() as i64;
        let mut best: Option<Fill> = None;
        for dy in -search_px..=search_px {
            for dx in -search_px..=search_px {
                if let Some(f) = self.fill(t, x0 + dx, y0 + dy)
                    && best.is_none_or(|b| f.score > b.score)
                {
                    best = Some(f);
                }
            }
        }
        best
    }

    /// The fill of `t` with its top-left corner at `(x, y)`.
    fn fill(&self, t: &Silhouette, x: i64, y: i64) -> Option<Fill> {
        let score = score_at(&self.sums, t, x, y, f64::NEG_INFINITY, self.min_inside)?;
        let (w, h) = (self.sums.w as i64, self.sums.h as i64);
        let (x0, x1) = (x.max(0), (x + i64::from(t.width)).min(w));
        let (y0, y1) = (y.max(0), (y + i64::from(t.height)).min(h));
        let area = ((x1 - x0) * (y1 - y0)) as f64;
        let low_from = (y + i64::from(t.height) * 3 / 4).clamp(y0, y1);
        let window = |ya: i64, yb: i64| {
            f64::from(
                self.sums
                    .window(x0 as usize, ya as usize, x1 as usize, yb as usize),
            )
        };
        let (sw, sw_low) = (window(y0, y1), window(low_from, y1));
        let (mut t1, mut c, mut c_low) = (0.0, 0.0, 0.0);
        for (r, &(a, b)) in t.spans.iter().enumerate() {
            let yy = y + r as i64;
            if yy < y0 || yy >= y1 {
                continue;
            }
            let (a, b) = (
                (x + i64::from(a)).clamp(0, w),
                (x + i64::from(b)).clamp(0, w),
            );
            if b > a {
                let n = f64::from(self.sums.row(yy as usize, a as usize, b as usize));
                t1 += (b - a) as f64;
                c += n;
                if yy >= low_from {
                    c_low += n;
                }
            }
        }
        let ratio = |a: f64, b: f64| if b > 0.0 { a / b } else { 0.0 };
        Some(Fill {
            score,
            inside: ratio(c, t1),
            margin: ratio(sw - c, area - t1),
            margin_low: ratio(sw_low - c_low, sw - c),
            missing: (t1 - c) / area,
            extra: (sw - c) / area,
        })
    }
}

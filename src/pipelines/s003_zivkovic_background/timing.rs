//! Time per frame (paper fig. 2) of the adaptive GMM and the fixed-M baseline at the default
//! c_thr, each on a one-thread pool, alternating which runs first. Each frame's update is
//! timed [`REPEATS`] times, each run on a fresh clone of the model as it was before the
//! frame, and the fastest run is kept: stalls of a loaded machine only ever add time. The
//! model goes on from the last clone, so masks and components are those of one update.
//! Aggregation reports the median and quartiles over frames (robust to the stalls left).

use std::time::Instant;

use anyhow::Context;
use image::RgbImage;

use super::components::{self, ComponentsSample};
use super::params::{Params, model_name};
use super::shared::{Frame, by_dataset, session_row};
use crate::report::figure::{Bar, BarPlot, FigureKind};
use crate::report::rows::Rows;
use crate::report::{Figure, Table};
use crate::run::{Aggregate, Products, SessionTables};
use crate::table_row;
use crate::vision::AdaptiveGmm;

/// Runs of each frame's update; the fastest is kept.
const REPEATS: usize = 3;
pub(super) const SAMPLES_TABLE: &str = "timing";

table_row! {
    /// Cached per session, one row per frame: the fastest of [`REPEATS`] updates (ms).
    #[derive(Debug, Clone, PartialEq)]
    pub(super) struct TimingSample {
        pub t_s: f64,
        pub adaptive_ms: f64,
        pub baseline_ms: f64,
    }
}

table_row! {
    /// A row of the `timing_gmm` table.
    #[derive(Debug, Clone, PartialEq)]
    struct TimingRow {
        dataset: String,
        model: String,
        frames: i64,
        median_ms: f64,
        p25_ms: f64,
        p75_ms: f64,
        frames_per_s: f64,
    }
}

table_row! {
    /// A row of `timing_gmm.samples.parquet`.
    #[derive(Debug, Clone, PartialEq)]
    struct TimingSampleRow {
        dataset: String,
        model: String,
        ms: f64,
    }
}

/// The timed pair `[adaptive, baseline]` and what it records per frame.
pub(super) struct TimingRun {
    pool: rayon::ThreadPool,
    models: [AdaptiveGmm; 2],
    masks: [Vec<u8>; 2],
    samples: Vec<TimingSample>,
    components: Vec<ComponentsSample>,
}

impl TimingRun {
    pub fn new(p: &Params) -> anyhow::Result<Self> {
        Ok(Self {
            pool: rayon::ThreadPoolBuilder::new()
                .num_threads(1)
                .build()
                .context("building the one-thread pool for timing")?,
            models: [
                AdaptiveGmm::new(p.roc.adaptive)?,
                AdaptiveGmm::new(p.roc.baseline)?,
            ],
            masks: [Vec::new(), Vec::new()],
            samples: Vec::new(),
            components: Vec::new(),
        })
    }

    pub fn step(&mut self, f: &Frame) -> anyhow::Result<()> {
        let npx = (f.rgb.width() * f.rgb.height()) as usize;
        let order = if f.index % 2 == 0 { [0, 1] } else { [1, 0] };
        let mut ms = [0.0; 2];
        for i in order {
            self.masks[i].resize(npx, 0);
            let mut best = f64::INFINITY;
            let mut updated = None;
            for _ in 0..REPEATS {
                let mut model = self.models[i].clone();
                let mask = &mut self.masks[i];
                let started = Instant::now();
                self.pool.install(|| model.apply(f.view, None, mask))?;
                best = best.min(started.elapsed().as_secs_f64() * 1e3);
                updated = Some(model);
            }
            if let Some(m) = updated {
                self.models[i] = m;
            }
            ms[i] = best;
        }
        self.samples.push(TimingSample {
            t_s: f.t_s,
            adaptive_ms: ms[0],
            baseline_ms: ms[1],
        });
        self.components.push(ComponentsSample {
            t_s: f.t_s,
            adaptive_mean_components: components::mean_components(&self.models[0]),
            baseline_mean_components: components::mean_components(&self.models[1]),
        });
        Ok(())
    }

    /// The cached `timing` table and the components tables.
    pub fn finish(
        self,
        last_frame: Option<&RgbImage>,
        out: &mut SessionTables,
    ) -> anyhow::Result<()> {
        out.insert(SAMPLES_TABLE.into(), TimingSample::frame(&self.samples)?);
        components::finish(&self.components, &self.models[0], last_frame, out)?;
        Ok(())
    }
}

/// Median and quartiles of a sample.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Quartiles {
    p25: f64,
    median: f64,
    p75: f64,
}

/// Quantile `q` of sorted values, linear between order statistics (R's type 7, numpy's
/// default): position `q (n − 1)`.
fn quantile(sorted: &[f64], q: f64) -> f64 {
    let Some(last) = sorted.len().checked_sub(1) else {
        return f64::NAN;
    };
    let pos = q.clamp(0.0, 1.0) * last as f64;
    let lo = pos.floor() as usize;
    let hi = (lo + 1).min(last);
    sorted[lo] + (sorted[hi] - sorted[lo]) * (pos - lo as f64)
}

fn quartiles(values: &[f64]) -> Quartiles {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    Quartiles {
        p25: quantile(&sorted, 0.25),
        median: quantile(&sorted, 0.5),
        p75: quantile(&sorted, 0.75),
    }
}

/// The `timing_gmm` table (with its per-frame samples), a summary line per scene and the
/// timing figure.
pub(super) fn products(ctx: &Aggregate, products: &mut Products) -> anyhow::Result<()> {
    let mut rows = Vec::new();
    let mut bars = Vec::new();
    let mut samples = Vec::new();
    let mut sizes: Vec<String> = Vec::new();
    for (dataset, sessions) in by_dataset(ctx) {
        let mut ms = [Vec::new(), Vec::new()];
        for f in &sessions {
            if let Some(t) = f.get(SAMPLES_TABLE) {
                for s in TimingSample::read(t)? {
                    ms[0].push(s.adaptive_ms);
                    ms[1].push(s.baseline_ms);
                }
                let r = session_row(f);
                let size = format!("{}x{}", r.width, r.height);
                if !sizes.contains(&size) {
                    sizes.push(size);
                }
            }
        }
        if ms[0].len() < 2 {
            continue;
        }
        let mut medians = [0.0; 2];
        for (k, adaptive) in [true, false].into_iter().enumerate() {
            let q = quartiles(&ms[k]);
            medians[k] = q.median;
            rows.push(TimingRow {
                dataset: dataset.clone(),
                model: model_name(adaptive).to_string(),
                frames: ms[k].len() as i64,
                median_ms: q.median,
                p25_ms: q.p25,
                p75_ms: q.p75,
                frames_per_s: 1e3 / q.median,
            });
            bars.push(Bar {
                label: format!(
                    "{dataset}\n{}",
                    if adaptive { "adaptive" } else { "fixed M=4" }
                ),
                value: q.median,
                error: (q.p75 - q.p25) / 2.0,
            });
            samples.extend(ms[k].iter().map(|&v| TimingSampleRow {
                dataset: dataset.clone(),
                model: model_name(adaptive).to_string(),
                ms: v,
            }));
        }
        products.summary.push(format!(
            "{dataset}: time per frame (measured, one thread, median) adaptive {:.2} ms vs fixed-M {:.2} ms (×{:.2}).",
            medians[0],
            medians[1],
            medians[1] / medians[0]
        ));
    }
    if rows.is_empty() {
        return Ok(());
    }
    products.tables.push(
        Table::new(
            "timing_gmm",
            "Time per frame of the adaptive GMM and the fixed-M baseline (MEASURED: varies between runs and machines)",
            TimingRow::frame(&rows)?,
        )
        .with_precision("median_ms", 3)
        .with_precision("p25_ms", 3)
        .with_precision("p75_ms", 3)
        .with_precision("frames_per_s", 0)
        .with_samples(TimingSampleRow::frame(&samples)?)
        .with_note(format!(
            "Wall-clock time of one model update + mask ({} RGB after JPEG decoding, not counted), each model on its own one-thread pool, the two alternating which runs first; each frame's update is run {REPEATS} times on clones of the model and the fastest run counts (a stall only adds time); median and quartiles (linear interpolation) over frames, frames_per_s = 1000 / median. Other sessions may run at the same time on other cores. This table and the timing figure are measurements: they are excluded from the byte-identical outputs. `make bench-gmm` measures throughput under controlled conditions beside OpenCV.",
            sizes.join(", ")
        ))
        .with_note("Paper (fig. 2): processing times on a 2 GHz PC for 320x240 images; the text gives no numbers, only that the adaptive model is faster except on the highly dynamic 'trees' scene where it is almost the same."),
    );
    products.figures.push(Figure::new(
        "timing_per_frame",
        "Time per frame, adaptive vs fixed-M GMM (measured, one thread)",
        FigureKind::Bars(BarPlot {
            y_label: "ms per frame (median, bar = half the interquartile range)".into(),
            bars,
            significance: Vec::new(),
        }),
    ));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quartiles_of_known_samples() {
        // 1..=9: type-7 quartiles are the 3rd, 5th and 7th values
        let q = quartiles(&[9.0, 1.0, 8.0, 2.0, 7.0, 3.0, 6.0, 4.0, 5.0]);
        assert_eq!(
            q,
            Quartiles {
                p25: 3.0,
                median: 5.0,
                p75: 7.0
            }
        );
        // even count: interpolated (numpy: 1.75, 2.5, 3.25)
        let q = quartiles(&[4.0, 1.0, 3.0, 2.0]);
        assert_eq!(
            q,
            Quartiles {
                p25: 1.75,
                median: 2.5,
                p75: 3.25
            }
        );
        // one stall does not move the median
        let q = quartiles(&[1.0, 1.1, 0.9, 1.0, 250.0]);
        assert_eq!(q.median, 1.0);
        assert!(quantile(&[], 0.5).is_nan());
        assert_eq!(quantile(&[2.0], 0.75), 2.0);
    }

    #[test]
    fn repeated_timing_leaves_the_model_as_one_update() {
        use crate::vision::ImageView;
        let p = Params::default();
        let mut run = TimingRun::new(&p).expect("run");
        let mut reference = AdaptiveGmm::new(p.roc.adaptive).expect("model");
        let mut mask = vec![0u8; 16 * 8];
        for k in 0..4u8 {
            let img = RgbImage::from_fn(16, 8, |x, y| {
                image::Rgb([x as u8 * 9 + k * 40, y as u8 * 20, 90])
            });
            let view = ImageView::rgb(&img).expect("view");
            let f = Frame {
                index: i64::from(k),
                t_s: f64::from(k) * 0.1,
                rgb: &img,
                view,
                mask: None,
                person_ids: None,
                truth: None,
                moving: false,
            };
            run.step(&f).expect("step");
            reference.apply(view, None, &mut mask).expect("apply");
            assert_eq!(run.masks[0], mask, "frame {k}");
        }
        assert_eq!(run.models[0].frames_seen(), 4);
        assert_eq!(run.samples.len(), 4);
        assert!(
            run.samples
                .iter()
                .all(|s| s.adaptive_ms >= 0.0 && s.baseline_ms >= 0.0)
        );
        assert_eq!(
            run.components[3].adaptive_mean_components,
            components::mean_components(&reference)
        );
    }
}

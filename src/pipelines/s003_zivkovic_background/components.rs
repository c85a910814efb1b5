//! Components per pixel (paper fig. 2, right): the mean number of components per pixel of
//! both timed models every frame, and the adaptive model's components-per-pixel image at the
//! last frame beside that frame. The timing run records them (it owns the models); this file
//! has their cached tables and figures.

use std::collections::BTreeSet;

use image::RgbImage;
use polars::prelude::*;

use super::shared::{by_dataset, session_row};
use crate::names::sanitize;
use crate::report::Figure;
use crate::report::columns::{image_table, read_image_table};
use crate::report::figure::{FigureKind, ImageOverlay, LinePlot, Mark, Series};
use crate::report::rows::Rows;
use crate::run::{Aggregate, Products, SessionTables};
use crate::table_row;
use crate::vision::AdaptiveGmm;

pub(super) const SAMPLES_TABLE: &str = "components";
pub(super) const IMAGE_TABLE: &str = "components_image";
pub(super) const LAST_FRAME_TABLE: &str = "last_frame";

table_row! {
    /// Cached per session, one row per frame: mean components per pixel of both models.
    #[derive(Debug, Clone, PartialEq)]
    pub(super) struct ComponentsSample {
        pub t_s: f64,
        pub adaptive_mean_components: f64,
        pub baseline_mean_components: f64,
    }
}

impl ComponentsSample {
    /// A session's samples (none when the models did not run).
    pub fn of_session(tables: &SessionTables) -> PolarsResult<Vec<Self>> {
        tables.get(SAMPLES_TABLE).map_or(Ok(Vec::new()), Self::read)
    }
}

/// Mean components per pixel of a model.
pub(super) fn mean_components(model: &AdaptiveGmm) -> f64 {
    let cpp = model.components_per_pixel();
    let sum: u64 = cpp.iter().map(|&c| u64::from(c)).sum();
    sum as f64 / cpp.len().max(1) as f64
}

/// The cached tables: per-frame samples, the components image of `model` and the last frame.
pub(super) fn finish(
    samples: &[ComponentsSample],
    model: &AdaptiveGmm,
    last_frame: Option<&RgbImage>,
    out: &mut SessionTables,
) -> PolarsResult<()> {
    out.insert(SAMPLES_TABLE.into(), ComponentsSample::frame(samples)?);
    let cpp = model.components_per_pixel();
    out.insert(
        IMAGE_TABLE.into(),
        df! { "components" => cpp.iter().map(|&c| i32::from(c)).collect::<Vec<_>>() }?,
    );
    if let Some(img) = last_frame {
        out.insert(LAST_FRAME_TABLE.into(), image_table(img)?);
    }
    Ok(())
}

/// The last frame beside its components image (black 1 … white `max`, at least 2).
fn side_by_side(frame: &RgbImage, comps: &[i32]) -> anyhow::Result<(RgbImage, i32)> {
    let (w, h) = frame.dimensions();
    if comps.len() != (w * h) as usize {
        anyhow::bail!("components image has the wrong size");
    }
    let m = comps.iter().copied().max().unwrap_or(1).max(2);
    let mut img = RgbImage::new(2 * w, h);
    for y in 0..h {
        for x in 0..w {
            img.put_pixel(x, y, *frame.get_pixel(x, y));
            let c = comps[(y * w + x) as usize];
            let g = (((c - 1).max(0) as f64) / f64::from(m - 1) * 255.0).round() as u8;
            img.put_pixel(w + x, y, image::Rgb([g, g, g]));
        }
    }
    Ok((img, m))
}

/// The components image of each scene's first session and the components over time.
pub(super) fn products(ctx: &Aggregate, products: &mut Products) -> anyhow::Result<()> {
    let mut seen = BTreeSet::new();
    for (info, tables) in ctx.sessions {
        let (Some(cpp), Some(last)) = (tables.get(IMAGE_TABLE), tables.get(LAST_FRAME_TABLE))
        else {
            continue;
        };
        if !seen.insert(info.dataset.clone()) {
            continue;
        }
        let row = session_row(tables);
        let frame = read_image_table(last)?;
        if i64::from(frame.width()) != row.width || i64::from(frame.height()) != row.height {
            anyhow::bail!(
                "{}/{}: cached last frame has the wrong size",
                info.dataset,
                info.name
            );
        }
        let comps: Vec<i32> = cpp
            .column("components")?
            .i32()?
            .iter()
            .map(|v| v.unwrap_or(0))
            .collect();
        let (img, m) = side_by_side(&frame, &comps)
            .map_err(|e| anyhow::anyhow!("{}/{}: {e}", info.dataset, info.name))?;
        products.figures.push(Figure::new(
            format!("components_{}", sanitize(&info.dataset)),
            format!(
                "{}/{}: last frame and components per pixel (black 1 ... white {m})",
                info.dataset, info.name
            ),
            FigureKind::Overlay(ImageOverlay {
                image: img,
                shapes: Vec::new(),
            }),
        ));
    }
    let mut series = Vec::new();
    for (k, (dataset, sessions)) in by_dataset(ctx).into_iter().enumerate() {
        let Some(c) = sessions.iter().find(|f| f.contains_key(SAMPLES_TABLE)) else {
            continue;
        };
        let samples = ComponentsSample::of_session(c)?;
        let line = |get: fn(&ComponentsSample) -> f64| -> Vec<(f64, f64)> {
            samples.iter().map(|s| (s.t_s, get(s))).collect()
        };
        series.push(Series::line(
            format!("{dataset} adaptive"),
            line(|s| s.adaptive_mean_components),
            k + 1,
        ));
        series.push(
            Series::line(
                format!("{dataset} fixed M=4"),
                line(|s| s.baseline_mean_components),
                k + 1,
            )
            .with_mark(Mark::Dashed),
        );
    }
    if !series.is_empty() {
        products.figures.push(Figure::new(
            "components_over_time",
            "Mean components per pixel over time (first session of each scene)",
            FigureKind::Lines(LinePlot {
                x_label: "time (s)".into(),
                y_label: "components per pixel".into(),
                series,
                ..Default::default()
            }),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_components_image_is_grey_from_one_to_the_most() {
        let frame = RgbImage::from_pixel(2, 1, image::Rgb([9, 8, 7]));
        let (img, m) = side_by_side(&frame, &[1, 3]).expect("sizes match");
        assert_eq!(m, 3);
        assert_eq!(img.dimensions(), (4, 1));
        assert_eq!(img.get_pixel(0, 0).0, [9, 8, 7]);
        assert_eq!(img.get_pixel(2, 0).0, [0, 0, 0]);
        assert_eq!(img.get_pixel(3, 0).0, [255, 255, 255]);
        // one component everywhere still scales to a maximum of 2
        assert_eq!(side_by_side(&frame, &[1, 1]).expect("sizes").1, 2);
        assert!(side_by_side(&frame, &[1]).is_err());
    }

    #[test]
    fn a_new_model_has_no_components() {
        let gmm = AdaptiveGmm::new(Default::default()).expect("valid");
        assert_eq!(mean_components(&gmm), 0.0);
    }
}

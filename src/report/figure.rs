//! Figures in one house style, rendered by `plotters` to PNG and SVG from the same drawing
//! code, with an embedded font (DejaVu Sans, `assets/fonts/`) so no system font library is
//! needed. Kinds, as the experiments need them:
//!
//! - [`LinePlot`]: series over x with optional ±kσ bands and event marks (time series, sweeps,
//!   ROC curves, rates over time);
//! - [`ScatterPlot`]: points per series with an annotation (e.g. Pearson r) and a fit line;
//! - [`TopView`]: room outline, obstacles, sensors, trajectories and cylinders, equal aspect;
//! - [`BarPlot`]: bars with error bars and significance marks;
//! - [`ImageOverlay`]: a camera image with boxes, ellipses and polylines (projected cylinders);
//! - [`GroupedBars`]: bars in groups with a legend (a metric per sequence and method);
//! - [`Panels`]: figures side by side in a grid under one title.
//!
//! Colours are the Okabe–Ito palette (distinguishable with colour-vision deficiency).

use std::sync::Once;

use image::RgbImage;
use plotters::prelude::*;
use plotters::style::FontStyle;

const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
static FONT_ONCE: Once = Once::new();

fn register_font() {
    FONT_ONCE.call_once(|| {
        // The bytes are a valid TrueType font checked into the repository.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
        let _ = plotters::style::register_font("sans-serif", FontStyle::Bold, FONT);
    });
}

mod draw;
mod grouped;
mod spec;

#[cfg(test)]
use draw::emptiest_corner;
pub use draw::least_squares;
pub use spec::{
    Bar, BarPlot, Circle, Event, Figure, FigureKind, GroupedBars, ImageOverlay, LinePlot, Mark,
    Overlay, PALETTE, Panels, ScatterPlot, Sensor, Series, Significance, TopView, color,
};

/// A figure that could not be drawn (`figure NAME: reason`) or written (`writing figure NAME
/// to PATH: reason`, the reason naming the step and its path).
#[derive(Debug, thiserror::Error)]
#[error("{}", match path {
    Some(p) => format!("writing figure {name} to {}: {reason}", p.display()),
    None => format!("figure {name}: {reason}"),
})]
pub struct FigureError {
    pub name: String,
    pub reason: String,
    /// The file being written, for an I/O error.
    pub path: Option<std::path::PathBuf>,
}

impl FigureError {
    /// An I/O error writing figure `name` to `path`.
    pub fn io(name: &str, path: &std::path::Path, e: &std::io::Error) -> FigureError {
        FigureError {
            name: name.to_string(),
            reason: e.to_string(),
            path: Some(path.to_path_buf()),
        }
    }
}

impl Figure {
    fn err(&self, e: impl std::fmt::Display) -> FigureError {
        FigureError {
            name: self.name.clone(),
            reason: e.to_string(),
            path: None,
        }
    }

    /// PNG bytes.
    pub fn to_png(&self) -> Result<Vec<u8>, FigureError> {
        register_font();
        let (w, h) = self.size;
        let mut buf = vec![255u8; (w * h * 3) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
            self.draw(&root, true).map_err(|e| self.err(e))?;
            root.present().map_err(|e| self.err(e))?;
        }
        let img = RgbImage::from_raw(w, h, buf).ok_or_else(|| self.err("buffer size"))?;
        let mut out = Vec::new();
        img.write_to(&mut std::io::Cursor::new(&mut out), image::ImageFormat::Png)
            .map_err(|e| self.err(e))?;
        Ok(out)
    }

    /// SVG text. Image overlays embed the image as a PNG data URI under the vector shapes.
    pub fn to_svg(&self) -> Result<String, FigureError> {
        register_font();
        let mut s = String::new();
        {
            let root = SVGBackend::with_string(&mut s, self.size).into_drawing_area();
            self.draw(&root, false).map_err(|e| self.err(e))?;
            root.present().map_err(|e| self.err(e))?;
        }
        if let FigureKind::Overlay(o) = &self.kind {
            use base64::Engine;
            let mut png = Vec::new();
            o.image
                .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
                .map_err(|e| self.err(e))?;
            let data = base64::engine::general_purpose::STANDARD.encode(&png);
            let tag = format!(
                "<image x=\"0\" y=\"30\" width=\"{}\" height=\"{}\" href=\"data:image/png;base64,{data}\"/>",
                o.image.width(),
                o.image.height()
            );
            // insert right after the opening <svg ...> tag so shapes draw on top
            if let Some(end) = s.find('>') {
                s.insert_str(end + 1, &tag);
            }
        }
        Ok(s)
    }
}

#[cfg(test)]
mod tests;

//! Output: result tables (CSV, Parquet, Markdown, LaTeX), figures (PNG, SVG) and the run
//! report, all written atomically under `out/`. Only this module and `log` touch files.

pub mod atomic;
pub mod columns;
pub mod figure;
pub mod preview;
pub mod rows;
pub mod table;

use std::path::{Path, PathBuf};

pub use figure::Figure;
pub use table::{Provenance, Table};

/// Write `<dir>/<name>.png` and `<dir>/<name>.svg` atomically; returns the paths.
pub fn write_figure(
    dir: &Path,
    fig: &Figure,
    root: &Path,
) -> Result<Vec<PathBuf>, figure::FigureError> {
    let png = dir.join(format!("{}.png", fig.name));
    atomic::write_atomic(&png, &fig.to_png()?, Some(root))
        .map_err(|e| figure::FigureError::io(&fig.name, &png, &e))?;
    let svg = dir.join(format!("{}.svg", fig.name));
    atomic::write_atomic(&svg, fig.to_svg()?.as_bytes(), Some(root))
        .map_err(|e| figure::FigureError::io(&fig.name, &svg, &e))?;
    Ok(vec![png, svg])
}

//! Aggregation: the cached per-session tables → scored runs (`scored`) → the evaluation's
//! tables (`evaluate`) and the figures (`figures`); then, only when asked, the export of the
//! tracks into copies of the logs (`markers`, which reads the logs).

use super::scored::{self, Scored};
use super::{Params, evaluate, figures, markers};
use crate::run::{Aggregate, Products};

/// The first summary line: the main run's scores at the largest threshold.
fn main_line(s: &Scored) -> Option<String> {
    let t = s.t_max();
    let m = &s.eval(&s.main, t)?.metrics;
    Some(format!(
        "Main run ({}, {}, N_app = {}): MOTA {:.3} and IDF1 {:.3} at {} m.",
        s.main.0, s.main.1, s.main.2, m.clear.mota, m.identity.idf1, t
    ))
}

/// Sessions, frames and decoding failures.
fn sessions_line(s: &Scored) -> String {
    let failures: i64 = s.data.iter().map(|d| d.session.decode_failures).sum();
    format!(
        "{} session(s), {} frames in all; {failures} camera frames failed to decode{}.",
        s.data.len(),
        s.data.iter().map(|d| d.session.frames).sum::<i64>(),
        s.data
            .iter()
            .find(|d| !d.session.first_error.is_empty())
            .map(|d| format!(" (first: {})", d.session.first_error))
            .unwrap_or_default()
    )
}

pub(crate) fn aggregate(ctx: &Aggregate, p: &Params) -> anyhow::Result<Products> {
    let scored = scored::score(ctx, p)?;
    let mut products = Products::default();
    products.summary.push(sessions_line(&scored));
    evaluate::evaluate(&scored, p, &mut products)?;
    products.figures.extend(figures::birdseye(&scored, p));
    match figures::camera_views(&scored, p) {
        Ok(Some(f)) => products.figures.push(f),
        Ok(None) => {}
        Err(e) => products
            .summary
            .push(format!("Camera-view figure not drawn: {e:#}")),
    }
    // the export step: reads the logs, runs only when asked
    if let Some(dir) = markers::export_dir(ctx, p) {
        products.summary.extend(markers::export(&scored, p, &dir)?);
    }
    if let Some(line) = main_line(&scored) {
        products.summary.insert(0, line);
    }
    Ok(products)
}

//! The evaluation, one file per sub-experiment, each with its tables (and figures where it
//! has one): `tracks`, `clear_mot` (CLEAR MOT / IDF1 / HOTA at each threshold), `moda` (MODA / MODP), `decompose` (ghosts by cameras, development / held-out splits), `gt_boxes`
//! (the 3-D stage on ground-truth boxes), `noise` (the 3-D stage under the detector model's
//! noise, issue 32), `position` (position, height and radius errors),
//! `sweep` (`N_app` against latency and false alarms), `head_centroid` (t-test),
//! `selection` (E_c vs E_m), `stages` (per-camera image stages), `detections_2d` (the
//! template detector alone), `error_causes` (its misses and false detections by cause) and
//! `search` (the 3-D search statistics). All read only the
//! [`Scored`] sessions.

mod clear_mot;
mod decompose;
mod detections_2d;
mod error_causes;
mod gt_boxes;
mod head_centroid;
mod moda;
mod noise;
mod position;
mod search;
mod selection;
mod stages;
mod sweep;
mod timing;
mod tracks;

use super::Params;
use super::scored::Scored;
use crate::eval::stats::describe;
use crate::run::Products;

/// Every table and evaluation figure, in report order, with their summary lines.
pub(crate) fn evaluate(s: &Scored, p: &Params, products: &mut Products) -> anyhow::Result<()> {
    products.tables.push(tracks::table(s)?);
    if s.has_truth() {
        products.tables.push(clear_mot::table(s, p)?);
        products.tables.push(moda::table(s)?);
        if p.decompose {
            products.tables.push(decompose::ghosts(s)?);
            products.tables.push(decompose::splits(s, p)?);
        }
        if !p.detector_noise.is_empty() {
            products.tables.push(noise::table(s, p)?);
        }
        if let Some(t) = gt_boxes::table(s, &mut products.summary)? {
            products.tables.push(t);
        }
        products
            .tables
            .push(position::table(s, &mut products.summary)?);
        let (sweep, curve) = sweep::table(s, p)?;
        products.tables.push(sweep);
        products.figures.push(curve);
        let (hc, bars) = head_centroid::table(s, p, &mut products.summary)?;
        products.tables.push(hc);
        products.figures.extend(bars);
        products
            .tables
            .push(selection::table(s, &mut products.summary)?);
    } else {
        products
            .summary
            .push("No ground truth in these logs: tracks only, no accuracy tables.".to_string());
    }
    products.tables.push(stages::table(s)?);
    if let Some(t) = detections_2d::table(s, &mut products.summary)? {
        let note = bootstrap_note(p);
        products.tables.push(if note.is_empty() {
            t
        } else {
            t.with_note(note)
        });
    }
    if let Some(t) = error_causes::table(s, &mut products.summary)? {
        products.tables.push(t);
    }
    products.tables.push(search::table(s)?);
    products.tables.push(timing::table(s)?);
    Ok(())
}

/// What the image chain's background starts from, said in the tables it affects: the default
/// median over frames spread across the whole log uses frames later than those it is applied
/// to (the paper does not say how its background starts).
/// Empty when the detections come from the log (no background).
fn bootstrap_note(p: &Params) -> String {
    if p.detector != super::params::Detector::Templates {
        return String::new();
    }
    let start = start_note(p);
    if p.ghost_removal {
        format!(
            "{start} Ghost removal (our addition): a foreground region with more luminance edge along its contour in the background than in the frame is a ghost, learnt once a pixel has lain in ghosts for {} frames running (ghost_removal = false turns it off).",
            p.ghost_frames
        )
    } else {
        start
    }
}

fn start_note(p: &Params) -> String {
    if p.bootstrap_frames == 0 {
        "Background (template chain): started from the first frame alone and updated by eq. 2 (a causal start: no frame later than the one processed is used).".to_string()
    } else {
        format!(
            "Background (template chain): started from the per-pixel median of {} frames spread evenly over the whole log, so it uses frames later than those it is applied to (not causal); bootstrap_frames = 0 starts from the first frame alone (causal).",
            p.bootstrap_frames
        )
    }
}

fn mean(v: &[f64]) -> Option<f64> {
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

fn std(v: &[f64]) -> Option<f64> {
    describe(v).ok().map(|s| s.std)
}

fn median(v: &[f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    Some(if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    })
}

/// Linear interpolation between order statistics (numpy's default).
fn percentile(v: &[f64], q: f64) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let pos = q * (s.len() - 1) as f64;
    let (i, f) = (pos.floor() as usize, pos.fract());
    Some(s[i] * (1.0 - f) + s[(i + 1).min(s.len() - 1)] * f)
}

/// A table's frame with some columns renamed (names that are not identifiers, e.g.
/// `MOTA_0.5m`).
fn renamed(
    mut df: polars::prelude::DataFrame,
    names: &[(&str, String)],
) -> polars::prelude::PolarsResult<polars::prelude::DataFrame> {
    for (from, to) in names {
        df.rename(from, to.as_str().into())?;
    }
    Ok(df)
}

#[cfg(test)]
pub(crate) mod testdata;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn order_statistics() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), Some(2.5));
        assert_eq!(median(&[]), None);
        // 0.95 · 4 = 3.8: 0.2 · 4 + 0.8 · 5
        assert_eq!(percentile(&[5.0, 1.0, 2.0, 3.0, 4.0], 0.95), Some(4.8));
        assert_eq!(mean(&[1.0, 2.0, 6.0]), Some(3.0));
        assert_eq!(mean(&[]), None);
    }
}

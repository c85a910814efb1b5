//! How well the colour descriptor separates the target from everything else (seed 001 §V's
//! HS-histogram correlation, normalised form): for every blob the paper's configuration saw,
//! its normalised correlation with the template, grouped by what the ground truth says the
//! blob is — the target, another person, or something static (a tree, a bush). The table says
//! how many blobs of each kind pass the re-acquisition floor (`follower.reacquire_corr`); the
//! quick profile chose that floor (see docs/s001_kobilarov_following.md).

use super::params::Params;
use super::tables::SessionData;
use crate::report::rows::Rows;
use crate::report::table::Table;
use crate::table_row;

table_row! {
    /// One kind of blob: `colour_separation`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct SeparationRow {
        pub kind: String,
        pub blobs: i64,
        pub p05: Option<f64>,
        pub p25: Option<f64>,
        pub median: Option<f64>,
        pub p75: Option<f64>,
        pub p95: Option<f64>,
        /// Share at or above the re-acquisition floor.
        pub above_floor: Option<f64>,
    }
}

/// The `q`-quantile of sorted values (nearest rank).
fn quantile(sorted: &[f64], q: f64) -> Option<f64> {
    if sorted.is_empty() {
        return None;
    }
    let k = ((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len());
    Some(sorted[k - 1])
}

/// The rows, one per kind, in the order target, person, static.
pub fn rows(data: &[&SessionData], p: &Params) -> Vec<SeparationRow> {
    let floor = p.follower.reacquire_corr;
    ["target", "person", "static"]
        .iter()
        .map(|kind| {
            let mut v: Vec<f64> = data
                .iter()
                .flat_map(|d| d.colour.iter())
                .filter(|r| r.kind == *kind)
                .map(|r| r.corr)
                .collect();
            v.sort_by(f64::total_cmp);
            let n = v.len();
            SeparationRow {
                kind: (*kind).into(),
                blobs: n as i64,
                p05: quantile(&v, 0.05),
                p25: quantile(&v, 0.25),
                median: quantile(&v, 0.5),
                p75: quantile(&v, 0.75),
                p95: quantile(&v, 0.95),
                above_floor: (n > 0)
                    .then(|| v.iter().filter(|c| **c >= floor).count() as f64 / n as f64),
            }
        })
        .collect()
}

/// `colour_separation`.
pub fn table(data: &[&SessionData], p: &Params) -> anyhow::Result<Table> {
    let mut t = Table::new(
        "colour_separation",
        "Normalised HS-histogram correlation with the template, per kind of blob (the paper's configuration)",
        SeparationRow::frame(&rows(data, p))?,
    );
    for c in ["p05", "p25", "median", "p75", "p95", "above_floor"] {
        t = t.with_precision(c, 3);
    }
    Ok(t.with_note(format!(
        "Every blob of every scan with a template and an omni frame. Kind from the ground truth: target (within {} m of the followed person), person (of another), static (nobody). above_floor: share with a normalised correlation of at least {} (follower.reacquire_corr, the re-acquisition floor).",
        p.lock_m, p.follower.reacquire_corr
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_rank_quantiles() {
        let v = [1.0, 2.0, 3.0, 4.0];
        assert_eq!(quantile(&v, 0.5), Some(2.0));
        assert_eq!(quantile(&v, 0.05), Some(1.0));
        assert_eq!(quantile(&v, 0.95), Some(4.0));
        assert_eq!(quantile(&[], 0.5), None);
    }
}

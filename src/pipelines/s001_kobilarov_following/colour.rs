//! How well the colour descriptor separates the target from everything else (seed 001 §V's
//! HS-histogram correlation, normalised form): for every blob the paper's configuration saw,
//! its normalised correlation with the template, grouped by what the ground truth says the
//! blob is — the target, another person, or something static (a tree, a bush). The table says
//! how many blobs of each kind pass the re-acquisition floor (`follower.reacquire_corr`); the
//! quick profile chose that floor (see docs/s001_kobilarov_following.md).
//!
//! `blob_scatter`: the same blobs' centres about the true position of the person they belong
//! to — the laser measurement noise σ_r of the PDAF's `z = (x, y) + v`, `v ~ N(0, σ_r² I)`
//! (seed 001 §V). `sigma_axis` = √(mean(dx² + dy²)/2) is the per-axis RMS about the truth
//! (bias included: the laser sees a person's near side, so a blob centre lies towards the
//! robot, in a direction that turns with the robot). The quick profile's target row chose
//! `track::pdaf::SIGMA_R`. Blobs farther than `lock_m` from every person are not a person's,
//! so the scatter is truncated there (≫ 3σ for the values measured).

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

table_row! {
    /// A person's blob centres about their true position: `blob_scatter`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct ScatterRow {
        pub kind: String,
        pub blobs: i64,
        pub mean_dx: Option<f64>,
        pub mean_dy: Option<f64>,
        pub sd_x: Option<f64>,
        pub sd_y: Option<f64>,
        /// √(mean(dx² + dy²)/2): the per-axis RMS about the true position.
        pub sigma_axis: Option<f64>,
        /// 95th percentile of the distance to the true position.
        pub p95_dist: Option<f64>,
    }
}

/// The scatter of one set of offsets `(dx, dy)` (m).
fn scatter(kind: &str, o: &[[f64; 2]]) -> ScatterRow {
    let n = o.len() as f64;
    let some = |v: f64| (!o.is_empty()).then_some(v);
    let mean = |i: usize| o.iter().map(|d| d[i]).sum::<f64>() / n;
    let (mx, my) = (mean(0), mean(1));
    let sd = |i: usize, m: f64| {
        (o.len() > 1)
            .then(|| (o.iter().map(|d| (d[i] - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt())
    };
    let mut dist: Vec<f64> = o.iter().map(|d| d[0].hypot(d[1])).collect();
    dist.sort_by(f64::total_cmp);
    ScatterRow {
        kind: kind.into(),
        blobs: o.len() as i64,
        mean_dx: some(mx),
        mean_dy: some(my),
        sd_x: sd(0, mx),
        sd_y: sd(1, my),
        sigma_axis: some(
            (o.iter().map(|d| d[0] * d[0] + d[1] * d[1]).sum::<f64>() / (2.0 * n)).sqrt(),
        ),
        p95_dist: quantile(&dist, 0.95),
    }
}

/// The rows, target then other people.
pub fn scatter_rows(data: &[&SessionData]) -> Vec<ScatterRow> {
    ["target", "person"]
        .iter()
        .map(|kind| {
            let o: Vec<[f64; 2]> = data
                .iter()
                .flat_map(|d| d.colour.iter())
                .filter(|r| r.kind == *kind)
                .filter_map(|r| Some([r.dx?, r.dy?]))
                .collect();
            scatter(kind, &o)
        })
        .collect()
}

/// `blob_scatter`.
pub fn scatter_table(data: &[&SessionData], p: &Params) -> anyhow::Result<Table> {
    let mut t = Table::new(
        "blob_scatter",
        "Laser blob centres about the true person position (the measurement noise σ_r)",
        ScatterRow::frame(&scatter_rows(data))?,
    );
    for c in [
        "mean_dx",
        "mean_dy",
        "sd_x",
        "sd_y",
        "sigma_axis",
        "p95_dist",
    ] {
        t = t.with_precision(c, 3);
    }
    Ok(t.with_note(format!(
        "The blobs of colour_separation (map frame, m) within {} m of a person: centre (mean of the blob's points) minus the person's true position at the scan. sigma_axis = sqrt(mean(dx^2 + dy^2) / 2), the per-axis RMS about the truth, bias included; the quick profile's target row chose the follower's sigma_r (now {} m).",
        p.lock_m, p.follower.sigma_r
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

    #[test]
    fn scatter_of_four_offsets() {
        // offsets (±0.1, 0) and (0, ±0.2) about a bias of (0.05, 0)
        let o = [[0.15, 0.0], [-0.05, 0.0], [0.05, 0.2], [0.05, -0.2]];
        let r = scatter("target", &o);
        assert_eq!(r.blobs, 4);
        assert!((r.mean_dx.expect("mean_dx") - 0.05).abs() < 1e-12);
        assert!(r.mean_dy.expect("mean_dy").abs() < 1e-12);
        // sample sd: x √(0.02/3), y √(0.08/3)
        assert!((r.sd_x.expect("sd_x") - (0.02f64 / 3.0).sqrt()).abs() < 1e-12);
        assert!((r.sd_y.expect("sd_y") - (0.08f64 / 3.0).sqrt()).abs() < 1e-12);
        // Σ|d|² = 0.0225 + 0.0025 + 0.0425 + 0.0425 = 0.11; /(2·4) → √0.01375
        assert!((r.sigma_axis.expect("sigma_axis") - 0.01375f64.sqrt()).abs() < 1e-12);
        assert_eq!(scatter("person", &[]).sigma_axis, None);
    }
}

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

table_row! {
    /// The density of blobs that are not the target around the target: `clutter_density`.
    #[derive(Debug, Clone, PartialEq)]
    pub struct ClutterRow {
        pub radius_m: f64,
        /// Scans with the target in the laser's view.
        pub scans: i64,
        /// Blobs of other people and of static things within `radius_m` of the target.
        pub person_blobs: i64,
        pub static_blobs: i64,
        /// (person + static blobs) / (scans · π radius²), per m².
        pub density: Option<f64>,
        /// The same for other people's blobs only.
        pub person_density: Option<f64>,
    }
}

/// Radii (m) of the discs about the target that `clutter_density` counts in: the PDAF's gate
/// (99 % χ²₂ with σ_r 0.19 m and a settled track: ~0.75 m) and twice and four times it.
pub const CLUTTER_RADII: [f64; 3] = [0.75, 1.5, 3.0];

/// The rows, one per radius of [`CLUTTER_RADII`] (see [`clutter_table`]).
pub fn clutter_rows(data: &[&SessionData]) -> Vec<ClutterRow> {
    let in_view: std::collections::BTreeSet<(usize, i64)> = data
        .iter()
        .enumerate()
        .flat_map(|(k, d)| {
            d.truth
                .iter()
                .filter(|t| t.target_x.is_some() && !t.out_of_view)
                .map(move |t| (k, t.scan_idx))
        })
        .collect();
    let scans = in_view.len() as i64;
    CLUTTER_RADII
        .iter()
        .map(|&r| {
            let count = |kind: &str| {
                data.iter()
                    .enumerate()
                    .flat_map(|(k, d)| d.colour.iter().map(move |c| (k, c)))
                    .filter(|(k, c)| c.kind == kind && in_view.contains(&(*k, c.scan_idx)))
                    .filter(|(_, c)| c.tdx.zip(c.tdy).is_some_and(|(x, y)| x.hypot(y) <= r))
                    .count() as i64
            };
            let (person, stat) = (count("person"), count("static"));
            let area = scans as f64 * std::f64::consts::PI * r * r;
            ClutterRow {
                radius_m: r,
                scans,
                person_blobs: person,
                static_blobs: stat,
                density: (scans > 0).then(|| (person + stat) as f64 / area),
                person_density: (scans > 0).then(|| person as f64 / area),
            }
        })
        .collect()
}

/// `clutter_density`.
pub fn clutter_table(data: &[&SessionData], p: &Params) -> anyhow::Result<Table> {
    let mut t = Table::new(
        "clutter_density",
        "Blobs that are not the target, per m² about the target (the PDAF's clutter density λ)",
        ClutterRow::frame(&clutter_rows(data))?,
    );
    for c in ["density", "person_density"] {
        t = t.with_precision(c, 4);
    }
    Ok(t.with_note(format!(
        "The blobs of colour_separation whose centre lies within radius_m of the target's true position, on the scans where the target is in the laser's view, divided by the scans and the disc's area; person blobs lie within {} m of another person, static ones near nobody. The disc is in the map frame; where it reaches behind the target or out of the laser's field the density is an under-estimate. The follower's clutter_density (λ) is now {} /m².",
        p.lock_m, p.follower.clutter_density
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

    fn truth(scan_idx: i64, out_of_view: bool) -> super::super::tables::TruthRow {
        super::super::tables::TruthRow {
            scan_idx,
            t_s: 0.1 * scan_idx as f64,
            robot_x: 0.0,
            robot_y: 0.0,
            robot_yaw: 0.0,
            robot_v: 0.0,
            pitch: 0.0,
            target_x: Some(5.0),
            target_y: Some(0.0),
            target_vx: None,
            target_vy: None,
            range_m: Some(5.0),
            bearing_rad: Some(0.0),
            ground: false,
            occluded: false,
            out_of_view,
            obstacle: false,
        }
    }

    fn blob(scan_idx: i64, kind: &str, t: [f64; 2]) -> super::super::tables::ColourRow {
        super::super::tables::ColourRow {
            scan_idx,
            kind: kind.into(),
            corr: 0.0,
            dx: None,
            dy: None,
            tdx: Some(t[0]),
            tdy: Some(t[1]),
        }
    }

    /// Four scans with the target in view (a fifth out of view is not counted, nor are its
    /// blobs): a person 1 m from the target on every scan, a tree 2 m away on two, the
    /// target's own blob, and a tree 0.5 m away on the out-of-view scan. Densities in closed
    /// form: 0.75 m — nothing; 1.5 m — 4 / (4 π 1.5²); 3 m — 6 / (4 π 9).
    #[test]
    fn clutter_density_in_closed_form() {
        let mut colour = Vec::new();
        for k in 0..4 {
            colour.push(blob(k, "target", [0.1, 0.0]));
            colour.push(blob(k, "person", [0.0, 1.0]));
        }
        colour.push(blob(0, "static", [2.0, 0.0]));
        colour.push(blob(1, "static", [0.0, -2.0]));
        colour.push(blob(4, "static", [0.5, 0.0]));
        let d = SessionData {
            name: "s".into(),
            tracks: vec![],
            truth: (0..5).map(|k| truth(k, k == 4)).collect(),
            closed_loop: vec![],
            method1: vec![],
            real: vec![],
            colour,
        };
        let rows = clutter_rows(&[&d]);
        let pi = std::f64::consts::PI;
        let r: Vec<(i64, i64, i64)> = rows
            .iter()
            .map(|r| (r.scans, r.person_blobs, r.static_blobs))
            .collect();
        assert_eq!(r, vec![(4, 0, 0), (4, 4, 0), (4, 4, 2)]);
        assert_eq!(rows[0].density, Some(0.0));
        assert!((rows[1].density.expect("1.5") - 4.0 / (4.0 * pi * 2.25)).abs() < 1e-12);
        assert!((rows[2].density.expect("3") - 6.0 / (36.0 * pi)).abs() < 1e-12);
        assert!((rows[2].person_density.expect("3 p") - 4.0 / (36.0 * pi)).abs() < 1e-12);
    }
}

//! Sub-experiment 4 (section 4.3, fig. 5): Pearson r of each depth-cue feature and of the
//! appearance model's output (split 0's test frames) with the measured distance, and the
//! scatter plots.

use super::ann::{Learner, Split0};
use crate::eval::stats;
use crate::report::figure::{FigureKind, ScatterPlot, Series};
use crate::report::rows::Rows;
use crate::report::{Figure, Table};
use crate::run::Products;
use crate::table_row;

/// The features, in the order of the feature vector.
pub const FEATURES: [&str; 3] = ["width", "apparent_distance", "pixels"];

table_row! {
    /// A row of the `correlations` table.
    #[derive(Debug, Clone, PartialEq)]
    pub struct CorrelationRow {
        pub quantity: String,
        pub r: f64,
        pub ci95_low: f64,
        pub ci95_high: f64,
        pub p: f64,
    }
}

/// Pearson r of `x` with `y` and its Fisher 95 % interval.
pub fn correlation(quantity: &str, x: &[f64], y: &[f64]) -> anyhow::Result<CorrelationRow> {
    let c = stats::pearson(x, y, 0.95)?;
    Ok(CorrelationRow {
        quantity: quantity.into(),
        r: c.r,
        ci95_low: c.ci_low,
        ci95_high: c.ci_high,
        p: c.p_two_sided,
    })
}

fn scatter(name: String, title: String, y_label: &str, x: &[f64], y: &[f64], r: f64) -> Figure {
    Figure::new(
        name,
        title,
        FigureKind::Scatter(ScatterPlot {
            x_label: "distance from the measurement system (m)".into(),
            y_label: y_label.into(),
            series: vec![Series::points(
                "",
                x.iter().copied().zip(y.iter().copied()).collect(),
                5,
            )],
            annotation: format!("r = {r:.3}"),
            fit_line: true,
        }),
    )
}

/// The table and fig. 5's four scatter plots.
pub fn run(l: &Learner, split0: &Split0, out: &mut Products) -> anyhow::Result<()> {
    let mut rows = Vec::new();
    for (k, n) in FEATURES.iter().enumerate() {
        let x: Vec<f64> = l.xs.iter().map(|f| f[k]).collect();
        let c = correlation(n, &x, &l.dist)?;
        out.figures.push(scatter(
            format!("fig5_{n}"),
            format!("{n} vs distance (r = {:.3})", c.r),
            n,
            &l.dist,
            &x,
            c.r,
        ));
        rows.push(c);
    }
    // ANN output vs distance (fig 5, bottom right): split 0's test predictions
    let pred: Vec<f64> = split0
        .test
        .iter()
        .map(|i| split0.model.predict(&l.xs[*i]))
        .collect();
    let truth0: Vec<f64> = split0.test.iter().map(|i| l.dist[*i]).collect();
    let c = correlation("appearance model output", &pred, &truth0)?;
    out.figures.push(scatter(
        "fig5_ann".into(),
        format!("Appearance model output vs distance (r = {:.3})", c.r),
        "appearance model output (m)",
        &truth0,
        &pred,
        c.r,
    ));
    rows.push(c);
    out.tables.push(
        Table::new(
            "correlations",
            "Linear correlation of each feature and of the appearance model with the true distance (fig. 5)",
            CorrelationRow::frame(&rows)?,
        )
        .with_precision("p", 6)
        .with_note("The paper shows these r values inside fig. 5 but not in its text, so no paper column. Fisher 95 % intervals."),
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn perfectly_correlated_data_give_r_plus_or_minus_one() {
        let d: Vec<f64> = (0..20).map(|i| 1.0 + 0.1 * f64::from(i)).collect();
        let up: Vec<f64> = d.iter().map(|x| 3.0 * x + 2.0).collect();
        let down: Vec<f64> = d.iter().map(|x| 10.0 - x).collect();
        let c = correlation("apparent_distance", &up, &d).expect("r");
        assert_eq!(c.quantity, "apparent_distance");
        assert!((c.r - 1.0).abs() < 1e-12, "r = {}", c.r);
        assert!(c.p < 1e-10);
        assert!((correlation("width", &down, &d).expect("r").r + 1.0).abs() < 1e-12);
    }

    #[test]
    fn uncorrelated_data_give_r_zero_and_an_interval_around_it() {
        // symmetric about the mean of x: covariance exactly zero
        let x = [-2.0, -1.0, 0.0, 1.0, 2.0, -2.0, -1.0, 0.0, 1.0, 2.0];
        let y = [1.0, 2.0, 3.0, 2.0, 1.0, 1.0, 2.0, 3.0, 2.0, 1.0];
        let c = correlation("pixels", &x, &y).expect("r");
        assert!(c.r.abs() < 1e-12);
        assert!(c.ci95_low < 0.0 && c.ci95_high > 0.0);
        assert!(c.p > 0.99);
    }
}

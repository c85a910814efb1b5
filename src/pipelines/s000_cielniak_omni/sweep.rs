//! Sub-experiment 5 (section 4.4): mean test error over a grid of hidden units × learning
//! rates, a few splits each; the figure and the table.

use rayon::prelude::*;

use super::ann::Learner;
use super::params::Params;
use super::shared::mean_std;
use crate::learn::mlp::TrainSpec;
use crate::report::figure::{FigureKind, LinePlot, Mark, Series};
use crate::report::rows::Rows;
use crate::report::{Figure, Table};
use crate::run::Products;
use crate::table_row;

table_row! {
    /// One configuration's mean test error: the `ann_sweep` table.
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct SweepRow {
        pub hidden_units: i64,
        pub learning_rate: f64,
        pub mean_error_m: f64,
    }
}

/// The configurations, hidden units outermost.
pub fn grid(hidden: &[usize], rates: &[f64]) -> Vec<(usize, f64)> {
    hidden
        .iter()
        .flat_map(|h| rates.iter().map(move |lr| (*h, *lr)))
        .collect()
}

/// The configuration with the lowest mean error (the first of ties).
pub fn best(results: &[SweepRow]) -> Option<SweepRow> {
    results
        .iter()
        .min_by(|a, b| a.mean_error_m.total_cmp(&b.mean_error_m))
        .copied()
}

fn figure(rates: &[f64], results: &[SweepRow]) -> Figure {
    let series = rates
        .iter()
        .enumerate()
        .map(|(k, lr)| {
            Series::line(
                format!("learning rate {lr}"),
                results
                    .iter()
                    .filter(|r| r.learning_rate == *lr)
                    .map(|r| (r.hidden_units as f64, r.mean_error_m))
                    .collect(),
                k + 1,
            )
            .with_mark(Mark::LinePoints)
        })
        .collect();
    Figure::new(
        "ann_sweep",
        "Mean test error by hidden units and learning rate",
        FigureKind::Lines(LinePlot {
            x_label: "hidden units".into(),
            y_label: "mean distance error (m)".into(),
            series,
            ..Default::default()
        }),
    )
}

/// Run the sweep (not with a loaded model, nor with an empty grid).
pub fn run(l: &Learner, p: &Params, out: &mut Products) -> anyhow::Result<()> {
    if l.loaded.is_some() || p.sweep_hidden.is_empty() {
        return Ok(());
    }
    let all = l.all();
    let results: Vec<SweepRow> = grid(&p.sweep_hidden, &p.sweep_learning_rates)
        .par_iter()
        .map(|&(h, lr)| {
            let spec = TrainSpec {
                hidden: h,
                learning_rate: lr,
                epochs: p.epochs,
            };
            let mut errs: Vec<f64> = Vec::new();
            for s in 0..p.sweep_splits {
                let (train, test) = l.split(s, &all);
                errs.extend(l.errors(&l.fit(&train, 1000 + s as u64, spec)?, &test));
            }
            Ok(SweepRow {
                hidden_units: h as i64,
                learning_rate: lr,
                mean_error_m: mean_std(&errs).0,
            })
        })
        .collect::<anyhow::Result<_>>()?;
    out.figures.push(figure(&p.sweep_learning_rates, &results));
    if let Some(b) = best(&results) {
        out.summary.push(format!(
            "Sweep: lowest mean error {:.3} m with {} hidden units and learning rate {} (paper's best: 4 units, 0.3).",
            b.mean_error_m, b.hidden_units, b.learning_rate
        ));
    }
    out.tables.push(Table::new(
        "ann_sweep",
        "Mean test error (m) by hidden units and learning rate",
        SweepRow::frame(&results)?,
    ));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grid_runs_learning_rates_inside_hidden_units() {
        assert_eq!(
            grid(&[1, 4], &[0.1, 0.3]),
            [(1, 0.1), (1, 0.3), (4, 0.1), (4, 0.3)]
        );
        assert!(grid(&[], &[0.1]).is_empty());
    }

    #[test]
    fn the_best_configuration_is_the_first_lowest_error() {
        let row = |h, lr, e| SweepRow {
            hidden_units: h,
            learning_rate: lr,
            mean_error_m: e,
        };
        let rows = [row(1, 0.1, 0.3), row(4, 0.3, 0.1), row(5, 0.3, 0.1)];
        assert_eq!(best(&rows), Some(rows[1]));
        assert_eq!(best(&[]), None);
    }
}

//! Sub-experiment 3 (sections 4.4, 6.1): the 3-H-1 network trained on random 30/70 splits,
//! repeated; the average, best and worst split's distance error.

use rayon::prelude::*;

use super::ann::Learner;
use super::dataset::Row;
use super::params::Params;
use super::shared::{fmt_ms, mean_std};
use crate::report::Table;
use crate::report::rows::Rows;
use crate::run::Products;
use crate::table_row;

table_row! {
    /// A row of the `ann_error` table.
    pub struct AnnErrorRow {
        pub results: String,
        pub ours_m: String,
        pub paper_m: String,
        pub frames: i64,
    }
}

table_row! {
    /// One test frame's error in one split (the table's samples).
    pub struct AnnErrorSample {
        pub split: i64,
        pub stamp: i64,
        pub abs_error_m: f64,
    }
}

/// One split's test frames with their absolute errors.
pub struct SplitErrors {
    pub split: usize,
    pub errors: Vec<(usize, f64)>,
}

/// Indices of the splits with the lowest mean (the first of ties) and the highest (the last of
/// ties); 0 if none.
pub fn best_and_worst(means: &[f64]) -> (usize, usize) {
    let best = (0..means.len())
        .min_by(|a, b| means[*a].total_cmp(&means[*b]))
        .unwrap_or(0);
    let worst = (0..means.len())
        .max_by(|a, b| means[*a].total_cmp(&means[*b]))
        .unwrap_or(0);
    (best, worst)
}

/// Train and test on `p.splits` splits (in parallel, collected in order).
pub fn per_split(l: &Learner, splits: usize) -> anyhow::Result<Vec<SplitErrors>> {
    let all = l.all();
    (0..splits)
        .into_par_iter()
        .map(|s| {
            let (train, test) = l.split(s, &all);
            let model = l.model(&train, s as u64)?;
            let e = l.errors(&model, &test);
            Ok(SplitErrors {
                split: s,
                errors: test.into_iter().zip(e).collect(),
            })
        })
        .collect()
}

pub fn run(l: &Learner, rows: &[Row], p: &Params, out: &mut Products) -> anyhow::Result<()> {
    let per_split = per_split(l, p.splits)?;
    let stats: Vec<(f64, f64)> = per_split
        .iter()
        .map(|s| mean_std(&s.errors.iter().map(|x| x.1).collect::<Vec<_>>()))
        .collect();
    let samples: Vec<AnnErrorSample> = per_split
        .iter()
        .flat_map(|s| {
            s.errors.iter().map(|(i, e)| AnnErrorSample {
                split: s.split as i64,
                stamp: rows[*i].stamp,
                abs_error_m: *e,
            })
        })
        .collect();
    let pooled: Vec<f64> = samples.iter().map(|s| s.abs_error_m).collect();
    let (pm, ps) = mean_std(&pooled);
    let (best, worst) = best_and_worst(&stats.iter().map(|s| s.0).collect::<Vec<_>>());
    let row = |results: &str, ours: String, paper: &str, frames: usize| AnnErrorRow {
        results: results.into(),
        ours_m: ours,
        paper_m: paper.into(),
        frames: frames as i64,
    };
    let split_row = |results: &str, k: usize, paper: &str| {
        let frames = per_split.get(k).map_or(0, |s| s.errors.len());
        let (m, s) = stats.get(k).copied().unwrap_or((f64::NAN, f64::NAN));
        row(results, fmt_ms(m, s), paper, frames)
    };
    let table = [
        row("Average", fmt_ms(pm, ps), "0.126 ± 0.167", pooled.len()),
        split_row("Best", best, "0.110 ± 0.099"),
        split_row("Worst", worst, "0.163 ± 0.325"),
    ];
    let note = if l.loaded.is_some() {
        format!("Model loaded from {} (not retrained).", p.model)
    } else {
        "Paper section 6.1 (684 frames at 3 Hz, two people). Error against the external measurement system.".into()
    };
    out.tables.push(
        Table::new(
            "ann_error",
            format!(
                "Appearance model (ANN 3-{}-1, learning rate {}) distance error over {} random {:.0}/{:.0} splits",
                p.hidden_units,
                p.learning_rate,
                p.splits,
                100.0 * p.train_fraction,
                100.0 * (1.0 - p.train_fraction)
            ),
            AnnErrorRow::frame(&table)?,
        )
        .with_note(note)
        .with_samples(AnnErrorSample::frame(&samples)?),
    );
    out.summary.push(format!(
        "ANN distance error {} m over {} splits (paper 0.126 ± 0.167).",
        fmt_ms(pm, ps),
        p.splits
    ));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn best_and_worst_split_by_mean_first_of_ties() {
        assert_eq!(best_and_worst(&[0.3, 0.1, 0.5, 0.1, 0.5]), (1, 4));
        assert_eq!(best_and_worst(&[0.2]), (0, 0));
        assert_eq!(best_and_worst(&[]), (0, 0));
    }
}

//! Sub-experiment 6 (section 6.1): person-specific appearance models — the 2×2 table of test
//! subject × model trained for, and an unpaired t-test of the specific models on their own
//! person against a general model trained on the same frames.

use std::collections::BTreeMap;

use super::ann::Learner;
use super::dataset::Row;
use super::shared::{cell, fmt_ms, frame_named, mean_std, verdict};
use crate::eval::stats::{self, DEFAULT_LEVEL};
use crate::learn::mlp::Regressor;
use crate::report::Table;
use crate::report::rows::Rows;
use crate::run::Products;
use crate::table_row;

/// The paper's table: row = test subject, column = model trained for.
const PAPER: [[&str; 2]; 2] = [
    ["0.096 ± 0.074", "0.133 ± 0.126"],
    ["0.231 ± 0.276", "0.117 ± 0.111"],
];

table_row! {
    /// A row of the `person_specific` table (columns renamed with the persons' ids).
    pub struct PersonRow {
        pub test_subject: String,
        pub model_a: String,
        pub model_b: String,
        pub paper_model_1: String,
        pub paper_model_2: String,
    }
}

table_row! {
    /// One test frame's error under a specific or the general model (the samples).
    pub struct PersonSample {
        pub model: String,
        pub abs_error_m: f64,
    }
}

/// The two lowest person ids in the data, if there are two.
pub fn two_persons(rows: &[Row]) -> Option<[i64; 2]> {
    let mut v: Vec<i64> = rows.iter().map(|r| r.person).collect();
    v.sort_unstable();
    v.dedup();
    (v.len() >= 2).then(|| [v[0], v[1]])
}

/// Each person's frames split into training and test frames (split 100 + k for person k).
pub fn person_splits(
    l: &Learner,
    rows: &[Row],
    persons: [i64; 2],
) -> BTreeMap<i64, (Vec<usize>, Vec<usize>)> {
    persons
        .iter()
        .enumerate()
        .map(|(k, pid)| {
            let idx: Vec<usize> = (0..rows.len())
                .filter(|i| rows[*i].person == *pid)
                .collect();
            (*pid, l.split(100 + k, &idx))
        })
        .collect()
}

pub fn run(l: &Learner, rows: &[Row], out: &mut Products) -> anyhow::Result<()> {
    let Some(pa) = two_persons(rows).filter(|_| l.loaded.is_none()) else {
        return Ok(());
    };
    for pid in pa {
        let n = rows.iter().filter(|r| r.person == pid).count();
        l.check_fraction(n, &format!("person {pid}'s frames"))?;
    }
    let splits = person_splits(l, rows, pa);
    let models: BTreeMap<i64, Regressor> = pa
        .iter()
        .map(|pid| Ok((*pid, l.fit(&splits[pid].0, 200 + *pid as u64, l.spec)?)))
        .collect::<anyhow::Result<_>>()?;
    let union: Vec<usize> = pa.iter().flat_map(|pid| splits[pid].0.clone()).collect();
    let general = l.fit(&union, 300, l.spec)?;
    let mut table = Vec::new();
    let (mut specific, mut generic) = (Vec::new(), Vec::new());
    for (a, subject) in pa.iter().enumerate() {
        let test = &splits[subject].1;
        let e: [Vec<f64>; 2] = pa.map(|model_for| l.errors(&models[&model_for], test));
        table.push(PersonRow {
            test_subject: format!("person {subject}"),
            model_a: cell(&e[0]),
            model_b: cell(&e[1]),
            paper_model_1: PAPER[a][0].into(),
            paper_model_2: PAPER[a][1].into(),
        });
        specific.extend_from_slice(&e[a]);
        generic.extend(l.errors(&general, test));
    }
    let tt = stats::student_t(&specific, &generic, DEFAULT_LEVEL)?;
    let (sm, ss) = mean_std(&specific);
    let (gm, gs) = mean_std(&generic);
    let samples: Vec<PersonSample> = [("specific", &specific), ("general", &generic)]
        .iter()
        .flat_map(|(model, errors)| {
            errors.iter().map(|e| PersonSample {
                model: (*model).into(),
                abs_error_m: *e,
            })
        })
        .collect();
    let (col_a, col_b) = (
        format!("model person {}", pa[0]),
        format!("model person {}", pa[1]),
    );
    out.tables.push(
        Table::new(
            "person_specific",
            "Person-specific appearance models: distance error (m), test subject × model trained for",
            frame_named(&table, &["test subject", &col_a, &col_b, "paper model 1", "paper model 2"])?,
        )
        .with_note(format!(
            "Specific models on their own person {} vs the general model (trained on the same frames) {}: Student t = {:.3}, df = {:.0}, p = {:.4}, 99 % CI of the difference [{:.3}, {:.3}] m; {} at the 99 % level (paper: specific significantly better).",
            fmt_ms(sm, ss),
            fmt_ms(gm, gs),
            tt.t,
            tt.df,
            tt.p_two_sided,
            tt.ci_low,
            tt.ci_high,
            verdict(tt.significant(0.01))
        ))
        .with_samples(PersonSample::frame(&samples)?),
    );
    out.summary.push(format!(
        "Person-specific {} vs general {} m: p = {:.4} ({} at 99 %).",
        fmt_ms(sm, ss),
        fmt_ms(gm, gs),
        tt.p_two_sided,
        verdict(tt.significant(0.01))
    ));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::dataset::test_row;
    use super::super::params::Params;
    use super::*;

    fn rows(persons: &[i64]) -> Vec<Row> {
        persons
            .iter()
            .enumerate()
            .map(|(i, p)| test_row(0, i as i64, *p, [1.0, i as f64, 2.0]))
            .collect()
    }

    #[test]
    fn the_two_lowest_ids_are_the_persons() {
        assert_eq!(two_persons(&rows(&[5, 3, 5, 9])), Some([3, 5]));
        assert_eq!(two_persons(&rows(&[2, 2])), None);
        assert_eq!(two_persons(&[]), None);
    }

    #[test]
    fn each_person_is_split_within_their_own_frames() {
        let rows = rows(&[1, 2, 1, 1, 2, 2, 2, 1, 1, 2]);
        let l = Learner::of(
            rows.iter().map(|r| r.features.to_vec()).collect(),
            rows.iter().map(|r| r.distance).collect(),
            &Params::default(),
            None,
        );
        let splits = person_splits(&l, &rows, [1, 2]);
        for (pid, (train, test)) in &splits {
            assert_eq!(train.len() + test.len(), 5);
            assert_eq!(train.len(), 2, "round(5 × 0.3)");
            assert!(train.iter().chain(test).all(|i| rows[*i].person == *pid));
        }
        let mut all: Vec<usize> = splits
            .values()
            .flat_map(|(a, b)| a.iter().chain(b).copied())
            .collect();
        all.sort_unstable();
        assert_eq!(all, (0..10).collect::<Vec<_>>());
    }
}

//! Small helpers the sub-experiments share: "mean ± std" cells and tables whose column names
//! are not Rust identifiers.

use polars::prelude::DataFrame;

use crate::eval::stats;
use crate::report::rows::Rows;

/// A "mean ± std" cell (three decimals).
pub fn fmt_ms(m: f64, s: f64) -> String {
    format!("{m:.3} ± {s:.3}")
}

/// Mean and sample standard deviation; a single value gives (value, NaN), none (NaN, NaN).
pub fn mean_std(v: &[f64]) -> (f64, f64) {
    match stats::describe(v) {
        Ok(s) => (s.mean, s.std),
        Err(_) => (v.first().copied().unwrap_or(f64::NAN), f64::NAN),
    }
}

/// "mean ± std" of `v`.
pub fn cell(v: &[f64]) -> String {
    let (m, s) = mean_std(v);
    fmt_ms(m, s)
}

/// "significant" or "not significant" at level `alpha`.
pub fn verdict(significant: bool) -> &'static str {
    if significant {
        "significant"
    } else {
        "not significant"
    }
}

/// The frame of `rows` with its columns renamed, in order, to `names` (column names with
/// spaces or keywords, which a field cannot have).
pub fn frame_named<R: Rows>(rows: &[R], names: &[&str]) -> anyhow::Result<DataFrame> {
    let mut df = R::frame(rows)?;
    anyhow::ensure!(
        names.len() == R::COLUMNS.len(),
        "{} names for {} columns",
        names.len(),
        R::COLUMNS.len()
    );
    for (old, new) in R::COLUMNS.iter().zip(names) {
        df.rename(old, (*new).into())?;
    }
    Ok(df)
}

#[cfg(test)]
mod tests {
    use super::*;

    crate::table_row! {
        struct Two {
            test_subject: String,
            frames: i64,
        }
    }

    #[test]
    fn mean_and_sample_std_in_a_cell() {
        assert_eq!(cell(&[1.0, 2.0, 3.0]), "2.000 ± 1.000");
        let (m, s) = mean_std(&[4.0]);
        assert_eq!(m, 4.0);
        assert!(s.is_nan());
        assert!(mean_std(&[]).0.is_nan());
    }

    #[test]
    fn columns_are_renamed_in_order() {
        let rows = [Two {
            test_subject: "person 1".into(),
            frames: 3,
        }];
        let df = frame_named(&rows, &["test subject", "true"]).expect("frame");
        let names: Vec<&str> = df.get_column_names().iter().map(|c| c.as_str()).collect();
        assert_eq!(names, ["test subject", "true"]);
        assert!(frame_named(&rows, &["one"]).is_err());
    }
}

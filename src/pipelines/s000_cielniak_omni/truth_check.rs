//! Extra (not in the paper): the measurement system, the appearance model and the Kalman
//! filter against the simulator's truth, when the log has it.

use nalgebra::Vector2;

use super::dataset::{Dataset, Row};
use super::kalman::Tracked;
use super::shared::cell;
use crate::report::Table;
use crate::report::rows::Rows;
use crate::run::Products;
use crate::table_row;

table_row! {
    /// A row of the `truth_check` table.
    pub struct TruthCheckRow {
        pub quantity: String,
        pub error_m: String,
        pub frames: i64,
    }
}

/// The summary line on the measurement system's own error (none without truth).
pub fn measurement_summary(data: &Dataset, out: &mut Products) {
    if !data.ext_err_truth.is_empty() {
        out.summary.push(format!(
            "Measurement system vs simulator truth: {} over {} frames (the paper's ground truth has its own error; this is it).",
            cell(&data.ext_err_truth),
            data.ext_err_truth.len()
        ));
    }
}

/// Distances of `v` to the truth on the frames `idx` that have one.
pub fn errors_to_truth(rows: &[Row], v: &[Vector2<f64>], idx: &[usize]) -> Vec<f64> {
    idx.iter()
        .filter_map(|i| {
            rows[*i]
                .truth
                .map(|(x, y)| (v[*i] - Vector2::new(x, y)).norm())
        })
        .collect()
}

pub fn run(data: &Dataset, t: &Tracked, out: &mut Products) -> anyhow::Result<()> {
    if data.rows.iter().all(|r| r.truth.is_none()) {
        return Ok(());
    }
    let app = errors_to_truth(&data.rows, &t.z, &t.test);
    let kf = errors_to_truth(&data.rows, &t.est, &t.test);
    let row = |quantity: &str, errors: &[f64]| TruthCheckRow {
        quantity: quantity.into(),
        error_m: cell(errors),
        frames: errors.len() as i64,
    };
    let table = [
        row("measurement system position", &data.ext_err_truth),
        row("appearance model position", &app),
        row("with Kalman filter", &kf),
    ];
    out.tables.push(
        Table::new(
            "truth_check",
            "Extra (not in the paper): errors against the simulator's truth instead of the measurement system",
            TruthCheckRow::frame(&table)?,
        )
        .with_note("The paper could only compare with its webcam system; a synthetic log also knows where the person really was."),
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::dataset::test_row;
    use super::*;

    #[test]
    fn only_frames_with_truth_count() {
        let mut rows: Vec<Row> = (0..3).map(|i| test_row(0, i, 1, [0.0; 3])).collect();
        rows[0].truth = Some((1.0, 1.0));
        rows[2].truth = Some((0.0, 0.0));
        let v = [
            Vector2::new(4.0, 5.0),
            Vector2::new(9.0, 9.0),
            Vector2::new(0.0, 2.0),
        ];
        assert_eq!(errors_to_truth(&rows, &v, &[0, 1, 2]), [5.0, 2.0]);
        assert_eq!(errors_to_truth(&rows, &v, &[1, 2]), [2.0]);
    }
}

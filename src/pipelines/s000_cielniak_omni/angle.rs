//! Sub-experiment 2 (section 4.2): the bearing of the person from the panorama's horizontal
//! histogram against the measurement system's bearing.

use super::dataset::Row;
use super::shared::cell;
use crate::calib::external;
use crate::report::Table;
use crate::report::rows::Rows;
use crate::run::Products;
use crate::table_row;

table_row! {
    /// The `angle_error` table's row.
    pub struct AngleRow {
        pub quantity: String,
        pub ours: String,
        pub paper: String,
        pub frames: i64,
    }
}

table_row! {
    /// One frame's absolute angle error (the table's samples).
    pub struct AngleSample {
        pub session: i64,
        pub stamp: i64,
        pub angle_error_deg: f64,
    }
}

/// Absolute difference of two bearings (rad) in degrees, the short way round.
pub fn angle_error_deg(omni_bearing: f64, bearing: f64) -> f64 {
    external::wrap(omni_bearing - bearing).abs().to_degrees()
}

pub fn run(rows: &[Row], out: &mut Products) -> anyhow::Result<()> {
    let errors: Vec<f64> = rows
        .iter()
        .map(|r| angle_error_deg(r.omni_bearing, r.bearing))
        .collect();
    let table = [AngleRow {
        quantity: "absolute angle error (deg)".into(),
        ours: cell(&errors),
        paper: "2.01 ± 1.60".into(),
        frames: errors.len() as i64,
    }];
    let samples: Vec<AngleSample> = rows
        .iter()
        .zip(&errors)
        .map(|(r, e)| AngleSample {
            session: r.session as i64,
            stamp: r.stamp,
            angle_error_deg: *e,
        })
        .collect();
    out.tables.push(
        Table::new(
            "angle_error",
            "Angle to the person from the horizontal histogram mean",
            AngleRow::frame(&table)?,
        )
        .with_note(
            "Paper section 4.2. Error against the bearing from the external measurement system.",
        )
        .with_samples(AngleSample::frame(&samples)?),
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_error_goes_the_short_way_round() {
        let deg = f64::to_radians;
        assert!((angle_error_deg(deg(359.0), deg(1.0)) - 2.0).abs() < 1e-9);
        assert!((angle_error_deg(deg(10.0), deg(-5.0)) - 15.0).abs() < 1e-9);
        assert!(angle_error_deg(deg(-170.0), deg(190.0)).abs() < 1e-9);
    }
}

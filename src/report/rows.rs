//! Tables from rows: a row struct declared with [`table_row!`] turns a slice of rows into a
//! polars `DataFrame` (one column per field, in field order) and reads one back from a
//! cached per-session table. This replaces hand-built tuples of column vectors.
//!
//! ```
//! use peopletrack::table_row;
//! use peopletrack::report::rows::Rows;
//!
//! table_row! {
//!     /// One model's time per frame.
//!     #[derive(Debug, Clone, PartialEq)]
//!     pub struct Timing {
//!         pub model: String,
//!         pub frames: i64,
//!         pub median_ms: f64,
//!     }
//! }
//! let rows = vec![Timing { model: "adaptive".into(), frames: 3, median_ms: 1.5 }];
//! let df = Timing::frame(&rows).unwrap();
//! let names: Vec<&str> = df.get_column_names().iter().map(|c| c.as_str()).collect();
//! assert_eq!(names, ["model", "frames", "median_ms"]);
//! assert_eq!(Timing::read(&df).unwrap(), rows);
//! ```

use polars::prelude::*;

/// A row type: its rows become a `DataFrame` and back.
pub trait Rows: Sized {
    /// Column names, in field order.
    const COLUMNS: &'static [&'static str];
    /// One column per field, one row per element.
    fn frame(rows: &[Self]) -> PolarsResult<DataFrame>;
    /// Rows back from a frame that has (at least) these columns.
    fn read(df: &DataFrame) -> PolarsResult<Vec<Self>>;
}

/// A field type that can be read back from a column (casting where polars can).
pub trait Cell: Sized {
    fn read_column(df: &DataFrame, name: &str) -> PolarsResult<Vec<Self>>;
}

fn as_f64(df: &DataFrame, name: &str) -> PolarsResult<Vec<Option<f64>>> {
    Ok(df
        .column(name)?
        .cast(&DataType::Float64)?
        .f64()?
        .iter()
        .collect())
}

fn as_i64(df: &DataFrame, name: &str) -> PolarsResult<Vec<Option<i64>>> {
    Ok(df
        .column(name)?
        .cast(&DataType::Int64)?
        .i64()?
        .iter()
        .collect())
}

fn missing(name: &str, what: &str) -> PolarsError {
    PolarsError::ComputeError(format!("column '{name}': null where a {what} is required").into())
}

impl Cell for f64 {
    /// Nulls read as NaN (a float column's missing value).
    fn read_column(df: &DataFrame, name: &str) -> PolarsResult<Vec<f64>> {
        Ok(as_f64(df, name)?
            .into_iter()
            .map(|v| v.unwrap_or(f64::NAN))
            .collect())
    }
}

impl Cell for Option<f64> {
    fn read_column(df: &DataFrame, name: &str) -> PolarsResult<Vec<Option<f64>>> {
        as_f64(df, name)
    }
}

impl Cell for i64 {
    fn read_column(df: &DataFrame, name: &str) -> PolarsResult<Vec<i64>> {
        as_i64(df, name)?
            .into_iter()
            .map(|v| v.ok_or_else(|| missing(name, "integer")))
            .collect()
    }
}

impl Cell for Option<i64> {
    fn read_column(df: &DataFrame, name: &str) -> PolarsResult<Vec<Option<i64>>> {
        as_i64(df, name)
    }
}

impl Cell for u32 {
    fn read_column(df: &DataFrame, name: &str) -> PolarsResult<Vec<u32>> {
        as_i64(df, name)?
            .into_iter()
            .map(|v| {
                v.and_then(|x| u32::try_from(x).ok())
                    .ok_or_else(|| missing(name, "u32"))
            })
            .collect()
    }
}

impl Cell for bool {
    fn read_column(df: &DataFrame, name: &str) -> PolarsResult<Vec<bool>> {
        df.column(name)?
            .bool()?
            .iter()
            .map(|v| v.ok_or_else(|| missing(name, "boolean")))
            .collect()
    }
}

impl Cell for String {
    fn read_column(df: &DataFrame, name: &str) -> PolarsResult<Vec<String>> {
        df.column(name)?
            .str()?
            .iter()
            .map(|v| v.map(str::to_string).ok_or_else(|| missing(name, "string")))
            .collect()
    }
}

impl Cell for Option<String> {
    fn read_column(df: &DataFrame, name: &str) -> PolarsResult<Vec<Option<String>>> {
        Ok(df
            .column(name)?
            .str()?
            .iter()
            .map(|v| v.map(str::to_string))
            .collect())
    }
}

/// Declare a row struct whose slices become tables ([`Rows`]). Fields may be `f64`,
/// `Option<f64>`, `i64`, `Option<i64>`, `u32`, `bool`, `String` or `Option<String>`; the
/// column is named after the field.
#[macro_export]
macro_rules! table_row {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident {
            $( $(#[$fmeta:meta])* $fvis:vis $field:ident : $ty:ty ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        $vis struct $name {
            $( $(#[$fmeta])* $fvis $field : $ty ),*
        }

        impl $crate::report::rows::Rows for $name {
            const COLUMNS: &'static [&'static str] = &[$(stringify!($field)),*];

            fn frame(rows: &[Self]) -> ::polars::prelude::PolarsResult<::polars::prelude::DataFrame> {
                ::polars::prelude::DataFrame::new_infer_height(vec![
                    $(
                        ::polars::prelude::Column::new(
                            stringify!($field).into(),
                            rows.iter().map(|r| r.$field.clone()).collect::<Vec<$ty>>(),
                        )
                    ),*
                ])
            }

            fn read(
                df: &::polars::prelude::DataFrame,
            ) -> ::polars::prelude::PolarsResult<Vec<Self>> {
                $(
                    let $field = <$ty as $crate::report::rows::Cell>::read_column(
                        df,
                        stringify!($field),
                    )?.into_iter();
                )*
                #[allow(unused_mut)]
                let mut zipped = Vec::with_capacity(df.height());
                $( let mut $field = $field; )*
                for _ in 0..df.height() {
                    zipped.push($name {
                        $( $field: match $field.next() {
                            Some(v) => v,
                            None => break,
                        } ),*
                    });
                }
                Ok(zipped)
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    crate::table_row! {
        #[derive(Debug, Clone, PartialEq)]
        struct Mixed {
            name: String,
            count: i64,
            small: u32,
            value: f64,
            maybe: Option<f64>,
            flag: bool,
            label: Option<String>,
        }
    }

    fn rows() -> Vec<Mixed> {
        vec![
            Mixed {
                name: "a".into(),
                count: -3,
                small: 7,
                value: 0.25,
                maybe: None,
                flag: true,
                label: Some("x".into()),
            },
            Mixed {
                name: "b".into(),
                count: 4,
                small: 0,
                value: f64::NAN,
                maybe: Some(2.0),
                flag: false,
                label: None,
            },
        ]
    }

    #[test]
    fn columns_in_field_order_with_their_types() {
        let df = Mixed::frame(&rows()).expect("frame");
        assert_eq!(
            df.get_column_names()
                .iter()
                .map(|c| c.as_str())
                .collect::<Vec<_>>(),
            ["name", "count", "small", "value", "maybe", "flag", "label"]
        );
        assert_eq!(Mixed::COLUMNS.len(), 7);
        let dtypes: Vec<DataType> = df.dtypes();
        assert_eq!(
            dtypes,
            [
                DataType::String,
                DataType::Int64,
                DataType::UInt32,
                DataType::Float64,
                DataType::Float64,
                DataType::Boolean,
                DataType::String
            ]
        );
        assert_eq!(df.column("maybe").expect("col").null_count(), 1);
    }

    #[test]
    fn read_gives_the_rows_back() {
        let back = Mixed::read(&Mixed::frame(&rows()).expect("frame")).expect("read");
        assert_eq!(back.len(), 2);
        assert_eq!(back[0], rows()[0]);
        assert!(back[1].value.is_nan());
        assert_eq!(back[1].maybe, Some(2.0));
        assert_eq!(back[1].label, None);
    }

    #[test]
    fn empty_rows_give_an_empty_frame_with_the_columns() {
        let df = Mixed::frame(&[]).expect("frame");
        assert_eq!(df.height(), 0);
        assert_eq!(df.width(), 7);
        assert!(Mixed::read(&df).expect("read").is_empty());
    }

    #[test]
    fn a_missing_column_or_a_null_integer_is_an_error() {
        let df = df! { "name" => ["a"] }.expect("df");
        assert!(Mixed::read(&df).is_err());
        let df = df! { "n" => [Some(1i64), None] }.expect("df");
        assert!(i64::read_column(&df, "n").is_err());
    }
}

//! Small helpers for reading and stacking the polars tables pipelines pass around.

use image::ImageEncoder;
use polars::prelude::*;

/// A float column (nulls read as NaN).
pub fn f64s(df: &DataFrame, name: &str) -> PolarsResult<Vec<f64>> {
    Ok(df
        .column(name)?
        .cast(&DataType::Float64)?
        .f64()?
        .iter()
        .map(|v| v.unwrap_or(f64::NAN))
        .collect())
}

/// A float column with its nulls.
pub fn opt_f64s(df: &DataFrame, name: &str) -> PolarsResult<Vec<Option<f64>>> {
    Ok(df
        .column(name)?
        .cast(&DataType::Float64)?
        .f64()?
        .iter()
        .collect())
}

/// An integer column (nulls read as 0).
pub fn i64s(df: &DataFrame, name: &str) -> PolarsResult<Vec<i64>> {
    Ok(df
        .column(name)?
        .cast(&DataType::Int64)?
        .i64()?
        .iter()
        .map(|v| v.unwrap_or(0))
        .collect())
}

/// A string column (nulls read as empty).
pub fn strs(df: &DataFrame, name: &str) -> PolarsResult<Vec<String>> {
    Ok(df
        .column(name)?
        .str()?
        .iter()
        .map(|v| v.unwrap_or_default().to_string())
        .collect())
}

/// A boolean column (nulls read as false).
pub fn bools(df: &DataFrame, name: &str) -> PolarsResult<Vec<bool>> {
    Ok(df
        .column(name)?
        .bool()?
        .iter()
        .map(|v| v.unwrap_or(false))
        .collect())
}

/// Stack frames with the same columns.
pub fn concat(frames: Vec<DataFrame>) -> PolarsResult<DataFrame> {
    let mut it = frames.into_iter();
    let mut acc = it.next().unwrap_or_default();
    for df in it {
        acc.vstack_mut(&df)?;
    }
    Ok(acc)
}

/// Column of [`image_table`] holding the PNG bytes.
const PNG_COLUMN: &str = "png";

/// An image cached with a session's tables (e.g. a view a figure will draw), as a one-row
/// table of lossless PNG bytes, so that aggregation never has to re-open the log.
pub fn image_table(img: &image::RgbImage) -> PolarsResult<DataFrame> {
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(
            img.as_raw(),
            img.width(),
            img.height(),
            image::ExtendedColorType::Rgb8,
        )
        .map_err(|e| PolarsError::ComputeError(format!("encoding a cached image: {e}").into()))?;
    let column = Column::new(PNG_COLUMN.into(), [png.as_slice()]);
    DataFrame::new_infer_height(vec![column])
}

/// The image of an [`image_table`].
pub fn read_image_table(df: &DataFrame) -> PolarsResult<image::RgbImage> {
    let bytes = df
        .column(PNG_COLUMN)?
        .binary()?
        .get(0)
        .ok_or_else(|| PolarsError::NoData("cached image table is empty".into()))?;
    image::load_from_memory_with_format(bytes, image::ImageFormat::Png)
        .map(|i| i.to_rgb8())
        .map_err(|e| PolarsError::ComputeError(format!("decoding a cached image: {e}").into()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cached_image_comes_back_pixel_for_pixel() {
        let img = image::RgbImage::from_fn(7, 3, |x, y| image::Rgb([x as u8 * 30, y as u8, 200]));
        let df = image_table(&img).expect("table");
        assert_eq!(df.height(), 1);
        assert_eq!(read_image_table(&df).expect("image"), img);
        let bytes = crate::report::table::parquet_bytes(&df, &Default::default()).expect("parquet");
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("t.parquet");
        std::fs::write(&path, bytes).expect("write");
        let back = crate::report::table::read_parquet(&path).expect("read");
        assert_eq!(read_image_table(&back).expect("image"), img);
    }
}

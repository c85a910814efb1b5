//! Result tables: a polars `DataFrame` plus what a reader needs to trust it — a caption, the
//! paper's values beside ours where the paper gives one, and provenance (dataset, seed, git
//! commit, parameters). Written as CSV and Parquet (for tools) and Markdown and LaTeX (for
//! people and papers), with the per-sample values behind every mean and test saved as
//! `<name>.samples.parquet` beside the table.
//!
//! Writers are pure (`DataFrame` → bytes); [`write_table`] does the I/O, atomically.
//! Markdown and LaTeX print floats at each column's stated precision; CSV keeps full precision.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use polars::prelude::*;
use serde::Serialize;

use super::atomic::write_atomic;

/// Where a table's numbers came from.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Provenance {
    /// Dataset name(s) and the sessions used.
    pub dataset: String,
    pub seed: Option<u64>,
    /// `git describe`-style commit of the code that produced it (`unknown` outside a checkout).
    pub git_commit: String,
    pub tool_version: String,
    /// Parameters that shaped the numbers, as `name = value` text.
    pub parameters: BTreeMap<String, String>,
}

/// A result table ready to be written.
#[derive(Debug, Clone)]
pub struct Table {
    /// File stem: `<name>.csv`, `<name>.md`, ...
    pub name: String,
    /// One-line caption.
    pub title: String,
    pub df: DataFrame,
    /// Decimals for float columns in Markdown/LaTeX (default 3).
    pub precision: BTreeMap<String, usize>,
    /// Lines printed under the table (sources of the paper's values, caveats).
    pub notes: Vec<String>,
    pub provenance: Provenance,
    /// The per-sample values behind the table's means and tests, if any.
    pub samples: Option<DataFrame>,
}

// `error`, not `source`: a source would be printed twice in an error chain
#[derive(Debug, thiserror::Error)]
pub enum TableError {
    #[error("table {table}: {error}")]
    Polars { table: String, error: PolarsError },
    #[error("writing table {table} to {}: {error}", path.display())]
    Io {
        table: String,
        path: PathBuf,
        error: std::io::Error,
    },
}

impl Table {
    pub fn new(name: impl Into<String>, title: impl Into<String>, df: DataFrame) -> Table {
        Table {
            name: name.into(),
            title: title.into(),
            df,
            precision: BTreeMap::new(),
            notes: Vec::new(),
            provenance: Provenance::default(),
            samples: None,
        }
    }

    pub fn with_precision(mut self, column: &str, decimals: usize) -> Table {
        self.precision.insert(column.to_string(), decimals);
        self
    }

    /// [`Table::with_precision`] for several columns at once.
    pub fn with_precisions(self, columns: &[&str], decimals: usize) -> Table {
        columns
            .iter()
            .fold(self, |t, c| t.with_precision(c, decimals))
    }

    pub fn with_note(mut self, note: impl Into<String>) -> Table {
        self.notes.push(note.into());
        self
    }

    pub fn with_provenance(mut self, p: Provenance) -> Table {
        self.provenance = p;
        self
    }

    pub fn with_samples(mut self, samples: DataFrame) -> Table {
        self.samples = Some(samples);
        self
    }

    fn err(&self, source: PolarsError) -> TableError {
        TableError::Polars {
            table: self.name.clone(),
            error: source,
        }
    }

    fn decimals(&self, column: &str) -> usize {
        self.precision.get(column).copied().unwrap_or(3)
    }

    /// Cell text for Markdown/LaTeX.
    fn cell(&self, column: &str, v: &AnyValue) -> String {
        match v {
            AnyValue::Null => "—".to_string(),
            AnyValue::Float64(x) => fmt_float(*x, self.decimals(column)),
            AnyValue::Float32(x) => fmt_float(f64::from(*x), self.decimals(column)),
            AnyValue::String(s) => (*s).to_string(),
            AnyValue::StringOwned(s) => s.to_string(),
            AnyValue::Boolean(b) => if *b { "yes" } else { "no" }.to_string(),
            other => other.to_string(),
        }
    }

    fn rows(&self) -> Result<Vec<Vec<String>>, TableError> {
        let cols = self.df.columns();
        let mut out = Vec::with_capacity(self.df.height());
        for i in 0..self.df.height() {
            let mut row = Vec::with_capacity(cols.len());
            for c in cols {
                let v = c.get(i).map_err(|e| self.err(e))?;
                row.push(self.cell(c.name(), &v));
            }
            out.push(row);
        }
        Ok(out)
    }

    /// CSV with a header row, full float precision.
    pub fn to_csv(&self) -> Result<Vec<u8>, TableError> {
        let mut buf = Vec::new();
        let mut df = self.df.clone();
        CsvWriter::new(&mut buf)
            .include_header(true)
            .finish(&mut df)
            .map_err(|e| self.err(e))?;
        Ok(buf)
    }

    /// Markdown: caption, pipe table, notes, provenance.
    pub fn to_markdown(&self) -> Result<String, TableError> {
        let header: Vec<String> = self
            .df
            .get_column_names()
            .iter()
            .map(|s| s.to_string())
            .collect();
        let rows = self.rows()?;
        let numeric: Vec<bool> = self
            .df
            .columns()
            .iter()
            .map(|c| c.dtype().is_primitive_numeric())
            .collect();
        let mut o = format!("**{}**\n\n", self.title);
        o.push_str(&format!("| {} |\n", header.join(" | ")));
        let rule: Vec<&str> = numeric
            .iter()
            .map(|n| if *n { "---:" } else { "---" })
            .collect();
        o.push_str(&format!("| {} |\n", rule.join(" | ")));
        for r in rows {
            let cells: Vec<String> = r.iter().map(|c| c.replace('|', "\\|")).collect();
            o.push_str(&format!("| {} |\n", cells.join(" | ")));
        }
        for n in &self.notes {
            o.push_str(&format!("\n{n}\n"));
        }
        o.push_str(&format!("\n{}\n", provenance_line(&self.provenance)));
        Ok(o)
    }

    /// LaTeX `table` with a booktabs `tabular`.
    pub fn to_latex(&self) -> Result<String, TableError> {
        let header: Vec<String> = self
            .df
            .get_column_names()
            .iter()
            .map(|s| latex_escape(s))
            .collect();
        let align: String = self
            .df
            .columns()
            .iter()
            .map(|c| {
                if c.dtype().is_primitive_numeric() {
                    'r'
                } else {
                    'l'
                }
            })
            .collect();
        let mut o = String::from("\\begin{table}[t]\n\\centering\n");
        o.push_str(&format!("\\caption{{{}}}\n", latex_escape(&self.title)));
        o.push_str(&format!("\\label{{tab:{}}}\n", self.name));
        o.push_str(&format!("\\begin{{tabular}}{{{align}}}\n\\toprule\n"));
        o.push_str(&format!("{} \\\\\n\\midrule\n", header.join(" & ")));
        for r in self.rows()? {
            let cells: Vec<String> = r.iter().map(|c| latex_escape(c)).collect();
            o.push_str(&format!("{} \\\\\n", cells.join(" & ")));
        }
        o.push_str("\\bottomrule\n\\end{tabular}\n");
        for n in &self.notes {
            o.push_str(&format!("\\par\\footnotesize {}\n", latex_escape(n)));
        }
        o.push_str(&format!(
            "% {}\n\\end{{table}}\n",
            provenance_line(&self.provenance)
        ));
        Ok(o)
    }

    /// Parquet with the provenance as key-value metadata.
    pub fn to_parquet(&self) -> Result<Vec<u8>, TableError> {
        parquet_bytes(&self.df, &self.provenance).map_err(|e| self.err(e))
    }
}

/// Parquet bytes of a frame, with provenance as key-value metadata.
///
/// Written and read without polars' own thread pool: these run inside the runner's per-session
/// rayon jobs, and a job that waits on another pool lets its thread start further sessions
/// meanwhile, so the stack grew with the number of sessions (a 1,000-session aggregate
/// overflowed it); one table of one session gains nothing from parallel columns.
pub fn parquet_bytes(df: &DataFrame, provenance: &Provenance) -> PolarsResult<Vec<u8>> {
    let mut buf = Vec::new();
    let mut df = df.clone();
    let meta = serde_json::to_string(provenance).unwrap_or_default();
    ParquetWriter::new(&mut buf)
        .set_parallel(false)
        .with_key_value_metadata(Some(KeyValueMetadata::from_static(vec![(
            "peopletrack.provenance".to_string(),
            meta,
        )])))
        .finish(&mut df)?;
    Ok(buf)
}

/// Read a Parquet file written by [`parquet_bytes`] (or any tool), on the calling thread (see
/// [`parquet_bytes`]).
pub fn read_parquet(path: &Path) -> PolarsResult<DataFrame> {
    let f = std::fs::File::open(path)?;
    ParquetReader::new(f)
        .read_parallel(ParallelStrategy::None)
        .finish()
}

fn provenance_line(p: &Provenance) -> String {
    let mut s = format!(
        "Provenance: dataset {}; seed {}; peopletrack {} ({})",
        if p.dataset.is_empty() {
            "—"
        } else {
            &p.dataset
        },
        p.seed.map_or("—".to_string(), |s| s.to_string()),
        p.tool_version,
        p.git_commit
    );
    if !p.parameters.is_empty() {
        let params: Vec<String> = p
            .parameters
            .iter()
            .map(|(k, v)| format!("{k} = {v}"))
            .collect();
        s.push_str(&format!("; parameters: {}", params.join(", ")));
    }
    s.push('.');
    s
}

/// Fixed decimals, `NaN`/`inf` spelled out.
pub fn fmt_float(x: f64, decimals: usize) -> String {
    if x.is_nan() {
        "NaN".into()
    } else if x.is_infinite() {
        if x > 0.0 { "inf".into() } else { "-inf".into() }
    } else {
        let s = format!("{x:.decimals$}");
        // "-0.000" reads as a sign error in a table
        if s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.') {
            s[1..].to_string()
        } else {
            s
        }
    }
}

fn latex_escape(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '\\' => o.push_str("\\textbackslash{}"),
            '&' | '%' | '$' | '#' | '_' | '{' | '}' => {
                o.push('\\');
                o.push(c);
            }
            '~' => o.push_str("\\textasciitilde{}"),
            '^' => o.push_str("\\textasciicircum{}"),
            '±' => o.push_str("$\\pm$"),
            '—' => o.push_str("---"),
            _ => o.push(c),
        }
    }
    o
}

/// Write `<dir>/<name>.{csv,parquet,md,tex}` (and `.samples.parquet`), atomically; returns the
/// paths written. `root` is the output root holding the scratch folder.
pub fn write_table(dir: &Path, table: &Table, root: &Path) -> Result<Vec<PathBuf>, TableError> {
    let mut written = Vec::new();
    let mut put = |ext: &str, bytes: Vec<u8>| -> Result<(), TableError> {
        let path = dir.join(format!("{}.{ext}", table.name));
        write_atomic(&path, &bytes, Some(root)).map_err(|error| TableError::Io {
            table: table.name.clone(),
            path: path.clone(),
            error,
        })?;
        written.push(path);
        Ok(())
    };
    put("csv", table.to_csv()?)?;
    put("parquet", table.to_parquet()?)?;
    put("md", table.to_markdown()?.into_bytes())?;
    put("tex", table.to_latex()?.into_bytes())?;
    if let Some(s) = &table.samples {
        put(
            "samples.parquet",
            parquet_bytes(s, &table.provenance).map_err(|e| table.err(e))?,
        )?;
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Table {
        let df = df! {
            "method" => ["appearance model", "with Kalman filter"],
            "ours_mean_m" => [0.15431, 0.14512],
            "ours_std_m" => [0.0941, 0.0922],
            "paper" => ["0.154 ± 0.094", "0.145 ± 0.092"],
            "n" => [476i64, 476],
        }
        .expect("frame");
        Table::new(
            "kalman",
            "Distance error: appearance model vs Kalman filter",
            df,
        )
        .with_precision("ours_std_m", 2)
        .with_note("Paper: Cielniak et al., section 5.")
        .with_provenance(Provenance {
            dataset: "omni_lab (quick)".into(),
            seed: Some(7),
            git_commit: "abc123".into(),
            tool_version: "0.1.0".into(),
            parameters: BTreeMap::from([("hidden_units".into(), "4".into())]),
        })
    }

    #[test]
    fn markdown_snapshot() {
        insta::assert_snapshot!(sample().to_markdown().expect("md"));
    }

    #[test]
    fn latex_snapshot() {
        insta::assert_snapshot!(sample().to_latex().expect("tex"));
    }

    #[test]
    fn csv_snapshot() {
        insta::assert_snapshot!(String::from_utf8(sample().to_csv().expect("csv")).expect("utf8"));
    }

    #[test]
    fn parquet_round_trip_keeps_values_and_is_deterministic() {
        let t = sample();
        let a = t.to_parquet().expect("parquet");
        assert_eq!(a, t.to_parquet().expect("again"));
        let back = ParquetReader::new(std::io::Cursor::new(a))
            .finish()
            .expect("reads");
        assert!(back.equals(&t.df));
    }

    #[test]
    fn floats_format_without_negative_zero() {
        assert_eq!(fmt_float(-0.0004, 3), "0.000");
        assert_eq!(fmt_float(-0.0006, 3), "-0.001");
        assert_eq!(fmt_float(f64::NAN, 2), "NaN");
    }
}

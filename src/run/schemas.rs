//! The schemas of what a pipeline wrote, read back from its output folder: every per-session
//! table of the cache (`<out>/<pipeline>/sessions/dataset=<d>/session=<s>/<table>.parquet`) and
//! every aggregate table (`<out>/<pipeline>/tables/<table>.parquet`), columns in file order
//! with their polars dtype, from each file's Parquet footer only (no rows are read). Sessions
//! whose copies of one table disagree are reported: a notebook that concatenates them would
//! break. [`doc`] renders them as `docs/schemas.md` and checks a run against that page.
//!
//! Meanings come from code, never from the data: a per-session table's from its experiment's
//! [`crate::run::Experiment::SESSION_TABLES`] (a table name there may hold one placeholder,
//! `{n}` for digits or `{name}` for anything, for tables written once per camera or snapshot),
//! an aggregate table's from the title its `<table>.md` opens with. This does not read
//! figures, the laser tracks' CSV exports or shard records.

pub mod doc;

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use polars::prelude::{DataType, ParquetReader, SerReader};

use super::cache::{DATASET_KEY, SESSION_KEY};

/// A per-session table an experiment writes and what one row of it is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TableDoc {
    /// The table's file stem; may hold one placeholder (`{n}`: digits, `{name}`: anything).
    pub name: &'static str,
    /// One line: what a row is.
    pub meaning: &'static str,
}

/// A [`TableDoc`], for the experiments' `SESSION_TABLES` lists.
pub const fn table(name: &'static str, meaning: &'static str) -> TableDoc {
    TableDoc { name, meaning }
}

/// What the registry knows of an experiment kind.
#[derive(Debug, Clone, Copy)]
pub struct KindInfo {
    pub version: u32,
    pub session_tables: &'static [TableDoc],
}

/// The cache's files besides the tables (`run::cache`), and what each holds.
pub const CACHE_FILES: &[(&str, &str)] = &[
    (
        "key.txt",
        "the cache key (32 hex digits): the hash of the log's bytes, the experiment's kind and \
         VERSION, the tool version, the parameters and topic remaps; written last, so a folder \
         with it is complete",
    ),
    (
        "source.txt",
        "two lines: the xxh3-128 hash of the log's bytes (32 hex digits) and the log's path",
    ),
    (
        "warnings.txt",
        "only when reading the log warned (recovery losses, a linear re-index): one warning a line",
    ),
];

/// One column: name and polars dtype, in file order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Column {
    pub name: String,
    /// polars' name of the dtype (`str`, `f64`, `i64`, `bool`, `list[f64]`, ...).
    pub dtype: String,
    /// Parquet OPTIONAL (nulls allowed); polars writes every column so.
    pub nullable: bool,
}

/// One schema of a table and the files that have it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Variant {
    pub columns: Vec<Column>,
    /// The first file (in path order) with this schema.
    pub example: PathBuf,
    pub files: usize,
}

/// A table (or a family of per-session tables that share a name pattern) and its schemas.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TableSchema {
    /// File stem, or the documented pattern for a family (`camera_obs_{name}`).
    pub name: String,
    /// From code; `None` when code does not describe it.
    pub meaning: Option<String>,
    /// Distinct schemas, the most common first (ties: path order). More than one is a
    /// disagreement.
    pub variants: Vec<Variant>,
    /// Folders (sessions, for a per-session table) holding at least one of its files.
    pub folders: usize,
}

impl TableSchema {
    /// The columns of the most common schema.
    pub fn columns(&self) -> &[Column] {
        &self.variants[0].columns
    }

    /// Files of this table (a family has several in one session).
    pub fn files(&self) -> usize {
        self.variants.iter().map(|v| v.files).sum()
    }
}

/// Everything one pipeline's output folder holds, as schemas.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PipelineSchemas {
    /// `[pipeline] name`: the folder under the output root.
    pub name: String,
    /// Session folders (`dataset=*/session=*`).
    pub sessions: usize,
    pub session_tables: Vec<TableSchema>,
    pub aggregate_tables: Vec<TableSchema>,
    /// Non-Parquet files of the session folders, with the number of sessions that have each.
    pub cache_files: BTreeMap<String, usize>,
    /// Folders under `sessions/` not in the hive layout (the runner ignores them).
    pub ignored: Vec<PathBuf>,
}

impl PipelineSchemas {
    /// Tables whose files disagree, as `(kind, table)`.
    pub fn disagreements(&self) -> Vec<(&'static str, &TableSchema)> {
        let per = self.session_tables.iter().map(|t| ("per-session", t));
        let agg = self.aggregate_tables.iter().map(|t| ("aggregate", t));
        per.chain(agg)
            .filter(|(_, t)| t.variants.len() > 1)
            .collect()
    }
}

#[derive(Debug, thiserror::Error)]
pub enum SchemaError {
    #[error("{}: no output of pipeline {name} here (neither sessions/ nor tables/); run it first", path.display())]
    NotRun { name: String, path: PathBuf },
    #[error("reading {}: {error}", path.display())]
    Io {
        path: PathBuf,
        error: std::io::Error,
    },
    #[error("reading the Parquet footer of {}: {message}", path.display())]
    Parquet { path: PathBuf, message: String },
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> SchemaError + '_ {
    move |error| SchemaError::Io {
        path: path.to_path_buf(),
        error,
    }
}

/// The entries of a folder, sorted by name.
fn sorted_entries(dir: &Path) -> Result<Vec<PathBuf>, SchemaError> {
    let mut v = Vec::new();
    for e in std::fs::read_dir(dir).map_err(io(dir))? {
        v.push(e.map_err(io(dir))?.path());
    }
    v.sort();
    Ok(v)
}

/// The columns of a Parquet file, from its footer.
pub fn parquet_columns(path: &Path) -> Result<Vec<Column>, SchemaError> {
    let f = std::fs::File::open(path).map_err(io(path))?;
    let schema = ParquetReader::new(f)
        .schema()
        .map_err(|e| SchemaError::Parquet {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
    Ok(schema
        .iter_values()
        .map(|field| Column {
            name: field.name.to_string(),
            dtype: DataType::from_arrow_field(field).to_string(),
            nullable: field.is_nullable,
        })
        .collect())
}

/// Does `name` match `pattern` (one `{..}` placeholder at most; `{n}` matches digits only)?
pub fn matches(pattern: &str, name: &str) -> bool {
    let Some(open) = pattern.find('{') else {
        return pattern == name;
    };
    let Some(close) = pattern[open..].find('}').map(|c| open + c) else {
        return pattern == name;
    };
    let (prefix, suffix) = (&pattern[..open], &pattern[close + 1..]);
    let Some(middle) = name
        .strip_prefix(prefix)
        .and_then(|rest| rest.strip_suffix(suffix))
    else {
        return false;
    };
    !middle.is_empty()
        && (&pattern[open..=close] != "{n}" || middle.bytes().all(|b| b.is_ascii_digit()))
}

/// The documented table a per-session file stem belongs to: an exact name first, else the
/// first pattern that matches.
fn documented<'a>(docs: &'a [TableDoc], stem: &str) -> Option<&'a TableDoc> {
    docs.iter()
        .find(|d| d.name == stem)
        .or_else(|| docs.iter().find(|d| matches(d.name, stem)))
}

/// One table as gathered so far.
struct Gathered {
    meaning: Option<String>,
    variants: Vec<Variant>,
    folders: BTreeSet<PathBuf>,
}

/// Tables gathered file by file, in path order.
#[derive(Default)]
struct Gather {
    tables: BTreeMap<String, Gathered>,
}

impl Gather {
    fn add(
        &mut self,
        name: String,
        meaning: Option<String>,
        path: &Path,
    ) -> Result<(), SchemaError> {
        let columns = parquet_columns(path)?;
        let g = self.tables.entry(name).or_insert(Gathered {
            meaning,
            variants: Vec::new(),
            folders: BTreeSet::new(),
        });
        g.folders
            .insert(path.parent().unwrap_or(path).to_path_buf());
        match g.variants.iter_mut().find(|v| v.columns == columns) {
            Some(v) => v.files += 1,
            None => g.variants.push(Variant {
                columns,
                example: path.to_path_buf(),
                files: 1,
            }),
        }
        Ok(())
    }

    fn finish(self) -> Vec<TableSchema> {
        self.tables
            .into_iter()
            .map(|(name, mut g)| {
                // stable: ties keep path order
                g.variants.sort_by_key(|v| std::cmp::Reverse(v.files));
                TableSchema {
                    name,
                    meaning: g.meaning,
                    variants: g.variants,
                    folders: g.folders.len(),
                }
            })
            .collect()
    }
}

/// The session folders under `sessions/` in hive layout, and the other folders found there.
fn session_folders(root: &Path) -> Result<(Vec<PathBuf>, Vec<PathBuf>), SchemaError> {
    let (mut sessions, mut ignored) = (Vec::new(), Vec::new());
    if !root.is_dir() {
        return Ok((sessions, ignored));
    }
    let is = |p: &Path, key: &str| {
        p.is_dir()
            && p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with(key))
    };
    for d in sorted_entries(root)? {
        if !is(&d, DATASET_KEY) {
            ignored.push(d);
            continue;
        }
        for s in sorted_entries(&d)? {
            if is(&s, SESSION_KEY) {
                sessions.push(s);
            } else {
                ignored.push(s);
            }
        }
    }
    Ok((sessions, ignored))
}

/// Read the schemas of pipeline `name` under `out`; `docs` are its kind's per-session tables.
pub fn read_pipeline(
    out: &Path,
    name: &str,
    docs: &[TableDoc],
) -> Result<PipelineSchemas, SchemaError> {
    let base = out.join(name);
    let (sessions_dir, tables_dir) = (base.join("sessions"), base.join("tables"));
    if !sessions_dir.is_dir() && !tables_dir.is_dir() {
        return Err(SchemaError::NotRun {
            name: name.to_string(),
            path: base,
        });
    }
    let (sessions, ignored) = session_folders(&sessions_dir)?;
    let mut per = Gather::default();
    let mut cache_files = BTreeMap::new();
    for s in &sessions {
        for f in sorted_entries(s)? {
            let file = f
                .file_name()
                .unwrap_or_default()
                .to_string_lossy()
                .into_owned();
            match file.strip_suffix(".parquet") {
                Some(stem) => {
                    let (table, meaning) = match documented(docs, stem) {
                        Some(d) => (d.name.to_string(), Some(d.meaning.to_string())),
                        None => (stem.to_string(), None),
                    };
                    per.add(table, meaning, &f)?;
                }
                None => *cache_files.entry(file).or_insert(0) += 1,
            }
        }
    }
    let mut agg = Gather::default();
    if tables_dir.is_dir() {
        for f in sorted_entries(&tables_dir)? {
            let file = f
                .file_name()
                .unwrap_or_default()
                .to_string_lossy()
                .into_owned();
            if let Some(stem) = file.strip_suffix(".parquet") {
                agg.add(stem.to_string(), aggregate_meaning(&tables_dir, stem), &f)?;
            }
        }
    }
    Ok(PipelineSchemas {
        name: name.to_string(),
        sessions: sessions.len(),
        session_tables: per.finish(),
        aggregate_tables: agg.finish(),
        cache_files,
        ignored,
    })
}

/// An aggregate table's meaning: the title its `.md` opens with (`**title**`); for
/// `<table>.samples`, the per-sample values behind `<table>`.
fn aggregate_meaning(dir: &Path, stem: &str) -> Option<String> {
    let title = |t: &str| {
        let text = std::fs::read_to_string(dir.join(format!("{t}.md"))).ok()?;
        let first = text.lines().next()?.trim();
        let title = first.strip_prefix("**")?.strip_suffix("**")?;
        Some(title.to_string())
    };
    match stem.strip_suffix(".samples") {
        Some(parent) => Some(format!(
            "The per-sample values behind `{parent}` ({}).",
            title(parent)?
        )),
        None => title(stem).map(|t| format!("{t}.")),
    }
}

#[cfg(test)]
mod tests;

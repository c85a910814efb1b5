//! `docs/schemas.md`: the schemas of [`super::read_pipeline`] rendered as Markdown (pure: text
//! from data), read back from that page, and a run checked against it — what `peopletrack
//! schemas` prints and what `make test` compares, so the page and the code cannot drift apart.
//!
//! The page opens with the layout, the cache's other files ([`super::CACHE_FILES`]) and the
//! stability rule; then one section per pipeline: its per-session tables, then its aggregate
//! tables, each with its meaning and a `| column | type |` table in file order. Only the
//! headings and those rows are read back.

use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::Path;

use super::{CACHE_FILES, Column, KindInfo, PipelineSchemas, TableSchema};

/// The command that regenerates the page (named at its top).
pub const REGENERATE: &str = "make schemas";

/// One pipeline as the page documents it.
pub struct Documented<'a> {
    /// The pipeline file, as given on the command line.
    pub file: &'a Path,
    pub kind: &'a str,
    pub info: KindInfo,
    pub schemas: &'a PipelineSchemas,
}

/// A column as one row of the page: its name and its type text.
fn cell(c: &Column) -> (String, String) {
    let dtype = if c.nullable {
        c.dtype.clone()
    } else {
        format!("{} (required)", c.dtype)
    };
    (c.name.clone(), dtype)
}

/// Problems that stop the page from being written (or a check from passing), one line each:
/// sessions that disagree, tables code does not describe, cache files the page does not know.
pub fn problems(p: &PipelineSchemas) -> Vec<String> {
    let mut out = Vec::new();
    for (kind, t) in p.disagreements() {
        let mut line = format!(
            "{}: the {kind} table `{}` has {} different schemas:",
            p.name,
            t.name,
            t.variants.len()
        );
        for v in &t.variants {
            let cols: Vec<String> = v
                .columns
                .iter()
                .map(|c| format!("{} {}", c.name, c.dtype))
                .collect();
            let _ = write!(
                line,
                " [{}] in {} file(s), e.g. {};",
                cols.join(", "),
                v.files,
                v.example.display()
            );
        }
        out.push(line);
    }
    for t in p.session_tables.iter().filter(|t| t.meaning.is_none()) {
        out.push(format!(
            "{}: the per-session table `{}` (e.g. {}) has no meaning in code: add it to the \
             experiment's SESSION_TABLES",
            p.name,
            t.name,
            t.variants[0].example.display()
        ));
    }
    for t in p.aggregate_tables.iter().filter(|t| t.meaning.is_none()) {
        out.push(format!(
            "{}: the aggregate table `{}` has no title (no `{}.md` opening with **title**)",
            p.name, t.name, t.name
        ));
    }
    for f in p.cache_files.keys() {
        if !CACHE_FILES.iter().any(|(known, _)| known == f) {
            out.push(format!(
                "{}: session folders hold `{f}`, which run::schemas::CACHE_FILES does not describe",
                p.name
            ));
        }
    }
    out
}

const INTRO: &str = "\
Every table a pipeline writes, with its columns in file order and their polars dtypes, so a
notebook can rely on them ([notebooks.md](notebooks.md) loads them in polars, pandas and DuckDB).

**Stability rule.** A per-session table's columns — name, type, order and meaning — change only
with a bump of its experiment's `VERSION` (given for each pipeline below): the cache key holds
the `VERSION`, so the sessions of one run never mix schemas, and a changed schema comes with a
new `VERSION` and this page regenerated in the same commit. Aggregate tables are recomputed by
every run; they change only with a commit that regenerates this page. `make test` runs
`peopletrack schemas PIPELINE --out OUT --check docs/schemas.md` on the outputs of the
pipelines its tests run, and fails when a table, a column or a type differs from this page.

**Layout.** Per-session tables (the cache) are hive-style:
`out/<pipeline>/sessions/dataset=<dataset>/session=<session>/<table>.parquet`. The `dataset`
is the name of the folder the log lies in (for `datasets/<name>/full/`, `<name>`), the
`session` the log's file name without `.mcap`; readers with hive partitioning (polars
`hive_partitioning=True`, DuckDB `hive_partitioning = true`) add both as `str` columns
(`dataset`, `session`) from the path — a table that also has a column of that name holds the
same values. Aggregate tables are `out/<pipeline>/tables/<table>.parquet`, each with the same
rows as `.csv`, `.md` and `.tex` (a `<table>.samples.parquet` holds the per-sample values
behind a table's means and tests). Every Parquet file carries its provenance (dataset, seed,
commit, tool version, parameters) as the key-value metadata `peopletrack.provenance` (JSON).

**Types.** polars' dtype names (`str`, `f64`, `i64`, `bool`, `list[...]`, `binary`). Every
column is stored nullable (Parquet OPTIONAL) unless marked `(required)`; a float that was not
measured is NaN or null, as the table's meaning says. A table listed with \"in k of n sessions\"
is written only for the sessions it applies to.
";

/// The whole page.
pub fn render(pipelines: &[Documented]) -> String {
    let mut o = String::from("# Table schemas\n\n");
    let _ = writeln!(
        o,
        "<!-- Generated by `{REGENERATE}` from a `make eval` run (out/); do not edit by hand: \
         the meanings live in code (each experiment's `SESSION_TABLES`, each aggregate \
         table's title). -->\n"
    );
    let _ = writeln!(
        o,
        "Regenerate with `{REGENERATE}` after `make eval` (the command: `peopletrack schemas \
         PIPELINE_FILE... --out out -o docs/schemas.md`).\n"
    );
    o.push_str(INTRO);
    o.push_str("\n**The cache's other files**, beside each session's tables:\n\n");
    for (file, meaning) in CACHE_FILES {
        let _ = writeln!(o, "- `{file}`: {meaning}.");
    }
    o.push_str("\n**Pipelines**: ");
    let links: Vec<String> = pipelines
        .iter()
        .map(|p| format!("[`{0}`](#pipeline-{0})", p.schemas.name))
        .collect();
    o.push_str(&links.join(" · "));
    o.push('\n');
    for p in pipelines {
        render_pipeline(&mut o, p);
    }
    o
}

fn render_pipeline(o: &mut String, p: &Documented) {
    let s = p.schemas;
    let _ = writeln!(o, "\n## Pipeline `{}`\n", s.name);
    let _ = writeln!(
        o,
        "`{}` (kind `{}`, VERSION {}); the run this page came from had {} session(s).",
        p.file.display(),
        p.kind,
        p.info.version,
        s.sessions
    );
    let _ = writeln!(o, "\n### Per-session tables\n");
    let _ = writeln!(
        o,
        "`out/{}/sessions/dataset=<dataset>/session=<session>/<table>.parquet`",
        s.name
    );
    for t in &s.session_tables {
        let of = (t.folders < s.sessions).then_some((t.folders, s.sessions));
        render_table(o, t, of);
    }
    let _ = writeln!(o, "\n### Aggregate tables\n");
    let _ = writeln!(o, "`out/{}/tables/<table>.parquet`", s.name);
    for t in &s.aggregate_tables {
        render_table(o, t, None);
    }
}

fn render_table(o: &mut String, t: &TableSchema, of: Option<(usize, usize)>) {
    let _ = writeln!(o, "\n#### `{}`\n", t.name);
    let mut meaning = t.meaning.clone().unwrap_or_default();
    if let Some((k, n)) = of {
        let _ = write!(meaning, " (in {k} of {n} sessions)");
    }
    let _ = writeln!(o, "{meaning}\n");
    o.push_str("| column | type |\n| --- | --- |\n");
    for c in t.columns() {
        let (name, dtype) = cell(c);
        let _ = writeln!(o, "| `{name}` | {dtype} |");
    }
}

/// A pipeline's tables as the page lists them: table → `(column, type)` rows.
#[derive(Debug, Default, Clone, PartialEq, Eq)]
pub struct PageSection {
    pub session_tables: BTreeMap<String, Vec<(String, String)>>,
    pub aggregate_tables: BTreeMap<String, Vec<(String, String)>>,
}

/// Read the page back: pipeline name → its section (headings and column rows only).
pub fn parse(text: &str) -> BTreeMap<String, PageSection> {
    let mut pages: BTreeMap<String, PageSection> = BTreeMap::new();
    let (mut pipeline, mut aggregate, mut table) = (None::<String>, false, None::<String>);
    let ticked = |s: &str| {
        let s = s.trim();
        s.strip_prefix('`')
            .and_then(|s| s.strip_suffix('`'))
            .map(str::to_string)
    };
    for line in text.lines() {
        if let Some(rest) = line.strip_prefix("## Pipeline ") {
            pipeline = ticked(rest);
            if let Some(p) = &pipeline {
                pages.entry(p.clone()).or_default();
            }
            table = None;
        } else if line.starts_with("### ") {
            aggregate = line.starts_with("### Aggregate");
            table = None;
        } else if let Some(rest) = line.strip_prefix("#### ") {
            table = ticked(rest);
        } else if let (Some(p), Some(t), Some(row)) = (&pipeline, &table, line.strip_prefix("| `"))
            && let Some((name, rest)) = row.split_once("` |")
        {
            let dtype = rest.trim().trim_end_matches('|').trim().to_string();
            let section = pages.entry(p.clone()).or_default();
            let tables = if aggregate {
                &mut section.aggregate_tables
            } else {
                &mut section.session_tables
            };
            tables
                .entry(t.clone())
                .or_default()
                .push((name.to_string(), dtype));
        }
    }
    pages
}

/// How a run's tables differ from the page's section for that pipeline, one line each
/// (empty: they agree). Tables the page lists that this run did not write are not problems (a
/// test's small run writes fewer); tables the run wrote must be there, column for column.
pub fn check(p: &PipelineSchemas, page: &BTreeMap<String, PageSection>) -> Vec<String> {
    let Some(section) = page.get(&p.name) else {
        return vec![format!(
            "pipeline {} has no section (`## Pipeline `{}``) in the page",
            p.name, p.name
        )];
    };
    let mut out = problems(p);
    let pairs = [
        ("per-session", &p.session_tables, &section.session_tables),
        ("aggregate", &p.aggregate_tables, &section.aggregate_tables),
    ];
    for (kind, tables, listed) in pairs {
        for t in tables {
            let Some(rows) = listed.get(&t.name) else {
                out.push(format!(
                    "{}: the {kind} table `{}` (e.g. {}) is not in the page",
                    p.name,
                    t.name,
                    t.variants[0].example.display()
                ));
                continue;
            };
            let wrote: Vec<(String, String)> = t.columns().iter().map(cell).collect();
            if let Some(d) = first_difference(rows, &wrote) {
                out.push(format!(
                    "{}: the {kind} table `{}` differs from the page: {d} (the run's file: {})",
                    p.name,
                    t.name,
                    t.variants[0].example.display()
                ));
            }
        }
    }
    out
}

fn first_difference(page: &[(String, String)], wrote: &[(String, String)]) -> Option<String> {
    let show = |c: Option<&(String, String)>| match c {
        Some((n, t)) => format!("`{n}` ({t})"),
        None => "nothing".to_string(),
    };
    (0..page.len().max(wrote.len()))
        .find(|&i| page.get(i) != wrote.get(i))
        .map(|i| {
            format!(
                "column {} is {} in the page, {} in the run",
                i + 1,
                show(page.get(i)),
                show(wrote.get(i))
            )
        })
}

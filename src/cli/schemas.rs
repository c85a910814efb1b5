//! `peopletrack schemas PIPELINE... [--out OUT] [-o FILE | --check PAGE]`: the schema of every
//! table the pipelines wrote under OUT (per-session cache and aggregate tables, read from the
//! Parquet footers by `peopletrack::run::schemas`), as the Markdown of `docs/schemas.md`; or
//! that run checked against the page. Sessions whose tables disagree fail either way.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use peopletrack::pipelines;
use peopletrack::run::config;
use peopletrack::run::schemas::{self, PipelineSchemas, doc};

#[derive(Debug, clap::Args)]
#[command(after_help = "Examples:
  peopletrack schemas pipelines/dataset_quality.toml                 # print its tables' schemas
  peopletrack schemas pipelines/*.toml --out out -o docs/schemas.md  # what `make schemas` does
  peopletrack schemas pipelines/laser_people.toml --check docs/schemas.md

Reads only what a run left under OUT (run the pipelines first). Exits 1 when two sessions'
copies of a table disagree, a table has no meaning in code, or (--check) the run's tables differ
from the page.")]
pub struct Args {
    /// Pipeline files; each names its output folder (`[pipeline] name`) and its kind.
    #[arg(required = true)]
    pub pipelines: Vec<PathBuf>,
    /// Output root the pipelines ran into.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Write the Markdown page here (atomically) instead of to standard output.
    #[arg(short = 'o', long, value_name = "FILE", conflicts_with = "check")]
    pub output: Option<PathBuf>,
    /// Check the run against this page (e.g. docs/schemas.md) instead of printing one.
    #[arg(long, value_name = "PAGE")]
    pub check: Option<PathBuf>,
}

/// One pipeline file's name, kind and what its run wrote.
struct Read {
    file: PathBuf,
    kind: String,
    info: schemas::KindInfo,
    schemas: PipelineSchemas,
}

fn read(file: &Path, out: &Path) -> anyhow::Result<Read> {
    let (text, kind) = config::read_kind(file)?;
    let parsed = config::parse::<toml::Table>(file, &text)?;
    let info = pipelines::kind_info(&kind).with_context(|| {
        format!(
            "{}: unknown kind {kind:?} (known: {})",
            file.display(),
            pipelines::KINDS.join(", ")
        )
    })?;
    let schemas = schemas::read_pipeline(out, &parsed.pipeline.name, info.session_tables)?;
    Ok(Read {
        file: file.to_path_buf(),
        kind,
        info,
        schemas,
    })
}

pub fn run(a: &Args, out: &mut dyn std::io::Write) -> anyhow::Result<()> {
    let runs = a
        .pipelines
        .iter()
        .map(|f| read(f, &a.out))
        .collect::<anyhow::Result<Vec<_>>>()?;
    for r in &runs {
        for folder in &r.schemas.ignored {
            eprintln!(
                "note: {} is not in the hive layout (dataset=/session=); the runner ignores it",
                folder.display()
            );
        }
    }
    if let Some(page) = &a.check {
        let text =
            std::fs::read_to_string(page).with_context(|| format!("reading {}", page.display()))?;
        let sections = doc::parse(&text);
        let problems: Vec<String> = runs
            .iter()
            .flat_map(|r| doc::check(&r.schemas, &sections))
            .collect();
        if !problems.is_empty() {
            bail!(
                "{} does not match the tables under {} ({} problem(s); `make schemas` \
                 regenerates the page, with a VERSION bump if a per-session table changed):\n{}",
                page.display(),
                a.out.display(),
                problems.len(),
                problems.join("\n")
            );
        }
        let tables: usize = runs
            .iter()
            .map(|r| r.schemas.session_tables.len() + r.schemas.aggregate_tables.len())
            .sum();
        writeln!(
            out,
            "{}: the {tables} tables of {} pipeline(s) under {} match",
            page.display(),
            runs.len(),
            a.out.display()
        )?;
        return Ok(());
    }
    let problems: Vec<String> = runs
        .iter()
        .flat_map(|r| doc::problems(&r.schemas))
        .collect();
    if !problems.is_empty() {
        bail!(
            "no page written ({} problem(s)):\n{}",
            problems.len(),
            problems.join("\n")
        );
    }
    let documented: Vec<doc::Documented> = runs
        .iter()
        .map(|r| doc::Documented {
            file: &r.file,
            kind: &r.kind,
            info: r.info,
            schemas: &r.schemas,
        })
        .collect();
    let page = doc::render(&documented);
    match &a.output {
        Some(path) => peopletrack::report::atomic::write_atomic(path, page.as_bytes(), None)
            .with_context(|| format!("writing {}", path.display()))?,
        None => out.write_all(page.as_bytes())?,
    }
    Ok(())
}

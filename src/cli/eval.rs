//! `peopletrack eval`: every pipeline in `pipelines/`, then `out/REPORT.md` linking every table
//! and figure, with versions and timings.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;

use crate::pipelines;
use crate::report::atomic;
use crate::run::{RunOptions, report};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Folder of pipeline files (every *.toml runs, in name order).
    #[arg(long, default_value = "pipelines")]
    pub pipelines: PathBuf,
    /// Run only these pipelines (file stems); repeat for more.
    #[arg(long, value_name = "NAME")]
    pub only: Vec<String>,
    /// Recompute sessions even when cached results match.
    #[arg(long)]
    pub force: bool,
    /// Output root.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
}

pub fn run(a: &Args, out: &mut dyn std::io::Write) -> anyhow::Result<()> {
    let started = Instant::now();
    let mut files: Vec<PathBuf> = std::fs::read_dir(&a.pipelines)
        .with_context(|| format!("reading pipeline folder {}", a.pipelines.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .filter(|p| {
            a.only.is_empty()
                || p.file_stem()
                    .is_some_and(|s| a.only.iter().any(|o| o.as_str() == s))
        })
        .collect();
    files.sort();
    if files.is_empty() {
        anyhow::bail!("no pipeline files in {}", a.pipelines.display());
    }
    atomic::sweep_scratch(&a.out)?;
    let opts = RunOptions {
        sessions: None,
        dry_run: false,
        shard: None,
        aggregate_only: false,
        force: a.force,
        out: a.out.clone(),
        git_commit: super::git_commit(),
        progress: super::stderr_is_terminal(),
        write_tracks: None,
    };
    let mut runs = Vec::new();
    for f in &files {
        let s =
            pipelines::run_file(f, &opts).with_context(|| format!("pipeline {}", f.display()))?;
        writeln!(
            out,
            "{:24} {:>3} sessions ({} computed, {} cached, {} skipped)  {:>7.1} s",
            s.pipeline,
            s.sessions,
            s.computed,
            s.cached,
            s.skipped.len(),
            s.seconds
        )?;
        for (session, why) in &s.skipped {
            eprintln!("warning: {}: skipped {session}: {why}", s.pipeline);
        }
        runs.push(s);
    }
    let mut tables = BTreeMap::new();
    for (_, path) in runs.iter().flat_map(|r| r.tables.iter()) {
        let text =
            std::fs::read_to_string(a.out.join(path)).with_context(|| format!("reading {path}"))?;
        tables.insert(path.clone(), text);
    }
    let header = report::Header {
        tool_version: env!("CARGO_PKG_VERSION").to_string(),
        git_commit: opts.git_commit.clone(),
        rustc: super::rustc_version(),
        total_seconds: started.elapsed().as_secs_f64(),
    };
    let md = report::render(&runs, &tables, &header);
    let path = a.out.join("REPORT.md");
    atomic::write_atomic(&path, md.as_bytes(), Some(&a.out))?;
    writeln!(out, "wrote {}", path.display())?;
    Ok(())
}

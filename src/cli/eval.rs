//! `peopletrack eval`: every pipeline in `pipelines/`, then `out/REPORT.md` linking every table
//! and figure, with versions and timings.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;

use peopletrack::pipelines;
use peopletrack::report::atomic;
use peopletrack::run::lock::FolderLock;
use peopletrack::run::{RunOptions, report};

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
    /// Dataset profile: `quick` (the default datasets) or `full` (paper-sized logs that
    /// `make datasets PROFILE=full` writes to `datasets/<name>/full/`; each pipeline's input
    /// globs are redirected there and the default output root becomes `out/full`).
    #[arg(long, default_value = "quick", value_parser = ["quick", "full"])]
    pub profile: String,
    /// Output root (default `out`, or `out/full` for the full profile).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Do not fail when a session's results, computed, cannot be stored in the cache (as
    /// `run --keep-going`).
    #[arg(long)]
    pub keep_going: bool,
}

/// `datasets/x/*.mcap` -> `datasets/x/full/*.mcap`: the same glob one folder down.
fn full_profile_glob(glob: &str) -> String {
    let p = std::path::Path::new(glob);
    match (p.parent(), p.file_name()) {
        (Some(dir), Some(name)) => dir.join("full").join(name).display().to_string(),
        _ => format!("full/{glob}"),
    }
}

/// The `[inputs] sessions` globs of a pipeline file, redirected for the full profile.
fn full_sessions(file: &std::path::Path) -> anyhow::Result<Vec<String>> {
    let text =
        std::fs::read_to_string(file).with_context(|| format!("reading {}", file.display()))?;
    let v: toml::Value =
        toml::from_str(&text).with_context(|| format!("{} is not TOML", file.display()))?;
    let globs = v
        .get("inputs")
        .and_then(|i| i.get("sessions"))
        .and_then(|s| s.as_array())
        .map_or_else(Vec::new, |a| {
            a.iter()
                .filter_map(|g| g.as_str().map(full_profile_glob))
                .collect()
        });
    Ok(globs)
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
    let out_root = a.out.clone().unwrap_or_else(|| {
        PathBuf::from(if a.profile == "full" {
            "out/full"
        } else {
            "out"
        })
    });
    // one eval per output root: it writes REPORT.md from every pipeline's tables
    let held = FolderLock::acquire(&out_root)?;
    if let Some(n) = &held.unsupported {
        eprintln!("warning: {n}");
    }
    atomic::sweep_scratch(&out_root)?;
    let base = RunOptions {
        sessions: None,
        dry_run: false,
        shard: None,
        aggregate_only: false,
        expect_shards: None,
        force: a.force,
        out: out_root.clone(),
        git_commit: super::git_commit(),
        progress: super::progress::shared(super::stderr_is_terminal()),
        write_tracks: None,
        recover: false,
        keep_going: a.keep_going,
    };
    let mut runs = Vec::new();
    for f in &files {
        let mut opts = base.clone();
        if a.profile == "full" {
            opts.sessions = Some(full_sessions(f)?);
        }
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
        for (session, why) in &s.warned {
            let how = super::run::kept_how(why);
            eprintln!(
                "warning: {}: {session} {how} (results kept): {why}",
                s.pipeline
            );
        }
        for n in &s.notices {
            eprintln!("warning: {}: {n}", s.pipeline);
        }
        runs.push(s);
    }
    let mut tables = BTreeMap::new();
    for (_, path) in runs.iter().flat_map(|r| r.tables.iter()) {
        let file = out_root.join(path);
        let text = std::fs::read_to_string(&file)
            .with_context(|| format!("reading table {}", file.display()))?;
        tables.insert(path.clone(), text);
    }
    let header = report::Header {
        tool_version: env!("CARGO_PKG_VERSION").to_string(),
        git_commit: base.git_commit.clone(),
        rustc: super::rustc_version(),
        total_seconds: started.elapsed().as_secs_f64(),
    };
    let md = report::render(&runs, &tables, &header);
    let path = out_root.join("REPORT.md");
    atomic::write_atomic(&path, md.as_bytes(), Some(&out_root))
        .with_context(|| format!("writing the report to {}", path.display()))?;
    writeln!(out, "wrote {}", path.display())?;
    drop(held);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::full_profile_glob;

    #[test]
    fn full_profile_globs_go_one_folder_down() {
        assert_eq!(
            full_profile_glob("datasets/omni_lab/*.mcap"),
            "datasets/omni_lab/full/*.mcap"
        );
        assert_eq!(full_profile_glob("*.mcap"), "full/*.mcap");
    }
}

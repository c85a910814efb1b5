//! `peopletrack run PIPELINE.toml`: one pipeline — plan, per-session processing (cached), and
//! aggregation into tables and figures under `out/<pipeline>/`.

use std::path::PathBuf;

use anyhow::Context;
use peopletrack::pipelines;
use peopletrack::report::atomic;
use peopletrack::run::{RunOptions, config, lock, skipped, slurm};
use peopletrack::storage::{self, mirror::Mirror};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Pipeline file, e.g. pipelines/dataset_quality.toml.
    pub pipeline: PathBuf,
    /// Run on these sessions instead of the file's [inputs] (glob; repeat for more). With a
    /// build that has object storage (`make build-s3`), also `s3://bucket/prefix/*.mcap`:
    /// the store is listed and each log read in place with range requests.
    #[arg(long, value_name = "GLOB")]
    pub sessions: Vec<String>,
    /// Print which sessions, topics and stages would run, and stop.
    #[arg(long)]
    pub dry_run: bool,
    /// Process only shard K of N (1-based) and skip aggregation: for array jobs on a cluster.
    #[arg(long, value_name = "K/N", value_parser = parse_shard)]
    pub shard: Option<(usize, usize)>,
    /// Take the shard from the scheduler: a Slurm array task (SLURM_ARRAY_TASK_ID of
    /// SLURM_ARRAY_TASK_COUNT) or a Kubernetes indexed job (JOB_COMPLETION_INDEX of
    /// PEOPLETRACK_SHARDS). `peopletrack submit --slurm` writes jobs that use it.
    #[arg(long, conflicts_with_all = ["shard", "aggregate_only"])]
    pub shard_from_env: bool,
    /// Aggregate cached per-session results only (after all shards ran).
    #[arg(long, conflicts_with = "shard")]
    pub aggregate_only: bool,
    /// With --aggregate-only: all N shards of a sharded run must have left their record
    /// (`out/<pipeline>/shards/N/K.json`); a shard that did not finish, ran another
    /// configuration or left a damaged record is named and nothing is aggregated. The sessions
    /// a shard skipped are reported with the shard's reason, even with the logs gone.
    #[arg(long, value_name = "N", requires = "aggregate_only", value_parser = clap::value_parser!(u32).range(1..))]
    pub expect_shards: Option<u32>,
    /// Recompute sessions even when a cached result matches.
    #[arg(long)]
    pub force: bool,
    /// Output root: a folder, or (object storage build) `s3://bucket/prefix`, where the
    /// pipeline's folder is fetched, worked on locally and written back file by file
    /// (credentials and endpoint from AWS_* variables; docs/cluster.md).
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Write the tracks back into a copy of each log (as visualization_msgs/msg/MarkerArray,
    /// for Foxglove) under DIR (default: <out>/tracks), for pipelines that produce tracks.
    // Given without DIR it is `Some(None)`: a path value parser rejects an empty default.
    #[arg(long, value_name = "DIR", num_args = 0..=1)]
    pub write_tracks: Option<Option<PathBuf>>,
    /// Read damaged logs as far as they go, as `cat --recover` does: every complete chunk
    /// before the damage (and good chunks after a bad one); each session read so is listed
    /// with what was lost (bytes, time span, topics) in the `skipped_sessions` table and the
    /// report, its results kept.
    #[arg(long)]
    pub recover: bool,
    /// Do not fail the run when a session's results, computed, cannot be stored in the cache
    /// (a full disk, a read-only cache folder): they are still in this run's tables and the
    /// session is listed as `unstored` in the `skipped_sessions` table.
    #[arg(long)]
    pub keep_going: bool,
}

fn parse_shard(s: &str) -> Result<(usize, usize), String> {
    let (k, n) = s.split_once('/').ok_or("expected K/N, e.g. 3/10")?;
    let (k, n): (usize, usize) = (
        k.parse().map_err(|_| "K is not a number")?,
        n.parse().map_err(|_| "N is not a number")?,
    );
    if n == 0 || k == 0 || k > n {
        return Err(format!("shard {k}/{n}: need 1 <= K <= N"));
    }
    Ok((k, n))
}

pub fn options(a: &Args, progress: bool) -> RunOptions {
    RunOptions {
        sessions: (!a.sessions.is_empty()).then(|| a.sessions.clone()),
        dry_run: a.dry_run,
        shard: a.shard,
        aggregate_only: a.aggregate_only,
        expect_shards: a.expect_shards.map(|n| n as usize),
        force: a.force,
        out: a.out.clone(),
        git_commit: super::git_commit(),
        progress: super::progress::shared(progress),
        write_tracks: a
            .write_tracks
            .as_ref()
            .map(|d| d.clone().unwrap_or_else(|| a.out.join("tracks"))),
        recover: a.recover,
        keep_going: a.keep_going,
    }
}

/// `--out s3://...`: a local mirror of the pipeline's folder that the run works in
/// ([`storage::mirror`]); `--write-tracks` below `--out` goes there too.
fn object_store_out(a: &Args, opts: &mut RunOptions) -> anyhow::Result<Option<Mirror>> {
    if !storage::is_url(&a.out) {
        return Ok(None);
    }
    let name = config::read_name(&a.pipeline)?;
    let url = a.out.to_string_lossy();
    let mirror = Mirror::pull(&url, &name).with_context(|| format!("reading {url}/{name}/"))?;
    opts.out = mirror.local().to_path_buf();
    if let Some(dir) = &opts.write_tracks {
        opts.write_tracks = Some(match dir.strip_prefix(&a.out) {
            Ok(rel) => mirror.local().join(rel),
            Err(_) if storage::is_url(dir) => anyhow::bail!(
                "--write-tracks {}: tracks go to a local folder or below --out",
                dir.display()
            ),
            Err(_) => dir.clone(),
        });
    }
    Ok(Some(mirror))
}

/// How a session kept with a warning was kept (for the warning line).
pub fn kept_how(why: &str) -> &'static str {
    if skipped::warned_status(why) == skipped::UNSTORED {
        "not stored in the cache"
    } else {
        "read with warnings"
    }
}

pub fn run(a: &Args, out: &mut dyn std::io::Write) -> anyhow::Result<()> {
    let mut opts = options(a, super::stderr_is_terminal());
    if a.shard_from_env {
        opts.shard = Some(slurm::shard_from_env(|k| std::env::var(k).ok())?);
    }
    let mirror = object_store_out(a, &mut opts)?;
    if !a.dry_run {
        atomic::sweep_scratch(&opts.out)?;
    }
    let s = pipelines::run_file(&a.pipeline, &opts)?;
    if let (Some(m), false) = (&mirror, a.dry_run) {
        let pushed = m
            .push(&[lock::LOCK_FILE])
            .with_context(|| format!("writing to {}", a.out.display()))?;
        eprintln!(
            "{}: {} files written ({} bytes), {} unchanged",
            a.out.display(),
            pushed.files,
            pushed.bytes,
            pushed.unchanged
        );
    }
    if a.dry_run {
        write!(out, "{}", s.plan)?;
        for n in &s.notices {
            eprintln!("warning: {n}");
        }
        return Ok(());
    }
    writeln!(
        out,
        "{}: {} sessions ({} computed, {} from cache, {} skipped) in {:.1} s",
        s.pipeline,
        s.sessions,
        s.computed,
        s.cached,
        s.skipped.len(),
        s.seconds
    )?;
    for (t, p) in s.tables.iter().chain(&s.figures) {
        writeln!(out, "  {}  {t}", a.out.join(p).display())?;
    }
    for p in &s.artifacts {
        writeln!(out, "  {p}")?;
    }
    for (session, why) in &s.skipped {
        eprintln!("warning: skipped {session}: {why}");
    }
    for (session, why) in &s.warned {
        eprintln!("warning: {session} {} (results kept): {why}", kept_how(why));
    }
    for n in &s.notices {
        eprintln!("warning: {n}");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        run: Args,
    }

    fn write_tracks(args: &[&str]) -> Option<PathBuf> {
        let cli = Cli::try_parse_from(args).expect("parses");
        options(&cli.run, false).write_tracks
    }

    /// Regression: a bare `--write-tracks` was rejected ("a value is required") because the
    /// empty default value does not parse as a path.
    #[test]
    fn write_tracks_without_a_folder_goes_under_out() {
        assert_eq!(
            write_tracks(&["run", "p.toml", "--write-tracks"]),
            Some(PathBuf::from("out/tracks"))
        );
        assert_eq!(
            write_tracks(&["run", "p.toml", "--out", "o", "--write-tracks"]),
            Some(PathBuf::from("o/tracks"))
        );
        assert_eq!(
            write_tracks(&["run", "p.toml", "--write-tracks", "d"]),
            Some(PathBuf::from("d"))
        );
        assert_eq!(write_tracks(&["run", "p.toml"]), None);
    }
}

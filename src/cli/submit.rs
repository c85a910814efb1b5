//! `peopletrack submit --slurm PIPELINE.toml`: run one pipeline on a Slurm cluster as an array
//! of shards plus one aggregate job (see `peopletrack::run::slurm`, and docs/cluster.md).

use std::path::{Path, PathBuf};

use anyhow::Context;
use peopletrack::pipelines;
use peopletrack::run::config;
use peopletrack::run::slurm::Submission;

#[derive(Debug, clap::Args)]
#[command(after_help = "Examples:
  peopletrack submit --slurm pipelines/dataset_quality.toml --shards 8 --dry-run
  peopletrack submit --slurm pipelines/laser_people.toml --shards 32 --throttle 8 \\
      --partition cpu --time 1:00:00 --mem 8G --out /scratch/$USER/out

Each array task runs `run --shard-from-env` (shard K of N from SLURM_ARRAY_TASK_ID); the
aggregate job waits for all of them (--dependency=afterok) and runs `run --aggregate-only
--expect-shards N`, which names any shard that did not finish. Slurm schedules and retries.")]
pub struct Args {
    /// Pipeline file, e.g. pipelines/dataset_quality.toml.
    pub pipeline: PathBuf,
    /// Submit to Slurm (`sbatch` on PATH; SLURM_CONF as for any Slurm command).
    #[arg(long, required = true)]
    pub slurm: bool,
    /// Number of shards (array tasks).
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub shards: u32,
    /// At most this many array tasks at once (`--array=1-N%T`).
    #[arg(long, value_name = "T")]
    pub throttle: Option<u32>,
    /// Slurm partition (default: the cluster's default).
    #[arg(long)]
    pub partition: Option<String>,
    /// Time limit of each job, in Slurm's format.
    #[arg(long, default_value = "1:00:00")]
    pub time: String,
    /// Memory of each job, in Slurm's format.
    #[arg(long, default_value = "4G")]
    pub mem: String,
    /// CPUs (worker threads) of each job.
    #[arg(long, default_value_t = 1)]
    pub cpus: u32,
    /// Run on these sessions instead of the file's [inputs] (glob; repeat for more).
    #[arg(long, value_name = "GLOB")]
    pub sessions: Vec<String>,
    /// Output root (a folder every node sees).
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Print the two batch scripts instead of submitting them.
    #[arg(long)]
    pub dry_run: bool,
}

fn absolute(p: &Path, cwd: &Path) -> PathBuf {
    if p.is_absolute() {
        p.to_path_buf()
    } else {
        cwd.join(p)
    }
}

pub fn run(a: &Args, out: &mut dyn std::io::Write) -> anyhow::Result<()> {
    let (text, _) = config::read_kind(&a.pipeline)?;
    pipelines::check_text(&a.pipeline, &text)?;
    let file = config::parse::<toml::Table>(&a.pipeline, &text)?;
    let cwd = std::env::current_dir().context("reading the current directory")?;
    let mut run_args = Vec::new();
    for s in &a.sessions {
        run_args.extend(["--sessions".to_string(), s.clone()]);
    }
    let sub = Submission {
        exe: std::env::current_exe().context("finding this program's path")?,
        workdir: cwd.clone(),
        pipeline: a.pipeline.clone(),
        name: file.pipeline.name.clone(),
        out: absolute(&a.out, &cwd),
        shards: a.shards as usize,
        throttle: a.throttle.map(|t| t as usize),
        partition: a.partition.clone(),
        time: a.time.clone(),
        mem: a.mem.clone(),
        cpus: a.cpus.max(1) as usize,
        run_args,
    };
    if a.dry_run {
        writeln!(out, "# {}/array.sbatch", sub.dir().display())?;
        write!(out, "{}", sub.array_script())?;
        writeln!(out, "# {}/aggregate.sbatch", sub.dir().display())?;
        write!(out, "{}", sub.aggregate_script())?;
        return Ok(());
    }
    let ids = sub.submit()?;
    writeln!(
        out,
        "submitted {}: array job {} ({} shards), aggregate job {} (after the array succeeds)",
        file.pipeline.name, ids.array, sub.shards, ids.aggregate
    )?;
    writeln!(out, "logs: {}", sub.dir().display())?;
    Ok(())
}

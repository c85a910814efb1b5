//! Command-line interface of the binary (not part of the library): parsing (clap), terminal
//! progress bars (indicatif) and one module per subcommand, all through `peopletrack::…`.
//! `main.rs` only calls [`main`]; errors become exit codes here, in one place.

pub mod cat;
pub mod eval;
pub mod import;
pub mod inspect;
pub mod progress;
pub mod run;
pub mod schemas;
pub mod score;
pub mod submit;
pub mod synth;
pub mod train;
pub mod wav;

use std::io::{self, Write};
use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// peopletrack turns logged robot sessions (MCAP) into calibrated models, tracks, and
/// paper-style tables and figures with honest statistics.
#[derive(Debug, Parser)]
#[command(name = "peopletrack", version, about, long_about = None, after_help = EXAMPLES)]
pub struct Cli {
    /// Worker threads for sessions, frames and cameras (default: all cores). Results do not
    /// depend on it.
    #[arg(long, short = 'j', global = true, value_name = "N")]
    pub jobs: Option<usize>,
    /// Most MiB of structure (fields and array slots) one decoded message may take, for any
    /// command that decodes messages (default: 16 MiB plus 8 bytes per payload byte). Raise
    /// it for a valid message the default refuses, e.g. millions of one-byte structs.
    #[arg(long, global = true, value_name = "MIB")]
    pub max_structure_mib: Option<usize>,
    /// Crash test: abort just before the N-th file replacement (hidden; for tests).
    #[arg(long, global = true, hide = true, value_name = "N")]
    pub debug_abort_after_writes: Option<u64>,
    #[command(subcommand)]
    pub command: Command,
}

const EXAMPLES: &str = "Examples:
  peopletrack inspect ../shared/real/laser/general_tracking_moving_1/general_tracking_moving_1.mcap
  peopletrack cat LOG.mcap --topic /scan --limit 1 --max-array 8
  peopletrack run pipelines/dataset_quality.toml --dry-run
  peopletrack run pipelines/dataset_quality.toml --sessions 'mylogs/*.mcap'
  peopletrack eval                      # every pipeline, then out/REPORT.md
  peopletrack synth datasets/omni_lab/scenario.toml --profile full";

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Describe logs: topics, schemas, encodings, counts, rates, gaps, time span, TF tree.
    Inspect(inspect::Args),
    /// Print one topic's messages as JSON lines, decoded whatever their type.
    Cat(cat::Args),
    /// Run one pipeline file: per-session processing (cached) and tables and figures in out/.
    Run(run::Args),
    /// Run every pipeline in pipelines/ and write out/REPORT.md.
    Eval(eval::Args),
    /// Render a synthetic dataset (sessions as MCAP logs, and a preview sheet).
    Synth(synth::Args),
    /// Score tracks against ground truth (MOTChallenge CSV): HOTA, CLEAR MOT (MOTA, MOTP,
    /// switches, MT/PT/ML) and IDF1.
    Score(score::Args),
    /// Train a model on your own logs and save it for `run` to load, e.g.
    /// `peopletrack train omni-appearance --sessions 'logs/*.mcap'`.
    Train(train::Args),
    /// Write a public dataset as a session log, e.g.
    /// `peopletrack import wildtrack ../shared/real/wildtrack -o wildtrack.mcap`.
    Import(import::Args),
    /// Run one pipeline on a Slurm cluster: an array of shards, then the aggregate, e.g.
    /// `peopletrack submit --slurm pipelines/laser_people.toml --shards 16`.
    Submit(submit::Args),
    /// Print the schema of every table the pipelines wrote (per-session cache and aggregate
    /// tables, from the Parquet footers) as Markdown, or check them against a page, e.g.
    /// `peopletrack schemas pipelines/*.toml --check docs/schemas.md`.
    Schemas(schemas::Args),
    /// Write a session's two-microphone audio as a WAV file to listen to, e.g.
    /// `peopletrack wav datasets/biron_home/biron_home_00.mcap -o biron.wav`.
    Wav(wav::Args),
}

/// Parse arguments, run the command, and map the outcome to an exit code:
/// 0 success, 1 error (printed with its causes), 2 bad usage (clap's).
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    if let Some(n) = cli.jobs
        && let Err(e) = rayon::ThreadPoolBuilder::new()
            .num_threads(n.max(1))
            .build_global()
    {
        eprintln!("error: cannot start {n} worker threads: {e}");
        return ExitCode::FAILURE;
    }
    if let Some(n) = cli.debug_abort_after_writes {
        peopletrack::report::atomic::abort_before_rename(n);
    }
    if let Some(mib) = cli.max_structure_mib {
        peopletrack::log::cdr::set_structure_limit(Some(mib.saturating_mul(1 << 20)));
    }
    let stdout = io::stdout();
    let mut out = io::BufWriter::new(stdout.lock());
    let result = match &cli.command {
        Command::Inspect(a) => inspect::run(a, &mut out),
        Command::Cat(a) => cat::run(a, &mut out),
        Command::Run(a) => run::run(a, &mut out),
        Command::Eval(a) => eval::run(a, &mut out),
        Command::Synth(a) => synth::run(a, &mut out),
        Command::Score(a) => score::run(a, &mut out),
        Command::Train(a) => train::run(a, &mut out),
        Command::Import(a) => import::run(a, &mut out),
        Command::Submit(a) => submit::run(a, &mut out),
        Command::Schemas(a) => schemas::run(a, &mut out),
        Command::Wav(a) => wav::run(a, &mut out),
    }
    .and_then(|()| out.flush().map_err(anyhow::Error::from));
    // this process's scratch folders (empty once every write is done) go
    peopletrack::report::atomic::release_scratch();
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // `peopletrack cat ... | head` closes the pipe early: not an error
        Err(e) if is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<io::Error>()
            .is_some_and(|io| io.kind() == io::ErrorKind::BrokenPipe)
    })
}

/// Short commit of the working tree (with `+dirty` if tracked files changed), or `unknown`.
pub fn git_commit() -> String {
    let git = |args: &[&str]| {
        std::process::Command::new("git")
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
    };
    match git(&["rev-parse", "--short=12", "HEAD"]) {
        Some(c) if !c.is_empty() => {
            let dirty = git(&["status", "--porcelain", "--untracked-files=no"])
                .is_some_and(|s| !s.is_empty());
            if dirty { format!("{c}+dirty") } else { c }
        }
        _ => "unknown".to_string(),
    }
}

/// `rustc --version` of the toolchain on this machine (for the report), or `unknown`.
pub fn rustc_version() -> String {
    std::process::Command::new("rustc")
        .arg("--version")
        .output()
        .ok()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "unknown".to_string())
}

/// Progress bars only when a person is watching.
pub fn stderr_is_terminal() -> bool {
    use std::io::IsTerminal;
    io::stderr().is_terminal()
}

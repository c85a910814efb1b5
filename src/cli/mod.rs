//! Command-line interface: parsing (clap) and one module per subcommand. `main.rs` only calls
//! [`main`]; errors become exit codes here, in one place.

pub mod cat;
pub mod inspect;
pub mod score;

use std::io::{self, Write};
use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// peopletrack turns logged robot sessions (MCAP) into calibrated models, tracks, and
/// paper-style tables and figures with honest statistics.
#[derive(Debug, Parser)]
#[command(name = "peopletrack", version, about, long_about = None, after_help = EXAMPLES)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

const EXAMPLES: &str = "Examples:
  peopletrack inspect ../shared/real/laser/general_tracking_moving_1/general_tracking_moving_1.mcap
  peopletrack cat LOG.mcap --topic /scan --limit 1 --max-array 8";

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Describe logs: topics, schemas, encodings, counts, rates, gaps, time span, TF tree.
    Inspect(inspect::Args),
    /// Print one topic's messages as JSON lines, decoded whatever their type.
    Cat(cat::Args),
    /// Score tracks against ground truth (MOTChallenge CSV): HOTA, CLEAR MOT (MOTA, MOTP,
    /// switches, MT/PT/ML) and IDF1.
    Score(score::Args),
}

/// Parse arguments, run the command, and map the outcome to an exit code:
/// 0 success, 1 error (printed with its causes), 2 bad usage (clap's).
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let stdout = io::stdout();
    let mut out = io::BufWriter::new(stdout.lock());
    let result = match &cli.command {
        Command::Inspect(a) => inspect::run(a, &mut out),
        Command::Cat(a) => cat::run(a, &mut out),
        Command::Score(a) => score::run(a, &mut out),
    }
    .and_then(|()| out.flush().map_err(anyhow::Error::from));
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

//! The `peopletrack` binary: the command line (clap) and terminal progress bars (indicatif) live
//! here, in [`cli`]; everything else is the `peopletrack` library. See `peopletrack --help`.

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}

//! The `peopletrack` binary: everything lives in the library; see `peopletrack --help`.

fn main() -> std::process::ExitCode {
    peopletrack::cli::main()
}

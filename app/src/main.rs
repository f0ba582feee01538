//! The `tracelab` binary: the command line, and (with no subcommand) the GUI.

fn main() -> std::process::ExitCode {
    tracelab::cli::main()
}

//! The `galvoplan` binary: no subcommand opens the GUI; subcommands run headless.

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}

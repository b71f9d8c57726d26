//! The `galvoplan` binary: no subcommand opens the GUI; subcommands run headless.

mod cli;

/// mimalloc: large jobs free hundreds of MB between stages (hatch, fields, order, lowering);
/// glibc's per-thread arenas kept it, mimalloc gives it back (docs/BENCHMARKS.md, issue 24).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> std::process::ExitCode {
    cli::main()
}

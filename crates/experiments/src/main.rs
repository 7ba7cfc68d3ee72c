//! The `experiments` command line: the commands on one run directory ([`experiments::cli`]),
//! the same as `cargo xtask fit | eval | energy | export | export-merl`.

use clap::Parser;
use experiments::cli::RunCommand;

/// Neural BRDF experiments: fit, evaluate and export one run (`cargo xtask` has the same
/// commands, and the sweeps).
#[derive(Parser)]
#[command(name = "experiments", version, about)]
struct Cli {
    #[command(subcommand)]
    command: RunCommand,
}

fn main() -> anyhow::Result<()> {
    experiments::cli::run(Cli::parse().command)
}

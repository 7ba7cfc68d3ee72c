//! `cargo xtask`: the orchestration CLI of the neural-BRDF comparison.
//!
//! Every user-facing job of the workspace is a subcommand here; run `cargo xtask --help`.

use anyhow::Result;
use clap::{Parser, Subcommand};

/// Orchestration CLI of the neural-BRDF comparison workspace.
#[derive(Parser)]
#[command(name = "cargo xtask", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print the workspace's crates in layering order.
    Layers,
}

fn main() -> Result<()> {
    match Cli::parse().command {
        Command::Layers => {
            for c in LAYERS {
                println!("{c}");
            }
        }
    }
    Ok(())
}

/// The workspace crates, bottom first: a crate may depend only on crates before it.
pub const LAYERS: &[&str] = &[
    "angles",
    "brdf-analytic",
    "mesh-encoding",
    "raycast-precompute",
    "dataset-merl",
    "dataset-diligent",
    "metrics",
    "brdf-neural",
    "experiments",
    "xtask",
];

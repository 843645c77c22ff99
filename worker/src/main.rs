//! `cosdem-worker`: the DEM worker binary (benchmarks now; the gRPC `listen` mode is added by
//! the service).

use anyhow::Result;
use clap::{Parser, Subcommand};
use cosdem_worker::BoundarySpec;

/// The cosdem DEM worker.
#[derive(Parser, Debug)]
#[command(name = "cosdem-worker", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Benchmarks.
    Bench {
        #[command(subcommand)]
        what: BenchWhat,
    },
}

#[derive(Subcommand, Debug)]
enum BenchWhat {
    /// DEM kernel throughput and one full relaxation.
    Dem {
        /// Fewer steps (a smoke run).
        #[arg(long)]
        quick: bool,
    },
}

fn main() -> Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Bench { what: BenchWhat::Dem { quick } } => bench_dem(quick),
    }
}

fn bench_dem(quick: bool) -> Result<()> {
    let work: f64 = if quick { 2e6 } else { 4e7 };
    for n in [100usize, 400, 1600, 6400] {
        let steps = (work / n as f64).max(200.0) as u64;
        let r = cosdem_worker::bench::rate(n, steps)?;
        println!("{:>6} discs {:>8} steps {:.3e} particle-steps/s", r.discs, r.steps, r.rate);
    }
    let (n, steps, conv, wall) = cosdem_worker::bench::relaxation()?;
    println!(
        "relaxation 0.0784 m^2 ({n} discs, e_yy = -1e-3): {steps} steps, converged {conv}, {wall:.3} s"
    );
    for boundary in [BoundarySpec::default(), BoundarySpec::Periodic] {
        let (n, wall) = cosdem_worker::bench::random_build(0.28, boundary.clone())?;
        println!("random packing 0.0784 m^2 ({n} discs, {boundary:?}): built in {wall:.3} s");
    }
    Ok(())
}

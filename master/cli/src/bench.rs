//! `cosdem bench`: the coupling benchmarks of `cosdem_study::bench` (printed figures) and the
//! speed/accuracy sweeps ([`crate::tradeoff`]).

use crate::tradeoff::{
    TradeoffArgs, TradeoffPlotArgs, TradeoffSpecimensArgs, tradeoff, tradeoff_plot,
    tradeoff_specimens,
};
use anyhow::Result;
use clap::Subcommand;
use cosdem_study::bench::{Workload, fe_versus_dem, overhead, rpc_floor, scaling, worker_binary};
use std::path::PathBuf;

#[derive(Subcommand)]
pub(crate) enum BenchWhat {
    /// The coupling's own cost without DEM work (stand-in assemblies): fixed per iteration
    /// and per Gauss point, in-process and loopback TCP.
    Floor(FloorArgs),
    /// RPC overhead per Gauss point per iteration: direct vs in-process pool vs loopback TCP.
    Overhead(OverheadArgs),
    /// Step time of a 64-Gauss-point job with 1 and 2 workers of one thread each.
    Scaling(ScalingArgs),
    /// FE cost of one Newton iteration against the DEM cost of the same iteration.
    Fe(FeArgs),
    /// All three with their defaults.
    All(CommonArgs),
    /// Speed against accuracy: sweep every speed knob of a job against a tight reference
    /// run; writes tradeoff.csv, tradeoff.md and one run directory per setting.
    Tradeoff(TradeoffArgs),
    /// Redraw the Pareto plot of an existing tradeoff.csv without running anything, and print
    /// its Markdown table (Pareto column filled).
    TradeoffPlot(TradeoffPlotArgs),
    /// Average the sweeps of several specimens (one `bench tradeoff` directory per packing
    /// seed): specimen-mean F_u, F_res and E against the mean of the references, with the
    /// paired differences' standard errors; writes tradeoff.csv, tradeoff.md and pareto.png
    /// (with pareto.svg).
    TradeoffSpecimens(TradeoffSpecimensArgs),
}

#[derive(clap::Args, Clone)]
pub(crate) struct CommonArgs {
    /// Repetitions of every measurement.
    #[arg(long, default_value_t = 3)]
    repeats: usize,
    /// The `cosdem-worker` binary for the TCP runs (default: next to this executable).
    #[arg(long)]
    worker_bin: Option<PathBuf>,
    /// Skip the TCP runs.
    #[arg(long)]
    no_tcp: bool,
    /// Export the committed states every this many commits (the pool's `export_every`).
    #[arg(long, default_value_t = cosdem_pool::PoolConfig::default().export_every)]
    export_every: u64,
    /// Send every commit as a call of its own instead of carrying it on the next SolveBatch
    /// (the pool's `defer_commits = false`: the protocol-1 behaviour, for comparison).
    #[arg(long)]
    commit_calls: bool,
}

#[derive(clap::Args)]
pub(crate) struct OverheadArgs {
    /// About this many discs per assembly.
    #[arg(long, default_value_t = 400)]
    discs: usize,
    /// Gauss points (assemblies).
    #[arg(long, default_value_t = 4)]
    points: usize,
    /// Iterations (load steps) per run.
    #[arg(long, default_value_t = 10)]
    iterations: u64,
    #[command(flatten)]
    common: CommonArgs,
}

#[derive(clap::Args)]
pub(crate) struct ScalingArgs {
    /// About this many discs per assembly.
    #[arg(long, default_value_t = 400)]
    discs: usize,
    /// Gauss points (assemblies).
    #[arg(long, default_value_t = 64)]
    points: usize,
    /// Iterations (load steps) per run.
    #[arg(long, default_value_t = 2)]
    iterations: u64,
    #[command(flatten)]
    common: CommonArgs,
}

#[derive(clap::Args)]
pub(crate) struct FloorArgs {
    /// Batch sizes (Gauss points per worker per iteration).
    #[arg(long, value_delimiter = ',', default_values_t = [1usize, 4, 16, 64])]
    points: Vec<usize>,
    /// Iterations per run.
    #[arg(long, default_value_t = 200)]
    iterations: u64,
    /// Repetitions.
    #[arg(long, default_value_t = 3)]
    repeats: usize,
}

#[derive(clap::Args)]
pub(crate) struct FeArgs {
    /// Elements per side of the Q8 panel.
    #[arg(long, default_value_t = 10)]
    elements: usize,
    /// About this many discs per DEM assembly.
    #[arg(long, default_value_t = 105)]
    discs: usize,
    /// DEM iterations per measurement.
    #[arg(long, default_value_t = 10)]
    iterations: u64,
    /// Repetitions.
    #[arg(long, default_value_t = 3)]
    repeats: usize,
}

pub(crate) fn workload(
    discs: usize,
    points: usize,
    iterations: u64,
    c: &CommonArgs,
) -> Result<Workload> {
    let worker_bin = if c.no_tcp {
        None
    } else {
        Some(worker_binary(c.worker_bin.as_deref()).map_err(|e| anyhow::anyhow!("{e}"))?)
    };
    Ok(Workload {
        discs,
        points,
        iterations,
        repeats: c.repeats,
        worker_bin,
        export_every: c.export_every,
        defer_commits: !c.commit_calls,
    })
}

pub(crate) fn bench(what: BenchWhat) -> Result<()> {
    let out = &mut std::io::stdout();
    let e = |e: Box<dyn std::error::Error + Send + Sync>| anyhow::anyhow!("{e}");
    match what {
        BenchWhat::Floor(a) => rpc_floor(&a.points, a.iterations, a.repeats, out).map_err(e),
        BenchWhat::Overhead(a) => {
            overhead(&workload(a.discs, a.points, a.iterations, &a.common)?, out).map_err(e)
        }
        BenchWhat::Scaling(a) => {
            scaling(&workload(a.discs, a.points, a.iterations, &a.common)?, out).map_err(e)
        }
        BenchWhat::Fe(a) => {
            fe_versus_dem(a.elements, a.discs, a.iterations, a.repeats, out).map_err(e)
        }
        BenchWhat::Tradeoff(a) => tradeoff(a),
        BenchWhat::TradeoffPlot(a) => tradeoff_plot(a),
        BenchWhat::TradeoffSpecimens(a) => tradeoff_specimens(a),
        BenchWhat::All(c) => {
            overhead(&workload(400, 4, 10, &c)?, out).map_err(e)?;
            scaling(&workload(400, 64, 2, &c)?, out).map_err(e)?;
            fe_versus_dem(10, 105, 10, c.repeats, out).map_err(e)
        }
    }
}

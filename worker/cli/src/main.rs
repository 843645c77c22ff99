//! `cosdem-worker`: the DEM worker binary.
//!
//! ```text
//! cosdem-worker listen [--listen ADDR] [--token-file FILE] [--threads N] [--grace-period SECS]
//! cosdem-worker health [--addr HOST:PORT]
//! cosdem-worker bench dem [--quick]
//! ```
//!
//! Both default to `127.0.0.1:7700`, the port of the docs and the deploy recipes; a worker
//! for other hosts listens on `0.0.0.0:7700` with a token.

use anyhow::Result;
use clap::{Parser, Subcommand};
use cosdem_dem::BoundarySpec;
use cosdem_worker_cli::ListenArgs;

/// The cosdem DEM worker.
#[derive(Parser, Debug)]
#[command(name = "cosdem-worker", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Serve DEM assemblies over gRPC until SIGTERM / Ctrl-C (then drain: new calls refused,
    /// calls in flight finished, exit within --grace-period).
    Listen(ListenArgs),
    /// Exit 0 iff the worker at `--addr` reports SERVING (for container health checks).
    Health {
        /// `host:port` of the worker.
        #[arg(long, default_value = "127.0.0.1:7700")]
        addr: String,
        /// Seconds to wait for the answer.
        #[arg(long, default_value_t = 5)]
        timeout: u64,
    },
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
        /// Only the relaxation yardstick, with the candidates whose names contain one of these
        /// words (comma separated, e.g. `extrapolated,warm`); the default relaxation always
        /// runs first. The kernel's rates are skipped.
        #[arg(long, value_delimiter = ',')]
        candidates: Vec<String>,
    },
}

fn main() -> Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Listen(args) => listen(args),
        Command::Health { addr, timeout } => health(&addr, timeout),
        Command::Bench { what: BenchWhat::Dem { quick, candidates } } => {
            if candidates.is_empty() {
                bench_dem(quick)
            } else {
                bench_relaxation(quick, &candidates)
            }
        }
    }
}

fn bench_dem(quick: bool) -> Result<()> {
    let work: f64 = if quick { 2e6 } else { 4e7 };
    for n in [100usize, 400, 1600, 6400] {
        let steps = (work / n as f64).max(200.0) as u64;
        let r = cosdem_dem::bench::rate(n, steps)?;
        println!("{:>6} discs {:>8} steps {:.3e} particle-steps/s", r.discs, r.steps, r.rate);
    }
    // Where a step's time goes (issue 30): the same workload with the equilibrium ratio at the
    // spec's check_every, timed by stage.
    for n in [100usize, 400, 1600, 6400] {
        let steps = (work / n as f64).max(200.0) as u64;
        let s = cosdem_dem::bench::split(n, steps)?;
        let total: f64 = s.seconds.iter().sum();
        let pct = |k: usize| 100.0 * s.seconds[k] / total;
        println!(
            "{:>6} discs stage split: integration {:.1} %, broad phase {:.1} %, forces {:.1} %, \
             criterion {:.1} % ({:.3e} particle-steps/s with the criterion)",
            s.discs,
            pct(0),
            pct(1),
            pct(2),
            pct(3),
            s.discs as f64 * s.steps as f64 / total
        );
    }
    // The force kernel alone, per pair (issue 30, item 2).
    for n in [1600usize, 6400] {
        let passes = if quick { 20 } else { 1000 };
        let (pairs, lanes) = cosdem_dem::bench::pair_cost(n, passes, false)?;
        let (_, one) = cosdem_dem::bench::pair_cost(n, passes, true)?;
        println!(
            "{pairs:>6} pairs force kernel alone: {:.2} ns per pair four at a time, {:.2} ns one \
             at a time ({:.2}x)",
            lanes * 1e9,
            one * 1e9,
            one / lanes
        );
    }
    // What a switched-off sub-model saves (issue 6, item 3b): the kernel is monomorphized on
    // "has rolling" (k_r > 0 or c_r > 0) and "has dashpots" (any c > 0).
    use cosdem_dem::spec::{ContactParams, NormalModel, RollingModel, TangentialModel};
    let full = ContactParams::default();
    let laws = [
        ("full law (rolling k_r = 25, no dashpots)", full.clone()),
        (
            "rolling k_r = 0 (coulomb model)",
            ContactParams {
                rolling: RollingModel::Coulomb { k_r: 0.0, mu_r: 0.2, c_r: 0.0 },
                ..full.clone()
            },
        ),
        ("rolling none", ContactParams { rolling: RollingModel::None, ..full.clone() }),
        (
            "rolling none, tangential none",
            ContactParams {
                rolling: RollingModel::None,
                tangential: TangentialModel::None,
                ..full.clone()
            },
        ),
        (
            "full law + dashpots (c_n = 10)",
            ContactParams { normal: NormalModel::LinearDashpot { k_n: 6.7e7, c_n: 10.0 }, ..full },
        ),
    ];
    let n = 1600;
    let steps = (work / n as f64).max(200.0) as u64;
    for (name, law) in laws {
        let r = cosdem_dem::bench::rate_with(n, steps, law)?;
        println!("{:>6} discs {name}: {:.3e} particle-steps/s", r.discs, r.rate);
    }
    bench_relaxation(quick, &[])?;
    let (n, steps, conv, wall) = cosdem_dem::bench::relaxation()?;
    println!(
        "relaxation 0.0784 m^2 ({n} discs, e_yy = -1e-3): {steps} steps, converged {conv}, {wall:.3} s"
    );
    for boundary in [BoundarySpec::default(), BoundarySpec::Periodic] {
        let (n, wall) = cosdem_dem::bench::random_build(0.28, boundary.clone())?;
        println!("random packing 0.0784 m^2 ({n} discs, {boundary:?}): built in {wall:.3} s");
    }
    Ok(())
}

/// DEM steps per answer against the assembly's size (issue 30, item 1): the biaxial example's
/// specimen at sides 0.05-0.4 m (about 100-6 700 discs), relaxed by each candidate (all of
/// them, or the default and those whose names contain one of `only`).
fn bench_relaxation(quick: bool, only: &[String]) -> Result<()> {
    let sides: &[f64] = if quick { &[0.05, 0.1] } else { &[0.05, 0.1, 0.2, 0.4] };
    // Issue 30, item 1's candidates on the same specimens and path, each at the default
    // criterion and tolerance; the first is the default relaxation, the yardstick itself.
    let candidates: Vec<_> = cosdem_dem::bench::Candidate::all()
        .into_iter()
        .enumerate()
        .filter(|(i, c)| *i == 0 || only.is_empty() || only.iter().any(|w| c.name.contains(w)))
        .map(|(_, c)| c)
        .collect();
    let mut measured = Vec::with_capacity(candidates.len());
    for c in &candidates {
        measured.push(cosdem_dem::bench::relaxation_scaling_with(sides, c)?);
    }
    let runs = &measured[0];
    for r in runs {
        println!(
            "biaxial load steps to 1 % ({} discs, random 2-3 mm, periodic, 100 kPa): {} \
             relaxations, {} converged, {:.0} steps and {:.2} ms per relaxation",
            r.discs,
            r.count,
            r.converged,
            r.steps as f64 / r.count as f64,
            1e3 * r.seconds / r.count as f64
        );
    }
    println!(
        "relaxation cost ~ N^{:.2}, steps ~ N^{:.2} (least squares over {} sizes)",
        exponent(runs, |r| r.seconds),
        exponent(runs, |r| r.steps as f64),
        runs.len()
    );
    // Each candidate: cost per solve, its exponent, and the times at the smallest and largest
    // size.
    for (c, runs) in candidates.iter().zip(&measured) {
        let per = |r: &cosdem_dem::bench::Relaxation| {
            format!(
                "{} discs {:.0} steps {:.2} ms",
                r.discs,
                r.steps as f64 / r.count as f64,
                1e3 * r.seconds / r.count as f64
            )
        };
        let (first, last) = (&runs[0], &runs[runs.len() - 1]);
        println!(
            "candidate {}: cost ~ N^{:.2}, steps ~ N^{:.2}; per solve {} .. {}; {} of {} solves converged",
            c.name,
            exponent(runs, |r| r.seconds),
            exponent(runs, |r| r.steps as f64),
            per(first),
            per(last),
            runs.iter().map(|r| r.converged).sum::<usize>(),
            runs.iter().map(|r| r.count).sum::<usize>(),
        );
    }
    Ok(())
}

/// The least-squares exponent of `f` against the disc count over `runs`.
fn exponent(
    runs: &[cosdem_dem::bench::Relaxation],
    f: fn(&cosdem_dem::bench::Relaxation) -> f64,
) -> f64 {
    let pts: Vec<(f64, f64)> = runs.iter().map(|r| (r.discs as f64, f(r))).collect();
    cosdem_dem::bench::power_law_exponent(&pts)
}

fn listen(args: ListenArgs) -> Result<()> {
    use cosdem_worker::{Dem, WorkerConfig, bind, serve_listener_with, shutdown_signal};
    use std::io::IsTerminal;
    // The log goes to stderr, which the deploy recipes send to a file (Slurm's job output,
    // `2> worker.log`, a container's log): colour codes only when it is a terminal.
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| "info".into()),
        )
        .with_writer(std::io::stderr)
        .with_ansi(std::io::stderr().is_terminal())
        .init();
    let options = args.serve_options()?;
    let config: WorkerConfig = args.try_into()?;
    let runtime = tokio::runtime::Builder::new_multi_thread().enable_all().build()?;
    // The signal handlers are installed before the port is bound (see `shutdown_signal`).
    let shutdown = {
        let _guard = runtime.enter();
        shutdown_signal()
    };
    let served = runtime.block_on(async {
        let listener = bind(&config).await?;
        serve_listener_with(listener, config, Dem, shutdown, options).await
    });
    // Past the grace period calls may still run: do not wait for them (dropping the runtime
    // would wait for its blocking tasks).
    runtime.shutdown_background();
    served?;
    Ok(())
}

fn health(addr: &str, timeout: u64) -> Result<()> {
    use tonic_health::pb::health_check_response::ServingStatus;
    use tonic_health::pb::{HealthCheckRequest, health_client::HealthClient};
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build()?;
    runtime.block_on(async {
        let uri = format!("http://{addr}");
        let channel = tonic::transport::Endpoint::from_shared(uri)?
            .connect_timeout(std::time::Duration::from_secs(timeout))
            .timeout(std::time::Duration::from_secs(timeout))
            .connect()
            .await?;
        let reply = HealthClient::new(channel)
            .check(HealthCheckRequest { service: String::new() })
            .await?
            .into_inner();
        anyhow::ensure!(
            reply.status == ServingStatus::Serving as i32,
            "worker at {addr} is not serving (status {})",
            reply.status
        );
        Ok(())
    })
}

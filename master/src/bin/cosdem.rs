//! `cosdem`: run a two-scale job file.
//!
//! ```text
//! cosdem run JOB.toml [--workers LIST] [--out DIR] [--token-file FILE]
//! cosdem bench overhead|scaling|fe|all [OPTIONS]
//! cosdem plot RUN_DIR
//! ```
//! `plot` (re)draws the PNG figures of a run directory into `RUN_DIR/plots/`; `run` does it
//! at its end (a figure that fails is a warning, never a failed run).
//! `bench` prints the coupling benchmarks of `cosdem_master::bench` (build with `--release`;
//! the TCP runs start the `cosdem-worker` binary found next to `cosdem`).
//! With no workers given, the DEM assemblies are solved by in-process workers (no servers to
//! start). The run directory is written as the run goes (see `cosdem_master::output::run_dir`).

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use cosdem_common::GaussPointId;
use cosdem_common::micro::{AssemblyRequest, BoundaryKind};
use cosdem_master::bench::{Workload, fe_versus_dem, overhead, scaling, worker_binary};
use cosdem_master::job::{Job, MaterialSection};
use cosdem_master::material::{ElasticCosserat, Material};
use cosdem_master::output::run_dir::{RunSettings, RunWriter};
use cosdem_master::pool::{Pool, PoolConfig};
use cosdem_master::solve::{SolutionView, Solver, StepObserver, StepReport};
use cosdem_worker::service::{Dem, Token};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Parser)]
#[command(name = "cosdem", version, about = "Two-scale FEM x DEM for granular materials")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a job file.
    Run(RunArgs),
    /// Draw the PNG figures of a run directory into RUN_DIR/plots/.
    Plot {
        /// The run directory (holds curve.csv).
        run_dir: PathBuf,
    },
    /// Benchmarks of the coupling (see `cosdem_master::bench`): printed figures.
    Bench {
        #[command(subcommand)]
        what: BenchWhat,
    },
}

#[derive(Subcommand)]
enum BenchWhat {
    /// RPC overhead per Gauss point per iteration: direct vs in-process pool vs loopback TCP.
    Overhead(OverheadArgs),
    /// Step time of a 64-Gauss-point job with 1 and 2 workers of one thread each.
    Scaling(ScalingArgs),
    /// FE cost of one Newton iteration against the DEM cost of the same iteration.
    Fe(FeArgs),
    /// All three with their defaults.
    All(CommonArgs),
}

#[derive(clap::Args, Clone)]
struct CommonArgs {
    /// Repetitions of every measurement.
    #[arg(long, default_value_t = 3)]
    repeats: usize,
    /// The `cosdem-worker` binary for the TCP runs (default: next to this executable).
    #[arg(long)]
    worker_bin: Option<PathBuf>,
    /// Skip the TCP runs.
    #[arg(long)]
    no_tcp: bool,
}

#[derive(clap::Args)]
struct OverheadArgs {
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
struct ScalingArgs {
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
struct FeArgs {
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

fn workload(discs: usize, points: usize, iterations: u64, c: &CommonArgs) -> Result<Workload> {
    let worker_bin = if c.no_tcp {
        None
    } else {
        Some(worker_binary(c.worker_bin.as_deref()).map_err(|e| anyhow::anyhow!("{e}"))?)
    };
    Ok(Workload { discs, points, iterations, repeats: c.repeats, worker_bin })
}

fn bench(what: BenchWhat) -> Result<()> {
    let out = &mut std::io::stdout();
    let e = |e: Box<dyn std::error::Error + Send + Sync>| anyhow::anyhow!("{e}");
    match what {
        BenchWhat::Overhead(a) => {
            overhead(&workload(a.discs, a.points, a.iterations, &a.common)?, out).map_err(e)
        }
        BenchWhat::Scaling(a) => {
            scaling(&workload(a.discs, a.points, a.iterations, &a.common)?, out).map_err(e)
        }
        BenchWhat::Fe(a) => {
            fe_versus_dem(a.elements, a.discs, a.iterations, a.repeats, out).map_err(e)
        }
        BenchWhat::All(c) => {
            overhead(&workload(400, 4, 10, &c)?, out).map_err(e)?;
            scaling(&workload(400, 64, 2, &c)?, out).map_err(e)?;
            fe_versus_dem(10, 105, 10, c.repeats, out).map_err(e)
        }
    }
}

#[derive(clap::Args)]
struct RunArgs {
    /// The job file (TOML).
    job: PathBuf,
    /// Remote workers: `host:port,host:port` or `dns:NAME:PORT`; default: in-process.
    #[arg(long, value_delimiter = ',')]
    workers: Vec<String>,
    /// Run directory (default: the job's `[output] dir`, else `runs/<job stem>`).
    #[arg(long)]
    out: Option<PathBuf>,
    /// File holding the shared token for remote workers (else env COSDEM_TOKEN).
    #[arg(long)]
    token_file: Option<PathBuf>,
    /// No progress bar (logs only).
    #[arg(long)]
    quiet: bool,
}

/// Forwards every step to the run writer and moves the progress bar.
struct Progress<'a> {
    writer: &'a mut RunWriter,
    bar: ProgressBar,
    started: Instant,
}

impl StepObserver for Progress<'_> {
    fn on_step(&mut self, r: &StepReport, s: &SolutionView<'_>) -> cosdem_master::Result<()> {
        self.writer.on_step(r, s)?;
        let sum = self.writer.summary();
        let secs = self.started.elapsed().as_secs_f64().max(1e-9);
        let discs_per_s = sum.dem_steps as f64 / secs;
        self.bar.set_position((r.load_factor * 1000.0).round() as u64);
        self.bar.set_message(format!(
            "step {} d={:.4e} m load={:.4e} N it={} DEM {:.2e} relax-steps/s",
            r.step,
            sum.displacement,
            self.writer.curve().last().map_or(0.0, |p| p.1),
            r.iterations,
            discs_per_s
        ));
        tracing::info!(
            step = r.step,
            load_factor = r.load_factor,
            displacement = sum.displacement,
            iterations = r.iterations,
            cuts = r.cuts,
            "converged"
        );
        Ok(())
    }
}

fn run_dir(args: &RunArgs, job: &Job) -> PathBuf {
    if let Some(d) = &args.out {
        return d.clone();
    }
    if let Some(d) = &job.output.dir {
        return d.clone();
    }
    let stem = args.job.file_stem().map_or("run".into(), |s| s.to_string_lossy().into_owned());
    Path::new("runs").join(stem)
}

fn init_logging(dir: &Path) -> Result<()> {
    let file = std::fs::File::create(dir.join("cosdem.log"))
        .with_context(|| format!("creating {}", dir.join("cosdem.log").display()))?;
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| "info".into()),
        )
        .with_writer(std::sync::Mutex::new(file))
        .with_ansi(false)
        .init();
    Ok(())
}

/// The DEM pool: remote workers when addresses are given (CLI first, then the job), else
/// in-process workers (no servers to start).
fn dem_pool(
    job: &Job,
    args: &RunArgs,
    spec: &cosdem_worker::AssemblySpec,
    ids: &[GaussPointId],
) -> Result<Pool> {
    let token = Token::load(args.token_file.as_deref())?;
    let config = PoolConfig { token, ..PoolConfig::default() };
    let addresses: Vec<String> =
        if args.workers.is_empty() { job.workers.addresses.clone() } else { args.workers.clone() };
    // `dns:NAME:PORT` (a headless service) is the same as `NAME:PORT`: every address the name
    // resolves to becomes a worker.
    let addresses: Vec<String> =
        addresses.iter().map(|a| a.strip_prefix("dns:").unwrap_or(a).to_string()).collect();
    let mut pool = if addresses.is_empty() {
        let n = job.workers.in_process.max(1);
        Pool::in_process(n, config, |_| Dem)?
    } else {
        Pool::connect(&addresses, config)?
    };
    let request = AssemblyRequest {
        spec_json: serde_json::to_vec(spec)?,
        boundary: BoundaryKind::Unspecified,
        disc_count_hint: 0,
    };
    pool.create_assemblies(ids, &request)?;
    Ok(pool)
}

fn material(job: &Job, args: &RunArgs, ids: &[GaussPointId]) -> Result<(Box<dyn Material>, usize)> {
    match &job.material {
        MaterialSection::Elastic { shear_modulus, poisson, cosserat_modulus, length } => {
            let g = *shear_modulus;
            let m = ElasticCosserat::new(
                g,
                *poisson,
                cosserat_modulus.unwrap_or(0.5 * g),
                length.unwrap_or(0.01),
            );
            Ok((Box::new(m), 0))
        }
        MaterialSection::Dem { assembly } => {
            let pool = dem_pool(job, args, assembly, ids)?;
            let n = pool.live_workers();
            Ok((Box::new(pool), n))
        }
    }
}

fn run(args: RunArgs) -> Result<()> {
    let job = Job::load(&args.job)?;
    let dir = run_dir(&args, &job);
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    init_logging(&dir)?;
    let internal_length = match &job.material {
        MaterialSection::Elastic { length, .. } => length.unwrap_or(0.01),
        MaterialSection::Dem { .. } => 0.01,
    };
    let settings = RunSettings {
        title: job.title.clone(),
        shortening: job.shortening(),
        load_set: job.loading.load_set.clone(),
        vtk_every: job.output.vtk_every,
        internal_length,
        linear_range: 0.01,
    };
    let mut writer = RunWriter::create(&dir, settings)?;
    let mut solver = Solver::new(job.model()?, job.solver_settings()?)?;
    let per_element = solver.gauss().per_element as u32;
    let ids: Vec<GaussPointId> = (0..solver.model().mesh.n_elements() as u32)
        .flat_map(|e| (0..per_element).map(move |p| GaussPointId::new(e, p)))
        .collect();
    let snapshots = cosdem_master::output::snapshots::resolve_snapshot_ids(
        &job.output.snapshots,
        solver.model().mesh.n_elements(),
        per_element as usize,
    )?;
    let (mut material, workers) = material(&job, &args, &ids)?;
    let mut material = writer.watch(material.as_mut(), snapshots, &job.output.field_plots_at);
    writer.set_workers(workers);
    let bar = if args.quiet { ProgressBar::hidden() } else { ProgressBar::new(1000) };
    bar.set_style(
        ProgressStyle::with_template("[{elapsed_precise}] {bar:30} {percent:>3}% ETA {eta} {msg}")
            .expect("static template"),
    );
    let span = tracing::info_span!("run", job = %args.job.display());
    let _enter = span.enter();
    let outcome = {
        let mut progress =
            Progress { writer: &mut writer, bar: bar.clone(), started: Instant::now() };
        solver.run(&mut material, &mut progress)
    };
    bar.finish_and_clear();
    writer.finish(outcome.as_ref().map(|_| ()).map_err(|e| e.to_string()))?;
    let s = writer.summary();
    let m = &s.metrics;
    println!(
        "{} steps, d = {:.4e} m, F_u = {:.4e} N at {:.4e} m, F_res = {}, E = {}, E50 = {}, {:.1} s -> {}",
        s.steps,
        s.displacement,
        m.peak_load,
        m.peak_displacement,
        m.residual_load.map_or("-".into(), |v| format!("{v:.4e} N")),
        m.stiffness.map_or("-".into(), |v| format!("{v:.4e} N/m")),
        m.stiffness_50.map_or("-".into(), |v| format!("{v:.4e} N/m")),
        s.wall_seconds,
        dir.display()
    );
    if let Err(e) = plot(&dir) {
        eprintln!("warning: plots: {e:#}");
        tracing::warn!(error = %format!("{e:#}"), "plots not written");
    }
    outcome.with_context(|| format!("run stopped; finished steps are in {}", dir.display()))?;
    Ok(())
}

/// Draws the figures of a run directory; an error if any figure failed (after trying all).
fn plot(dir: &Path) -> Result<()> {
    let report = cosdem_master::output::plot::plot_run(dir)?;
    println!("{} plots in {}", report.written.len(), dir.join("plots").display());
    for (what, e) in &report.failed {
        eprintln!("plot failed: {what}: {e}");
    }
    anyhow::ensure!(report.failed.is_empty(), "{} plot(s) failed", report.failed.len());
    Ok(())
}

fn main() -> Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Run(args) => run(args),
        Command::Plot { run_dir } => plot(&run_dir),
        Command::Bench { what } => bench(what),
    }
}

//! `cosdem`: run a two-scale job file.
//!
//! ```text
//! cosdem run JOB.toml [--workers LIST] [--out DIR] [--token-file FILE] [--resume]
//! cosdem rve JOB.toml --path biaxial|isotropic|simple-shear|FILE [--steps N] [--increment X]
//!     [--pressure P] [--out DIR]
//! cosdem study rve-size JOB.toml --sizes V1,V2,... [--radius R] [--out DIR]
//! cosdem bench overhead|scaling|fe|all [OPTIONS]
//! cosdem bench tradeoff JOB.toml [--displacement D] [--out DIR]
//! cosdem bench tradeoff-plot DIR/tradeoff.csv [--out PNG] [--title T]
//! cosdem bench tradeoff-specimens SWEEP_DIR SWEEP_DIR... [--out DIR] [--title T]
//! cosdem plot RUN_DIR
//! ```
//! `run` checkpoints into `RUN/checkpoint.bin` (every `[output] checkpoint_every` steps);
//! Ctrl-C or SIGTERM stops after the current step (checkpoint written, status `interrupted`,
//! exit code 1; a second one quits at once with 130) and `--resume` continues from the
//! checkpoint.
//! `plot` (re)draws the PNG figures of a run directory into `RUN_DIR/plots/`; `run` does it
//! at its end (a figure that fails is a warning, never a failed run).
//! `bench` prints the coupling benchmarks of `cosdem_study::bench` (build with `--release`;
//! the TCP runs start the `cosdem-worker` binary found next to `cosdem`).
//! With no workers given, the DEM assemblies are solved by in-process workers (no servers to
//! start). The run directory is written as the run goes (see `cosdem_app::output::run_dir`).

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use cosdem_app::checkpoint::{self, Checkpoint, Checkpointer};
use cosdem_app::output::run_dir::RunWriter;
use cosdem_app::run::{WorkerChoice, gauss_point_ids, material_for, run_settings};
use cosdem_fem::solve::{SolutionView, Solver, StepObserver, StepReport};
use cosdem_job::{Job, MaterialSection};
use cosdem_pool::PoolConfig;
use cosdem_study::bench::{Workload, fe_versus_dem, overhead, rpc_floor, scaling, worker_binary};
use cosdem_worker::Token;
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
    /// One DEM assembly of the job driven through a laboratory path (calibration).
    Rve(RveArgs),
    /// Parameter studies over whole runs.
    Study {
        #[command(subcommand)]
        what: StudyWhat,
    },
    /// Draw the PNG figures of a run directory (or of an RVE-size study directory) into
    /// RUN_DIR/plots/.
    Plot {
        /// The run directory (holds curve.csv), or a study directory (holds study.json).
        run_dir: PathBuf,
    },
    /// Benchmarks of the coupling (see `cosdem_study::bench`): printed figures.
    Bench {
        #[command(subcommand)]
        what: BenchWhat,
    },
}

#[derive(Subcommand)]
enum BenchWhat {
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
    /// paired differences' standard errors; writes tradeoff.csv, tradeoff.md and pareto.png.
    TradeoffSpecimens(TradeoffSpecimensArgs),
}

#[derive(clap::Args)]
struct TradeoffSpecimensArgs {
    /// The sweep directories (each holds tradeoff.csv and runs/), at least two.
    #[arg(required = true, num_args = 2..)]
    sweeps: Vec<PathBuf>,
    /// Output directory.
    #[arg(long, default_value = "runs/tradeoff-specimens")]
    out: PathBuf,
    /// The table's title.
    #[arg(long, default_value = "Speed against accuracy averaged over specimens")]
    title: String,
}

fn tradeoff_specimens(a: TradeoffSpecimensArgs) -> Result<()> {
    use cosdem_study::specimens::{average, markdown, read_sweep};
    use cosdem_study::tradeoff::{PARETO_FILE, csv, write_pareto};
    let specimens = a.sweeps.iter().map(|d| read_sweep(d)).collect::<Result<Vec<_>, _>>()?;
    let averaged = average(&specimens)?;
    std::fs::create_dir_all(&a.out).with_context(|| format!("creating {}", a.out.display()))?;
    let write = |name: &str, text: String| {
        let path = a.out.join(name);
        cosdem_app::output::write_atomic(&path, text.as_bytes())
            .with_context(|| format!("writing {}", path.display()))
    };
    write("tradeoff.csv", csv(&averaged.rows))?;
    let md = markdown(&a.title, &averaged);
    write("tradeoff.md", md.clone())?;
    let png = a.out.join(PARETO_FILE);
    if let Err(e) = write_pareto(&averaged.rows, &a.title, &png) {
        eprintln!("warning: Pareto plot: {e}");
    }
    print!("{md}");
    eprintln!("{} rows -> {}", averaged.rows.len(), a.out.display());
    Ok(())
}

#[derive(clap::Args)]
struct TradeoffPlotArgs {
    /// The sweep's CSV (written by `cosdem bench tradeoff`).
    csv: PathBuf,
    /// The PNG to write (default: pareto.png beside the CSV).
    #[arg(long)]
    out: Option<PathBuf>,
    /// The figure's title (default: "Speed against accuracy: <CSV>").
    #[arg(long)]
    title: Option<String>,
}

fn tradeoff_plot(a: TradeoffPlotArgs) -> Result<()> {
    use cosdem_study::tradeoff::{PARETO_FILE, markdown, read_csv, write_pareto};
    let text =
        std::fs::read_to_string(&a.csv).with_context(|| format!("reading {}", a.csv.display()))?;
    let rows = read_csv(&text, &a.csv.display().to_string())?;
    let out = a.out.unwrap_or_else(|| a.csv.with_file_name(PARETO_FILE));
    let title = a.title.unwrap_or_else(|| format!("Speed against accuracy: {}", a.csv.display()));
    write_pareto(&rows, &title, &out)?;
    print!("{}", markdown(&title, &rows));
    eprintln!("{} rows -> {}", rows.len(), out.display());
    Ok(())
}

#[derive(clap::Args)]
struct TradeoffArgs {
    /// The job whose scene is swept (a DEM job).
    job: PathBuf,
    /// Output directory (default: runs/tradeoff-<job stem>).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Stop every run at this displacement (m) instead of the job's (a shorter sweep).
    #[arg(long)]
    displacement: Option<f64>,
    /// Leave out these variants: a knob (`relaxation.driver`) or a knob=setting
    /// (`relaxation.driver=fire`), comma-separated (e.g. a setting known to stall the scene).
    #[arg(long, value_delimiter = ',')]
    skip: Vec<String>,
    /// Go on with an earlier sweep into the same --out: a setting whose run directory holds a
    /// run of the same job that ended (finished or failed) is read back, with the wall time
    /// it took then, instead of run again. Interrupted runs and runs of another job are run
    /// again. The run directories must come from the same cosdem build.
    #[arg(long)]
    resume: bool,
}

fn tradeoff(a: TradeoffArgs) -> Result<()> {
    let mut job = Job::load(&a.job)?;
    if let (Some(d), Some(c)) = (a.displacement, job.loading.compression.as_mut()) {
        anyhow::ensure!(d > 0.0 && d.is_finite(), "--displacement must be > 0, got {d}");
        c.displacement = d;
    }
    let stem = a.job.file_stem().map_or("job".into(), |s| s.to_string_lossy().into_owned());
    let out = a.out.unwrap_or_else(|| Path::new("runs").join(format!("tradeoff-{stem}")));
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    let title = format!("Speed against accuracy: {} ({})", job.title, a.job.display());
    println!(
        "{:<26} {:<14} {:>9} {:>8} {:>8} {:>8} {:>8} {:>8}",
        "knob", "setting", "wall s", "speedup", "F_u", "F_res", "E", "curve"
    );
    let pct = |e: Option<f64>| e.map_or("-".into(), |e| format!("{:.2}%", 100.0 * e));
    let workers = WorkerChoice::default();
    let rows =
        cosdem_study::tradeoff::sweep(&job, &title, &out, &workers, &a.skip, a.resume, |r| {
            println!(
                "{:<26} {:<14} {:>9.1} {:>7.2}x {:>8} {:>8} {:>8} {:>8} {}",
                r.knob,
                r.setting,
                r.wall_seconds,
                r.speedup,
                pct(r.errors.peak),
                pct(r.errors.residual),
                pct(r.errors.stiffness),
                pct(r.errors.curve),
                if r.status == "finished" { String::new() } else { r.status.clone() }
            );
        })?;
    println!("{} settings -> {}", rows.len(), out.join("tradeoff.md").display());
    // The sweep redraws the plot after every row and only logs a failure: say it here.
    let png = out.join(cosdem_study::tradeoff::PARETO_FILE);
    match cosdem_study::tradeoff::write_pareto(&rows, &title, &png) {
        Ok(()) => println!("Pareto plot -> {}", png.display()),
        Err(e) => eprintln!("warning: Pareto plot: {e}"),
    }
    Ok(())
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
    /// Export the committed states every this many commits (the pool's `export_every`).
    #[arg(long, default_value_t = cosdem_pool::PoolConfig::default().export_every)]
    export_every: u64,
    /// Send every commit as a call of its own instead of carrying it on the next SolveBatch
    /// (the pool's `defer_commits = false`: the protocol-1 behaviour, for comparison).
    #[arg(long)]
    commit_calls: bool,
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
struct FloorArgs {
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

fn bench(what: BenchWhat) -> Result<()> {
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
    /// Continue from the run directory's checkpoint.bin.
    #[arg(long)]
    resume: bool,
    /// With --resume: the job's [newton] settings may differ from the checkpoint's (the steps
    /// to come are solved with the job's; e.g. more iterations for a run that stalled).
    #[arg(long, requires = "resume")]
    newton_changed: bool,
    /// Stop cleanly after this many committed steps (counted from the start of the run,
    /// resumed steps included): checkpoint written, status `stopped`, exit code 0; go on later
    /// with `--resume`.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    max_steps: Option<u64>,
}

#[derive(Subcommand)]
enum StudyWhat {
    /// Scene A once per assembly size V; fit of Eqs. 30-32 (study.csv, study.json).
    RveSize(RveSizeArgs),
}

#[derive(clap::Args)]
struct RveSizeArgs {
    /// The job file (TOML) with `[material] kind = "dem"`.
    job: PathBuf,
    /// Assembly sizes V (m^2): the packing side becomes sqrt(V).
    #[arg(long, value_delimiter = ',', required = true)]
    sizes: Vec<f64>,
    /// Disc radius (m) replacing the job's (hexagonal packings).
    #[arg(long)]
    radius: Option<f64>,
    /// V^cr is where a property comes within this fraction of its representative value.
    #[arg(long, default_value_t = 0.01)]
    tolerance: f64,
    /// Runs side by side (0 = one per core); each run is single-threaded.
    #[arg(long, default_value_t = 0)]
    threads: usize,
    /// Output directory (default `runs/<job stem>-rve-size`).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Reuse the curves already in `OUT/curves/` (a study continued or assembled from runs
    /// made elsewhere): a size whose curve file exists is read, not run again.
    #[arg(long)]
    reuse: bool,
}

#[derive(clap::Args)]
struct RveArgs {
    /// The job file (TOML) with `[material] kind = "dem"`.
    job: PathBuf,
    /// `biaxial`, `isotropic`, `simple-shear`, or a CSV file of prescribed F, w, kappa.
    #[arg(long)]
    path: String,
    /// Load steps after the initial state (tables: one per row).
    #[arg(long, default_value_t = 100)]
    steps: usize,
    /// Strain (or shear) increment per step.
    #[arg(long, default_value_t = 1e-3)]
    increment: f64,
    /// Confining pressure (biaxial) or vertical stress (simple shear), Pa, compression
    /// positive. Default: the job's largest `[[loading.pressure]]`, else the random packing's
    /// confining stress, else 100 kPa (biaxial) / none (simple shear).
    #[arg(long)]
    pressure: Option<f64>,
    /// Stress-control tolerance, relative to the pressure.
    #[arg(long, default_value_t = 1e-3)]
    tolerance: f64,
    /// Output directory (default `runs/<job stem>-rve-<path>`).
    #[arg(long)]
    out: Option<PathBuf>,
}

fn stem(job: &Path) -> String {
    job.file_stem().map_or("run".into(), |s| s.to_string_lossy().into_owned())
}

fn rve(args: RveArgs) -> Result<()> {
    use cosdem_app::rve::{RvePath, RveSettings, drive, report, table};
    let job = Job::load(&args.job)?;
    let MaterialSection::Dem { assembly } = &job.material else {
        anyhow::bail!("{}: `cosdem rve` needs [material] kind = \"dem\"", args.job.display());
    };
    let path = match args.path.as_str() {
        "biaxial" => RvePath::Biaxial,
        "isotropic" => RvePath::Isotropic,
        "simple-shear" => RvePath::SimpleShear,
        file => RvePath::Table(table::read(Path::new(file))?),
    };
    let from_job = job.loading.pressure.iter().map(|p| p.value).fold(0.0, f64::max);
    let from_packing = match &assembly.packing {
        cosdem_dem::PackingSpec::Random { confining_stress, .. } => *confining_stress,
        _ => 0.0,
    };
    let pressure = args.pressure.unwrap_or(match (&path, from_job, from_packing) {
        (_, p, _) if p > 0.0 => p,
        (_, _, p) if p > 0.0 => p,
        (RvePath::Biaxial, _, _) => 1e5,
        _ => 0.0,
    });
    let settings = RveSettings {
        path,
        steps: args.steps,
        increment: args.increment,
        pressure,
        tolerance: args.tolerance,
        ..RveSettings::default()
    };
    settings.validate()?;
    let dir = args.out.clone().unwrap_or_else(|| {
        Path::new("runs").join(format!("{}-rve-{}", stem(&args.job), settings.path.name()))
    });
    let t0 = Instant::now();
    let mut a = cosdem_dem::Assembly::new(assembly)?;
    let summary = report::RveSummary {
        path: settings.path.name().into(),
        discs: a.disc_count(),
        area: a.area(),
        ..Default::default()
    };
    let mut writer = report::RveWriter::create(&dir, summary, settings.tolerance)?;
    println!(
        "{} test: {} discs, V = {:.4e} m^2, p = {:.4e} Pa, {} steps of {:.1e} -> {}",
        settings.path.name(),
        a.disc_count(),
        a.area(),
        settings.pressure,
        settings.steps,
        settings.increment,
        dir.display()
    );
    let outcome = drive(&mut a, &settings, &mut |r| {
        writer.write(r).map_err(|e| cosdem_fem::Error::Observer(e.to_string()))
    });
    writer.finish(t0.elapsed().as_secs_f64())?;
    let s = writer.summary();
    println!(
        "peak friction angle {:.2} deg at step {} (strain {:.4e}, q = {:.4e} Pa), dilatancy at peak {:.2} deg, max {:.2} deg; final friction angle {:.2} deg, volumetric strain {:.4e}; {} DEM steps, {:.1} s",
        s.peak_friction_angle,
        s.peak_step,
        s.peak_strain,
        s.peak_deviatoric_stress,
        s.dilatancy_at_peak,
        s.max_dilatancy_angle,
        s.final_friction_angle,
        s.final_volumetric_strain,
        s.dem_steps,
        s.wall_seconds
    );
    if s.uncontrolled_steps > 0 {
        println!(
            "warning: {} step(s) missed the stress-control tolerance (column control_residual)",
            s.uncontrolled_steps
        );
    }
    outcome.with_context(|| format!("test stopped; finished steps are in {}", dir.display()))?;
    Ok(())
}

fn study(what: StudyWhat) -> Result<()> {
    use cosdem_study::rve_size::{FitOutcome, RveSizeSettings, rve_size};
    let StudyWhat::RveSize(a) = what;
    let job = Job::load(&a.job)?;
    let dir = a
        .out
        .clone()
        .unwrap_or_else(|| Path::new("runs").join(format!("{}-rve-size", stem(&a.job))));
    let settings = RveSizeSettings {
        sizes: a.sizes.clone(),
        radius: a.radius,
        tolerance: a.tolerance,
        threads: a.threads,
        reuse: a.reuse,
    };
    println!("RVE-size study: {} sizes -> {}", settings.sizes.len(), dir.display());
    let study = rve_size(&job, &settings, &dir)?;
    let opt = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.4e}"));
    println!(
        "{:>10} {:>6} {:>6} {:>11} {:>11} {:>11} {:>11} {:>8}  status",
        "V (m^2)", "discs", "steps", "F_u (N)", "F_res (N)", "E (N/m)", "E50 (N/m)", "wall (s)"
    );
    for r in &study.runs {
        let m = &r.metrics;
        println!(
            "{:>10.4e} {:>6} {:>6} {:>11.4e} {:>11} {:>11} {:>11} {:>8.1}  {}",
            r.size,
            r.discs,
            r.steps,
            m.peak_load,
            opt(m.residual_load),
            opt(m.stiffness),
            opt(m.stiffness_50),
            r.wall_seconds,
            r.status
        );
    }
    let ci = |e: &cosdem_study::rve_size::fit::Estimate| match (e.low, e.high) {
        (Some(l), Some(h)) => format!("{:.4e} [{l:.4e}, {h:.4e}]", e.value),
        _ => format!("{:.4e}", e.value),
    };
    for (name, fit) in [
        ("F_u (Eq. 30)", &study.peak_load),
        ("F_res (Eq. 31)", &study.residual_load),
        ("E (Eq. 32)", &study.stiffness),
        ("E50 (Eq. 32)", &study.stiffness_50),
    ] {
        match fit {
            FitOutcome::Fitted(f) => println!(
                "{name}: a = {}, b* = {}, representative = {}, V^cr = {} m^2",
                ci(&f.a),
                ci(&f.b_star),
                ci(&f.representative),
                f.v_cr.as_ref().map_or("undefined (no plateau)".into(), ci)
            ),
            FitOutcome::Failed { error } => println!("{name}: no fit: {error}"),
        }
    }
    Ok(())
}

/// Forwards every step to the run writer and moves the progress bar.
struct Progress<'a> {
    writer: &'a mut RunWriter,
    bar: ProgressBar,
    started: Instant,
}

impl StepObserver for Progress<'_> {
    fn on_step(&mut self, r: &StepReport, s: &SolutionView<'_>) -> cosdem_fem::Result<()> {
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

fn init_logging(dir: &Path, append: bool) -> Result<()> {
    let file = std::fs::OpenOptions::new()
        .create(true)
        .write(true)
        .append(append)
        .truncate(!append)
        .open(dir.join("cosdem.log"))
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

/// Where the DEM assemblies are solved: the CLI's `--workers` first, then the job's.
fn worker_choice(job: &Job, args: &RunArgs) -> Result<WorkerChoice> {
    let token = Token::load(args.token_file.as_deref())?;
    let addresses =
        if args.workers.is_empty() { job.workers.addresses.clone() } else { args.workers.clone() };
    Ok(WorkerChoice { addresses, config: PoolConfig { token, ..PoolConfig::default() } })
}

fn run(args: RunArgs) -> Result<()> {
    let job = Job::load(&args.job)?;
    let dir = run_dir(&args, &job);
    // `accuracy`: the settings picked for the target replace the job's (a pure function of
    // the job, so a resume picks the same ones).
    let (job, accuracy) = cosdem_app::run::tuned(&job)?;
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    init_logging(&dir, args.resume)?;
    if let Some(report) = &accuracy {
        cosdem_app::run::write_accuracy_report(report, &dir)?;
        for line in report.lines() {
            eprintln!("{line}");
            tracing::info!("{line}");
        }
    }
    let checkpoint = if args.resume {
        let path = dir.join(checkpoint::FILE);
        let c = Checkpoint::read(&path)?;
        c.check_job(&job, &path, args.newton_changed)?;
        tracing::info!(step = c.solver.step, "resuming from {}", path.display());
        Some(c)
    } else {
        None
    };
    let mut writer = match &checkpoint {
        Some(c) => RunWriter::resume(&dir, run_settings(&job), c.solver.step)?,
        None => RunWriter::create(&dir, run_settings(&job))?,
    };
    let mut solver = Solver::new(job.model()?, job.solver_settings()?)?;
    let ids = gauss_point_ids(&solver);
    let snapshots = cosdem_app::output::snapshots::resolve_snapshot_ids(
        &job.output.snapshots,
        solver.model().mesh.n_elements(),
        solver.gauss().per_element,
    )?;
    let saved = checkpoint.as_ref().map(Checkpoint::assembly_states);
    let (mut material, workers) = material_for(&job, &worker_choice(&job, &args)?, &ids, saved)?;
    if let Some(c) = checkpoint {
        solver.restore(c.solver)?;
    }
    let stop = checkpoint::ctrl_c_flag().context("installing the Ctrl-C handler")?;
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
        let progress = Progress { writer: &mut writer, bar: bar.clone(), started: Instant::now() };
        let every = job.output.checkpoint_every;
        let mut observer =
            Checkpointer::new(progress, &dir, every, &job, stop).stop_at(args.max_steps);
        let outcome = solver.run(&mut material, &mut observer);
        (outcome, observer.reached(solver.step()))
    };
    let (outcome, reached_max) = outcome;
    bar.finish_and_clear();
    writer.add_uncommitted_dem_steps(solver.uncommitted_dem_steps());
    let stopped = matches!(outcome, Err(cosdem_fem::Error::Interrupted { .. }));
    let interrupted = stopped && !reached_max;
    if stopped && reached_max {
        writer.finish_stopped()?;
    } else if interrupted {
        writer.finish_interrupted()?;
    } else {
        writer.finish(outcome.as_ref().map(|_| ()).map_err(|e| e.to_string()))?;
    }
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
    if s.skipped_relaxations + s.linear_answers > 0 {
        println!(
            "answers without relaxation: {} skipped, {} linear (largest stress-error bound {:.3e} Pa)",
            s.skipped_relaxations, s.linear_answers, s.max_error_bound
        );
    }
    if interrupted {
        anyhow::bail!(
            "interrupted after step {}: finished steps and the checkpoint are in {}; continue with `cosdem run {} --resume`",
            s.steps,
            dir.display(),
            args.job.display()
        );
    }
    if stopped {
        println!(
            "stopped after step {} (--max-steps); continue with `cosdem run {} --resume`",
            s.steps,
            args.job.display()
        );
        return Ok(());
    }
    outcome.with_context(|| format!("run stopped; finished steps are in {}", dir.display()))?;
    Ok(())
}

/// Draws the figures of a run directory; an error if any figure failed (after trying all).
fn plot(dir: &Path) -> Result<()> {
    if dir.join("study.json").is_file() && !dir.join("curve.csv").is_file() {
        // An RVE-size study directory (`cosdem study rve-size`).
        let study = cosdem_study::rve_size::read_study(dir)?;
        let title = dir.file_name().map_or(String::new(), |n| n.to_string_lossy().into_owned());
        let failed = cosdem_study::rve_size::plot_study(&study, dir, &title);
        for (what, e) in &failed {
            eprintln!("plot failed: {what}: {e}");
        }
        println!("study plots in {}", dir.join("plots").display());
        return Ok(());
    }
    let report = cosdem_app::output::plot::plot_run(dir)?;
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
        Command::Rve(args) => rve(args),
        Command::Study { what } => study(what),
        Command::Plot { run_dir } => plot(&run_dir),
        Command::Bench { what } => bench(what),
    }
}

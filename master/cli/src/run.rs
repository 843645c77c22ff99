//! `cosdem run`: a job file run through the run driver ([`cosdem_app::run::Run`]) with a
//! progress bar, the log in `RUN/cosdem.log`, checkpoints, Ctrl-C/SIGTERM handling,
//! `--resume` and `--max-steps`; prints the summary and draws the figures.

use crate::logging::LogFile;
use crate::plot::plot;
use anyhow::{Context, Result};
use cosdem_app::output::run_dir::RunWriter;
use cosdem_app::run::{
    Ending, HookError, PROGRESS_TEMPLATE, Run, RunObserver, WorkerChoice, step_message,
};
use cosdem_fem::solve::{SolutionView, StepReport};
use cosdem_job::Job;
use cosdem_pool::PoolConfig;
use cosdem_worker::Token;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

#[derive(clap::Args)]
pub(crate) struct RunArgs {
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
    #[arg(long, conflicts_with = "overwrite")]
    resume: bool,
    /// Start again in a run directory that holds a previous run: once the setup has
    /// succeeded, the old directory is renamed RUN.old-N (without this, such a directory is
    /// refused).
    #[arg(long)]
    overwrite: bool,
    /// With --resume: the job's [newton] settings may differ from the checkpoint's (the steps
    /// to come are solved with the job's; e.g. more iterations for a run that stalled).
    #[arg(long, requires = "resume")]
    newton_changed: bool,
    /// Stop cleanly after this many committed steps (counted from the start of the run,
    /// resumed steps included): checkpoint written, status `stopped`, exit code 0; go on later
    /// with `--resume`.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    max_steps: Option<u64>,
    /// Refuse the job before it starts when its estimated memory in this process exceeds
    /// this (e.g. `16GiB`, `512MiB`, `2e9`; `none`: no check). Default: 80 % of the machine's.
    #[arg(long, value_parser = parse_memory)]
    max_memory: Option<u64>,
    /// Deadline (s) of a worker's CreateAssemblies at the setup; default: scaled with the
    /// discs to build (see docs/guide/workers.md).
    #[arg(long, value_parser = parse_seconds)]
    create_timeout: Option<f64>,
}

/// A positive, finite number of seconds (at most a year).
fn parse_seconds(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(s) if s > 0.0 && s <= 3.2e7 => Ok(s),
        _ => Err(format!("{text:?}: seconds must be a number in (0, 3.2e7]")),
    }
}

/// A memory size: bytes, or a number with `K`, `M`, `G`, `T` (powers of 1024, with or
/// without `iB`/`B`); `none` for no limit.
fn parse_memory(text: &str) -> Result<u64, String> {
    let t = text.trim();
    if t.eq_ignore_ascii_case("none") {
        return Ok(u64::MAX);
    }
    let split =
        t.find(|c: char| c.is_ascii_alphabetic() && c != 'e' && c != 'E').unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let scale: f64 =
        match unit.trim().to_ascii_uppercase().trim_end_matches("IB").trim_end_matches('B') {
            "" => 1.0,
            "K" => 1024.0,
            "M" => 1024.0f64.powi(2),
            "G" => 1024.0f64.powi(3),
            "T" => 1024.0f64.powi(4),
            _ => {
                return Err(format!(
                    "{text:?}: the unit is not one of K, M, G, T (or KiB, MiB, GiB, TiB)"
                ));
            }
        };
    let value: f64 =
        number.trim().parse().map_err(|_| format!("{text:?} is not a size such as 16GiB"))?;
    let bytes = value * scale;
    if !(bytes.is_finite() && bytes >= 1.0) {
        return Err(format!("{text:?}: a memory limit is at least one byte"));
    }
    Ok(bytes.min(u64::MAX as f64) as u64)
}

/// Opens the log in the run directory, prints the accuracy plan, moves the progress bar and
/// logs every step.
struct Progress {
    /// The log, held in memory until the run directory is the run's.
    log: LogFile,
    /// `cosdem run --resume`: the log is appended to.
    resume: bool,
    quiet: bool,
    /// The job file, named by the log's `run` span.
    job: PathBuf,
    bar: ProgressBar,
    started: Instant,
    /// The `run` span, entered from the first step to the end of the command.
    span: Option<tracing::span::EnteredSpan>,
}

impl RunObserver for Progress {
    fn on_dir(&mut self, dir: &Path) -> Result<(), HookError> {
        Ok(self.log.open(dir, self.resume)?)
    }

    fn on_plan_line(&mut self, line: &str) {
        eprintln!("{line}");
    }

    fn on_start(&mut self) -> Result<(), HookError> {
        let bar = if self.quiet { ProgressBar::hidden() } else { ProgressBar::new(1000) };
        bar.set_style(ProgressStyle::with_template(PROGRESS_TEMPLATE).expect("static template"));
        self.bar = bar;
        self.span = Some(tracing::info_span!("run", job = %self.job.display()).entered());
        self.started = Instant::now();
        Ok(())
    }

    fn on_step(
        &mut self,
        r: &StepReport,
        _: &SolutionView<'_>,
        record: Option<&RunWriter>,
    ) -> cosdem_fem::Result<()> {
        let Some(writer) = record else { return Ok(()) };
        self.bar.set_position((r.load_factor * 1000.0).round() as u64);
        self.bar.set_message(step_message(r, writer, self.started.elapsed().as_secs_f64()));
        let sum = writer.summary();
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

    fn on_end(&mut self) {
        self.bar.finish_and_clear();
    }
}

/// The command that goes on with this run: the same job, `--out` and workers, `--resume`.
fn resume_command(args: &RunArgs) -> String {
    let mut c = format!("cosdem run {}", args.job.display());
    if let Some(out) = &args.out {
        c.push_str(&format!(" --out {}", out.display()));
    }
    if !args.workers.is_empty() {
        c.push_str(&format!(" --workers {}", args.workers.join(",")));
    }
    if let Some(t) = &args.token_file {
        c.push_str(&format!(" --token-file {}", t.display()));
    }
    c.push_str(" --resume");
    c
}

pub(crate) fn run_dir(args: &RunArgs, job: &Job) -> PathBuf {
    if let Some(d) = &args.out {
        return d.clone();
    }
    if let Some(d) = &job.output.dir {
        return d.clone();
    }
    let stem = args.job.file_stem().map_or("run".into(), |s| s.to_string_lossy().into_owned());
    Path::new("runs").join(stem)
}

/// Where the DEM assemblies are solved: the CLI's `--workers` first, then the job's.
fn worker_choice(job: &Job, args: &RunArgs) -> Result<WorkerChoice> {
    let token = Token::load(args.token_file.as_deref())?;
    let addresses =
        if args.workers.is_empty() { job.workers.addresses.clone() } else { args.workers.clone() };
    let create_timeout = args.create_timeout.map(std::time::Duration::from_secs_f64);
    let config = PoolConfig { token, create_timeout, ..PoolConfig::default() };
    Ok(WorkerChoice { addresses, config })
}

/// Runs the job; a run stopped by Ctrl-C or SIGTERM is a deliberate stop, not an error: its
/// message goes to standard error as a plain line (no error chain or backtrace) and the exit
/// code is 1.
pub(crate) fn run(args: RunArgs) -> Result<ExitCode> {
    let job = Job::load(&args.job)?;
    let dir = run_dir(&args, &job);
    let workers = worker_choice(&job, &args)?;
    let mut progress = Progress {
        log: LogFile::init(),
        resume: args.resume,
        quiet: args.quiet,
        job: args.job.clone(),
        bar: ProgressBar::hidden(),
        started: Instant::now(),
        span: None,
    };
    let mut run = Run::new(&job, &dir)
        .workers(workers)
        .checkpoints(true)
        .snapshots(true)
        .max_steps(args.max_steps)
        .overwrite(args.overwrite)
        .origin(cosdem_app::output::provenance::Origin {
            command: std::env::args().collect(),
            job_text: std::fs::read_to_string(&args.job).ok(),
        })
        .max_memory(args.max_memory)
        .stop_on_signals()
        .observer(&mut progress);
    if args.resume {
        run = run.resume(args.newton_changed);
    }
    let outcome = run.execute()?;
    let resume_command = resume_command(&args);
    let s = outcome.summary.as_ref().expect("a run with a directory has a summary");
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
    match outcome.ending {
        Ending::Finished => Ok(ExitCode::SUCCESS),
        Ending::Interrupted => {
            eprintln!(
                "interrupted after step {}: the finished steps and the checkpoint are in {}; continue with `{resume_command}`",
                s.steps,
                dir.display(),
            );
            Ok(ExitCode::FAILURE)
        }
        Ending::Stopped => {
            println!(
                "stopped after step {} (--max-steps); continue with `{resume_command}`",
                s.steps
            );
            Ok(ExitCode::SUCCESS)
        }
        Ending::Failed(e) => {
            Err(e).with_context(|| format!("run stopped; finished steps are in {}", dir.display()))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::parse_memory;

    #[test]
    fn memory_sizes_parse_with_binary_units_and_bad_ones_are_named() {
        assert_eq!(parse_memory("16GiB"), Ok(16 << 30));
        assert_eq!(parse_memory("512M"), Ok(512 << 20));
        assert_eq!(parse_memory("2e9"), Ok(2_000_000_000));
        assert_eq!(parse_memory("1.5 KiB"), Ok(1536));
        assert_eq!(parse_memory("none"), Ok(u64::MAX));
        for bad in ["", "12 parsecs", "-1G", "0", "nan"] {
            let e = parse_memory(bad).expect_err(bad);
            assert!(e.contains(&format!("{bad:?}")), "{e}");
        }
        assert_eq!(super::parse_seconds("90"), Ok(90.0));
        for bad in ["0", "-3", "nan", "1e308", "soon"] {
            let e = super::parse_seconds(bad).expect_err(bad);
            assert!(e.contains(&format!("{bad:?}")), "{e}");
        }
    }
}

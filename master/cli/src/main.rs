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
//! cosdem export RUN_DIR --format yade|lammps|vtu [--out DIR]
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
//!
//! One file per subcommand: [`run`], [`rve`], [`study`], [`plot`], [`bench`](mod@bench)
//! (with its speed/accuracy sweeps in [`tradeoff`]); [`logging`] sets up the run's log.

mod bench;
mod export;
mod logging;
mod plot;
mod run;
mod rve;
mod study;
mod tradeoff;

use anyhow::Result;
use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "cosdem", version, about = "Two-scale FEM x DEM for granular materials")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a job file.
    Run(run::RunArgs),
    /// One DEM assembly of the job driven through a laboratory path (calibration).
    Rve(rve::RveArgs),
    /// Parameter studies over whole runs.
    Study {
        #[command(subcommand)]
        what: study::StudyWhat,
    },
    /// Draw the PNG figures of a run directory (or of an RVE-size study directory) into
    /// RUN_DIR/plots/.
    Plot {
        /// The run directory (holds curve.csv), or a study directory (holds study.json).
        run_dir: PathBuf,
    },
    /// Every Gauss point's packing at the run's checkpoint as YADE, LAMMPS or VTU files.
    Export(export::ExportArgs),
    /// Benchmarks of the coupling (see `cosdem_study::bench`): printed figures.
    Bench {
        #[command(subcommand)]
        what: bench::BenchWhat,
    },
}

/// The stem of a job file's name (`run` if it has none).
fn stem(job: &Path) -> String {
    job.file_stem().map_or("run".into(), |s| s.to_string_lossy().into_owned())
}

fn main() -> Result<ExitCode> {
    let cli = Cli::parse();
    match cli.command {
        Command::Run(args) => return run::run(args),
        Command::Rve(args) => rve::rve(args),
        Command::Study { what } => study::study(what),
        Command::Plot { run_dir } => plot::plot(&run_dir),
        Command::Export(args) => export::export(args),
        Command::Bench { what } => bench::bench(what),
    }?;
    Ok(ExitCode::SUCCESS)
}

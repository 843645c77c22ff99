//! `cosdem bench tradeoff`, `tradeoff-plot`, `tradeoff-specimens`: the speed/accuracy sweep
//! of `cosdem_study::tradeoff`, its Pareto plot, and its average over specimens.

use anyhow::{Context, Result};
use cosdem_app::run::WorkerChoice;
use cosdem_job::Job;
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub(crate) struct TradeoffSpecimensArgs {
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

pub(crate) fn tradeoff_specimens(a: TradeoffSpecimensArgs) -> Result<()> {
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
pub(crate) struct TradeoffPlotArgs {
    /// The sweep's CSV (written by `cosdem bench tradeoff`).
    csv: PathBuf,
    /// The PNG to write (default: pareto.png beside the CSV); the SVG goes beside it, same
    /// name.
    #[arg(long)]
    out: Option<PathBuf>,
    /// The figure's title (default: "Speed against accuracy: <CSV>").
    #[arg(long)]
    title: Option<String>,
}

pub(crate) fn tradeoff_plot(a: TradeoffPlotArgs) -> Result<()> {
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
pub(crate) struct TradeoffArgs {
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

pub(crate) fn tradeoff(a: TradeoffArgs) -> Result<()> {
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

//! `cosdem study rve-size`: the RVE-size study of `cosdem_study::rve_size` and its printed
//! table and fits.

use crate::stem;
use anyhow::Result;
use clap::Subcommand;
use cosdem_job::Job;
use std::path::{Path, PathBuf};

#[derive(Subcommand)]
pub(crate) enum StudyWhat {
    /// Scene A once per assembly size V; fit of Eqs. 30-32 (study.csv, study.json).
    RveSize(RveSizeArgs),
}

#[derive(clap::Args)]
pub(crate) struct RveSizeArgs {
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

pub(crate) fn study(what: StudyWhat) -> Result<()> {
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

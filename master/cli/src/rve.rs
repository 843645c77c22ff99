//! `cosdem rve`: one DEM assembly of the job driven through a laboratory path (calibration).

use crate::stem;
use anyhow::{Context, Result};
use cosdem_job::{Job, MaterialSection};
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(clap::Args)]
pub(crate) struct RveArgs {
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
    /// Replaces the random packing's seed: another specimen of the same material (the
    /// scatter of a calibration over seeds).
    #[arg(long)]
    seed: Option<u64>,
    /// Output directory (default `runs/<job stem>-rve-<path>`, `-seed<N>` appended with
    /// `--seed`).
    #[arg(long)]
    out: Option<PathBuf>,
}

pub(crate) fn rve(args: RveArgs) -> Result<()> {
    use cosdem_app::rve::{RvePath, RveSettings, drive, report, table};
    let mut job = Job::load(&args.job)?;
    let MaterialSection::Dem { assembly } = &mut job.material else {
        anyhow::bail!("{}: `cosdem rve` needs [material] kind = \"dem\"", args.job.display());
    };
    if let Some(new) = args.seed {
        let cosdem_dem::PackingSpec::Random { seed, .. } = &mut assembly.packing else {
            anyhow::bail!(
                "--seed {new}: the job's packing is `{}`; only a random packing has a seed",
                assembly.packing.kind()
            );
        };
        *seed = new;
    }
    let assembly = &*assembly;
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
        let seed = args.seed.map(|s| format!("-seed{s}")).unwrap_or_default();
        Path::new("runs").join(format!("{}-rve-{}{seed}", stem(&args.job), settings.path.name()))
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
        "peak friction angle {:.2} deg at step {} (strain {:.4e}, q = {:.4e} Pa), dilatancy at peak {:.2} deg, max {:.2} deg; final friction angle {:.2} deg, volumetric strain {:.4e}; from step {}: friction angle {:.2} deg, dilatancy {:.2} deg (the critical state if the dilatancy is near 0); {} DEM steps, {:.1} s",
        s.peak_friction_angle,
        s.peak_step,
        s.peak_strain,
        s.peak_deviatoric_stress,
        s.dilatancy_at_peak,
        s.max_dilatancy_angle,
        s.final_friction_angle,
        s.final_volumetric_strain,
        s.critical_state_from_step,
        s.critical_state_friction_angle,
        s.critical_state_dilatancy_angle,
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

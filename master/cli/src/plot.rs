//! `cosdem plot`: (re)draws the PNG figures of a run directory or of an RVE-size study
//! directory into `DIR/plots/`.

use anyhow::Result;
use std::path::Path;

/// Draws the figures of a run directory; an error if any figure failed (after trying all).
pub(crate) fn plot(dir: &Path) -> Result<()> {
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

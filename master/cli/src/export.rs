//! `cosdem export RUN_DIR --format yade|lammps|vtu [--out DIR]`: every Gauss point's packing
//! at the run's checkpoint (`RUN_DIR/checkpoint.bin`, each assembly's committed state), one
//! file per Gauss point (`e{E}_p{P}.txt|.data|.vtu`, see `cosdem_app::output::packing`).

use anyhow::{Context, Result};
use cosdem_app::checkpoint::{Checkpoint, FILE};
use cosdem_app::output::packing::export_states;
use cosdem_dem::packing::formats::OutputFormat;
use std::path::PathBuf;

#[derive(clap::Args)]
pub(crate) struct ExportArgs {
    /// The run directory (holds checkpoint.bin).
    run_dir: PathBuf,
    /// `yade` (text x y z r), `lammps` (data file, atom_style sphere) or `vtu` (ParaView).
    #[arg(long)]
    format: OutputFormat,
    /// Output directory (default RUN_DIR/packings).
    #[arg(long)]
    out: Option<PathBuf>,
}

pub(crate) fn export(args: ExportArgs) -> Result<()> {
    let path = args.run_dir.join(FILE);
    let c = Checkpoint::read(&path).with_context(|| format!("reading {}", path.display()))?;
    if c.assemblies.is_empty() {
        anyhow::bail!("{}: no assembly states (not a DEM run)", path.display());
    }
    let out = args.out.unwrap_or_else(|| args.run_dir.join("packings"));
    let states = c.assemblies.iter().map(|a| (a.id, a.state.as_slice()));
    let written = export_states(states, &out, args.format)?;
    println!("{} packings written to {}", written.len(), out.display());
    Ok(())
}

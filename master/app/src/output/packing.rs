//! Packing files written by a run and by `cosdem export`: the discs of an assembly as YADE
//! text, a LAMMPS data file (`cosdem_dem::packing::formats`, which reads both back to the last
//! bit) or a VTU point cloud (one `VTK_VERTEX` per disc centre with the point array `radius`,
//! for ParaView's glyphs).
//!
//! Two sources: a particle snapshot of a run (`[output] packing_formats`, written beside the
//! snapshot as `packing_NNNNN.{txt,data,vtu}` ([`snapshot_packing_path`]): it carries no
//! region, so the region is the discs' bounding box and the centres are shifted to it, see
//! [`super::snapshots::snapshot_packing`]) and an assembly's committed state in a checkpoint
//! ([`Packing::committed`]: the reference region mapped by the committed macro deformation).

use super::vtk::{DataArray, Encoding, VtuPiece, write_vtu_encoded};
use super::{Result, io_err, write_atomic};
use cosdem_common::GaussPointId;
use cosdem_dem::packing::Packing;
use cosdem_dem::packing::formats::{OutputFormat, write_lammps, write_yade};
use cosdem_job::{Job, MaterialSection};
use std::path::{Path, PathBuf};

/// The VTU piece of a packing: the centres (z = 0) as vertices with `radius`.
pub fn packing_piece(p: &Packing) -> VtuPiece {
    let centres: Vec<[f64; 2]> = p.x.iter().zip(&p.y).map(|(x, y)| [*x, *y]).collect();
    let mut piece = VtuPiece::point_cloud_2d(&centres);
    piece.add_point_data(DataArray::scalars("radius", p.r.clone()));
    piece
}

/// Writes `p` to `path` in `format` (atomically); `density` (kg/m^3) goes into a LAMMPS file.
pub fn write_packing(path: &Path, p: &Packing, density: f64, format: OutputFormat) -> Result<()> {
    match format {
        OutputFormat::Yade => write_atomic(path, write_yade(p).as_bytes()),
        OutputFormat::Lammps => write_atomic(path, write_lammps(p, density).as_bytes()),
        OutputFormat::Vtu => write_vtu_encoded(path, &packing_piece(p), Encoding::Ascii),
    }
}

/// `[output] packing_formats` of a run: the formats each particle snapshot is also written in,
/// and the solid density (kg/m^3) a LAMMPS file carries.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PackingOutput {
    /// The formats, in the job's order (empty: no packing files).
    pub formats: Vec<OutputFormat>,
    /// The assemblies' density (the DEM spec's; the spec's default for a job without discs).
    pub density: f64,
    /// Per element, the density of its region's assemblies (empty: `density` everywhere).
    pub element_density: Vec<f64>,
}

impl PackingOutput {
    /// The packing files `job` asks for.
    pub fn of(job: &Job) -> Self {
        let density = match &job.material {
            MaterialSection::Dem { assembly } => assembly.density,
            MaterialSection::Elastic { .. } => cosdem_dem::AssemblySpec::default().density,
        };
        Self { formats: job.output.packing_formats.clone(), density, element_density: Vec::new() }
    }

    /// The density of element `e`'s assemblies.
    pub fn density_of(&self, e: u32) -> f64 {
        self.element_density.get(e as usize).copied().unwrap_or(self.density)
    }

    /// Each element's density from its material (`element_materials`:
    /// [`Job::element_materials`]); an elastic element keeps `density`.
    pub fn set_regions(&mut self, job: &Job, element_materials: &[usize]) {
        let materials = job.materials();
        self.element_density = element_materials
            .iter()
            .map(|&m| match materials[m] {
                MaterialSection::Dem { assembly } => assembly.density,
                MaterialSection::Elastic { .. } => self.density,
            })
            .collect();
    }
}

/// The packing file of the snapshot of `step` in its series directory `dir`
/// (`dir/packing_NNNNN.{txt,data,vtu}`, beside `snap_NNNNN.vtu`).
pub fn snapshot_packing_path(dir: &Path, step: u64, format: OutputFormat) -> PathBuf {
    dir.join(format!("packing_{step:05}.{}", format.extension()))
}

/// The file of Gauss point `id`'s packing in `dir` (`e{E}_p{P}.{txt,data,vtu}`), the name
/// `cosdem export` writes.
pub fn export_path(dir: &Path, id: GaussPointId, format: OutputFormat) -> PathBuf {
    dir.join(format!("e{}_p{}.{}", id.element, id.point, format.extension()))
}

/// Writes the packing of each assembly state of a checkpoint (`(id, Assembly::to_bytes)`) into
/// `dir` in `format`; returns the files written. A state that does not decode is an error
/// naming the Gauss point.
pub fn export_states<'a>(
    states: impl IntoIterator<Item = (GaussPointId, &'a [u8])>,
    dir: &Path,
    format: OutputFormat,
) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).map_err(io_err(dir, "create directory"))?;
    let mut written = Vec::new();
    for (id, bytes) in states {
        let path = export_path(dir, id, format);
        let a = cosdem_dem::Assembly::from_bytes(bytes).map_err(|e| {
            super::invalid(
                &path,
                format!("assembly of element {} point {}: {e}", id.element, id.point),
            )
        })?;
        write_packing(&path, &Packing::committed(&a), a.spec().density, format)?;
        written.push(path);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;
    use cosdem_dem::packing::formats::{PackingFormat, ReadOptions, read};
    use cosdem_dem::{Assembly, AssemblySpec, PackingSpec};

    /// The committed state of a small hexagonal assembly, exported from its bytes in the
    /// three formats: YADE and LAMMPS read back to the same discs bit for bit, the VTU holds
    /// one vertex and one radius per disc.
    #[test]
    fn exported_states_read_back() {
        let spec =
            AssemblySpec { packing: PackingSpec::hexagonal(0.005, 0.05), ..Default::default() };
        let a = Assembly::new(&spec).unwrap();
        let bytes = a.to_bytes();
        let id = GaussPointId { element: 3, point: 1 };
        let dir = std::env::temp_dir().join(format!("cosdem-export-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let p = Packing::committed(&a);
        let opt = ReadOptions { density: spec.density, periodic: false };
        for (format, read_as) in [
            (OutputFormat::Yade, Some(PackingFormat::Yade)),
            (OutputFormat::Lammps, Some(PackingFormat::Lammps)),
            (OutputFormat::Vtu, None),
        ] {
            let files = export_states([(id, bytes.as_slice())], &dir, format).unwrap();
            assert_eq!(files, [export_path(&dir, id, format)]);
            let text = std::fs::read_to_string(&files[0]).unwrap();
            match read_as {
                Some(f) => {
                    let q = read(&text, f, "export", &opt).unwrap();
                    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                    assert_eq!(bits(&q.x), bits(&p.x));
                    assert_eq!(bits(&q.y), bits(&p.y));
                    assert_eq!(bits(&q.r), bits(&p.r));
                    assert_eq!((q.lx, q.ly), (p.lx, p.ly));
                }
                None => {
                    let piece = super::super::vtu_read::read_vtu(&files[0]).unwrap();
                    assert_eq!(piece.points.len(), p.r.len());
                    assert_eq!(piece.point_array("radius").unwrap().values, p.r);
                }
            }
        }
        let e = export_states([(id, &bytes[..20])], &dir, OutputFormat::Yade).unwrap_err();
        assert!(e.to_string().contains("element 3 point 1"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

//! `[material.assembly.packing] kind = "file"`: the packing file is read here, on the master,
//! when the job is loaded, and replaced by the explicit disc list it holds
//! ([`PackingSpec::Explicit`]), so the spec that travels to the workers carries discs, never a
//! path. A relative path is resolved against the job file (as `mesh.file` is). How a file maps
//! onto the 2D specimen, and what is refused, is `cosdem_dem::packing::formats`.

use crate::schema::{Job, MaterialSection};
use cosdem_dem::PackingSpec;
use cosdem_dem::packing::formats::{ReadOptions, read};
use cosdem_fem::error::{Error, Result};
use cosdem_fem::gmsh::read_regular;
use std::path::Path;

/// Largest packing file read (256 MiB): a line of a [`cosdem_dem::spec::MAX_DISCS`]-disc file
/// takes at most about 120 bytes in either format.
pub const MAX_PACKING_FILE_BYTES: u64 = 256 << 20;

/// Reads the packing file of each of `job`'s assemblies (`[material]`'s and every
/// region's), if it names one, into its explicit disc list; `base` is the directory relative
/// paths start from, `origin` names the job in errors.
pub(crate) fn resolve(job: &mut Job, base: &Path, origin: &str) -> Result<()> {
    resolve_one(&mut job.material, "material", base, origin)?;
    for (i, region) in job.region.iter_mut().enumerate() {
        resolve_one(&mut region.material, &format!("region[{i}].material"), base, origin)?;
    }
    Ok(())
}

/// [`resolve`] for one material, whose key is `prefix` (`material`, `region[0].material`).
fn resolve_one(
    material: &mut MaterialSection,
    prefix: &str,
    base: &Path,
    origin: &str,
) -> Result<()> {
    let MaterialSection::Dem { assembly } = material else {
        return Ok(());
    };
    let PackingSpec::File { file, format } = &assembly.packing else {
        return Ok(());
    };
    let path = if file.is_relative() { base.join(file) } else { file.clone() };
    let name = path.display().to_string();
    let err = |message: String| Error::JobFile {
        file: origin.to_string(),
        message: format!(
            "{prefix}.assembly.packing.file = {:?}: {message}",
            file.display().to_string()
        ),
    };
    let bytes = read_regular(&path, MAX_PACKING_FILE_BYTES).map_err(|e| err(e.to_string()))?;
    let text = String::from_utf8(bytes).map_err(|e| err(format!("{name}: not UTF-8 text: {e}")))?;
    let periodic = matches!(assembly.boundary, cosdem_dem::BoundarySpec::Periodic);
    let opt = ReadOptions { density: assembly.density, periodic };
    let p = read(&text, *format, &name, &opt).map_err(|e| err(e.to_string()))?;
    assembly.packing = PackingSpec::Explicit { x: p.x, y: p.y, radii: p.r, lx: p.lx, ly: p.ly };
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::{Job, fixtures};
    use cosdem_dem::PackingSpec;

    /// A fresh directory for one test.
    fn scratch(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("cosdem-pack-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// The DEM fixture job with its packing table replaced by `packing`, written to `dir`.
    fn job_with(dir: &std::path::Path, packing: &str) -> std::path::PathBuf {
        let text = fixtures::text("packing-file");
        let start = text.find("[material.assembly.packing]").unwrap();
        let end = text[start..].find("\n\n").map_or(text.len(), |e| start + e);
        let text =
            format!("{}[material.assembly.packing]\n{packing}{}", &text[..start], &text[end..]);
        let path = dir.join("job.toml");
        std::fs::write(&path, text).unwrap();
        path
    }

    /// The fixture's YADE file (examples/packings) is read beside the job into the explicit
    /// list: the workers get discs, not a path.
    #[test]
    fn a_relative_packing_file_becomes_discs() {
        let job = fixtures::load("packing-file");
        let crate::MaterialSection::Dem { assembly } = &job.material else { panic!() };
        let PackingSpec::Explicit { radii, .. } = &assembly.packing else {
            panic!("{:?}", assembly.packing.kind())
        };
        assert!(radii.len() >= 100, "{}", radii.len());
    }

    /// A region's packing file is read as `[material]`'s (relative to the job file), and its
    /// errors name the region's key.
    #[test]
    fn a_region_packing_file_becomes_discs_and_its_errors_name_the_region() {
        let dir = scratch("region");
        let text = fixtures::text("packing-file").replace(
            "[material]\nkind = \"dem\"",
            "[material]\nkind = \"elastic\"\nshear_modulus = 1e7\npoisson = 0.3\n\n[[region]]\nelements = [[0, 0]]\n[region.material]\nkind = \"dem\"",
        );
        let text =
            text.replace("[material.assembly.packing]", "[region.material.assembly.packing]");
        let text = text.replace("../../examples/packings/random-270.txt", "discs.txt");
        // A 5 x 5 square lattice of unit discs: a region of 10 x 10, five diameters each way.
        let lattice: String =
            (0..25).map(|k| format!("{} {} 0 1\n", 2 * (k % 5), 2 * (k / 5))).collect();
        std::fs::write(dir.join("discs.txt"), lattice).unwrap();
        std::fs::write(dir.join("job.toml"), &text).unwrap();
        let job = Job::load(&dir.join("job.toml")).unwrap_or_else(|e| panic!("{e}\n{text}"));
        let crate::MaterialSection::Dem { assembly } = &job.region[0].material else { panic!() };
        let PackingSpec::Explicit { radii, .. } = &assembly.packing else { panic!() };
        assert_eq!(radii, &[1.0; 25]);
        std::fs::write(dir.join("job.toml"), text.replace("discs.txt", "missing.txt")).unwrap();
        let e = Job::load(&dir.join("job.toml")).unwrap_err().to_string();
        assert!(e.contains("region[0].material.assembly.packing.file = \"missing.txt\""), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A missing file, a bad line and an unknown format are errors naming the job, the key,
    /// the packing file, the line and the value.
    #[test]
    fn packing_file_errors_name_the_job_the_file_and_the_line() {
        let dir = scratch("errors");
        let job = job_with(&dir, "kind = \"file\"\nfile = \"missing.txt\"\nformat = \"yade\"\n");
        let e = Job::load(&job).unwrap_err().to_string();
        assert!(e.contains("job.toml") && e.contains("packing.file = \"missing.txt\""), "{e}");
        std::fs::write(dir.join("bad.txt"), "0 0 0 1\n2 0 0 1\n0 2 0 NaN\n2 2 0 1\n").unwrap();
        let job = job_with(&dir, "kind = \"file\"\nfile = \"bad.txt\"\nformat = \"yade\"\n");
        let e = Job::load(&job).unwrap_err().to_string();
        assert!(e.contains("bad.txt, line 3: r = NaN"), "{e}");
        let job = job_with(&dir, "kind = \"file\"\nfile = \"bad.txt\"\nformat = \"xyz\"\n");
        let e = Job::load(&job).unwrap_err().to_string();
        assert!(e.contains("xyz") && e.contains("yade"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

//! A run directory cut back to the step of its checkpoint, for a resume: the files of later
//! steps (written after the checkpoint by the session that was stopped) are removed and every
//! ParaView series (`fields.pvd`, `gauss.pvd`, `snapshots/*.pvd`) is rebuilt from the files
//! that exist, so that the resumed run's directory ends as the uninterrupted run's.
//!
//! A series lists a step's file at that step's displacement (the `curve.csv` row), as the
//! writers do ([`super::run_dir::RunWriter`], [`super::visuals`]).

use super::pvd::PvdWriter;
use super::{Result, io_err};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The files `dir/<prefix>NNNNN<ext>` (`prefix` and `ext` as spelled in the name), by step.
fn numbered(dir: &Path, prefix: &str, ext: &str) -> Result<BTreeMap<u64, PathBuf>> {
    let mut files = BTreeMap::new();
    let Ok(read) = std::fs::read_dir(dir) else { return Ok(files) };
    for entry in read {
        let entry = entry.map_err(io_err(dir, "list"))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let step = name
            .strip_prefix(prefix)
            .and_then(|rest| rest.strip_suffix(ext))
            .filter(|digits| !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()))
            .and_then(|digits| digits.parse::<u64>().ok());
        if let Some(step) = step {
            files.insert(step, entry.path());
        }
    }
    Ok(files)
}

/// Removes the files of `dir/<prefix>NNNNN.<ext>` after `step`; returns those kept.
fn keep_up_to(dir: &Path, prefix: &str, ext: &str, step: u64) -> Result<BTreeMap<u64, PathBuf>> {
    let mut files = numbered(dir, &format!("{prefix}_"), &format!(".{ext}"))?;
    for (_, path) in files.split_off(&(step + 1)) {
        std::fs::remove_file(&path)
            .map_err(io_err(&path, "remove (written after the checkpoint)"))?;
    }
    Ok(files)
}

/// Rewrites the series `pvd` to list `files` at their steps' displacements. A file of a step
/// the curve does not have is left out.
fn rebuild(pvd: &Path, files: &BTreeMap<u64, PathBuf>, displacement: &[f64]) -> Result<()> {
    let mut w = PvdWriter::create(pvd)?;
    for (&step, path) in files {
        let Some(&d) = step.checked_sub(1).and_then(|i| displacement.get(i as usize)) else {
            continue;
        };
        w.add(d, path)?;
    }
    Ok(())
}

/// Cuts the run directory `dir` back to committed step `step`, whose displacements are
/// `displacement[0..step]` (steps 1..=step): removes the VTK files, field data and particle
/// snapshots of later steps and rebuilds the `.pvd` series from the files that remain.
/// `vtk`: the run writes `fields.pvd` and `gauss.pvd`.
pub fn cut_back(dir: &Path, step: u64, displacement: &[f64], vtk: bool) -> Result<()> {
    let vtk_dir = dir.join("vtk");
    for (series, prefix) in [("fields.pvd", "mesh"), ("gauss.pvd", "gauss")] {
        let kept = keep_up_to(&vtk_dir, prefix, "vtu", step)?;
        if vtk {
            rebuild(&dir.join(series), &kept, displacement)?;
        }
    }
    keep_up_to(&dir.join("fields"), "field", "json", step)?;
    let snapshots = dir.join("snapshots");
    if let Ok(read) = std::fs::read_dir(&snapshots) {
        let mut names: Vec<String> = read
            .flatten()
            .filter(|e| e.file_type().is_ok_and(|t| t.is_dir()))
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        for name in names {
            let kept = keep_up_to(&snapshots.join(&name), "snap", "vtu", step)?;
            // The packing files of `[output] packing_formats` beside the snapshots.
            for ext in ["txt", "data", "vtu"] {
                keep_up_to(&snapshots.join(&name), "packing", ext, step)?;
            }
            rebuild(&snapshots.join(format!("{name}.pvd")), &kept, displacement)?;
        }
    }
    Ok(())
}

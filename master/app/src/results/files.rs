//! The files of a run directory found by name, and `curve.csv` parsed: the naming rules of
//! the writers (`vtk/mesh_NNNNN.vtu`, `snapshots/eE_pP/snap_NNNNN.vtu`, the header and rows of
//! [`crate::output::CsvWriter`]) read backwards.

use super::Curve;
use crate::output::visuals::series_name;
use crate::output::{OutputError, invalid, io_err};
use cosdem_common::GaussPointId;
use std::path::{Path, PathBuf};

/// The file of `step` in a series: `dir/{prefix}_NNNNN.vtu` (at least five digits), as the
/// writers name them.
pub(super) fn step_file(dir: &Path, prefix: &str, step: u64) -> PathBuf {
    dir.join(format!("{prefix}_{step:05}.vtu"))
}

/// The names of the entries of `dir`; none when `dir` does not exist (a run that writes no
/// such files, or not yet).
fn names(dir: &Path) -> Result<Vec<(String, PathBuf)>, OutputError> {
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(io_err(dir, "list")(e)),
    };
    let mut out = Vec::new();
    for entry in entries {
        let entry = entry.map_err(io_err(dir, "list"))?;
        if let Some(name) = entry.file_name().to_str() {
            out.push((name.to_string(), entry.path()));
        }
    }
    Ok(out)
}

/// The steps of the files `dir/{prefix}_NNNNN.vtu`, ascending. Only names the writer gives
/// count (so that [`step_file`] of a listed step is the file listed): temporaries (`.*.tmp`)
/// and other files are ignored.
pub(super) fn steps(dir: &Path, prefix: &str) -> Result<Vec<u64>, OutputError> {
    let mut steps: Vec<u64> = names(dir)?
        .into_iter()
        .filter_map(|(name, path)| {
            let digits = name.strip_prefix(prefix)?.strip_prefix('_')?.strip_suffix(".vtu")?;
            let step: u64 =
                digits.bytes().all(|b| b.is_ascii_digit()).then(|| digits.parse().ok())??;
            (step_file(dir, prefix, step) == path && path.is_file()).then_some(step)
        })
        .collect();
    steps.sort_unstable();
    Ok(steps)
}

/// The Gauss points `(element, point)` with a snapshot series under `snapshots` (directories
/// `eE_pP` holding at least one `snap_NNNNN.vtu`), ascending.
pub(super) fn series(snapshots: &Path) -> Result<Vec<(u32, u32)>, OutputError> {
    let mut points = Vec::new();
    for (name, path) in names(snapshots)? {
        let Some((e, p)) = name.strip_prefix('e').and_then(|rest| rest.split_once("_p")) else {
            continue;
        };
        let (Ok(e), Ok(p)) = (e.parse::<u32>(), p.parse::<u32>()) else { continue };
        if series_name(GaussPointId::new(e, p)) == name
            && path.is_dir()
            && !steps(&path, "snap")?.is_empty()
        {
            points.push((e, p));
        }
    }
    points.sort_unstable();
    Ok(points)
}

/// `curve.csv` read: the header's columns (names quoted as [`crate::output::CsvWriter`]
/// writes them), then every complete row. A last row without its line end is one being
/// appended (or cut short by a kill) and is left out, as a resume drops it; any other row
/// that is not one number per column is an error naming the file and the line.
pub(super) fn read_curve(path: &Path) -> Result<Curve, OutputError> {
    let text = std::fs::read_to_string(path).map_err(io_err(path, "read"))?;
    let (names, body) = header(&text).map_err(|m| invalid(path, m))?;
    let first_row_line = 1 + text[..text.len() - body.len()].matches('\n').count();
    let mut columns: Vec<(String, Vec<f64>)> = names.into_iter().map(|n| (n, Vec::new())).collect();
    let complete = &body[..body.rfind('\n').map_or(0, |end| end + 1)];
    for (k, line) in complete.lines().enumerate() {
        let at = first_row_line + k;
        let values: Vec<&str> = line.split(',').collect();
        if values.len() != columns.len() {
            return Err(invalid(
                path,
                format!(
                    "line {at}: {line:?} has {} values for the {} columns",
                    values.len(),
                    columns.len()
                ),
            ));
        }
        for ((name, column), v) in columns.iter_mut().zip(values) {
            let x = v.trim().parse::<f64>().map_err(|_| {
                invalid(path, format!("line {at}: {v:?} (column {name:?}) is not a number"))
            })?;
            column.push(x);
        }
    }
    Ok(Curve { columns })
}

/// The column names of the header at the start of `text` (RFC 4180: a quoted name may hold
/// commas, doubled quotes and line breaks) and the text after its line end.
fn header(text: &str) -> Result<(Vec<String>, &str), String> {
    if text.is_empty() {
        return Err("the file is empty: no header".into());
    }
    let mut names = Vec::new();
    let mut name = String::new();
    let mut chars = text.char_indices().peekable();
    let mut quoted = false;
    while let Some((i, c)) = chars.next() {
        match c {
            '"' if quoted && chars.peek().is_some_and(|&(_, n)| n == '"') => {
                chars.next();
                name.push('"');
            }
            '"' => quoted = !quoted,
            ',' if !quoted => names.push(std::mem::take(&mut name)),
            '\n' if !quoted => {
                names.push(name.strip_suffix('\r').unwrap_or(&name).to_string());
                return Ok((names, &text[i + 1..]));
            }
            c => name.push(c),
        }
    }
    Err(format!("line 1: the header {:?} has no line end", text.lines().next().unwrap_or("")))
}

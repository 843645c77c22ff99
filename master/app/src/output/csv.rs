//! CSV curves (load-displacement and the like), one row per converged step.
//!
//! [`CsvWriter`] writes its header once, then appends each row with a single write and syncs
//! it to disk, so a run killed at any moment leaves every finished row (and at worst no part
//! of the row being written). Numbers are printed with [`fmt_f64`](crate::output::fmt_f64)
//! and parse back to the same `f64`; NaN and infinities are written as `NaN`, `inf`, `-inf`.

use std::io::{Seek, SeekFrom, Write as _};
use std::path::{Path, PathBuf};

use super::{Result, invalid, io_err, push_f64, write_atomic};

/// Appends rows of numbers under a fixed header.
#[derive(Debug)]
pub struct CsvWriter {
    path: PathBuf,
    file: std::fs::File,
    columns: Vec<String>,
    rows: usize,
}

impl CsvWriter {
    /// Creates (or replaces) the file at `path` with the header `columns`, e.g.
    /// `["step", "displacement", "load_top", "load_bottom"]`.
    pub fn create(path: &Path, columns: &[&str]) -> Result<Self> {
        let columns = check_columns(path, columns)?;
        write_atomic(path, header(&columns).as_bytes())?;
        let file = open_append(path)?;
        Ok(CsvWriter { path: path.to_path_buf(), file, columns, rows: 0 })
    }

    /// Continues the file at `path` (a restarted run): its header must equal `columns`; a
    /// last row cut short by a kill (no final newline) is removed. Creates the file if it
    /// does not exist.
    pub fn resume(path: &Path, columns: &[&str]) -> Result<Self> {
        let text = match std::fs::read_to_string(path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Self::create(path, columns);
            }
            Err(e) => return Err(io_err(path, "read")(e)),
        };
        let columns = check_columns(path, columns)?;
        let want = header(&columns);
        if !text.starts_with(&want) {
            let found = text.lines().next().unwrap_or("");
            return Err(invalid(
                path,
                format!("line 1: header {found:?} differs from the expected {:?}", want.trim_end()),
            ));
        }
        let complete = text.rfind('\n').map_or(0, |i| i + 1);
        let mut file = open_append(path)?;
        if complete < text.len() {
            file.set_len(complete as u64).map_err(io_err(path, "truncate a partial row of"))?;
            file.seek(SeekFrom::End(0)).map_err(io_err(path, "seek"))?;
        }
        let rows = text[..complete].lines().count().saturating_sub(1);
        Ok(CsvWriter { path: path.to_path_buf(), file, columns, rows })
    }

    /// Appends one row (one value per column) and syncs it to disk.
    pub fn write_row(&mut self, values: &[f64]) -> Result<()> {
        if values.len() != self.columns.len() {
            return Err(invalid(
                &self.path,
                format!(
                    "row {} has {} values for the {} columns {:?}",
                    self.rows + 1,
                    values.len(),
                    self.columns.len(),
                    self.columns
                ),
            ));
        }
        let mut line = String::with_capacity(24 * values.len());
        for (i, &v) in values.iter().enumerate() {
            if i > 0 {
                line.push(',');
            }
            push_f64(&mut line, v);
        }
        line.push('\n');
        self.file.write_all(line.as_bytes()).map_err(io_err(&self.path, "append a row to"))?;
        self.file.sync_data().map_err(io_err(&self.path, "sync"))?;
        self.rows += 1;
        Ok(())
    }

    /// The column names.
    pub fn columns(&self) -> &[String] {
        &self.columns
    }

    /// Rows written so far (including those found by [`Self::resume`]).
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// The file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

fn open_append(path: &Path) -> Result<std::fs::File> {
    std::fs::OpenOptions::new().append(true).open(path).map_err(io_err(path, "open for appending"))
}

fn check_columns(path: &Path, columns: &[&str]) -> Result<Vec<String>> {
    if columns.is_empty() {
        return Err(invalid(path, "a CSV needs at least one column".to_string()));
    }
    for (i, c) in columns.iter().enumerate() {
        if c.is_empty() {
            return Err(invalid(path, format!("column {i} has an empty name")));
        }
        if columns[..i].contains(c) {
            return Err(invalid(path, format!("column name {c:?} appears twice")));
        }
    }
    Ok(columns.iter().map(|c| c.to_string()).collect())
}

/// The header line, names quoted (RFC 4180) where they hold a comma, quote or line break.
fn header(columns: &[String]) -> String {
    let mut s = String::new();
    for (i, c) in columns.iter().enumerate() {
        if i > 0 {
            s.push(',');
        }
        if c.contains([',', '"', '\n', '\r']) {
            s.push('"');
            s.push_str(&c.replace('"', "\"\""));
            s.push('"');
        } else {
            s.push_str(c);
        }
    }
    s.push('\n');
    s
}

//! Prescribed deformation tables: the `FILE` path of `cosdem rve`.
//!
//! A CSV file with a header row and one row per load step. Recognized columns (any order,
//! case-insensitive; missing ones keep the undeformed value): `F_xx`, `F_xy`, `F_yx`, `F_yy`
//! (the deformation gradient, `F_ab = delta_ab + du_a/dx_b`), `w` (micro-rotation, rad),
//! `k_x`, `k_y` (curvature, 1/m; also `kappa_x`, `kappa_y`). A `step` column is allowed and
//! ignored; any other column is an error naming it. Blank lines and lines starting with `#`
//! are skipped.

use cosdem_common::MacroDeformation;
use cosdem_fem::error::{Error, Result};
use std::path::Path;

/// Reads a table of prescribed deformations.
pub fn read(path: &Path) -> Result<Vec<MacroDeformation>> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| Error::JobFile { file: path.display().to_string(), message: e.to_string() })?;
    parse(&text, &path.display().to_string())
}

/// Parses the text of a table; `origin` names it in errors.
pub fn parse(text: &str, origin: &str) -> Result<Vec<MacroDeformation>> {
    let err = |line: usize, message: String| Error::JobFile {
        file: origin.to_string(),
        message: format!("line {line}: {message}"),
    };
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let (hl, header) = lines.next().ok_or_else(|| err(1, "no header row".into()))?;
    let mut slots = Vec::new();
    for name in header.split(',').map(str::trim) {
        let slot = match name.to_ascii_lowercase().as_str() {
            "step" => None,
            "f_xx" => Some(0),
            "f_xy" => Some(1),
            "f_yx" => Some(2),
            "f_yy" => Some(3),
            "w" => Some(4),
            "k_x" | "kappa_x" => Some(5),
            "k_y" | "kappa_y" => Some(6),
            _ => {
                return Err(err(
                    hl,
                    format!(
                        "unknown column {name:?} (known: step, F_xx, F_xy, F_yx, F_yy, w, k_x, k_y)"
                    ),
                ));
            }
        };
        if slot.is_some() && slots.contains(&slot) {
            return Err(err(hl, format!("column {name:?} appears twice")));
        }
        slots.push(slot);
    }
    let mut out = Vec::new();
    for (ln, line) in lines {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        if cells.len() != slots.len() {
            return Err(err(ln, format!("{} values for {} columns", cells.len(), slots.len())));
        }
        let mut v = [1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
        for (cell, slot) in cells.iter().zip(&slots) {
            let x: f64 = cell.parse().map_err(|_| err(ln, format!("{cell:?} is not a number")))?;
            if let Some(k) = slot {
                v[*k] = x;
            }
        }
        let m = MacroDeformation { f: [[v[0], v[1]], [v[2], v[3]]], w: v[4], kappa: [v[5], v[6]] };
        m.validate().map_err(|e| err(ln, e.to_string()))?;
        out.push(m);
    }
    if out.is_empty() {
        return Err(err(hl, "no data rows".into()));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_columns_in_any_order_with_defaults() {
        let t = "# a comment\nstep, F_yy ,w\n1,0.999,0.001\n\n2,0.998,0.002\n";
        let m = parse(t, "t.csv").unwrap();
        assert_eq!(m.len(), 2);
        assert_eq!(m[1].f, [[1.0, 0.0], [0.0, 0.998]]);
        assert_eq!(m[1].w, 0.002);
        assert_eq!(m[0].kappa, [0.0, 0.0]);
    }

    #[test]
    fn errors_name_the_line_and_the_column() {
        let e = parse("F_xx,F_zz\n1,1\n", "t.csv").unwrap_err().to_string();
        assert!(e.contains("F_zz") && e.contains("line 1"), "{e}");
        let e = parse("F_xx\n1\nabc\n", "t.csv").unwrap_err().to_string();
        assert!(e.contains("line 3") && e.contains("abc"), "{e}");
        let e = parse("F_xx\n-1\n", "t.csv").unwrap_err().to_string();
        assert!(e.contains("det"), "{e}");
    }
}

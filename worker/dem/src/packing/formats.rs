//! Packing files of other codes, in and out: YADE text (`ymport.text`) and LAMMPS data files
//! (`atom_style sphere`).
//!
//! How a file maps onto cosdem's 2D specimen:
//! - **Plane.** Every particle must have the same `z` (within [`Z_TOLERANCE`] of the smaller
//!   of its radius and the first particle's): a 2D assembly has no out-of-plane offsets. The
//!   first line that differs is refused. `z` is then dropped.
//! - **Region.** The reference region `[0, lx] x [0, ly]` (the square of a penalty boundary,
//!   the cell of a periodic one) is the LAMMPS box (`xlo xhi`, `ylo yhi`); for a YADE file it
//!   is the box of a `# cosdem box: xlo xhi ylo yhi` comment (what cosdem writes; YADE skips
//!   it as a comment) or else the bounding box of the discs (`min(x - r)` to `max(x + r)`).
//!   Centres are shifted by `(-xlo, -ylo)` (exact for `xlo = ylo = 0`, what cosdem writes).
//!   Every centre must lie in the region grown by one largest diameter (a periodic state's
//!   discs move across the faces, a penalty state's boundary discs a little out). A periodic cell taken from a bounding box has the
//!   outermost discs just touching their images across the faces.
//! - **Radii.** YADE gives `r`; LAMMPS the diameter (`r = diameter / 2`, exact in binary).
//! - **Density.** A LAMMPS atom's density must equal the job's `density` within
//!   [`DENSITY_TOLERANCE`] (relative): one number describes the material, and the job's is
//!   the one the relaxation uses, so a file of another material is refused rather than
//!   silently re-weighted. Units are SI (`units si` in LAMMPS; YADE is SI).
//! - **Order.** Discs keep the file's order (not the LAMMPS atom ids), so a file reads the same
//!   way on every host.
//!
//! Refused, naming the file, the line and the value: an unreadable number, a NaN or infinite
//! number, a radius `<= 0`, a `z` that differs, a density that differs, a centre out of the
//! (grown) region, a LAMMPS atom style other than `sphere`, a triclinic box, an atom count that does
//! not match the header, fewer than [`MIN_DISCS`] discs, more than [`MAX_DISCS`], and two
//! discs overlapping by more than [`OVERLAP_TOLERANCE`] of the smaller radius
//! ([`super::explicit::first_overlap`], a cell grid, linear in N).
//!
//! Written numbers use Rust's shortest round-trip form (`{:e}`): a file read back gives the
//! same bits.

use super::Packing;
use super::explicit::{OVERLAP_TOLERANCE, first_overlap};
use crate::error::{Error, Result};
use crate::spec::MAX_DISCS;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;

/// Largest `|z - z_first|` accepted, as a fraction of the smaller of the two radii: a 2D
/// specimen has no out-of-plane offsets; 1e-6 of a radius passes files printed at 7
/// significant digits and refuses any real 3D packing.
pub const Z_TOLERANCE: f64 = 1e-6;

/// Largest relative difference between a LAMMPS atom's density and the job's `density`:
/// passes numbers printed at 7 significant digits (`%g` rounding), refuses another material.
pub const DENSITY_TOLERANCE: f64 = 1e-6;

/// Fewest discs a packing file may hold (as for an explicit `radii` list).
pub const MIN_DISCS: usize = 4;

/// A text format of packing files cosdem reads and writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PackingFormat {
    /// YADE text: `x y z r` a line, `#` comments (`ymport.text`, `export.text`).
    Yade,
    /// LAMMPS data file, `atom_style sphere`: `id type diameter density x y z`.
    Lammps,
}

impl PackingFormat {
    /// The format's name in job files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            PackingFormat::Yade => "yade",
            PackingFormat::Lammps => "lammps",
        }
    }

    /// The usual file extension of the format.
    pub fn extension(self) -> &'static str {
        match self {
            PackingFormat::Yade => "txt",
            PackingFormat::Lammps => "data",
        }
    }
}

/// A format cosdem writes packings in: the two it reads, and VTU (a ParaView point cloud of
/// the centres with a `radius` array; written by the application, not by this crate).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OutputFormat {
    /// YADE text ([`write_yade`]).
    Yade,
    /// LAMMPS data file ([`write_lammps`]).
    Lammps,
    /// VTK XML unstructured grid of vertices with `radius`.
    Vtu,
}

impl OutputFormat {
    /// The usual file extension of the format (`txt`, `data`, `vtu`).
    pub fn extension(self) -> &'static str {
        match self {
            OutputFormat::Yade => PackingFormat::Yade.extension(),
            OutputFormat::Lammps => PackingFormat::Lammps.extension(),
            OutputFormat::Vtu => "vtu",
        }
    }
}

impl std::str::FromStr for OutputFormat {
    type Err = String;

    /// `yade`, `lammps` or `vtu`; anything else is an error naming it.
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "yade" => Ok(OutputFormat::Yade),
            "lammps" => Ok(OutputFormat::Lammps),
            "vtu" => Ok(OutputFormat::Vtu),
            other => Err(format!("unknown packing format {other:?}: expected yade, lammps or vtu")),
        }
    }
}

/// What the reader needs to know of the job besides the text.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReadOptions {
    /// The job's solid density (kg/m^3): LAMMPS atoms must carry it.
    pub density: f64,
    /// Periodic boundary: overlaps across the cell faces count too.
    pub periodic: bool,
}

/// Reads the packing `text` of `format`; `file` names it in errors.
pub fn read(text: &str, format: PackingFormat, file: &str, opt: &ReadOptions) -> Result<Packing> {
    let parsed = match format {
        PackingFormat::Yade => read_yade(text, file)?,
        PackingFormat::Lammps => read_lammps(text, file, opt.density)?,
    };
    parsed.into_packing(file, opt.periodic)
}

/// A refused value of line `line` (1-based; 0: the file as a whole).
fn refuse(file: &str, line: usize, value: impl ToString, reason: impl ToString) -> Error {
    Error::PackingFile {
        file: file.to_string(),
        line,
        value: value.to_string(),
        reason: reason.to_string(),
    }
}

/// Discs as read, before they are placed in their region.
struct Parsed {
    x: Vec<f64>,
    y: Vec<f64>,
    r: Vec<f64>,
    /// Line of each disc.
    line: Vec<usize>,
    /// `[xlo, xhi, ylo, yhi]` when the file gives a box.
    bounds: Option<[f64; 4]>,
    /// The line of the box (0: none).
    bounds_line: usize,
    /// `z` of the first disc, checked as the discs are read.
    z0: Option<(f64, f64)>,
}

impl Parsed {
    fn new() -> Self {
        Self {
            x: Vec::new(),
            y: Vec::new(),
            r: Vec::new(),
            line: Vec::new(),
            bounds: None,
            bounds_line: 0,
            z0: None,
        }
    }

    /// Adds a disc read on line `line`, refusing a bad radius, a `z` off the plane and more
    /// than [`MAX_DISCS`] discs.
    fn push(&mut self, file: &str, line: usize, x: f64, y: f64, z: f64, r: f64) -> Result<()> {
        if r <= 0.0 {
            return Err(refuse(file, line, format!("r = {r:e}"), "a radius must be > 0"));
        }
        match self.z0 {
            None => self.z0 = Some((z, r)),
            Some((z0, r0)) => {
                if (z - z0).abs() > Z_TOLERANCE * r.min(r0) {
                    return Err(refuse(
                        file,
                        line,
                        format!("z = {z:e}"),
                        format!(
                            "differs from the first disc's z = {z0:e} by more than {Z_TOLERANCE:e} \
                             of the radius: a 2D specimen needs every disc in one plane"
                        ),
                    ));
                }
            }
        }
        if self.r.len() == MAX_DISCS {
            return Err(refuse(
                file,
                line,
                format!("disc {}", MAX_DISCS + 1),
                "more than MAX_DISCS = 1 000 000 discs in one assembly",
            ));
        }
        self.x.push(x);
        self.y.push(y);
        self.r.push(r);
        self.line.push(line);
        Ok(())
    }

    /// Places the discs in their region and checks count, containment and overlaps.
    fn into_packing(self, file: &str, periodic: bool) -> Result<Packing> {
        let n = self.r.len();
        if n < MIN_DISCS {
            return Err(refuse(
                file,
                0,
                format!("{n} discs"),
                format!("a packing needs at least {MIN_DISCS} discs"),
            ));
        }
        let [xlo, xhi, ylo, yhi] = self.bounds.unwrap_or_else(|| {
            let mut b = [f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY];
            for k in 0..n {
                b[0] = b[0].min(self.x[k] - self.r[k]);
                b[1] = b[1].max(self.x[k] + self.r[k]);
                b[2] = b[2].min(self.y[k] - self.r[k]);
                b[3] = b[3].max(self.y[k] + self.r[k]);
            }
            b
        });
        let (lx, ly) = (xhi - xlo, yhi - ylo);
        if !(lx > 0.0 && ly > 0.0 && lx.is_finite() && ly.is_finite()) {
            return Err(refuse(
                file,
                self.bounds_line,
                format!("box [{xlo:e}, {xhi:e}] x [{ylo:e}, {yhi:e}]"),
                "the region must have a finite positive width and height",
            ));
        }
        let x: Vec<f64> = self.x.iter().map(|v| v - xlo).collect();
        let y: Vec<f64> = self.y.iter().map(|v| v - ylo).collect();
        let d = 2.0 * self.r.iter().fold(0.0f64, |a, &b| a.max(b));
        for k in 0..n {
            if !(-d..=lx + d).contains(&x[k]) || !(-d..=ly + d).contains(&y[k]) {
                return Err(refuse(
                    file,
                    self.line[k],
                    format!("centre ({:e}, {:e})", self.x[k], self.y[k]),
                    format!(
                        "more than one largest diameter out of the box [{xlo:e}, {xhi:e}] x \
                         [{ylo:e}, {yhi:e}]"
                    ),
                ));
            }
        }
        if let Some(o) = first_overlap(&x, &y, &self.r, lx, ly, periodic) {
            return Err(refuse(
                file,
                self.line[o.j],
                format!("overlap {:e} of radii {:e} and {:e}", o.overlap, self.r[o.i], self.r[o.j]),
                format!(
                    "this disc and the one of line {} overlap by more than {OVERLAP_TOLERANCE:e} \
                     of the smaller radius",
                    self.line[o.i]
                ),
            ));
        }
        Ok(Packing { x, y, r: self.r, lx, ly })
    }
}

/// Parses one number of line `line`, refusing text, NaN and infinities.
fn number(file: &str, line: usize, name: &str, token: &str) -> Result<f64> {
    let v: f64 = token
        .parse()
        .map_err(|_| refuse(file, line, format!("{name} = {token:?}"), "not a number"))?;
    if !v.is_finite() {
        return Err(refuse(file, line, format!("{name} = {token}"), "must be finite"));
    }
    Ok(v)
}

/// The comment a cosdem YADE file carries its box in.
const BOX_COMMENT: &str = "# cosdem box:";

fn read_yade(text: &str, file: &str) -> Result<Parsed> {
    let mut p = Parsed::new();
    for (k, raw) in text.lines().enumerate() {
        let line = k + 1;
        let t = raw.trim();
        if let Some(rest) = t.strip_prefix(BOX_COMMENT) {
            let tok: Vec<&str> = rest.split_whitespace().collect();
            if tok.len() != 4 {
                return Err(refuse(file, line, t, "a box comment holds `xlo xhi ylo yhi`"));
            }
            let mut b = [0.0; 4];
            for (i, name) in ["xlo", "xhi", "ylo", "yhi"].iter().enumerate() {
                b[i] = number(file, line, name, tok[i])?;
            }
            p.bounds = Some(b);
            p.bounds_line = line;
            continue;
        }
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let tok: Vec<&str> = t.split_whitespace().collect();
        if tok.len() != 4 {
            return Err(refuse(
                file,
                line,
                format!("{} columns", tok.len()),
                "a YADE text line holds `x y z r`",
            ));
        }
        let x = number(file, line, "x", tok[0])?;
        let y = number(file, line, "y", tok[1])?;
        let z = number(file, line, "z", tok[2])?;
        let r = number(file, line, "r", tok[3])?;
        p.push(file, line, x, y, z, r)?;
    }
    Ok(p)
}

/// The words of a LAMMPS line without its `#` comment.
fn words(raw: &str) -> Vec<&str> {
    raw.split('#').next().unwrap_or("").split_whitespace().collect()
}

fn read_lammps(text: &str, file: &str, density: f64) -> Result<Parsed> {
    let mut p = Parsed::new();
    let mut lines = text.lines().enumerate().skip(1); // line 1: the title
    let mut atoms: Option<(usize, usize)> = None; // (count, line)
    let (mut xb, mut yb): (Option<[f64; 2]>, Option<[f64; 2]>) = (None, None);
    let mut section: Option<(String, usize)> = None;
    for (k, raw) in lines.by_ref() {
        let line = k + 1;
        let w = words(raw);
        if w.is_empty() {
            continue;
        }
        if w[0].parse::<f64>().is_err() {
            section = Some((raw.trim().to_string(), line));
            break;
        }
        let pair = |i: usize| -> Result<[f64; 2]> {
            Ok([number(file, line, w[i], w[0])?, number(file, line, w[i + 1], w[1])?])
        };
        match w.as_slice() {
            [n, "atoms"] => {
                let n = n.parse().map_err(|_| {
                    refuse(file, line, format!("atoms = {n}"), "not a whole number")
                })?;
                atoms = Some((n, line));
            }
            [_, _, "xlo", "xhi"] => {
                let b = pair(2)?;
                xb = Some(b);
                p.bounds_line = line;
            }
            [_, _, "ylo", "yhi"] => yb = Some(pair(2)?),
            [xy, xz, yz, "xy", "xz", "yz"] => {
                for (name, v) in [("xy", xy), ("xz", xz), ("yz", yz)] {
                    if number(file, line, name, v)? != 0.0 {
                        return Err(refuse(
                            file,
                            line,
                            format!("{name} = {v}"),
                            "a triclinic box does not map onto cosdem's rectangular region",
                        ));
                    }
                }
            }
            _ => {} // zlo zhi, atom types, bonds, ...: not used.
        }
    }
    let (Some(xb), Some(yb)) = (xb, yb) else {
        return Err(refuse(file, 0, "no box", "a LAMMPS data file needs `xlo xhi` and `ylo yhi`"));
    };
    p.bounds = Some([xb[0], xb[1], yb[0], yb[1]]);
    let mut in_atoms = false;
    let mut seen_atoms = false;
    if let Some((head, line)) = section {
        in_atoms = enter(file, line, &head)?;
        seen_atoms |= in_atoms;
    }
    for (k, raw) in lines {
        let line = k + 1;
        let w = words(raw);
        if w.is_empty() {
            continue;
        }
        if w[0].parse::<f64>().is_err() {
            in_atoms = enter(file, line, raw.trim())?;
            seen_atoms |= in_atoms;
            continue;
        }
        if !in_atoms {
            continue;
        }
        if w.len() != 7 && w.len() != 10 {
            return Err(refuse(
                file,
                line,
                format!("{} columns", w.len()),
                "an `Atoms # sphere` line holds `id type diameter density x y z [ix iy iz]`",
            ));
        }
        let d = number(file, line, "diameter", w[2])?;
        let rho = number(file, line, "density", w[3])?;
        if (rho - density).abs() > DENSITY_TOLERANCE * density {
            return Err(refuse(
                file,
                line,
                format!("density = {}", w[3]),
                format!(
                    "differs from the job's material.assembly.density = {density:e} (set the \
                     job's density to the file's)"
                ),
            ));
        }
        let x = number(file, line, "x", w[4])?;
        let y = number(file, line, "y", w[5])?;
        let z = number(file, line, "z", w[6])?;
        p.push(file, line, x, y, z, 0.5 * d)?;
    }
    if !seen_atoms {
        return Err(refuse(
            file,
            0,
            "no Atoms section",
            "a LAMMPS data file needs `Atoms # sphere`",
        ));
    }
    if let Some((n, line)) = atoms
        && n != p.r.len()
    {
        return Err(refuse(
            file,
            line,
            format!("{n} atoms"),
            format!("the header's count differs from the {} atoms of the Atoms section", p.r.len()),
        ));
    }
    Ok(p)
}

/// Whether the section headed `head` is `Atoms`; refuses an Atoms section of a style other
/// than `sphere`.
fn enter(file: &str, line: usize, head: &str) -> Result<bool> {
    let mut parts = head.splitn(2, '#');
    let name = parts.next().unwrap_or("").trim();
    if name != "Atoms" {
        return Ok(false);
    }
    let style = parts.next().map(str::trim).unwrap_or("");
    if !(style.is_empty() || style == "sphere") {
        return Err(refuse(
            file,
            line,
            format!("Atoms # {style}"),
            "only atom_style sphere (`id type diameter density x y z`) is read",
        ));
    }
    Ok(true)
}

/// The YADE text of `p` (`z = 0`), with its region in a `# cosdem box:` comment.
pub fn write_yade(p: &Packing) -> String {
    let mut s = String::with_capacity(64 * p.r.len() + 128);
    s.push_str("# cosdem packing (YADE ymport.text): x y z r in m\n");
    let _ = writeln!(s, "{BOX_COMMENT} 0e0 {:e} 0e0 {:e}", p.lx, p.ly);
    for k in 0..p.r.len() {
        let _ = writeln!(s, "{:e} {:e} 0e0 {:e}", p.x[k], p.y[k], p.r[k]);
    }
    s
}

/// The LAMMPS data file (`atom_style sphere`, SI units) of `p`, every atom of type 1 with
/// `density`, `z = 0`; the z extent of the box is `[-r_max, r_max]`.
pub fn write_lammps(p: &Packing, density: f64) -> String {
    let n = p.r.len();
    let r_max = p.r.iter().fold(0.0f64, |a, &b| a.max(b));
    let mut s = String::with_capacity(96 * n + 256);
    s.push_str("LAMMPS data file written by cosdem (atom_style sphere, units si)\n\n");
    let _ = writeln!(s, "{n} atoms\n1 atom types\n");
    let _ = writeln!(s, "0e0 {:e} xlo xhi", p.lx);
    let _ = writeln!(s, "0e0 {:e} ylo yhi", p.ly);
    let _ = writeln!(s, "{:e} {:e} zlo zhi\n", -r_max, r_max);
    s.push_str("Atoms # sphere\n\n");
    for k in 0..n {
        let _ =
            writeln!(s, "{} 1 {:e} {density:e} {:e} {:e} 0e0", k + 1, 2.0 * p.r[k], p.x[k], p.y[k]);
    }
    s
}

#[cfg(test)]
#[path = "formats_tests.rs"]
mod tests;

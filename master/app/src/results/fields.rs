//! What a run directory's files hold, as plain arrays: the types [`super::RunReader`] returns,
//! each built from the piece of `.vtu` it was read from (lengths checked against the points
//! and cells, errors naming the file).

use crate::output::snapshots::ParticleSnapshot;
use crate::output::vtk::{DataArray, VtuPiece};
use crate::output::{OutputError, invalid};
use cosdem_common::GaussPointId;
use std::path::Path;

/// One named array read from a file: `values.len() == rows * components`, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Array {
    /// The array's name in the file (`stress`, `displacement`, ...).
    pub name: String,
    /// Components per row (1 for a scalar).
    pub components: usize,
    /// The values, row after row.
    pub values: Vec<f64>,
}

impl Array {
    /// Rows (points or cells) of the array.
    pub fn rows(&self) -> usize {
        self.values.len().checked_div(self.components).unwrap_or(0)
    }
}

/// The load curve: every column of curve.csv in file order.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    /// `(name, values)` per column, one value per converged step.
    pub columns: Vec<(String, Vec<f64>)>,
}

impl Curve {
    /// The column `name`, if the curve has one.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.columns.iter().find(|(n, _)| n == name).map(|(_, v)| v.as_slice())
    }

    /// Rows (converged steps) of the curve.
    pub fn rows(&self) -> usize {
        self.columns.first().map_or(0, |(_, v)| v.len())
    }
}

/// Gauss-point fields of one saved step (`vtk/gauss_NNNNN.vtu`).
#[derive(Clone, Debug, PartialEq)]
pub struct GaussFields {
    /// The step.
    pub step: u64,
    /// x, y of each Gauss point (m).
    pub positions: Vec<[f64; 2]>,
    /// `element_id` of each Gauss point.
    pub element: Vec<i64>,
    /// `gauss_point_id` of each Gauss point (within its element).
    pub point: Vec<i64>,
    /// Every other point array in file order (module doc: names and components).
    pub arrays: Vec<Array>,
}

/// Mesh and nodal fields of one saved step (`vtk/mesh_NNNNN.vtu`).
#[derive(Clone, Debug, PartialEq)]
pub struct MeshFields {
    /// The step.
    pub step: u64,
    /// Node coordinates as written (the reference configuration, m).
    pub points: Vec<[f64; 2]>,
    /// Node indices of each cell, VTK order.
    pub cells: Vec<Vec<i64>>,
    /// VTK cell type codes (23: 8-node quadrilateral, 28: 9-node, 22: 6-node triangle, ...).
    pub cell_types: Vec<u8>,
    /// Point arrays in file order: `displacement`, `rotation`, `stress`, `couple_stress`.
    pub point_arrays: Vec<Array>,
    /// Cell arrays in file order (none written so far).
    pub cell_arrays: Vec<Array>,
}

/// One particle snapshot (`snapshots/eE_pP/snap_NNNNN.vtu`).
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    /// The element of the Gauss point.
    pub element: u32,
    /// The Gauss point within the element.
    pub point: u32,
    /// The step.
    pub step: u64,
    /// Disc centres (m, the assembly's frame).
    pub positions: Vec<[f64; 2]>,
    /// Disc radii (m).
    pub radius: Vec<f64>,
    /// Disc rotations (rad).
    pub rotation: Vec<f64>,
    /// Displacement fluctuation (Eq. 35, m): x, y of the file's 3 components (z = 0 dropped).
    pub fluctuation: Vec<[f64; 2]>,
    /// The two disc indices of each contact line.
    pub contacts: Vec<[i64; 2]>,
    /// Normal force of each contact (N per metre of thickness).
    pub normal_force: Vec<f64>,
    /// Tangential force of each contact (N per metre of thickness).
    pub tangential_force: Vec<f64>,
}

impl GaussFields {
    /// The fields of `step` in `piece`, read from `path` (named in errors).
    pub(crate) fn from_piece(
        step: u64,
        piece: &VtuPiece,
        path: &Path,
    ) -> Result<Self, OutputError> {
        let n = piece.points.len();
        let (mut element, mut point, mut arrays) = (None, None, Vec::new());
        for a in &piece.point_data {
            let a = array(a, n, "point", path)?;
            match a.name.as_str() {
                "element_id" | "gauss_point_id" if a.components != 1 => {
                    return Err(invalid(path, format!("{:?} is not a scalar", a.name)));
                }
                "element_id" => element = Some(ids(&a.values)),
                "gauss_point_id" => point = Some(ids(&a.values)),
                _ => arrays.push(a),
            }
        }
        let missing = |name: &str| invalid(path, format!("no point array {name:?}"));
        Ok(GaussFields {
            step,
            positions: piece.points.iter().map(|p| [p[0], p[1]]).collect(),
            element: element.ok_or_else(|| missing("element_id"))?,
            point: point.ok_or_else(|| missing("gauss_point_id"))?,
            arrays,
        })
    }
}

impl MeshFields {
    /// The fields of `step` in `piece`, read from `path` (named in errors).
    pub(super) fn from_piece(
        step: u64,
        piece: &VtuPiece,
        path: &Path,
    ) -> Result<Self, OutputError> {
        let n = piece.points.len();
        let (nc, mut cells) = (piece.cells.len(), Vec::with_capacity(piece.cells.len()));
        for (i, c) in piece.cells.iter().enumerate() {
            if let Some(k) = c.nodes.iter().find(|&&k| k >= n) {
                return Err(invalid(path, format!("cell {i} names node {k} of {n}")));
            }
            cells.push(c.nodes.iter().map(|&k| k as i64).collect());
        }
        let arrays = |data: &[DataArray], rows, kind| {
            data.iter().map(|a| array(a, rows, kind, path)).collect::<Result<Vec<_>, _>>()
        };
        Ok(MeshFields {
            step,
            points: piece.points.iter().map(|p| [p[0], p[1]]).collect(),
            cell_types: piece.cells.iter().map(|c| c.cell_type.vtk_id()).collect(),
            cells,
            point_arrays: arrays(&piece.point_data, n, "point")?,
            cell_arrays: arrays(&piece.cell_data, nc, "cell")?,
        })
    }
}

impl Snapshot {
    /// The snapshot `s` of Gauss point `id` at `step`, read from `path` (named in errors).
    pub(super) fn from_particles(
        id: GaussPointId,
        step: u64,
        s: ParticleSnapshot,
        path: &Path,
    ) -> Result<Self, OutputError> {
        let n = s.centres.len();
        if let Some(c) = s.contacts.iter().find(|c| c.0 >= n || c.1 >= n) {
            let m = format!("a contact joins discs {} and {} of {n}", c.0, c.1);
            return Err(invalid(path, m));
        }
        Ok(Snapshot {
            element: id.element,
            point: id.point,
            step,
            fluctuation: s.fluctuation,
            contacts: s.contacts.iter().map(|c| [c.0 as i64, c.1 as i64]).collect(),
            normal_force: s.contacts.iter().map(|c| c.2).collect(),
            tangential_force: s.contacts.iter().map(|c| c.3).collect(),
            positions: s.centres,
            radius: s.radius,
            rotation: s.rotation,
        })
    }
}

/// `a` as an [`Array`] of `rows` rows (`kind`: `point` or `cell`), its length checked.
fn array(a: &DataArray, rows: usize, kind: &str, path: &Path) -> Result<Array, OutputError> {
    if a.components == 0 || a.values.len() != rows * a.components {
        let m = format!(
            "{kind} array {:?} has {} values for {rows} {kind}s of {} component(s)",
            a.name,
            a.values.len(),
            a.components
        );
        return Err(invalid(path, m));
    }
    Ok(Array { name: a.name.clone(), components: a.components, values: a.values.clone() })
}

/// Integer ids stored as `f64` (`Int32` in the file: exact).
fn ids(values: &[f64]) -> Vec<i64> {
    values.iter().map(|&v| v as i64).collect()
}

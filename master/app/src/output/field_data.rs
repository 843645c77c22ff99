//! The equivalent-strain field of one step as a small JSON file (`fields/field_NNNNN.json`),
//! written at the job's `field_plots_at` displacements whatever `vtk_every` is, so that
//! `cosdem plot` can draw Fig. 9 from the run directory alone.

use super::{OutputError, Result, io_err, write_atomic};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Mesh, nodal displacements and the Gauss-point equivalent strain (Eq. 34) of one step.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FieldData {
    /// Converged load step.
    pub step: u64,
    /// Macro displacement of the step (m).
    pub displacement: f64,
    /// Internal length lc used in Eq. 34 (m).
    pub internal_length: f64,
    /// Reference node coordinates (m).
    pub nodes: Vec<[f64; 2]>,
    /// Nodal displacements `[u_x, u_y]` (m).
    pub displacements: Vec<[f64; 2]>,
    /// Element node lists (8 or 9 nodes, Gmsh order).
    pub elements: Vec<Vec<usize>>,
    /// Gauss points per element (4, 9 or 16: the tensor rule, xi running fastest).
    pub gauss_per_element: usize,
    /// Equivalent strain per Gauss point, element-major.
    pub equivalent_strain: Vec<f64>,
}

impl FieldData {
    /// Writes the JSON atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        let text = serde_json::to_string(self).map_err(|e| OutputError::InvalidData {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        write_atomic(path, text.as_bytes())
    }

    /// Reads a file written by [`FieldData::write`] and checks its sizes.
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(io_err(path, "read"))?;
        let f: FieldData = serde_json::from_str(&text).map_err(|e| OutputError::InvalidData {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        let bad = |m: String| OutputError::InvalidData { path: path.to_path_buf(), message: m };
        if f.displacements.len() != f.nodes.len() {
            return Err(bad(format!(
                "{} displacements for {} nodes",
                f.displacements.len(),
                f.nodes.len()
            )));
        }
        if f.equivalent_strain.len() != f.elements.len() * f.gauss_per_element {
            return Err(bad(format!(
                "{} equivalent strains for {} elements x {} points",
                f.equivalent_strain.len(),
                f.elements.len(),
                f.gauss_per_element
            )));
        }
        if !matches!(f.gauss_per_element, 4 | 9 | 16) {
            return Err(bad(format!("gauss_per_element = {}", f.gauss_per_element)));
        }
        for (e, nodes) in f.elements.iter().enumerate() {
            if !matches!(nodes.len(), 8 | 9) || nodes.iter().any(|&n| n >= f.nodes.len()) {
                return Err(bad(format!("element {e} has the nodes {nodes:?}")));
            }
        }
        Ok(f)
    }
}

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
    /// Element node lists (8 or 9 nodes of a quadrilateral, 6 of a triangle; Gmsh order).
    pub elements: Vec<Vec<usize>>,
    /// Gauss points per element: 4, 9 or 16 on quadrilaterals (the tensor rule, xi running
    /// fastest), 3 or 6 on triangles (the solver's triangle rule of that many points, in its
    /// order: [`cosdem_fem::element::Quadrature`]).
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
        for (e, nodes) in f.elements.iter().enumerate() {
            if !matches!(nodes.len(), 6 | 8 | 9) || nodes.iter().any(|&n| n >= f.nodes.len()) {
                return Err(bad(format!("element {e} has the nodes {nodes:?}")));
            }
            let rules: &[usize] = if nodes.len() == 6 { &[3, 6] } else { &[4, 9, 16] };
            if !rules.contains(&f.gauss_per_element) {
                return Err(bad(format!(
                    "gauss_per_element = {} for element {e} of {} nodes (expected {rules:?})",
                    f.gauss_per_element,
                    nodes.len()
                )));
            }
        }
        Ok(f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One 6-node triangle (the reference triangle's nodes) with `per` Gauss values.
    fn triangle(per: usize) -> FieldData {
        let nodes = vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.5, 0.0], [0.5, 0.5], [0.0, 0.5]];
        FieldData {
            step: 1,
            displacement: 0.001,
            internal_length: 0.01,
            displacements: vec![[0.0; 2]; 6],
            nodes,
            elements: vec![(0..6).collect()],
            gauss_per_element: per,
            equivalent_strain: vec![1e-3; per],
        }
    }

    /// A triangle's field reads back with the triangle rules' 3 or 6 points; the
    /// quadrilaterals' 4 points on a triangle are refused naming the count and the element.
    #[test]
    fn triangles_take_three_or_six_points() {
        let dir = std::env::temp_dir().join(format!("cosdem-field-data-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("field.json");
        for per in [3, 6] {
            triangle(per).write(&path).unwrap();
            assert_eq!(FieldData::read(&path).unwrap(), triangle(per));
        }
        triangle(4).write(&path).unwrap();
        let e = FieldData::read(&path).unwrap_err().to_string();
        assert!(e.contains("gauss_per_element = 4 for element 0 of 6 nodes"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

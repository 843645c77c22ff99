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
    /// Gauss points of each element: 4, 9 or 16 on quadrilaterals (the tensor rule, xi
    /// running fastest), 3 or 6 on triangles (the solver's triangle rule of that many points,
    /// in its order: [`cosdem_fem::element::Quadrature`]). Files written before meshes could
    /// mix kinds hold one `gauss_per_element` instead; [`FieldData::read`] takes both.
    pub gauss_points: Vec<usize>,
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
        let bad = |m: String| OutputError::InvalidData { path: path.to_path_buf(), message: m };
        let mut value: serde_json::Value =
            serde_json::from_str(&text).map_err(|e| bad(e.to_string()))?;
        if let Some(map) = value.as_object_mut()
            && let Some(per) = map.remove("gauss_per_element")
        {
            let elements = map.get("elements").and_then(|e| e.as_array()).map_or(0, Vec::len);
            map.insert("gauss_points".into(), vec![per; elements].into());
        }
        let f: FieldData = serde_json::from_value(value).map_err(|e| bad(e.to_string()))?;
        if f.displacements.len() != f.nodes.len() {
            return Err(bad(format!(
                "{} displacements for {} nodes",
                f.displacements.len(),
                f.nodes.len()
            )));
        }
        let points: usize = f.gauss_points.iter().sum();
        if f.gauss_points.len() != f.elements.len() || f.equivalent_strain.len() != points {
            return Err(bad(format!(
                "{} equivalent strains for {} elements with {} points in all ({} counts)",
                f.equivalent_strain.len(),
                f.elements.len(),
                points,
                f.gauss_points.len()
            )));
        }
        for (e, nodes) in f.elements.iter().enumerate() {
            if !matches!(nodes.len(), 6 | 8 | 9) || nodes.iter().any(|&n| n >= f.nodes.len()) {
                return Err(bad(format!("element {e} has the nodes {nodes:?}")));
            }
            let rules: &[usize] = if nodes.len() == 6 { &[3, 6] } else { &[4, 9, 16] };
            if !rules.contains(&f.gauss_points[e]) {
                return Err(bad(format!(
                    "gauss_points = {} for element {e} of {} nodes (expected {rules:?})",
                    f.gauss_points[e],
                    nodes.len()
                )));
            }
        }
        Ok(f)
    }

    /// The positions of element `e`'s values in `equivalent_strain`, for every element.
    pub fn point_ranges(&self) -> Vec<std::ops::Range<usize>> {
        let mut start = 0;
        self.gauss_points
            .iter()
            .map(|&n| {
                start += n;
                start - n..start
            })
            .collect()
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
            gauss_points: vec![per],
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
        assert!(e.contains("gauss_points = 4 for element 0 of 6 nodes"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A file of the older form (one `gauss_per_element` for all elements) reads as the
    /// same count for each element, so earlier run directories still plot.
    #[test]
    fn a_file_with_gauss_per_element_reads() {
        let dir = std::env::temp_dir().join(format!("cosdem-field-legacy-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("field.json");
        let text = serde_json::to_string(&triangle(3))
            .unwrap()
            .replace("\"gauss_points\":[3]", "\"gauss_per_element\":3");
        assert!(text.contains("gauss_per_element"), "{text}");
        std::fs::write(&path, text).unwrap();
        assert_eq!(FieldData::read(&path).unwrap(), triangle(3));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

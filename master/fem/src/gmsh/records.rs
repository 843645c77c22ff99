//! The records both format versions (and both encodings) read, before they become a
//! [`RawMesh`](super::RawMesh): nodes, elements, Gmsh's element type table, and the checks on
//! one record.

use super::{GmshError, Result};

/// One node: its Gmsh tag and (x, y).
pub(super) struct NodeRec {
    pub(super) tag: u64,
    pub(super) xy: [f64; 2],
}

/// One element of any type, with the physical groups it belongs to.
pub(super) struct ElemRec {
    pub(super) tag: u64,
    pub(super) gmsh_type: u32,
    /// Dimension of the element (from the type table, or the 4.1 entity block).
    pub(super) dim: Option<u32>,
    /// Physical tags (empty: none).
    pub(super) physicals: Vec<i32>,
    pub(super) nodes: Vec<u64>,
    pub(super) line: usize,
}

/// Gmsh's element types: (description, dimension, node count).
pub(super) fn type_info(t: u32) -> Option<(&'static str, u32, usize)> {
    Some(match t {
        1 => ("2-node line", 1, 2),
        2 => ("3-node triangle", 2, 3),
        3 => ("4-node quadrangle", 2, 4),
        4 => ("4-node tetrahedron", 3, 4),
        5 => ("8-node hexahedron", 3, 8),
        6 => ("6-node prism", 3, 6),
        7 => ("5-node pyramid", 3, 5),
        8 => ("3-node line", 1, 3),
        9 => ("6-node triangle", 2, 6),
        10 => ("9-node quadrangle", 2, 9),
        11 => ("10-node tetrahedron", 3, 10),
        12 => ("27-node hexahedron", 3, 27),
        13 => ("18-node prism", 3, 18),
        14 => ("14-node pyramid", 3, 14),
        15 => ("1-node point", 0, 1),
        16 => ("8-node quadrangle", 2, 8),
        17 => ("20-node hexahedron", 3, 20),
        18 => ("15-node prism", 3, 15),
        19 => ("13-node pyramid", 3, 13),
        20 => ("9-node incomplete triangle", 2, 9),
        21 => ("10-node triangle", 2, 10),
        22 => ("12-node incomplete triangle", 2, 12),
        23 => ("15-node triangle", 2, 15),
        24 => ("15-node incomplete triangle", 2, 15),
        25 => ("21-node triangle", 2, 21),
        26 => ("4-node line", 1, 4),
        27 => ("5-node line", 1, 5),
        28 => ("6-node line", 1, 6),
        36 => ("16-node quadrangle", 2, 16),
        37 => ("25-node quadrangle", 2, 25),
        _ => return None,
    })
}

/// Largest count from the file used to pre-allocate, so a corrupt count cannot exhaust memory.
pub(super) const CAPACITY_HINT: usize = 1 << 16;

/// A node must lie in z = 0 (to within 1e-12 of its distance from the origin) and have
/// finite coordinates.
pub(super) fn check_planar(
    file: &str,
    line: usize,
    tag: u64,
    x: f64,
    y: f64,
    z: f64,
) -> Result<()> {
    let scale = x.abs().max(y.abs()).max(1.0);
    if z.abs() > 1e-12 * scale || !z.is_finite() {
        return Err(GmshError::NonPlanar { file: file.to_string(), line, node: tag, z });
    }
    if !x.is_finite() || !y.is_finite() {
        return Err(GmshError::Syntax {
            file: file.to_string(),
            line,
            message: format!("node {tag} has a non-finite coordinate ({x}, {y})"),
        });
    }
    Ok(())
}

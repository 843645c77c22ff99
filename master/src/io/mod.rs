//! Reading the macro solver's input files into plain data.
//!
//! Nothing here knows the finite-element types: readers return raw descriptions (node
//! coordinates, connectivity, named groups) that the mesh code turns into its own structures.

/// Gmsh `.msh` meshes (ASCII 2.2 and 4.1, binary 4.1) of 8- and 9-node quadrilaterals.
pub mod gmsh;

pub use gmsh::{GmshError, QuadKind, RawElement, RawMesh, parse_msh, parse_msh_bytes, read_msh};

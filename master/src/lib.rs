//! The cosdem master: the Cosserat finite-element macro solver.

/// Reading input files (Gmsh meshes) into plain data.
pub mod io;
/// The constitutive operator at the Gauss points: the trait the FE solver talks to.
pub mod material;
/// Writing results: VTK unstructured grids, ParaView collections, CSV curves.
pub mod output;

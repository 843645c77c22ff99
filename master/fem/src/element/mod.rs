//! Reference elements: shape functions, quadrature, the isoparametric map and shape checks.
//!
//! Node order is Gmsh's for the 8-node (type 16) and 9-node (type 10) quadrilaterals:
//! corners 0-3 counter-clockwise from (-1,-1), mid-edge nodes 4 (0-1), 5 (1-2), 6 (2-3),
//! 7 (3-0), centre 8; and for the 6-node triangle (type 9): corners 0, 1, 2 at (0,0),
//! (1,0), (0,1) of the reference triangle, mid-side nodes 3 (0-1), 4 (1-2), 5 (2-0).

mod check;
mod quadrature;
mod shape;

pub use check::{MAX_MID_NODE_OFFSET, shape_defect};
pub use quadrature::{Quadrature, QuadratureRule, gauss_1d};
pub use shape::{ElementKind, ShapeAt, edge_shape, shape_at};

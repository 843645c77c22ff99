//! Reference elements: shape functions, quadrature and the isoparametric map.
//!
//! Node order is Gmsh's for the 8-node (type 16) and 9-node (type 10) quadrilaterals:
//! corners 0-3 counter-clockwise from (-1,-1), mid-edge nodes 4 (0-1), 5 (1-2), 6 (2-3),
//! 7 (3-0), centre 8.

mod quadrature;
mod shape;

pub use quadrature::{Quadrature, QuadratureRule, gauss_1d};
pub use shape::{ElementKind, ShapeAt, edge_shape, shape_at};

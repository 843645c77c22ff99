//! Identity of a Gauss point: the element and the quadrature point within it.

use serde::{Deserialize, Serialize};
use std::fmt;

/// A Gauss point of the macro mesh. Also the identity of the DEM assembly that backs it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct GaussPointId {
    /// Element index in the mesh (0-based).
    pub element: u32,
    /// Quadrature point index within the element (0-based).
    pub point: u32,
}

impl GaussPointId {
    /// A Gauss point id.
    pub const fn new(element: u32, point: u32) -> Self {
        Self { element, point }
    }
}

impl fmt::Display for GaussPointId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "element {} gauss point {}", self.element, self.point)
    }
}

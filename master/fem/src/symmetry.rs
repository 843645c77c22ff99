//! Symmetric scenes on a half or quarter mesh (issue 6, item 3d).
//!
//! A rectangle panel whose geometry, loads and material are mirror-symmetric about its
//! vertical mid-line can be solved on its left half: on the axis `u_x = 0` and, for the
//! Cosserat field, `w = 0` (a micro-rotation is a pseudo-scalar: mirroring flips its sign, so a
//! symmetric solution has `w = 0` on the axis). If it is also symmetric about its horizontal
//! mid-line (a compression with both platens moving by half), the lower-left quarter suffices,
//! with `u_y = 0` and `w = 0` on the horizontal axis.
//!
//! In the reduced mesh the structured node and edge sets keep their names, so `right` (and,
//! for the quarter, `top`) *are* the axes. Loads and prescribed values the job puts on the
//! removed side (`right`, `top_right`, `bottom_right`; for the quarter also `top`,
//! `top_left`) are the mirror images of those on the kept side and are dropped; the platen on
//! the removed top of a quarter is replaced by the axis condition. The curve's load is the
//! reaction of `load_set` over the reduced width, so it is doubled ([`Symmetry::load_scale`]):
//! for the quarter the default `load_set = "top"` is the horizontal axis, which carries the
//! same vertical force as the platen.
//!
//! [`Symmetry::load_scale`]: crate::symmetry::Symmetry::load_scale

use crate::assembly::{Component, Field};
use crate::solve::{Dirichlet, Loading};
use serde::{Deserialize, Serialize};

/// Which part of a symmetric rectangle is meshed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Symmetry {
    /// The whole panel.
    #[default]
    None,
    /// The left half, symmetric about the vertical mid-line.
    #[serde(alias = "half-x")]
    HalfX,
    /// The lower-left quarter, symmetric about both mid-lines.
    Quarter,
}

impl Symmetry {
    /// Factor from the reduced mesh's reaction to the whole panel's load.
    pub fn load_scale(self) -> f64 {
        match self {
            Symmetry::None => 1.0,
            Symmetry::HalfX | Symmetry::Quarter => 2.0,
        }
    }

    /// Element counts and size of the reduced rectangle: `(lx, ly, nx, ny)`.
    pub fn reduce_rectangle(
        self,
        lx: f64,
        ly: f64,
        nx: usize,
        ny: usize,
    ) -> (f64, f64, usize, usize) {
        match self {
            Symmetry::None => (lx, ly, nx, ny),
            Symmetry::HalfX => (0.5 * lx, ly, nx / 2, ny),
            Symmetry::Quarter => (0.5 * lx, 0.5 * ly, nx / 2, ny / 2),
        }
    }

    /// Sets of the whole panel that lie on the removed part.
    fn removed(self) -> &'static [&'static str] {
        match self {
            Symmetry::None => &[],
            Symmetry::HalfX => &["right", "top_right", "bottom_right"],
            Symmetry::Quarter => &["right", "top_right", "bottom_right", "top", "top_left"],
        }
    }

    /// The whole panel's loading turned into the reduced mesh's: conditions on removed sets
    /// dropped (a smooth platen's pin too: the axis fixes the rigid motion), the axis
    /// conditions appended (they win over anything earlier on the same dofs).
    pub fn reduce_loading(self, mut loading: Loading, field: Field) -> Loading {
        if self == Symmetry::None {
            return loading;
        }
        let removed = self.removed();
        let pin = |d: &Dirichlet| {
            d.set == "bottom_left" && d.component == Component::Ux && d.value == 0.0
        };
        loading.dirichlet.retain(|d| !removed.contains(&d.set.as_str()) && !pin(d));
        loading.edge_loads.retain(|e| !removed.contains(&e.set.as_str()));
        let cosserat = field == Field::Cosserat;
        loading.dirichlet.push(Dirichlet::new("right", Component::Ux, 0.0));
        if cosserat {
            loading.dirichlet.push(Dirichlet::new("right", Component::W, 0.0));
        }
        if self == Symmetry::Quarter {
            loading.dirichlet.push(Dirichlet::new("top", Component::Uy, 0.0));
            if cosserat {
                loading.dirichlet.push(Dirichlet::new("top", Component::W, 0.0));
            }
        }
        loading
    }
}

//! Mapped shape functions at every Gauss point of the mesh, computed once.

use crate::element::{Quadrature, QuadratureRule, shape_at};
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use cosdem_common::GaussPointId;

/// Shape functions, physical gradients, weights and positions of all Gauss points.
///
/// Gauss point `g = element * per_element + point`.
#[derive(Clone, Debug, PartialEq)]
pub struct GaussData {
    /// Nodes per element.
    pub nodes_per_element: usize,
    /// Gauss points per element.
    pub per_element: usize,
    /// `N_a` at each point (`nodes_per_element` per point).
    pub n: Vec<f64>,
    /// `[dN_a/dx, dN_a/dy]` at each point.
    pub grad: Vec<[f64; 2]>,
    /// Quadrature weight times Jacobian determinant (the area the point stands for).
    pub weight: Vec<f64>,
    /// Physical position.
    pub x: Vec<[f64; 2]>,
}

impl GaussData {
    /// Maps `rule` onto every element; fails on an inverted element, and on a rule that does
    /// not fit the mesh's elements (a square rule on triangles or the reverse: see
    /// [`QuadratureRule::for_kind`]).
    pub fn new(mesh: &Mesh, rule: QuadratureRule) -> Result<Self> {
        if !rule.fits(mesh.kind) {
            return Err(Error::InvalidSetting {
                field: "rule",
                value: format!("{rule:?}"),
                reason: format!(
                    "not a rule of {:?} elements; their reduced and full rules are {:?} and {:?}",
                    mesh.kind,
                    QuadratureRule::for_kind(mesh.kind, false),
                    QuadratureRule::for_kind(mesh.kind, true)
                ),
            });
        }
        let q = Quadrature::new(rule);
        let nn = mesh.kind.nodes();
        let total = mesh.n_elements() * q.len();
        let mut data = Self {
            nodes_per_element: nn,
            per_element: q.len(),
            n: Vec::with_capacity(total * nn),
            grad: Vec::with_capacity(total * nn),
            weight: Vec::with_capacity(total),
            x: Vec::with_capacity(total),
        };
        for e in 0..mesh.n_elements() {
            let coords = mesh.element_coords(e);
            for (p, w) in q.points.iter().zip(&q.weights) {
                let s = shape_at(mesh.kind, e, &coords, *p)?;
                data.n.extend_from_slice(&s.n);
                data.grad.extend_from_slice(&s.grad);
                data.weight.push(w * s.det_j);
                data.x.push(s.x);
            }
        }
        Ok(data)
    }

    /// Total number of Gauss points.
    pub fn len(&self) -> usize {
        self.weight.len()
    }

    /// True when the mesh has no Gauss points.
    pub fn is_empty(&self) -> bool {
        self.weight.is_empty()
    }

    /// Identity of Gauss point `g`.
    pub fn id(&self, g: usize) -> GaussPointId {
        GaussPointId::new((g / self.per_element) as u32, (g % self.per_element) as u32)
    }

    /// Shape values of point `g`.
    pub fn shape(&self, g: usize) -> &[f64] {
        &self.n[g * self.nodes_per_element..(g + 1) * self.nodes_per_element]
    }

    /// Shape gradients of point `g`.
    pub fn gradient(&self, g: usize) -> &[[f64; 2]] {
        &self.grad[g * self.nodes_per_element..(g + 1) * self.nodes_per_element]
    }
}

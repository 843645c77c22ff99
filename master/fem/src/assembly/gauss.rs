//! Mapped shape functions at every Gauss point of the mesh, computed once.

use crate::element::{ElementKind, Quadrature, QuadratureRule, shape_at};
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use cosdem_common::GaussPointId;
use std::ops::Range;

/// Shape functions, physical gradients, weights and positions of all Gauss points.
///
/// Points are numbered element by element: element `e` holds `points(e)`, in its rule's
/// order. On a mesh of one kind every element holds as many; a mesh mixing triangles and
/// quadrilaterals integrates each with its family's rule of the same role
/// ([`QuadratureRule::on`]).
#[derive(Clone, Debug, PartialEq)]
pub struct GaussData {
    /// First point of each element, and the number of points last.
    pub element_start: Vec<usize>,
    /// Element of each point.
    pub element: Vec<u32>,
    /// Start of each point's entries in `n` and `grad` (as many as its element has nodes),
    /// and their length last.
    pub shape_start: Vec<usize>,
    /// `N_a` at each point.
    pub n: Vec<f64>,
    /// `[dN_a/dx, dN_a/dy]` at each point.
    pub grad: Vec<[f64; 2]>,
    /// Quadrature weight times Jacobian determinant (the area the point stands for).
    pub weight: Vec<f64>,
    /// Physical position.
    pub x: Vec<[f64; 2]>,
}

impl GaussData {
    /// Maps `rule` onto every element it fits and its counterpart ([`QuadratureRule::on`])
    /// onto the others; fails on an inverted element, and on a rule that fits none of the
    /// mesh's elements (a square rule on a mesh of triangles or the reverse: see
    /// [`QuadratureRule::for_kind`]).
    pub fn new(mesh: &Mesh, rule: QuadratureRule) -> Result<Self> {
        if !mesh.kinds.iter().any(|&k| rule.fits(k)) {
            let kind = mesh.kinds[0];
            return Err(Error::InvalidSetting {
                field: "rule",
                value: format!("{rule:?}"),
                reason: format!(
                    "not a rule of {kind:?} elements; their reduced and full rules are {:?} \
                     and {:?}",
                    QuadratureRule::for_kind(kind, false),
                    QuadratureRule::for_kind(kind, true)
                ),
            });
        }
        let (square, triangle) =
            (Quadrature::new(rule.on(ElementKind::Q8)), Quadrature::new(rule.on(ElementKind::T6)));
        let mut data = Self {
            element_start: Vec::with_capacity(mesh.n_elements() + 1),
            element: Vec::new(),
            shape_start: vec![0],
            n: Vec::new(),
            grad: Vec::new(),
            weight: Vec::new(),
            x: Vec::new(),
        };
        for e in 0..mesh.n_elements() {
            let kind = mesh.element_kind(e);
            let q = if kind.is_triangle() { &triangle } else { &square };
            let coords = mesh.element_coords(e);
            data.element_start.push(data.weight.len());
            for (p, w) in q.points.iter().zip(&q.weights) {
                let s = shape_at(kind, e, &coords, *p)?;
                data.n.extend_from_slice(&s.n);
                data.grad.extend_from_slice(&s.grad);
                data.shape_start.push(data.n.len());
                data.weight.push(w * s.det_j);
                data.x.push(s.x);
                data.element.push(e as u32);
            }
        }
        data.element_start.push(data.weight.len());
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

    /// The points of element `e`.
    pub fn points(&self, e: usize) -> Range<usize> {
        self.element_start[e]..self.element_start[e + 1]
    }

    /// The number of points of each element.
    pub fn counts(&self) -> Vec<usize> {
        self.element_start.windows(2).map(|w| w[1] - w[0]).collect()
    }

    /// The element point `g` belongs to.
    pub fn element_of(&self, g: usize) -> usize {
        self.element[g] as usize
    }

    /// Identity of Gauss point `g`.
    pub fn id(&self, g: usize) -> GaussPointId {
        let e = self.element_of(g);
        GaussPointId::new(e as u32, (g - self.element_start[e]) as u32)
    }

    /// Every point's identity, in order.
    pub fn ids(&self) -> Vec<GaussPointId> {
        (0..self.len()).map(|g| self.id(g)).collect()
    }

    /// Shape values of point `g`.
    pub fn shape(&self, g: usize) -> &[f64] {
        &self.n[self.shape_start[g]..self.shape_start[g + 1]]
    }

    /// Shape gradients of point `g`.
    pub fn gradient(&self, g: usize) -> &[[f64; 2]] {
        &self.grad[self.shape_start[g]..self.shape_start[g + 1]]
    }
}

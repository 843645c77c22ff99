//! Integration rules: tensor-product Gauss-Legendre rules on the reference square
//! [-1, 1]^2 for the quadrilaterals, symmetric rules on the reference triangle
//! (`xi, eta >= 0`, `xi + eta <= 1`) for the triangles.
//!
//! A rule belongs to one reference element: [`QuadratureRule::fits`] tells whether it suits
//! an element kind, and [`QuadratureRule::for_kind`] picks the reduced or full rule of a kind
//! (what a job's `integration = "reduced" | "full"` means for that kind), and
//! [`QuadratureRule::on`] gives the rule of the same role on another reference element: a
//! mesh mixing triangles and quadrilaterals integrates each family with its own rule.

use super::ElementKind;

/// Which integration rule the elements use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum QuadratureRule {
    /// 2x2 Gauss points: reduced integration of the 8-node element (the paper's choice).
    Gauss2x2,
    /// 3x3 Gauss points: full integration of quadratic elements.
    Gauss3x3,
    /// 4x4 Gauss points: used for error norms.
    Gauss4x4,
    /// 3 points on the triangle, exact to degree 2: at `(1/6, 1/6)`, `(2/3, 1/6)`,
    /// `(1/6, 2/3)`, weights 1/6. Exact stiffness of a straight-sided 6-node triangle in
    /// the Cauchy terms (gradients are linear); the reduced rule of the 6-node triangle.
    Triangle3,
    /// 6 points on the triangle, exact to degree 4 (Strang and Fix; Dunavant's degree-4
    /// rule): exact for every term of a straight-sided 6-node triangle, including the
    /// Cosserat `N N` terms; the full rule of the 6-node triangle.
    Triangle6,
    /// 16 points on the triangle: 4x4 Gauss points on the square collapsed onto the
    /// triangle (Duffy), exact to degree 6; used for error norms, like `Gauss4x4`.
    Triangle16,
}

impl QuadratureRule {
    /// Points per direction of a tensor-product rule on the square; for a triangle rule, the
    /// points per direction of the square rule it comes from (`Triangle16`: 4) or, for the
    /// symmetric rules, 0.
    pub const fn order(self) -> usize {
        match self {
            Self::Gauss2x2 => 2,
            Self::Gauss3x3 => 3,
            Self::Gauss4x4 | Self::Triangle16 => 4,
            Self::Triangle3 | Self::Triangle6 => 0,
        }
    }

    /// True for the rules on the reference triangle.
    pub const fn is_triangle(self) -> bool {
        matches!(self, Self::Triangle3 | Self::Triangle6 | Self::Triangle16)
    }

    /// Whether the rule is defined on the reference element of `kind`.
    pub const fn fits(self, kind: ElementKind) -> bool {
        self.is_triangle() == kind.is_triangle()
    }

    /// The rule of the same role on the reference element of `kind`: itself when it fits,
    /// otherwise its counterpart (reduced `Gauss2x2` / `Triangle3`, full `Gauss3x3` /
    /// `Triangle6`, error norms `Gauss4x4` / `Triangle16`).
    pub const fn on(self, kind: ElementKind) -> Self {
        if self.fits(kind) {
            return self;
        }
        match self {
            Self::Gauss2x2 => Self::Triangle3,
            Self::Gauss3x3 => Self::Triangle6,
            Self::Gauss4x4 => Self::Triangle16,
            Self::Triangle3 => Self::Gauss2x2,
            Self::Triangle6 => Self::Gauss3x3,
            Self::Triangle16 => Self::Gauss4x4,
        }
    }

    /// The reduced (`full = false`) or full rule of an element kind: Q8 and Q9 `Gauss2x2` /
    /// `Gauss3x3`, T6 `Triangle3` / `Triangle6`.
    pub const fn for_kind(kind: ElementKind, full: bool) -> Self {
        match (kind.is_triangle(), full) {
            (false, false) => Self::Gauss2x2,
            (false, true) => Self::Gauss3x3,
            (true, false) => Self::Triangle3,
            (true, true) => Self::Triangle6,
        }
    }
}

/// Points and weights of a rule on its reference element.
///
/// On the square: point `p = i_eta * n + i_xi` (xi runs fastest); this is the `point` of a
/// `GaussPointId`. On the triangle: the order of [`Quadrature::new`]'s listing.
#[derive(Clone, Debug, PartialEq)]
pub struct Quadrature {
    /// Reference coordinates `[xi, eta]`.
    pub points: Vec<[f64; 2]>,
    /// Weights (they sum to 4 on the square, 1/2 on the triangle).
    pub weights: Vec<f64>,
}

/// 1D Gauss-Legendre points and weights on [-1, 1] (`n` = 2, 3 or 4).
pub fn gauss_1d(n: usize) -> (Vec<f64>, Vec<f64>) {
    match n {
        2 => {
            let a = 1.0 / 3f64.sqrt();
            (vec![-a, a], vec![1.0, 1.0])
        }
        3 => {
            let a = (3.0f64 / 5.0).sqrt();
            (vec![-a, 0.0, a], vec![5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0])
        }
        4 => {
            let a = (3.0 / 7.0 - 2.0 / 7.0 * (6.0f64 / 5.0).sqrt()).sqrt();
            let b = (3.0 / 7.0 + 2.0 / 7.0 * (6.0f64 / 5.0).sqrt()).sqrt();
            let wa = (18.0 + 30f64.sqrt()) / 36.0;
            let wb = (18.0 - 30f64.sqrt()) / 36.0;
            (vec![-b, -a, a, b], vec![wb, wa, wa, wb])
        }
        _ => unreachable!("only 2, 3 and 4 point rules are defined"),
    }
}

impl Quadrature {
    /// The points and weights of `rule`.
    ///
    /// `Triangle3` lists `(1/6, 1/6)`, `(2/3, 1/6)`, `(1/6, 2/3)`; `Triangle6` the orbit
    /// `(a, a)`, `(1 - 2a, a)`, `(a, 1 - 2a)` of `a = 0.4459...`, then of `a = 0.0915...`;
    /// `Triangle16` the collapsed 4x4 points, `xi = (1 + u)(1 - v) / 4`, `eta = (1 + v) / 2`
    /// with weight `w_u w_v (1 - v) / 8`, `u` running fastest.
    pub fn new(rule: QuadratureRule) -> Self {
        match rule {
            QuadratureRule::Triangle3 => {
                let (a, b) = (1.0 / 6.0, 2.0 / 3.0);
                Self { points: vec![[a, a], [b, a], [a, b]], weights: vec![1.0 / 6.0; 3] }
            }
            QuadratureRule::Triangle6 => {
                // Closed forms of the degree-4 rule (weights for the unit-area triangle, so
                // halved here).
                let s = (38.0 - 44.0 * (0.4f64).sqrt()).sqrt();
                let t = (213125.0 - 53320.0 * 10f64.sqrt()).sqrt();
                let orbits = [
                    ((8.0 - 10f64.sqrt() + s) / 18.0, (620.0 + t) / 3720.0),
                    ((8.0 - 10f64.sqrt() - s) / 18.0, (620.0 - t) / 3720.0),
                ];
                let mut q = Self { points: Vec::new(), weights: Vec::new() };
                for (a, w) in orbits {
                    let c = 1.0 - 2.0 * a;
                    q.points.extend([[a, a], [c, a], [a, c]]);
                    q.weights.extend([0.5 * w; 3]);
                }
                q
            }
            QuadratureRule::Triangle16 => {
                let (x, w) = gauss_1d(4);
                let mut q = Self { points: Vec::new(), weights: Vec::new() };
                for j in 0..x.len() {
                    for i in 0..x.len() {
                        let (u, v) = (x[i], x[j]);
                        q.points.push([(1.0 + u) * (1.0 - v) / 4.0, (1.0 + v) / 2.0]);
                        q.weights.push(w[i] * w[j] * (1.0 - v) / 8.0);
                    }
                }
                q
            }
            QuadratureRule::Gauss2x2 | QuadratureRule::Gauss3x3 | QuadratureRule::Gauss4x4 => {
                Self::square(rule.order())
            }
        }
    }

    /// The tensor-product rule of `n` points per direction on the square.
    fn square(n: usize) -> Self {
        let (x, w) = gauss_1d(n);
        let mut points = Vec::new();
        let mut weights = Vec::new();
        for j in 0..x.len() {
            for i in 0..x.len() {
                points.push([x[i], x[j]]);
                weights.push(w[i] * w[j]);
            }
        }
        Self { points, weights }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// True for an empty rule (never for the rules defined here).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `on` keeps a rule on its own element and swaps it for the counterpart of the same
    /// role on the other: what integrates a mixed mesh with one `integration` setting.
    #[test]
    fn on_maps_each_rule_to_the_same_role() {
        for full in [false, true] {
            for kind in [ElementKind::Q8, ElementKind::Q9, ElementKind::T6] {
                for from in [ElementKind::Q8, ElementKind::T6] {
                    let rule = QuadratureRule::for_kind(from, full);
                    assert_eq!(rule.on(kind), QuadratureRule::for_kind(kind, full));
                }
            }
        }
        assert_eq!(QuadratureRule::Gauss4x4.on(ElementKind::T6), QuadratureRule::Triangle16);
        assert_eq!(QuadratureRule::Triangle16.on(ElementKind::Q9), QuadratureRule::Gauss4x4);
    }

    /// Each rule integrates x^a y^b exactly up to degree 2n-1 per direction.
    #[test]
    fn rules_integrate_polynomials_exactly() {
        for rule in [QuadratureRule::Gauss2x2, QuadratureRule::Gauss3x3, QuadratureRule::Gauss4x4] {
            assert!(!rule.is_triangle());
            let q = Quadrature::new(rule);
            let n = rule.order() as i32;
            for a in 0..2 * n {
                for b in 0..2 * n {
                    let num: f64 = q
                        .points
                        .iter()
                        .zip(&q.weights)
                        .map(|(p, w)| w * p[0].powi(a) * p[1].powi(b))
                        .sum();
                    let exact_1d = |k: i32| if k % 2 == 1 { 0.0 } else { 2.0 / (k + 1) as f64 };
                    let exact = exact_1d(a) * exact_1d(b);
                    assert!((num - exact).abs() < 1e-14, "{rule:?} x^{a} y^{b}: {num} vs {exact}");
                }
            }
        }
    }

    /// Each triangle rule integrates every monomial `xi^a eta^b` of its degree (2, 4, 6)
    /// exactly: the exact value is `a! b! / (a + b + 2)!`. Tolerance 1e-15 on values of
    /// order 1e-1..1e-4: the weights and points are exact to an ulp or two (closed forms),
    /// and sums of at most 16 terms lose no more. One degree higher, each rule misses some
    /// monomial by more than 1e-6 (so the test would notice a rule of the wrong degree).
    #[test]
    fn triangle_rules_integrate_monomials_exactly() {
        let fact = |n: i32| (1..=n).map(f64::from).product::<f64>();
        for (rule, degree) in [
            (QuadratureRule::Triangle3, 2),
            (QuadratureRule::Triangle6, 4),
            (QuadratureRule::Triangle16, 6),
        ] {
            assert!(rule.is_triangle());
            let q = Quadrature::new(rule);
            assert!(q.points.iter().all(|p| p[0] > 0.0 && p[1] > 0.0 && p[0] + p[1] < 1.0));
            let mut worst_above = 0.0f64;
            for d in 0..=degree + 1 {
                for a in 0..=d {
                    let b = d - a;
                    let num: f64 = q
                        .points
                        .iter()
                        .zip(&q.weights)
                        .map(|(p, w)| w * p[0].powi(a) * p[1].powi(b))
                        .sum();
                    let exact = fact(a) * fact(b) / fact(a + b + 2);
                    if d <= degree {
                        assert!(
                            (num - exact).abs() < 1e-15,
                            "{rule:?} x^{a} y^{b}: {num} vs {exact}"
                        );
                    } else {
                        worst_above = worst_above.max((num - exact).abs());
                    }
                }
            }
            assert!(worst_above > 1e-6, "{rule:?} is exact beyond degree {degree}");
        }
    }

    /// The rule of each kind fits it, and no quadrilateral rule fits a triangle (or the
    /// reverse).
    #[test]
    fn rules_are_chosen_per_kind() {
        use ElementKind::{Q8, Q9, T6};
        assert_eq!(QuadratureRule::for_kind(Q8, false), QuadratureRule::Gauss2x2);
        assert_eq!(QuadratureRule::for_kind(Q9, true), QuadratureRule::Gauss3x3);
        assert_eq!(QuadratureRule::for_kind(T6, false), QuadratureRule::Triangle3);
        assert_eq!(QuadratureRule::for_kind(T6, true), QuadratureRule::Triangle6);
        for kind in [Q8, Q9, T6] {
            for full in [false, true] {
                assert!(QuadratureRule::for_kind(kind, full).fits(kind));
            }
        }
        assert!(!QuadratureRule::Gauss2x2.fits(T6) && !QuadratureRule::Triangle6.fits(Q8));
    }
}

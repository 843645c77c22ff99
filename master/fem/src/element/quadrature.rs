//! Tensor-product Gauss-Legendre rules on the reference square [-1, 1]^2.

/// Which integration rule the elements use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum QuadratureRule {
    /// 2x2 Gauss points: reduced integration of the 8-node element (the paper's choice).
    Gauss2x2,
    /// 3x3 Gauss points: full integration of quadratic elements.
    Gauss3x3,
    /// 4x4 Gauss points: used for error norms.
    Gauss4x4,
}

impl QuadratureRule {
    /// Points per direction.
    pub const fn order(self) -> usize {
        match self {
            Self::Gauss2x2 => 2,
            Self::Gauss3x3 => 3,
            Self::Gauss4x4 => 4,
        }
    }
}

/// Points and weights of a rule on [-1, 1]^2.
///
/// Point `p = i_eta * n + i_xi` (xi runs fastest); this is the `point` of a `GaussPointId`.
#[derive(Clone, Debug, PartialEq)]
pub struct Quadrature {
    /// Reference coordinates `[xi, eta]`.
    pub points: Vec<[f64; 2]>,
    /// Weights (they sum to 4).
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
    /// The tensor-product rule.
    pub fn new(rule: QuadratureRule) -> Self {
        let (x, w) = gauss_1d(rule.order());
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

    /// Each rule integrates x^a y^b exactly up to degree 2n-1 per direction.
    #[test]
    fn rules_integrate_polynomials_exactly() {
        for rule in [QuadratureRule::Gauss2x2, QuadratureRule::Gauss3x3, QuadratureRule::Gauss4x4] {
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
}

//! Linear-elastic Cosserat material, THEORY.md Eq. 8 (plane strain).

use super::{Material, MaterialError, MaterialInput, TrialId};
use cosdem_common::{MicroDiagnostics, MicroResponse, Tangent};

/// `s_xx = (lam+2G) e_xx + lam e_yy`, `s_xy = (G+Gc) e_xy + (G-Gc) e_yx`,
/// `s_yx = (G-Gc) e_xy + (G+Gc) e_yx`, `m_i = 2 G lc^2 k_i`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ElasticCosserat {
    /// Lame's first parameter `lam = 2 G nu / (1 - 2 nu)` (Pa).
    pub lambda: f64,
    /// Shear modulus `G` (Pa).
    pub shear: f64,
    /// Cosserat coupling modulus `Gc` (Pa); 0 decouples the micro-rotation from `u`.
    pub coupling: f64,
    /// Internal length `lc` (m).
    pub length: f64,
}

impl ElasticCosserat {
    /// From shear modulus, Poisson ratio, coupling modulus and internal length.
    pub fn new(shear: f64, poisson: f64, coupling: f64, length: f64) -> Self {
        Self { lambda: 2.0 * shear * poisson / (1.0 - 2.0 * poisson), shear, coupling, length }
    }

    /// The constant 6x6 tangent.
    pub fn tangent(&self) -> Tangent {
        let (l, g, gc) = (self.lambda, self.shear, self.coupling);
        let b = 2.0 * g * self.length * self.length;
        [
            [l + 2.0 * g, l, 0.0, 0.0, 0.0, 0.0],
            [l, l + 2.0 * g, 0.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, g + gc, g - gc, 0.0, 0.0],
            [0.0, 0.0, g - gc, g + gc, 0.0, 0.0],
            [0.0, 0.0, 0.0, 0.0, b, 0.0],
            [0.0, 0.0, 0.0, 0.0, 0.0, b],
        ]
    }

    /// Stress and couple stress of a strain vector.
    pub fn stress(&self, e: &[f64; 6]) -> [f64; 6] {
        let d = self.tangent();
        std::array::from_fn(|i| (0..6).map(|j| d[i][j] * e[j]).sum())
    }
}

impl Material for ElasticCosserat {
    fn evaluate(
        &mut self,
        _trial: TrialId,
        inputs: &[MaterialInput],
    ) -> Result<Vec<MicroResponse>, MaterialError> {
        let tangent = self.tangent();
        Ok(inputs
            .iter()
            .map(|i| MicroResponse {
                stress: self.stress(&i.deformation.strain()),
                tangent,
                diagnostics: MicroDiagnostics { converged: true, ..Default::default() },
            })
            .collect())
    }

    fn commit(&mut self, _step: u64) -> Result<(), MaterialError> {
        Ok(())
    }

    fn rollback(&mut self) -> Result<(), MaterialError> {
        Ok(())
    }

    fn is_symmetric(&self) -> bool {
        true
    }
}

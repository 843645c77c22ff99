//! A nonlinear, softening test material with its exact (non-symmetric) tangent.

use super::elastic::ElasticCosserat;
use super::{Material, MaterialError, MaterialInput, TrialId};
use cosdem_common::{MicroDiagnostics, MicroResponse};

/// `s = D e / (1 + beta |e|^2)` with `D` the elastic Cosserat matrix: the stress along a
/// proportional path peaks at `|e| = 1/sqrt(beta)` and softens after it.
///
/// Exact tangent: `C = D / (1 + beta q) - 2 beta (D e) e^T / (1 + beta q)^2`, `q = e . e`
/// (not symmetric). Path independent, so commit and rollback have nothing to do.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SofteningElastic {
    /// The initial (small-strain) elastic law.
    pub elastic: ElasticCosserat,
    /// Softening parameter `beta` (1 / strain^2).
    pub beta: f64,
}

impl SofteningElastic {
    /// Stress and exact tangent at strain `e`.
    pub fn response(&self, e: &[f64; 6]) -> MicroResponse {
        let d = self.elastic.tangent();
        let de = self.elastic.stress(e);
        let q: f64 = e.iter().map(|v| v * v).sum();
        let den = 1.0 + self.beta * q;
        let stress = de.map(|v| v / den);
        let mut tangent = [[0.0; 6]; 6];
        for i in 0..6 {
            for j in 0..6 {
                tangent[i][j] = d[i][j] / den - 2.0 * self.beta * de[i] * e[j] / (den * den);
            }
        }
        MicroResponse {
            stress,
            tangent,
            diagnostics: MicroDiagnostics { converged: true, ..Default::default() },
        }
    }
}

impl Material for SofteningElastic {
    fn evaluate(
        &mut self,
        _trial: TrialId,
        inputs: &[MaterialInput],
    ) -> Result<Vec<MicroResponse>, MaterialError> {
        Ok(inputs.iter().map(|i| self.response(&i.deformation.strain())).collect())
    }

    fn commit(&mut self, _step: u64) -> Result<(), MaterialError> {
        Ok(())
    }

    fn rollback(&mut self) -> Result<(), MaterialError> {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tangent matches central differences of the stress (h = 1e-7 on strains ~1e-2:
    /// truncation ~h^2 |s'''| and round-off ~1e-16 |s| / h, both << 1e-4 relative).
    #[test]
    fn tangent_matches_finite_differences() {
        let m = SofteningElastic { elastic: ElasticCosserat::new(1e6, 0.3, 5e5, 0.1), beta: 400.0 };
        let e = [0.01, -0.02, 0.015, -0.005, 0.03, 0.02];
        let c = m.response(&e).tangent;
        let h = 1e-7;
        for j in 0..6 {
            let (mut ep, mut em) = (e, e);
            ep[j] += h;
            em[j] -= h;
            let (sp, sm) = (m.response(&ep).stress, m.response(&em).stress);
            for i in 0..6 {
                let fd = (sp[i] - sm[i]) / (2.0 * h);
                assert!((fd - c[i][j]).abs() <= 1e-6 * 1e6 + 1e-5 * c[i][j].abs(), "C[{i}][{j}]");
            }
        }
    }
}

//! DEM assemblies solved directly in this thread, one after the other: no pool, no RPC, no
//! threads. What the size study runs (many small runs side by side, each single-threaded),
//! and the simplest DEM-backed [`Material`] for tests.

use cosdem_common::micro::AssemblyState;
use cosdem_common::{GaussPointId, MicroResponse};
use cosdem_dem::{Assembly, AssemblySpec};
use cosdem_fem::material::{Material, MaterialError, MaterialInput, TrialId};
use std::collections::BTreeMap;

/// One [`Assembly`] per Gauss point, solved sequentially on the caller's thread.
///
/// Same contract as the pool: every evaluation starts from the committed states; a relaxation
/// that hits its step cap fails its Gauss point.
pub struct DirectDem {
    assemblies: BTreeMap<GaussPointId, Assembly>,
    committed_step: u64,
}

impl DirectDem {
    /// Builds one assembly of `spec` for each id (all identical: built once and cloned).
    pub fn new(spec: &AssemblySpec, ids: &[GaussPointId]) -> Result<Self, MaterialError> {
        let proto = Assembly::new(spec)
            .map_err(|e| MaterialError::Unavailable(format!("building the assembly: {e}")))?;
        let assemblies = ids.iter().map(|id| (*id, proto.clone())).collect();
        Ok(Self { assemblies, committed_step: 0 })
    }

    /// Discs per assembly (0 without assemblies).
    pub fn disc_count(&self) -> usize {
        self.assemblies.values().next().map_or(0, Assembly::disc_count)
    }
}

impl Material for DirectDem {
    fn evaluate(
        &mut self,
        _trial: TrialId,
        inputs: &[MaterialInput],
    ) -> Result<Vec<MicroResponse>, MaterialError> {
        let mut out = Vec::with_capacity(inputs.len());
        let mut failed = Vec::new();
        for i in inputs {
            let a = self.assemblies.get_mut(&i.gauss_point).ok_or_else(|| {
                MaterialError::Unavailable(format!("no assembly for {}", i.gauss_point))
            })?;
            match a.solve(&i.deformation) {
                Ok(r) if r.diagnostics.converged => out.push(r),
                Ok(r) => failed.push((
                    i.gauss_point,
                    format!(
                        "relaxation hit its step cap: residual ratio {:.3e} after {} steps",
                        r.diagnostics.residual_ratio, r.diagnostics.steps
                    ),
                )),
                Err(e) => failed.push((i.gauss_point, e.to_string())),
            }
        }
        if failed.is_empty() { Ok(out) } else { Err(MaterialError::GaussPoints(failed)) }
    }

    fn commit(&mut self, step: u64) -> Result<(), MaterialError> {
        self.assemblies.values_mut().for_each(Assembly::commit);
        self.committed_step = step;
        Ok(())
    }

    fn rollback(&mut self) -> Result<(), MaterialError> {
        self.assemblies.values_mut().for_each(Assembly::rollback);
        Ok(())
    }

    fn committed_states(&mut self) -> Result<Option<Vec<AssemblyState>>, MaterialError> {
        let step = self.committed_step;
        Ok(Some(
            self.assemblies
                .iter()
                .map(|(id, a)| {
                    let mut a = a.clone();
                    a.rollback();
                    AssemblyState {
                        id: *id,
                        committed_step: step,
                        state: a.to_bytes(),
                        disc_count: a.disc_count() as u64,
                    }
                })
                .collect(),
        ))
    }

    /// Replaces the assemblies of `states` (those of a checkpoint, or states exported
    /// earlier: the material goes back to them) and takes their committed step.
    fn restore_states(&mut self, states: Vec<AssemblyState>) -> Result<(), MaterialError> {
        let mut step = 0;
        for s in states {
            let a = Assembly::from_bytes(&s.state)
                .map_err(|e| MaterialError::Unavailable(format!("restoring {}: {e}", s.id)))?;
            step = step.max(s.committed_step);
            self.assemblies.insert(s.id, a);
        }
        self.committed_step = step;
        Ok(())
    }
}

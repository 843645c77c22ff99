//! A test wrapper that makes Gauss points fail, as a DEM relaxation would on too large a
//! load increment.

use super::{Material, MaterialError, MaterialInput, TrialId};
use cosdem_common::{GaussPointId, MicroResponse};
use std::collections::HashMap;

/// Wraps a material; a Gauss point in `targets` fails whenever its trial strain differs from
/// its committed strain by more than `max_strain_increment` (max norm over the 6 components).
///
/// Step cutting therefore cures the failure once the increment is small enough; a tiny
/// `max_strain_increment` makes the run stop below the minimum increment.
#[derive(Clone, Debug)]
pub struct FailureInjector<M> {
    /// The wrapped material.
    pub inner: M,
    /// Gauss points that can fail.
    pub targets: Vec<GaussPointId>,
    /// Largest strain change per step a target accepts.
    pub max_strain_increment: f64,
    /// Number of evaluations that reported a failure so far.
    pub failures: usize,
    committed: HashMap<GaussPointId, [f64; 6]>,
    trial: HashMap<GaussPointId, [f64; 6]>,
}

impl<M> FailureInjector<M> {
    /// Wraps `inner`.
    pub fn new(inner: M, targets: Vec<GaussPointId>, max_strain_increment: f64) -> Self {
        Self {
            inner,
            targets,
            max_strain_increment,
            failures: 0,
            committed: HashMap::new(),
            trial: HashMap::new(),
        }
    }
}

impl<M: Material> Material for FailureInjector<M> {
    fn evaluate(
        &mut self,
        trial: TrialId,
        inputs: &[MaterialInput],
    ) -> Result<Vec<MicroResponse>, MaterialError> {
        let mut failed = Vec::new();
        self.trial.clear();
        for i in inputs.iter().filter(|i| self.targets.contains(&i.gauss_point)) {
            let e = i.deformation.strain();
            let e0 = self.committed.get(&i.gauss_point).copied().unwrap_or([0.0; 6]);
            let jump = e.iter().zip(&e0).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            if jump > self.max_strain_increment {
                failed.push((
                    i.gauss_point,
                    format!(
                        "injected failure: strain jump {jump:.3e} > {:.3e}",
                        self.max_strain_increment
                    ),
                ));
            }
            self.trial.insert(i.gauss_point, e);
        }
        if !failed.is_empty() {
            self.failures += 1;
            return Err(MaterialError::GaussPoints(failed));
        }
        self.inner.evaluate(trial, inputs)
    }

    fn commit(&mut self, step: u64) -> Result<(), MaterialError> {
        self.committed.extend(self.trial.drain());
        self.inner.commit(step)
    }

    fn rollback(&mut self) -> Result<(), MaterialError> {
        self.trial.clear();
        self.inner.rollback()
    }

    fn is_symmetric(&self) -> bool {
        self.inner.is_symmetric()
    }

    fn snapshot(
        &mut self,
        id: GaussPointId,
    ) -> Result<Option<cosdem_common::micro::MicroSnapshot>, MaterialError> {
        self.inner.snapshot(id)
    }
}

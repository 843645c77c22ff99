//! Loading in stages: after a stage's last step, the next stage's [`Loading`] takes over from
//! the converged state. Its load factor runs from 0 to 1 again; its prescribed dofs move from
//! where they are to their targets (or by their increments), its loads follow their ramps
//! (constant, linear, down), and a dof it no longer prescribes is released (its reaction is
//! no longer applied: the next steps find the equilibrium without it).
//!
//! When the set of prescribed dofs changes, the dof numbering, the sparsity pattern and the
//! linear solver are built again; the nodal values, the material's committed states and the
//! Gauss-point states carry over untouched.

use super::linear::LinearSolver;
use super::loading::Loading;
use super::solver::Solver;
use crate::assembly::{DofMap, Pattern};
use crate::error::{Error, Result};

impl Solver {
    /// The stage being run (0-based).
    pub fn stage(&self) -> u32 {
        self.stage
    }

    /// Starts the next stage from the converged state of the current one, which must be
    /// finished (load factor 1): `loading` with `steps` nominal equal steps. Relative
    /// prescribed values count from the dofs' current values.
    pub fn begin_stage(&mut self, loading: Loading, steps: usize) -> Result<()> {
        if self.position() < 1.0 - 1e-12 {
            return Err(Error::InvalidSetting {
                field: "stage",
                value: (self.stage + 1).to_string(),
                reason: format!(
                    "stage {} is not finished (load factor {}, progress {}): a stage starts after the last step of the one before",
                    self.stage, self.lambda, self.progress
                ),
            });
        }
        let start = self.u.clone();
        self.install(loading, steps, start)?;
        self.stage += 1;
        self.lambda = 0.0;
        self.progress = 0.0;
        self.increment = 1.0 / steps as f64;
        Ok(())
    }

    /// After [`Solver::restore`] of a state of stage `k > 0`: installs that stage's loading
    /// (the one [`Solver::begin_stage`] was given) with the start values the state saved, so
    /// the run goes on as if never interrupted. A no-op for a first-stage state.
    pub fn resume_stage(&mut self, loading: Loading, steps: usize) -> Result<()> {
        let Some(start) = self.saved_stage_start.take() else {
            return Ok(());
        };
        if start.len() != self.u.len() {
            return Err(Error::InvalidSetting {
                field: "checkpoint.stage_start",
                value: start.len().to_string(),
                reason: format!(
                    "the saved state does not fit this model: expected {}",
                    self.u.len()
                ),
            });
        }
        let (lambda, increment) = (self.lambda, self.increment);
        self.install(loading, steps, start)?;
        (self.lambda, self.increment) = (lambda, increment);
        Ok(())
    }

    /// Makes `loading` the model's, its vectors counted from `start`, rebuilding the dof
    /// numbering and the linear system when the prescribed dofs change.
    fn install(&mut self, loading: Loading, steps: usize, start: Vec<f64>) -> Result<()> {
        let mut settings = self.settings.clone();
        settings.steps = steps;
        settings.check()?;
        let field = self.model.field;
        let (prescribed, _) = loading.prescribed_from(&self.model.mesh, field, Some(&start))?;
        let dofs = if prescribed == self.loads.prescribed {
            None
        } else {
            Some(DofMap::new(field, self.model.mesh.n_nodes(), &prescribed))
        };
        let control = Self::control_of(&self.model, &loading, Some(&start))?;
        let (loads, followers) = Self::load_vectors(
            &self.model,
            &loading,
            dofs.as_ref().unwrap_or(&self.dofs),
            &self.gauss,
            Some(&start),
        )?;
        if let Some(dofs) = dofs {
            let pattern = Pattern::new(&self.model.mesh, &dofs);
            self.linear = LinearSolver::new(&pattern)?;
            self.values = vec![0.0; pattern.nnz()];
            self.pattern = pattern;
            self.dofs = dofs;
            tracing::info!(free_dofs = self.dofs.n_free, "dof numbering rebuilt for the stage");
        }
        self.loads = loads;
        self.followers = followers;
        self.control = control;
        self.model.loading = loading;
        self.settings = settings;
        Ok(())
    }
}

//! A stepper's checkpoint: the run's checkpoint ([`crate::checkpoint::Checkpoint`]: the
//! solver's state and the assemblies' committed states, written atomically with its checksum)
//! with the caller's stages so far, so that [`Stepper::resume`] goes on with the same loading,
//! and the job the stepper runs, so that nothing but the checkpoint is needed to go on
//! ([`Stepper::job_of`]).

use super::Stepper;
use crate::checkpoint::Checkpoint;
use crate::run::RunError;
use cosdem_job::Job;
use std::path::Path;

impl Stepper {
    /// Writes the checkpoint of the last committed step to `path` (atomically; any path, the
    /// run directory's or another). [`Stepper::resume`] from it goes on bit for bit as this
    /// stepper does.
    pub fn checkpoint(&mut self, path: &Path) -> Result<(), RunError> {
        if let Some(reason) = &self.broken {
            return Err(RunError::Broken { reason: reason.clone() });
        }
        let _s = tracing::info_span!("checkpoint", step = self.solver.step()).entered();
        let mut c = Checkpoint::capture(&self.solver, self.material.as_mut(), self.digests)?;
        c.stages = Some(self.history.stages.clone());
        let text = toml::to_string(&self.job).map_err(|e| RunError::Broken {
            reason: format!("the job cannot be written into the checkpoint as TOML: {e}"),
        })?;
        c.job = Some(text);
        c.write(path)?;
        Ok(())
    }

    /// The job a stepper's checkpoint was written by (the job it ran: the given one with its
    /// accuracy settings, without its loads), for [`Stepper::resume`] with nothing but the
    /// checkpoint. Refused, naming the file: a run's checkpoint, or one written without it.
    pub fn job_of(path: &Path) -> Result<Job, RunError> {
        let c = Checkpoint::read(path)?;
        c.check_kind(path, true)?;
        let Some(text) = c.job else {
            return Err(RunError::Solver(cosdem_fem::Error::Checkpoint {
                file: path.display().to_string(),
                message: "the checkpoint does not hold its job: give the job to resume".into(),
            }));
        };
        Ok(Job::from_toml(&text, &format!("the job of checkpoint {}", path.display()))?)
    }
}

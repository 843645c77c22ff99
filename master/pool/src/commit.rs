//! The committed states: commit (exporting the states every
//! [`PoolConfig::export_every`](crate::PoolConfig::export_every) steps, or holding the commit
//! back to ride on the next SolveBatch), rollback, export for a checkpoint, import from one,
//! and the master's copies ([`replay`](crate::replay)).

use crate::fanout::Job;
use crate::link::{PendingCommit, is_worker_failure};
use crate::membership::refused;
use crate::recovery::{Redo, Rounds};
use crate::replay::Increment;
use crate::{Cost, Pool, PoolError};
use cosdem_common::GaussPointId;
use cosdem_common::micro::{AssemblyState, MicroSnapshot};
use cosdem_fem::material::MaterialError;
use std::collections::BTreeMap;

impl Pool {
    /// The master's copy of each assembly's last exported committed state (taken every
    /// [`PoolConfig::export_every`](crate::PoolConfig::export_every) commits; see
    /// [`Pool::unexported_commits`]).
    pub fn committed_states(&self) -> &BTreeMap<GaussPointId, AssemblyState> {
        self.history.states()
    }

    /// Commits of `id` since its stored state was exported (what a failover would replay).
    pub fn unexported_commits(&self, id: &GaussPointId) -> usize {
        self.history.pending(id)
    }

    /// Particle-level snapshot of one assembly (committed state).
    pub fn snapshot(&mut self, id: GaussPointId) -> Result<MicroSnapshot, PoolError> {
        let h = self.handle.clone();
        h.block_on(self.flush_deferred()).map_err(|e| PoolError::Unavailable(e.to_string()))?;
        let w = *self
            .owner
            .get(&id)
            .ok_or_else(|| PoolError::Config(format!("no assembly for {id}")))?;
        let link = self.workers[w].link.clone();
        let t = self.config.call_timeout;
        self.handle.block_on(link.snapshot(id, t)).map_err(|s| refused(&link.name, &s))
    }

    /// Commits the last trial of `step` on every assembly it solved
    /// ([`Material::commit`](cosdem_fem::material::Material::commit)).
    pub(crate) async fn commit_async(&mut self, step: u64) -> Result<(), MaterialError> {
        let Some((trial, targets)) = self.last.clone() else {
            if step <= self.committed_step {
                return Ok(());
            }
            return Err(MaterialError::Unavailable(format!(
                "commit of step {step} without an evaluation"
            )));
        };
        if trial.step != step {
            return Err(MaterialError::Unavailable(format!(
                "commit of step {step}, but the last trial is of step {}",
                trial.step
            )));
        }
        self.flush_deferred().await?;
        let mut pending: Vec<GaussPointId> = targets.keys().copied().collect();
        let mut rounds = Rounds::default();
        let every = self.config.export_every;
        while !pending.is_empty() {
            if let Some(done) = rounds.start(self.workers.len()) {
                return Err(MaterialError::Unavailable(format!(
                    "commit of step {step} still failing after {done} rounds of worker losses"
                )));
            }
            let mut by_worker: BTreeMap<usize, Vec<GaussPointId>> = BTreeMap::new();
            for id in &pending {
                by_worker.entry(self.owner[id]).or_default().push(*id);
            }
            // Those that export nothing ride on their worker's next SolveBatch: taken as
            // committed here (the increments recorded for failover, as after an acknowledged
            // commit), sent with the next batch or before another call.
            let defer = self.config.defer_commits;
            let (held, by_worker): (BTreeMap<_, _>, BTreeMap<_, _>) = by_worker
                .into_iter()
                .partition(|(_, ids)| defer && !self.history.export_due(ids, every));
            for (w, ids) in held {
                for id in &ids {
                    self.history.record(
                        *id,
                        Increment { step, iteration: trial.iteration, target: targets[id] },
                    );
                }
                // The only commit held for `w` (flushed above): ids of a later round
                // (re-solved after a loss) join it.
                self.deferred
                    .entry(w)
                    .or_insert(PendingCommit { step, iteration: trial.iteration, ids: vec![] })
                    .ids
                    .extend(ids);
            }
            let t = self.config.call_timeout;
            let jobs = by_worker
                .iter()
                .map(|(w, ids)| {
                    let link = self.workers[*w].link.clone();
                    let ids = ids.clone();
                    let export = self.history.export_due(&ids, every);
                    let job: Job<_> = Box::pin(async move {
                        link.commit(&ids, step, trial.iteration, export, t).await
                    });
                    (*w, job)
                })
                .collect();
            let lost = self
                .round(jobs, is_worker_failure, |pool, w, r| {
                    let states = r.map_err(|s| pool.unavailable(w, "commit", &s))?;
                    if !states.is_empty() {
                        pool.stats.exports += 1;
                    }
                    let mut exported: BTreeMap<_, _> =
                        states.into_iter().map(|s| (s.id, s)).collect();
                    for id in &by_worker[&w] {
                        match exported.remove(id) {
                            Some(s) => pool.history.store(s),
                            None => pool.history.record(
                                *id,
                                Increment { step, iteration: trial.iteration, target: targets[id] },
                            ),
                        }
                    }
                    Ok(())
                })
                .await?;
            if lost.is_empty() {
                break;
            }
            pending = self.recover(lost, Redo::Commit(trial, &targets)).await?;
        }
        self.committed_step = step;
        self.last = None;
        Ok(())
    }

    /// Sends the held-back commits
    /// ([`PoolConfig::defer_commits`](crate::PoolConfig::defer_commits)) now, as Commit calls
    /// of their own: before any call that reads or discards states. A worker lost here is
    /// restored from the history, which holds the commit already.
    pub(crate) async fn flush_deferred(&mut self) -> Result<(), MaterialError> {
        if self.deferred.is_empty() {
            return Ok(());
        }
        let t = self.config.call_timeout;
        let jobs = std::mem::take(&mut self.deferred)
            .into_iter()
            .filter(|(w, _)| self.workers[*w].alive)
            .map(|(w, c)| {
                let link = self.workers[w].link.clone();
                let job: Job<_> =
                    Box::pin(
                        async move { link.commit(&c.ids, c.step, c.iteration, false, t).await },
                    );
                (w, job)
            })
            .collect();
        let lost = self
            .round(jobs, is_worker_failure, |pool, w, r| match r {
                Ok(_) => Ok(()),
                Err(s) => Err(pool.unavailable(w, "commit", &s)),
            })
            .await?;
        self.recover(lost, Redo::Nothing).await.map(drop)
    }

    /// Discards every trial state
    /// ([`Material::rollback`](cosdem_fem::material::Material::rollback)).
    pub(crate) async fn rollback_async(&mut self) -> Result<(), MaterialError> {
        self.flush_deferred().await?;
        self.last = None;
        let by_worker = self.owned_by_worker();
        let t = self.config.call_timeout;
        let jobs = by_worker
            .into_iter()
            .map(|(w, ids)| {
                let link = self.workers[w].link.clone();
                let job: Job<_> = Box::pin(async move { link.rollback(&ids, t).await });
                (w, job)
            })
            .collect();
        let lost = self
            .round(jobs, is_worker_failure, |pool, w, r| match r {
                Ok(()) => Ok(()),
                Err(s) => Err(MaterialError::Unavailable(format!(
                    "rollback on {}: {}",
                    pool.workers[w].link.name,
                    s.message()
                ))),
            })
            .await?;
        // A restored assembly holds its committed state only: exactly a rollback.
        self.recover(lost, Redo::Nothing).await.map(drop)
    }

    /// Exports every assembly's committed state from its owner now (a checkpoint needs the
    /// states of the last committed step, not those of the last periodic export), storing
    /// them as the failover copies. A worker lost here takes the loss path as in a solve: its
    /// assemblies are restored on the live workers from the committed history (the stored
    /// states and the increments committed since, held-back commits included) and exported
    /// from their new owners, so the states are those the lost worker would have given, to the
    /// byte. Only a worker that refuses the export (a status that is not a worker failure), or
    /// no worker left, is an error.
    pub(crate) async fn export_all(&mut self) -> Result<(), MaterialError> {
        self.flush_deferred().await?;
        let mut pending: Vec<GaussPointId> = self.owner.keys().copied().collect();
        let mut rounds = Rounds::default();
        let t = self.config.call_timeout;
        while !pending.is_empty() {
            if let Some(done) = rounds.start(self.workers.len()) {
                return Err(MaterialError::Unavailable(format!(
                    "export for a checkpoint still failing after {done} rounds of worker losses"
                )));
            }
            let mut by_worker: BTreeMap<usize, Vec<GaussPointId>> = BTreeMap::new();
            for id in &pending {
                by_worker.entry(self.owner[id]).or_default().push(*id);
            }
            let jobs = by_worker
                .into_iter()
                .map(|(w, ids)| {
                    let link = self.workers[w].link.clone();
                    let job: Job<_> = Box::pin(async move { link.export(&ids, t).await });
                    (w, job)
                })
                .collect();
            let lost = self
                .round(jobs, is_worker_failure, |pool, w, r| {
                    let states =
                        r.map_err(|s| pool.unavailable(w, "export for a checkpoint", &s))?;
                    for s in states {
                        pool.history.store(s);
                    }
                    Ok(())
                })
                .await?;
            if lost.is_empty() {
                break;
            }
            pending = self.recover(lost, Redo::Export).await?;
        }
        Ok(())
    }

    /// Places saved committed states (a checkpoint, or states exported earlier) on the live
    /// workers: the pool then holds exactly those assemblies, committed at the saved step. A
    /// pool that holds assemblies drops them all first ([`Pool::drop_all`]): it goes back to
    /// the saved states (a caller that undoes committed steps).
    pub(crate) async fn import_states(
        &mut self,
        states: Vec<AssemblyState>,
    ) -> Result<(), MaterialError> {
        if !self.owner.is_empty() {
            self.drop_all().await?;
        }
        let mut ids = Vec::with_capacity(states.len());
        for s in states {
            if self.owner.contains_key(&s.id) {
                return Err(MaterialError::Unavailable(format!(
                    "restoring {}: the pool already holds an assembly for it",
                    s.id
                )));
            }
            self.committed_step = self.committed_step.max(s.committed_step);
            self.costs.insert(s.id, Cost { discs: s.disc_count, seconds: None });
            ids.push(s.id);
            self.history.store(s);
        }
        self.last = None;
        self.restore(&ids).await?;
        // Not a failover: the restorations above are the resume, not a recovery.
        self.stats.restored = self.stats.restored.saturating_sub(ids.len() as u64);
        Ok(())
    }

    /// Every assembly's id, grouped by the worker that holds it.
    fn owned_by_worker(&self) -> BTreeMap<usize, Vec<GaussPointId>> {
        let mut by_worker: BTreeMap<usize, Vec<GaussPointId>> = BTreeMap::new();
        for (id, w) in &self.owner {
            by_worker.entry(*w).or_default().push(*id);
        }
        by_worker
    }

    /// Drops every assembly from its worker and forgets them: their committed history, last
    /// trial, held-back commits and the step committed. A worker lost on the way is marked
    /// dead (its assemblies are gone anyway); one that refuses is an error.
    async fn drop_all(&mut self) -> Result<(), MaterialError> {
        let by_worker = self.owned_by_worker();
        let t = self.config.call_timeout;
        let jobs = by_worker
            .into_iter()
            .filter(|(w, _)| self.workers[*w].alive)
            .map(|(w, ids)| {
                let link = self.workers[w].link.clone();
                let job: Job<_> = Box::pin(async move { link.drop_assemblies(&ids, t).await });
                (w, job)
            })
            .collect();
        self.round(jobs, is_worker_failure, |pool, w, r| {
            r.map_err(|s| pool.unavailable(w, "drop of the assemblies", &s))
        })
        .await?;
        self.owner.clear();
        self.history.clear();
        self.deferred.clear();
        self.last = None;
        self.committed_step = 0;
        Ok(())
    }
}

//! What happens when a worker is lost: the one worker-loss path.
//!
//! A worker is lost when a call to it fails with a status that says it is gone or unusable
//! ([`is_worker_failure`](crate::link::is_worker_failure): transport error, deadline, lost
//! assemblies). Every call that can lose a worker runs as a [`round`](Pool::round) and takes
//! the same path:
//!
//! 1. [`Pool::lose`], where the failure is seen: the worker is marked dead (its held-back
//!    commit is dropped: the history holds it) and the assemblies it holds at that moment are
//!    noted in [`Lost`](crate::recovery::Lost);
//! 2. [`Pool::recover`], once the round is over: those assemblies are [restored](Pool::restore)
//!    on the live workers from the last committed state the master holds (import of the
//!    stored state, then the committed increments since solved and committed again), then
//!    what the interrupted call needs is redone ([`Redo`](crate::recovery::Redo)), and the
//!    Gauss points the call must send again are handed back to it.
//!
//! Every round that leaves work lost at least one worker and none comes back inside a call
//! (admission happens at step boundaries), so a call ends: more rounds than workers + 1 is
//! an error ([`Rounds`](crate::recovery::Rounds)).

use crate::Pool;
use crate::balance::{effective_costs, place};
use crate::fanout::Job;
use crate::link::{Link, is_worker_failure};
use crate::replay::ReplayPlan;
use cosdem_common::{GaussPointId, MacroDeformation};
use cosdem_fem::material::{MaterialError, TrialId};
use std::collections::BTreeMap;
use std::time::Duration;
use tonic::{Code, Status};

/// The workers lost in one or more rounds, and the assemblies each held when it was lost.
#[derive(Debug, Default)]
pub(crate) struct Lost {
    /// The workers, in the order their failures were seen.
    workers: Vec<usize>,
    /// What they held, worker after worker.
    assemblies: Vec<GaussPointId>,
}

impl Lost {
    /// Whether nothing was lost with the workers (no assembly to restore).
    pub(crate) fn is_empty(&self) -> bool {
        self.assemblies.is_empty()
    }

    /// Adds the losses of a later round.
    pub(crate) fn extend(&mut self, later: Lost) {
        self.workers.extend(later.workers);
        self.assemblies.extend(later.assemblies);
    }

    /// The workers lost.
    pub(crate) fn workers(&self) -> &[usize] {
        &self.workers
    }
}

/// What the call a worker loss interrupted needs once the lost assemblies are back at their
/// last committed state.
pub(crate) enum Redo<'a> {
    /// Nothing: their committed state is what the call wanted (a flush of held-back commits,
    /// a rollback, a migration).
    Nothing,
    /// A solve of these targets: those that were lost solve again from their committed state.
    Solve(&'a BTreeMap<GaussPointId, MacroDeformation>),
    /// A commit of this trial: those whose commit was not acknowledged before their worker
    /// died lost their trial with it, and are solved again at the trial before they commit.
    Commit(TrialId, &'a BTreeMap<GaussPointId, MacroDeformation>),
    /// An export of the committed states (for a checkpoint): every lost assembly, once
    /// restored, is exported again from its new owner.
    Export,
}

/// Counts the rounds of one call; see the module's note on why a call ends.
#[derive(Debug, Default)]
pub(crate) struct Rounds(usize);

impl Rounds {
    /// Starts a round: `Some(rounds done)` when this one would be more than workers + 1.
    pub(crate) fn start(&mut self, workers: usize) -> Option<usize> {
        self.0 += 1;
        (self.0 > workers + 1).then_some(self.0 - 1)
    }
}

/// Whether a worker is lost for a restore: as for every call, or full (it cannot take the
/// assemblies; others are tried).
fn lost_for_restore(s: &Status) -> bool {
    is_worker_failure(s) || s.code() == Code::ResourceExhausted
}

/// Runs a replay plan on one worker: each batch solved, then committed at its trial (no
/// export). Returns the number of increments replayed, or the first Gauss point whose replayed
/// solve failed.
async fn replay_on(
    link: &Link,
    plan: ReplayPlan,
    solve_timeout: Duration,
    call_timeout: Duration,
) -> Result<Result<u64, (GaussPointId, String)>, Status> {
    let mut replayed = 0;
    for batch in plan.batches {
        let ids: Vec<_> = batch.items.iter().map(|(id, _)| *id).collect();
        replayed += ids.len() as u64;
        let results =
            link.solve(batch.step, batch.iteration, batch.items, None, solve_timeout).await?;
        if let Some((id, e)) = results.into_iter().find_map(|(id, r)| r.err().map(|e| (id, e))) {
            return Ok(Err((id, e)));
        }
        link.commit(&ids, batch.step, batch.iteration, false, call_timeout).await?;
    }
    Ok(Ok(replayed))
}

impl Pool {
    /// The first half of the loss path, where the failure of worker `w` is seen: marks it
    /// dead (counted once) and notes in `lost` the assemblies it holds now.
    pub(crate) fn lose(&mut self, w: usize, why: &Status, lost: &mut Lost) {
        if self.workers[w].alive {
            tracing::warn!(worker = %self.workers[w].link.name, code = ?why.code(), error = %why.message(), "worker lost");
            self.workers[w].alive = false;
            self.stats.workers_lost += 1;
        }
        // Its held-back commit is in the history: the restore replays it.
        self.deferred.remove(&w);
        lost.workers.push(w);
        lost.assemblies.extend(self.owned_by(w));
    }

    /// The loss path once a round is over: restores the assemblies the `lost` workers held
    /// ([`Pool::restore`]), does what `redo` says, and returns the Gauss points the
    /// interrupted call must send again.
    pub(crate) async fn recover(
        &mut self,
        lost: Lost,
        redo: Redo<'_>,
    ) -> Result<Vec<GaussPointId>, MaterialError> {
        // Back at their last committed step as the master knows it (during a commit, those
        // whose commit was acknowledged before their worker died are at its step already).
        // A worker lost during the restore takes its own assemblies down with it: they are
        // restored too and lost their trials like the others, so what the call redoes is
        // decided over all of them, not only over those the round lost.
        let lost = self.restore(&lost.assemblies).await?;
        match redo {
            Redo::Nothing => Ok(Vec::new()),
            Redo::Export => Ok(lost),
            Redo::Solve(targets) => {
                Ok(lost.into_iter().filter(|id| targets.contains_key(id)).collect())
            }
            Redo::Commit(trial, targets) => {
                let redo: BTreeMap<_, _> = lost
                    .iter()
                    .filter(|id| self.history.committed_step(id).is_some_and(|s| s < trial.step))
                    .filter_map(|id| targets.get(id).map(|t| (*id, *t)))
                    .collect();
                // Boxed: a solve may lose a worker in turn and come back here.
                let again = Box::pin(self.solve_all(trial, &redo)).await?;
                if let Some((id, e)) =
                    again.iter().find_map(|(id, r)| r.as_ref().err().map(|e| (id, e)))
                {
                    return Err(MaterialError::GaussPoints(vec![(
                        *id,
                        format!("re-solve after worker loss failed: {e}"),
                    )]));
                }
                Ok(redo.keys().copied().collect())
            }
        }
    }

    /// Imports the stored committed states of `ids` on live workers (by cost) and replays the
    /// increments committed since ([`replay`](crate::replay)), so that each assembly is back
    /// at its last committed step with no trial; retries on other workers when a target fails.
    /// Returns every assembly restored, sorted: `ids` and those that workers lost on the way
    /// held besides (their trials are gone too).
    pub(crate) async fn restore(
        &mut self,
        ids: &[GaussPointId],
    ) -> Result<Vec<GaussPointId>, MaterialError> {
        let mut todo: Vec<GaussPointId> = ids.to_vec();
        let mut restored: Vec<GaussPointId> = ids.to_vec();
        let mut rounds = Rounds::default();
        while !todo.is_empty() {
            if let Some(done) = rounds.start(self.workers.len()) {
                return Err(MaterialError::Unavailable(format!(
                    "restore of {} assemblies still failing after {done} rounds of worker losses",
                    todo.len(),
                )));
            }
            let alive = self.alive();
            if alive.is_empty() {
                return Err(MaterialError::Unavailable("every worker is lost".into()));
            }
            // Loads without the assemblies being moved.
            for id in &todo {
                self.owner.remove(id);
            }
            let costs = effective_costs(&self.costs);
            let mut load = self.loads();
            let new: Vec<_> =
                todo.iter().map(|id| (*id, costs.get(id).copied().unwrap_or(1.0))).collect();
            let mut by_worker: BTreeMap<usize, Vec<GaussPointId>> = BTreeMap::new();
            for (id, w) in place(&new, &alive, &mut load) {
                by_worker.entry(w).or_default().push(id);
            }
            let (t, ts) = (self.config.call_timeout, self.config.solve_timeout);
            let mut jobs = Vec::new();
            for (w, ids) in &by_worker {
                let mut states = Vec::with_capacity(ids.len());
                for id in ids {
                    let s = self.history.state(id).ok_or_else(|| {
                        MaterialError::Unavailable(format!("no stored state for {id}"))
                    })?;
                    states.push(s.clone());
                }
                let plan = self.history.plan(ids);
                let link = self.workers[*w].link.clone();
                let job: Job<_> = Box::pin(async move {
                    link.import(states, t).await?;
                    replay_on(&link, plan, ts, t).await
                });
                jobs.push((*w, job));
            }
            let lost = self
                .round(jobs, lost_for_restore, |pool, w, r| {
                    let ids = &by_worker[&w];
                    match r {
                        Ok(Ok(replayed)) => {
                            for id in ids {
                                pool.owner.insert(*id, w);
                            }
                            pool.stats.restored += ids.len() as u64;
                            pool.stats.replayed += replayed;
                            tracing::info!(worker = %pool.workers[w].link.name, n = ids.len(), replayed, "assemblies restored");
                            Ok(())
                        }
                        // Deterministic solves that succeeded once cannot fail on replay: a
                        // model that does is not replayable, say which point.
                        Ok(Err((id, e))) => Err(MaterialError::GaussPoints(vec![(
                            id,
                            format!("replay of a committed increment failed: {e}"),
                        )])),
                        Err(s) => Err(MaterialError::Unavailable(format!(
                            "restore on {}: {}",
                            pool.workers[w].link.name,
                            s.message()
                        ))),
                    }
                })
                .await?;
            // Those it held before, and those it was to take.
            todo = lost.workers.iter().flat_map(|w| by_worker[w].iter().copied()).collect();
            restored.extend(lost.assemblies.iter().copied());
            todo.extend(lost.assemblies);
            todo.sort();
            todo.dedup();
        }
        restored.sort();
        restored.dedup();
        Ok(restored)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_call_gets_one_round_per_worker_plus_one_then_says_how_many_it_did() {
        // With 3 workers a call can lose each of them once and still finish in a 4th round.
        let mut rounds = Rounds::default();
        for _ in 0..4 {
            assert_eq!(rounds.start(3), None);
        }
        assert_eq!(rounds.start(3), Some(4));
    }

    #[test]
    fn losses_of_later_rounds_add_up_and_only_lost_assemblies_make_them_count() {
        let mut lost = Lost::default();
        assert!(lost.is_empty());
        lost.extend(Lost { workers: vec![2], assemblies: vec![] });
        assert!(lost.is_empty(), "a worker that held nothing leaves nothing to restore");
        lost.extend(Lost { workers: vec![0], assemblies: vec![GaussPointId::new(1, 0)] });
        assert!(!lost.is_empty());
        assert_eq!(lost.workers(), [2, 0]);
    }
}

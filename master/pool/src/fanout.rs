//! One call per worker, all at once: the fan-out itself, a round of calls whose lost workers
//! take the loss path ([`recovery`](crate::recovery)), and the evaluation of one Newton
//! iteration (one SolveBatch per worker, the answers collected in the order of the inputs).

use crate::Pool;
use crate::link::is_worker_failure;
use crate::recovery::{Lost, Redo, Rounds};
use cosdem_common::{GaussPointId, MacroDeformation, MicroResponse};
use cosdem_fem::material::{MaterialError, MaterialInput, TrialId};
use std::collections::BTreeMap;
use tonic::Status;

/// One worker's share of a fan-out.
pub(crate) type Job<T> = std::pin::Pin<Box<dyn Future<Output = Result<T, Status>> + Send>>;

/// What each Gauss point's solve gave: its response, or why it failed.
pub(crate) type Outcomes = BTreeMap<GaussPointId, Result<MicroResponse, String>>;

/// Runs one job per worker concurrently, polled on the calling task (the thread blocked in
/// `block_on`): no task is spawned per job, so a call costs no hand-off to a runtime thread
/// and back (two thread wake-ups per call, which a loaded machine makes slow). The jobs only
/// await the network; their results are sorted by worker.
pub(crate) async fn fan_out<T>(jobs: Vec<(usize, Job<T>)>) -> Vec<(usize, Result<T, Status>)> {
    let mut pending = jobs;
    let mut out = Vec::with_capacity(pending.len());
    std::future::poll_fn(|cx| {
        let mut i = 0;
        while i < pending.len() {
            match pending[i].1.as_mut().poll(cx) {
                std::task::Poll::Ready(r) => {
                    let (w, _) = pending.swap_remove(i);
                    out.push((w, r));
                }
                std::task::Poll::Pending => i += 1,
            }
        }
        if pending.is_empty() { std::task::Poll::Ready(()) } else { std::task::Poll::Pending }
    })
    .await;
    out.sort_by_key(|(w, _)| *w);
    out
}

impl Pool {
    /// Runs `jobs` ([`fan_out`]) and goes through the answers in worker order: a worker whose
    /// status `is_loss` calls lost is marked dead where it is seen ([`Pool::lose`]); every
    /// other answer goes to `answer`, whose error ends the round at once (the answers after it
    /// are not looked at). Returns the workers lost, for [`Pool::recover`].
    pub(crate) async fn round<T>(
        &mut self,
        jobs: Vec<(usize, Job<T>)>,
        is_loss: fn(&Status) -> bool,
        mut answer: impl FnMut(&mut Pool, usize, Result<T, Status>) -> Result<(), MaterialError>,
    ) -> Result<Lost, MaterialError> {
        let mut lost = Lost::default();
        for (w, r) in fan_out(jobs).await {
            match r {
                Err(s) if is_loss(&s) => self.lose(w, &s, &mut lost),
                r => answer(self, w, r)?,
            }
        }
        Ok(lost)
    }

    /// The error for a worker that answered with a status that is not a worker failure.
    pub(crate) fn unavailable(&self, w: usize, call: &str, status: &Status) -> MaterialError {
        MaterialError::Unavailable(format!(
            "{call} on {}: {:?}: {}",
            self.workers[w].link.name,
            status.code(),
            status.message()
        ))
    }

    /// Solves `targets` at `trial` wherever their assemblies are, moving the assemblies of
    /// failed workers and solving them again until every Gauss point has an answer.
    pub(crate) async fn solve_all(
        &mut self,
        trial: TrialId,
        targets: &BTreeMap<GaussPointId, MacroDeformation>,
    ) -> Result<Outcomes, MaterialError> {
        let mut pending: Vec<GaussPointId> = targets.keys().copied().collect();
        let mut out = Outcomes::new();
        let mut first = true;
        let mut rounds = Rounds::default();
        while !pending.is_empty() {
            if let Some(done) = rounds.start(self.workers.len()) {
                return Err(MaterialError::Unavailable(format!(
                    "solve of {} gauss points still failing after {done} rounds of worker losses",
                    pending.len(),
                )));
            }
            if !first {
                self.stats.resolved += pending.len() as u64;
            }
            first = false;
            let mut by_worker: BTreeMap<usize, Vec<(GaussPointId, MacroDeformation)>> =
                BTreeMap::new();
            for id in &pending {
                by_worker.entry(self.owner[id]).or_default().push((*id, targets[id]));
            }
            let t = self.config.solve_timeout;
            let jobs = by_worker
                .into_iter()
                .map(|(w, items)| {
                    let link = self.workers[w].link.clone();
                    // A held-back commit is applied by the worker before this batch; if the
                    // worker fails instead, the restore replays it from the history.
                    let commit = self.deferred.remove(&w);
                    self.stats.carried_commits += u64::from(commit.is_some());
                    let job: Job<_> = Box::pin(async move {
                        link.solve(trial.step, trial.iteration, items, commit, t).await
                    });
                    (w, job)
                })
                .collect();
            let lost = self
                .round(jobs, is_worker_failure, |pool, w, r| match r {
                    Ok(results) => {
                        out.extend(results);
                        Ok(())
                    }
                    Err(s) => Err(pool.unavailable(w, "solve", &s)),
                })
                .await?;
            if lost.is_empty() {
                break;
            }
            // Everything that lived on a lost worker has lost its trial: solve it again.
            pending = self.recover(lost, Redo::Solve(targets)).await?;
        }
        Ok(out)
    }

    /// One Newton iteration's evaluation
    /// ([`Material::evaluate`](cosdem_fem::material::Material::evaluate)): checks the inputs,
    /// takes the step boundary at a new load step ([`Pool::step_boundary`]), solves, and
    /// answers in the order of `inputs`.
    pub(crate) async fn evaluate_async(
        &mut self,
        trial: TrialId,
        inputs: &[MaterialInput],
    ) -> Result<Vec<MicroResponse>, MaterialError> {
        let mut targets = BTreeMap::new();
        let mut bad = Vec::new();
        for input in inputs {
            let id = input.gauss_point;
            if !self.owner.contains_key(&id) {
                return Err(MaterialError::Unavailable(format!(
                    "no assembly for {id}: call Pool::create_assemblies first"
                )));
            }
            if let Err(e) = input.deformation.validate() {
                bad.push((id, e.to_string()));
            }
            if targets.insert(id, input.deformation).is_some() {
                return Err(MaterialError::Unavailable(format!(
                    "{id} appears twice in one evaluation"
                )));
            }
        }
        if !bad.is_empty() {
            return Err(MaterialError::GaussPoints(bad));
        }
        if self.current_step != Some(trial.step) {
            self.step_boundary().await?;
            self.current_step = Some(trial.step);
        }
        let mut out = self.solve_all(trial, &targets).await?;
        self.last = Some((trial, targets));
        let mut responses = Vec::with_capacity(inputs.len());
        let mut failed = Vec::new();
        for input in inputs {
            match out.remove(&input.gauss_point) {
                Some(Ok(r)) => {
                    if let Some(c) = self.costs.get_mut(&input.gauss_point) {
                        // Smoothed, so that timing noise does not shuffle assemblies.
                        let t = r.diagnostics.wall_seconds;
                        c.seconds = Some(c.seconds.map_or(t, |old| 0.5 * (old + t)));
                    }
                    responses.push(r);
                }
                Some(Err(e)) => failed.push((input.gauss_point, e)),
                None => failed.push((input.gauss_point, "no answer from its worker".into())),
            }
        }
        if failed.is_empty() { Ok(responses) } else { Err(MaterialError::GaussPoints(failed)) }
    }
}

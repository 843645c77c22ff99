//! What a new load step starts with: the admission of returned or new workers
//! ([`membership`](crate::membership)), then, when the loads are out of balance
//! ([`balance`](crate::balance)), the migration of assemblies (export of their committed
//! states from the old owner, import on the new one, drop on the old one).

use crate::Pool;
use crate::balance::{effective_costs, rebalance};
use crate::fanout::Job;
use crate::link::is_worker_failure;
use crate::recovery::Redo;
use cosdem_common::GaussPointId;
use cosdem_fem::material::MaterialError;
use std::collections::BTreeMap;

impl Pool {
    /// At a new load step: admit returned or new workers, then rebalance.
    pub(crate) async fn step_boundary(&mut self) -> Result<(), MaterialError> {
        self.admit().await;
        let costs = effective_costs(&self.costs);
        let moves = rebalance(&self.owner, &costs, &self.alive(), self.config.rebalance_threshold);
        if moves.is_empty() {
            return Ok(());
        }
        // Migration exports committed states: the sources must hold them.
        self.flush_deferred().await?;
        let mut by_dest: BTreeMap<usize, Vec<(GaussPointId, usize)>> = BTreeMap::new();
        for (id, from, to) in moves {
            by_dest.entry(to).or_default().push((id, from));
        }
        let t = self.config.call_timeout;
        // Fresh committed states from the current owners (exact, and no replay needed on the
        // destination); a source that fails is restored with the others at the end.
        let mut by_source: BTreeMap<usize, Vec<GaussPointId>> = BTreeMap::new();
        for list in by_dest.values() {
            for (id, from) in list {
                by_source.entry(*from).or_default().push(*id);
            }
        }
        let jobs = by_source
            .iter()
            .map(|(from, ids)| {
                let link = self.workers[*from].link.clone();
                let ids = ids.clone();
                let job: Job<_> = Box::pin(async move { link.export(&ids, t).await });
                (*from, job)
            })
            .collect();
        let mut failed_sources = Vec::new();
        let mut lost = self
            .round(jobs, is_worker_failure, |pool, from, r| {
                match r {
                    Ok(states) => {
                        for s in states {
                            pool.history.store(s);
                        }
                    }
                    Err(s) => {
                        tracing::warn!(worker = %pool.workers[from].link.name, error = %s.message(), "export for migration refused");
                        failed_sources.push(from);
                    }
                }
                Ok(())
            })
            .await?;
        // What a failed source was to give stays where it is (restored, if it was lost), and
        // a destination lost in the export round takes nothing: a worker lost by a bad answer
        // may still answer an import, and what it took would be owned by a dead worker (its
        // held-back commits are not sent, its assemblies would not be restored).
        failed_sources.extend_from_slice(lost.workers());
        for from in failed_sources {
            for list in by_dest.values_mut() {
                list.retain(|(_, f)| *f != from);
            }
        }
        by_dest.retain(|to, list| !list.is_empty() && !lost.workers().contains(to));
        let mut jobs = Vec::new();
        for (to, list) in &by_dest {
            let mut states = Vec::with_capacity(list.len());
            for (id, _) in list {
                let s = self.history.state(id).ok_or_else(|| {
                    MaterialError::Unavailable(format!("no stored state for {id}"))
                })?;
                states.push(s.clone());
            }
            let link = self.workers[*to].link.clone();
            let job: Job<_> = Box::pin(async move { link.import(states, t).await });
            jobs.push((*to, job));
        }
        let mut drops: BTreeMap<usize, Vec<GaussPointId>> = BTreeMap::new();
        let lost_destinations = self
            .round(jobs, is_worker_failure, |pool, to, r| {
                match r {
                    Ok(()) => {
                        for (id, from) in &by_dest[&to] {
                            pool.owner.insert(*id, to);
                            drops.entry(*from).or_default().push(*id);
                            pool.stats.migrated += 1;
                        }
                    }
                    // A full destination keeps nothing new; the assemblies stay where they are.
                    Err(s) => {
                        tracing::warn!(worker = %pool.workers[to].link.name, error = %s.message(), "migration refused")
                    }
                }
                Ok(())
            })
            .await?;
        lost.extend(lost_destinations);
        for (from, ids) in drops {
            if let Err(s) = self.workers[from].link.drop_assemblies(&ids, t).await {
                tracing::warn!(worker = %self.workers[from].link.name, error = %s.message(), "drop after migration failed");
            }
        }
        self.recover(lost, Redo::Nothing).await.map(drop)
    }
}

//! What the master knows of each assembly's committed history: the last committed state it
//! holds (exported by the worker at a commit, every [`PoolConfig::export_every`] steps) and
//! the committed increments since then (the step, Newton iteration and macro deformation of
//! each commit). Restoring an assembly = importing the stored state, then solving and
//! committing each recorded increment in order.
//!
//! Exact because a solve is a deterministic function of (committed state, target): the
//! worker's solve starts from its committed state (the DEM's `warm_start = false`, its
//! default; the stand-in always), so re-solving the committed iteration of each step
//! rebuilds the committed state bit for bit. The same assumption already makes the redo of a
//! lost iteration exact.
//!
//! [`PoolConfig::export_every`]: super::PoolConfig::export_every

use cosdem_common::micro::AssemblyState;
use cosdem_common::{GaussPointId, MacroDeformation};
use std::collections::BTreeMap;

/// One committed step of one assembly: the trial that became its committed state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Increment {
    /// Load step.
    pub step: u64,
    /// Newton iteration of the committed trial.
    pub iteration: u32,
    /// The macro deformation that trial was solved for.
    pub target: MacroDeformation,
}

/// Stored committed states and the increments committed since each was exported.
#[derive(Default)]
pub struct History {
    states: BTreeMap<GaussPointId, AssemblyState>,
    increments: BTreeMap<GaussPointId, Vec<Increment>>,
}

/// The solves and commits that bring restored assemblies from their stored states to their
/// last committed step, grouped into batches that one worker can run in order.
#[derive(Debug, Default, PartialEq)]
pub struct ReplayPlan {
    /// In increasing (step, iteration) order: solve these, then commit them at that trial.
    pub batches: Vec<ReplayBatch>,
}

/// One SolveBatch + Commit of a replay.
#[derive(Debug, PartialEq)]
pub struct ReplayBatch {
    /// Load step.
    pub step: u64,
    /// Newton iteration.
    pub iteration: u32,
    /// The assemblies and their targets.
    pub items: Vec<(GaussPointId, MacroDeformation)>,
}

impl History {
    /// Stores a freshly exported committed state; the increments before it are no longer
    /// needed.
    pub fn store(&mut self, state: AssemblyState) {
        self.increments.remove(&state.id);
        self.states.insert(state.id, state);
    }

    /// Records a commit that was not exported.
    pub fn record(&mut self, id: GaussPointId, inc: Increment) {
        self.increments.entry(id).or_default().push(inc);
    }

    /// The stored committed state of `id`.
    pub fn state(&self, id: &GaussPointId) -> Option<&AssemblyState> {
        self.states.get(id)
    }

    /// Every stored state (the last exported one of each assembly).
    pub fn states(&self) -> &BTreeMap<GaussPointId, AssemblyState> {
        &self.states
    }

    /// Increments committed since the stored state of `id` was exported.
    pub fn pending(&self, id: &GaussPointId) -> usize {
        self.increments.get(id).map_or(0, Vec::len)
    }

    /// The last committed step of `id` as the master knows it.
    pub fn committed_step(&self, id: &GaussPointId) -> Option<u64> {
        match self.increments.get(id).and_then(|v| v.last()) {
            Some(inc) => Some(inc.step),
            None => self.states.get(id).map(|s| s.committed_step),
        }
    }

    /// Whether the commit of `step` should also export the states of `ids`: when one of them
    /// would otherwise have `every` (or more) unexported commits.
    pub fn export_due(&self, ids: &[GaussPointId], every: u64) -> bool {
        ids.iter().any(|id| self.pending(id) as u64 + 1 >= every)
    }

    /// What to run after importing the stored states of `ids` to bring them to their last
    /// committed step. Each assembly's increments keep their order (the batches are sorted by
    /// (step, iteration), and an assembly has at most one increment per step).
    pub fn plan(&self, ids: &[GaussPointId]) -> ReplayPlan {
        let mut by_trial: BTreeMap<(u64, u32), Vec<(GaussPointId, MacroDeformation)>> =
            BTreeMap::new();
        for id in ids {
            for inc in self.increments.get(id).into_iter().flatten() {
                by_trial.entry((inc.step, inc.iteration)).or_default().push((*id, inc.target));
            }
        }
        ReplayPlan {
            batches: by_trial
                .into_iter()
                .map(|((step, iteration), items)| ReplayBatch { step, iteration, items })
                .collect(),
        }
    }

    /// Forgets everything.
    pub fn clear(&mut self) {
        self.states.clear();
        self.increments.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(e: u32, step: u64) -> AssemblyState {
        AssemblyState {
            id: GaussPointId::new(e, 0),
            committed_step: step,
            state: vec![e as u8],
            disc_count: 1,
        }
    }

    fn inc(step: u64, iteration: u32) -> Increment {
        let g = [[1e-4 * step as f64, 0.0], [0.0, 0.0]];
        Increment { step, iteration, target: MacroDeformation::from_gradient(g, 0.0, [0.0; 2]) }
    }

    #[test]
    fn increments_since_the_export_are_replayed_in_order_and_an_export_clears_them() {
        let (a, b) = (GaussPointId::new(0, 0), GaussPointId::new(1, 0));
        let mut h = History::default();
        h.store(state(0, 0));
        h.store(state(1, 0));
        h.record(a, inc(1, 2));
        h.record(b, inc(1, 2));
        h.record(a, inc(2, 4));
        // b was restored and exported again at step 2 (a fresh state replaces its log).
        h.store(state(1, 2));
        h.record(a, inc(3, 5));
        h.record(b, inc(3, 5));
        assert_eq!(h.committed_step(&a), Some(3));
        assert_eq!(h.committed_step(&b), Some(3));
        let plan = h.plan(&[a, b]);
        let trials: Vec<_> = plan.batches.iter().map(|p| (p.step, p.iteration)).collect();
        assert_eq!(trials, [(1, 2), (2, 4), (3, 5)]);
        let ids: Vec<Vec<_>> =
            plan.batches.iter().map(|p| p.items.iter().map(|x| x.0).collect()).collect();
        assert_eq!(ids, [vec![a], vec![a], vec![a, b]]);
        // Export every 3 steps: a has 3 unexported commits (due), b has 1 (not due alone).
        assert!(h.export_due(&[a], 3));
        assert!(!h.export_due(&[b], 3));
        assert!(h.export_due(&[b], 1), "every = 1 exports at every commit");
        h.store(state(0, 3));
        assert!(h.plan(&[a]).batches.is_empty());
        assert_eq!(h.committed_step(&a), Some(3));
    }
}

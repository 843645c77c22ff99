//! The assemblies a worker holds, with their committed step and last trial: what makes
//! SolveBatch and Commit idempotent under retries.

use super::config::Limits;
use super::error::{Result, ServiceError};
use super::model::MicroModel;
use cosdem_common::micro::{AssemblyInfo, AssemblyRequest, AssemblyState, MicroSnapshot};
use cosdem_common::{GaussPointId, MacroDeformation, MicroResponse};
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};

/// The last trial of an assembly and its outcome (the retry cache).
struct Trial {
    step: u64,
    iteration: u32,
    target: MacroDeformation,
    outcome: std::result::Result<MicroResponse, String>,
}

impl Trial {
    fn is(&self, step: u64, iteration: u32) -> bool {
        self.step == step && self.iteration == iteration
    }
}

/// One assembly and its bookkeeping.
struct Slot<A> {
    assembly: A,
    committed_step: u64,
    trial: Option<Trial>,
}

struct Entry<A> {
    discs: u64,
    slot: Arc<Mutex<Slot<A>>>,
}

/// All assemblies of a worker. Blocking: call it from rayon or `spawn_blocking`.
pub struct Registry<M: MicroModel> {
    model: M,
    limits: Limits,
    /// This machine's memory (bytes), for the caps derived from it.
    memory: Option<u64>,
    entries: Mutex<BTreeMap<GaussPointId, Entry<M::Assembly>>>,
    in_flight: AtomicU64,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    // A panic in a model must not wedge the worker: the data is still consistent per slot.
    m.lock().unwrap_or_else(|p| p.into_inner())
}

/// A handle on one assembly, resolved before a batch starts.
pub struct SlotHandle<A>(GaussPointId, Arc<Mutex<Slot<A>>>);

impl<M: MicroModel> Registry<M> {
    /// An empty registry.
    pub fn new(model: M, limits: Limits) -> Self {
        Self::with_memory(model, limits, Limits::machine_memory())
    }

    /// An empty registry on a machine of `memory` bytes (`None`: unknown, no cap from it).
    pub fn with_memory(model: M, limits: Limits, memory: Option<u64>) -> Self {
        Self { model, limits, memory, entries: Mutex::default(), in_flight: AtomicU64::new(0) }
    }

    /// (assemblies, discs, relaxations in flight).
    pub fn load(&self) -> (u64, u64, u64) {
        let e = lock(&self.entries);
        let discs = e.values().fold(0u64, |a, x| a.saturating_add(x.discs));
        (e.len() as u64, discs, self.in_flight.load(Ordering::SeqCst))
    }

    /// Refuses (RESOURCE_EXHAUSTED, naming the limit and the value) to hold `new` (ids and
    /// their disc counts, `what` says whence: hinted or built) besides what is held.
    fn check_limits(
        &self,
        entries: &BTreeMap<GaussPointId, Entry<M::Assembly>>,
        new: &[(GaussPointId, u64)],
        what: &str,
    ) -> Result<()> {
        let added: Vec<_> = new.iter().filter(|(id, _)| !entries.contains_key(id)).collect();
        // Saturating: a hostile disc-count hint (u64::MAX) must give RESOURCE_EXHAUSTED, not
        // an overflow.
        let count = (entries.len() as u64).saturating_add(added.len() as u64);
        if self.limits.max_assemblies > 0 && count > self.limits.max_assemblies {
            return Err(ServiceError::ResourceExhausted(format!(
                "{count} assemblies would exceed this worker's limit of {} assemblies \
                 (max_assemblies, --max-assemblies)",
                self.limits.max_assemblies
            )));
        }
        let replaced = new
            .iter()
            .filter_map(|(id, _)| entries.get(id).map(|e| e.discs))
            .fold(0u64, u64::saturating_add);
        let held = entries.values().fold(0u64, |a, e| a.saturating_add(e.discs));
        let discs = held
            .saturating_sub(replaced)
            .saturating_add(new.iter().fold(0u64, |a, (_, d)| a.saturating_add(*d)));
        if self.limits.max_discs > 0 && discs > self.limits.max_discs {
            return Err(ServiceError::ResourceExhausted(format!(
                "{discs} discs ({held} held, {} {what} for {} assemblies) would exceed this \
                 worker's limit of {} discs (max_discs, --max-discs)",
                discs.saturating_sub(held.saturating_sub(replaced)),
                new.len(),
                self.limits.max_discs
            )));
        }
        let cap = Limits::memory_disc_cap(self.memory);
        if self.limits.max_discs == 0 && discs > cap {
            return Err(ServiceError::ResourceExhausted(format!(
                "{discs} discs ({held} held, {} {what} for {} assemblies) would exceed what this \
                 worker's memory holds: {cap} discs ({} bytes at {} bytes a disc; \
                 --max-discs sets a limit)",
                discs.saturating_sub(held.saturating_sub(replaced)),
                new.len(),
                self.memory.unwrap_or(0),
                Limits::BYTES_PER_DISC_HELD
            )));
        }
        Ok(())
    }

    /// Refuses, before anything is built, a CreateAssemblies request over the per-request
    /// caps: more than [`Limits::MAX_IDS_PER_REQUEST`] ids, or more discs (`hint` per
    /// assembly) than [`Limits::request_disc_cap`] of this machine's memory.
    fn check_request(&self, ids: usize, hint: u64) -> Result<()> {
        if ids > Limits::MAX_IDS_PER_REQUEST {
            return Err(ServiceError::ResourceExhausted(format!(
                "{ids} ids in one CreateAssemblies request: over the limit of {} ids a request \
                 (MAX_IDS_PER_REQUEST; send them in several requests)",
                Limits::MAX_IDS_PER_REQUEST
            )));
        }
        let discs = hint.saturating_mul(ids as u64);
        let cap = Limits::request_disc_cap(self.memory);
        if discs > cap {
            return Err(ServiceError::ResourceExhausted(format!(
                "{ids} assemblies of {hint} discs (disc_count_hint) = {discs} discs in one \
                 CreateAssemblies request: over the limit of {cap} discs a request (half of \
                 this worker's {} bytes of memory at {} bytes a disc)",
                self.memory.unwrap_or(0),
                Limits::BYTES_PER_DISC_HELD
            )));
        }
        Ok(())
    }

    /// Builds assemblies; all or nothing.
    pub fn create(
        &self,
        ids: &[GaussPointId],
        spec: &AssemblyRequest,
    ) -> Result<Vec<AssemblyInfo>> {
        // The disc count per assembly before anything is built: the master's hint, or the
        // model's own reading of the spec when larger (a hint of 0 or a lie changes nothing).
        let hint = spec.disc_count_hint.max(self.model.disc_estimate(spec).unwrap_or(0));
        self.check_request(ids.len(), hint)?;
        {
            let entries = lock(&self.entries);
            if let Some(id) = ids.iter().find(|id| entries.contains_key(id)) {
                return Err(ServiceError::AlreadyExists(*id));
            }
            let hinted: Vec<_> = ids.iter().map(|id| (*id, hint)).collect();
            self.check_limits(&entries, &hinted, "hinted")?;
        }
        let built = self.build(ids, spec)?;
        let mut entries = lock(&self.entries);
        if let Some(id) = ids.iter().find(|id| entries.contains_key(id)) {
            return Err(ServiceError::AlreadyExists(*id));
        }
        let actual: Vec<_> = built.iter().map(|(id, a)| (*id, self.model.disc_count(a))).collect();
        self.check_limits(&entries, &actual, "built")?;
        let mut infos = Vec::with_capacity(built.len());
        for (id, a) in built {
            let info = AssemblyInfo {
                id,
                disc_count: self.model.disc_count(&a),
                cost_hint: self.model.cost_hint(&a),
            };
            let slot = Arc::new(Mutex::new(Slot { assembly: a, committed_step: 0, trial: None }));
            entries.insert(id, Entry { discs: info.disc_count, slot });
            infos.push(info);
        }
        Ok(infos)
    }

    /// The assemblies of `ids` from one spec: the first built and the rest copied where the
    /// model says a copy is what it would build ([`MicroModel::replicate`]), else all built in
    /// parallel.
    fn build(
        &self,
        ids: &[GaussPointId],
        spec: &AssemblyRequest,
    ) -> Result<Vec<(GaussPointId, M::Assembly)>> {
        use rayon::prelude::*;
        let Some((first, rest)) = ids.split_first() else { return Ok(Vec::new()) };
        let a = self.model.create(*first, spec)?;
        let copies: Option<Vec<_>> =
            rest.iter().map(|id| self.model.replicate(&a, *id).map(|c| (*id, c))).collect();
        let rest = match copies {
            Some(c) => c,
            None => rest
                .par_iter()
                .map(|id| self.model.create(*id, spec).map(|a| (*id, a)))
                .collect::<std::result::Result<Vec<_>, _>>()?,
        };
        Ok(std::iter::once((*first, a)).chain(rest).collect())
    }

    /// Creates or replaces assemblies from exported committed states; all or nothing. A state
    /// the model refuses is reported with the Gauss point it was sent for.
    pub fn import(&self, states: Vec<AssemblyState>) -> Result<Vec<AssemblyInfo>> {
        let mut built = Vec::with_capacity(states.len());
        for s in states {
            let a = self
                .model
                .import(&s.state)
                .map_err(|reason| ServiceError::Import { id: s.id, reason })?;
            built.push((s.id, s.committed_step, a));
        }
        let mut entries = lock(&self.entries);
        let actual: Vec<_> =
            built.iter().map(|(id, _, a)| (*id, self.model.disc_count(a))).collect();
        self.check_limits(&entries, &actual, "imported")?;
        let mut infos = Vec::with_capacity(built.len());
        for (id, committed_step, a) in built {
            let info = AssemblyInfo {
                id,
                disc_count: self.model.disc_count(&a),
                cost_hint: self.model.cost_hint(&a),
            };
            let slot = Arc::new(Mutex::new(Slot { assembly: a, committed_step, trial: None }));
            entries.insert(id, Entry { discs: info.disc_count, slot });
            infos.push(info);
        }
        Ok(infos)
    }

    /// Handles on the named assemblies (all of them for an empty list); NOT_FOUND names the
    /// first unknown one, duplicates are refused.
    pub fn resolve(&self, ids: &[GaussPointId]) -> Result<Vec<SlotHandle<M::Assembly>>> {
        let entries = lock(&self.entries);
        if ids.is_empty() {
            return Ok(entries.iter().map(|(id, e)| SlotHandle(*id, e.slot.clone())).collect());
        }
        let mut seen = std::collections::HashSet::with_capacity(ids.len());
        ids.iter()
            .map(|id| {
                if !seen.insert(*id) {
                    return Err(ServiceError::InvalidArgument(format!(
                        "{id} appears twice in one request"
                    )));
                }
                entries
                    .get(id)
                    .map(|e| SlotHandle(*id, e.slot.clone()))
                    .ok_or(ServiceError::NotFound(*id))
            })
            .collect()
    }

    /// A relaxation is queued: counted in flight until [`Registry::end`].
    pub fn begin(&self) {
        self.in_flight.fetch_add(1, Ordering::SeqCst);
    }

    /// A queued relaxation has finished.
    pub fn end(&self) {
        self.in_flight.fetch_sub(1, Ordering::SeqCst);
    }

    /// Solves one assembly for trial (step, iteration); a repeat of the last trial returns
    /// its cached outcome.
    pub fn solve(
        &self,
        h: &SlotHandle<M::Assembly>,
        step: u64,
        iteration: u32,
        target: MacroDeformation,
    ) -> std::result::Result<MicroResponse, String> {
        let mut slot = lock(&h.1);
        if let Some(t) = &slot.trial
            && t.is(step, iteration)
            && t.target == target
        {
            return t.outcome.clone();
        }
        if slot.committed_step >= step {
            return Err(format!(
                "step {step} is already committed on {} (committed step {})",
                h.0, slot.committed_step
            ));
        }
        let slot = &mut *slot;
        let outcome = self.model.solve(&mut slot.assembly, &target).map_err(|e| e.to_string());
        slot.trial = Some(Trial { step, iteration, target, outcome: outcome.clone() });
        outcome
    }

    /// Commits trial (step, iteration) of the named assemblies; a step already committed is
    /// skipped. Checks every assembly before changing any. Returns (committed, already,
    /// states if asked).
    pub fn commit(
        &self,
        ids: &[GaussPointId],
        step: u64,
        iteration: u32,
        export: bool,
    ) -> Result<(u32, u32, Vec<AssemblyState>)> {
        let handles = self.resolve(ids)?;
        let mut guards: Vec<_> = handles.iter().map(|h| (h.0, lock(&h.1))).collect();
        for (id, slot) in &guards {
            if slot.committed_step >= step {
                continue;
            }
            match &slot.trial {
                Some(t) if t.is(step, iteration) && t.outcome.is_ok() => {}
                Some(t) if t.is(step, iteration) => {
                    return Err(ServiceError::FailedPrecondition(format!(
                        "cannot commit {id}: its trial for step {step} iteration {iteration} failed"
                    )));
                }
                other => {
                    let has = other.as_ref().map_or("no trial".to_string(), |t| {
                        format!("trial step {} iteration {}", t.step, t.iteration)
                    });
                    return Err(ServiceError::FailedPrecondition(format!(
                        "cannot commit {id} at step {step} iteration {iteration}: it has {has}"
                    )));
                }
            }
        }
        let (mut committed, mut already) = (0, 0);
        let mut states = Vec::new();
        for (id, slot) in guards.iter_mut() {
            if slot.committed_step >= step {
                already += 1;
            } else {
                self.model.commit(&mut slot.assembly);
                slot.committed_step = step;
                committed += 1;
            }
            if export {
                states.push(self.state_of(*id, slot));
            }
        }
        Ok((committed, already, states))
    }

    fn state_of(&self, id: GaussPointId, slot: &Slot<M::Assembly>) -> AssemblyState {
        AssemblyState {
            id,
            committed_step: slot.committed_step,
            state: self.model.export(&slot.assembly),
            disc_count: self.model.disc_count(&slot.assembly),
        }
    }

    /// Discards trial states.
    pub fn rollback(&self, ids: &[GaussPointId]) -> Result<u32> {
        let handles = self.resolve(ids)?;
        for h in &handles {
            let mut slot = lock(&h.1);
            let slot = &mut *slot;
            self.model.rollback(&mut slot.assembly);
            slot.trial = None;
        }
        Ok(handles.len() as u32)
    }

    /// Committed states.
    pub fn export(&self, ids: &[GaussPointId]) -> Result<Vec<AssemblyState>> {
        let handles = self.resolve(ids)?;
        Ok(handles.iter().map(|h| self.state_of(h.0, &lock(&h.1))).collect())
    }

    /// Snapshot of one assembly and its committed step.
    pub fn snapshot(&self, id: GaussPointId) -> Result<(u64, MicroSnapshot)> {
        let h = self.resolve(&[id])?.pop().expect("one handle");
        let slot = lock(&h.1);
        Ok((slot.committed_step, self.model.snapshot(&slot.assembly)))
    }

    /// Frees assemblies (all for an empty list); unknown ids are ignored (idempotent).
    pub fn drop_assemblies(&self, ids: &[GaussPointId]) -> u32 {
        let mut entries = lock(&self.entries);
        if ids.is_empty() {
            let n = entries.len();
            entries.clear();
            return n as u32;
        }
        ids.iter().filter(|id| entries.remove(id).is_some()).count() as u32
    }
}

impl<A> SlotHandle<A> {
    /// The Gauss point.
    pub fn id(&self) -> GaussPointId {
        self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Dem;
    use cosdem_common::micro::MicroSnapshot;
    use cosdem_dem::{Assembly, AssemblySpec, PackingSpec};

    fn random_spec() -> AssemblySpec {
        AssemblySpec {
            packing: PackingSpec::Random {
                r_min: 0.002,
                r_max: 0.003,
                radii: vec![],
                side: 0.04,
                seed: 11,
                confining_stress: 1e5,
            },
            ..Default::default()
        }
    }

    /// A [`Dem`] that counts the assemblies it builds: what shows that a refusal came
    /// before building.
    #[derive(Default)]
    struct Counting(std::sync::atomic::AtomicUsize);

    impl MicroModel for Counting {
        type Assembly = Assembly;
        fn create(
            &self,
            id: GaussPointId,
            spec: &AssemblyRequest,
        ) -> std::result::Result<Assembly, crate::ModelError> {
            self.0.fetch_add(1, Ordering::SeqCst);
            Dem.create(id, spec)
        }
        fn solve(
            &self,
            a: &mut Assembly,
            t: &MacroDeformation,
        ) -> std::result::Result<MicroResponse, crate::ModelError> {
            Dem.solve(a, t)
        }
        fn commit(&self, a: &mut Assembly) {
            Dem.commit(a)
        }
        fn rollback(&self, a: &mut Assembly) {
            Dem.rollback(a)
        }
        fn export(&self, a: &Assembly) -> Vec<u8> {
            Dem.export(a)
        }
        fn import(&self, b: &[u8]) -> std::result::Result<Assembly, crate::ModelError> {
            Dem.import(b)
        }
        fn snapshot(&self, a: &Assembly) -> MicroSnapshot {
            Dem.snapshot(a)
        }
        fn disc_count(&self, a: &Assembly) -> u64 {
            Dem.disc_count(a)
        }
        fn disc_estimate(&self, spec: &AssemblyRequest) -> Option<u64> {
            Dem.disc_estimate(spec)
        }
    }

    fn request(spec: &AssemblySpec, hint: u64) -> AssemblyRequest {
        AssemblyRequest {
            spec_json: serde_json::to_vec(spec).unwrap(),
            boundary: Default::default(),
            disc_count_hint: hint,
        }
    }

    /// The message of a RESOURCE_EXHAUSTED refusal (a short panic if it was accepted).
    fn exhausted(r: Result<Vec<AssemblyInfo>>) -> String {
        let Err(e) = r else { panic!("accepted") };
        assert!(matches!(e, ServiceError::ResourceExhausted(_)), "{e:?}");
        e.to_string()
    }

    /// With no hint from the master (0, what masters sent), a worker reads the disc count
    /// from the spec and refuses over `max_discs` before building anything: two assemblies of
    /// the default hexagonal packing (105 discs) on a worker limited to 200 discs. Without
    /// that reading it built both (a large packing would crash it) and refused only then.
    #[test]
    fn the_limits_are_checked_before_building_whatever_the_hint() {
        let limits = Limits { max_discs: 200, ..Limits::default() };
        let reg = Registry::new(Counting::default(), limits);
        let ids = [GaussPointId::new(0, 0), GaussPointId::new(0, 1)];
        let e = exhausted(reg.create(&ids, &request(&AssemblySpec::default(), 0)));
        assert!(e.contains("210 discs") && e.contains("max_discs") && e.contains("hinted"), "{e}");
        assert_eq!(reg.model.0.load(Ordering::SeqCst), 0, "built before refusing");
        // Within the limit: built, and the real count is still checked after.
        reg.create(&ids[..1], &request(&AssemblySpec::default(), 0)).unwrap();
        assert_eq!(reg.load().1, 105);
    }

    /// Per request: more than MAX_IDS_PER_REQUEST ids, or more discs than half the machine's
    /// memory holds, are refused naming the cap, before anything is built; per worker (no
    /// `max_discs`): more discs than the machine's memory holds. (One CreateAssemblies of
    /// 100 000 ids took 2.1 GB; a second crashed the worker.)
    #[test]
    fn requests_and_workers_are_capped_before_building() {
        let spec = AssemblySpec::default();
        let reg = Registry::new(Counting::default(), Limits::default());
        let many: Vec<_> =
            (0..=Limits::MAX_IDS_PER_REQUEST as u32).map(|e| GaussPointId::new(e, 0)).collect();
        let e = exhausted(reg.create(&many, &request(&spec, 105)));
        assert!(e.contains("16385 ids") && e.contains("MAX_IDS_PER_REQUEST"), "{e}");
        // A machine of 1 MiB: 1024 discs in all, 512 a request.
        let reg = Registry::with_memory(Counting::default(), Limits::default(), Some(1 << 20));
        let e = exhausted(reg.create(&many[..5], &request(&spec, 105)));
        assert!(e.contains("525 discs") && e.contains("disc_count_hint"), "{e}");
        assert!(e.contains("limit of 512 discs a request"), "{e}");
        for k in 0..9 {
            reg.create(&many[k..k + 1], &request(&spec, 105)).unwrap();
        }
        let e = exhausted(reg.create(&many[9..10], &request(&spec, 105)));
        assert!(e.contains("1050 discs") && e.contains("memory holds: 1024 discs"), "{e}");
        assert!(e.contains("--max-discs"), "{e}");
        assert_eq!(reg.model.0.load(Ordering::SeqCst), 9, "built before refusing");
    }

    /// One spec for several Gauss points builds one random specimen and copies it: every
    /// point's committed state is, byte for byte, the specimen `Assembly::new` builds alone,
    /// and each copy relaxes as a freshly built one does (the copies share nothing). A copy
    /// that differed (a stale trial, shared state, another packing) would fail the byte
    /// comparison.
    #[test]
    fn one_spec_builds_one_specimen_for_all_points() {
        let spec = random_spec();
        let req = AssemblyRequest {
            spec_json: serde_json::to_vec(&spec).unwrap(),
            boundary: Default::default(),
            disc_count_hint: 100,
        };
        let reg = Registry::new(Dem, Limits::default());
        let ids: Vec<_> = (0..3).map(|p| GaussPointId::new(4, p)).collect();
        reg.create(&ids, &req).unwrap();
        let alone = Assembly::new(&spec).unwrap();
        let states = reg.export(&ids).unwrap();
        assert_eq!(states.len(), 3);
        for s in &states {
            assert_eq!(s.state, alone.to_bytes(), "{}", s.id);
        }
        let target = MacroDeformation { f: [[1.0, 2e-4], [0.0, 0.999]], w: 1e-4, kappa: [0.0; 2] };
        let mut fresh = Assembly::new(&spec).unwrap();
        let want = fresh.solve(&target).unwrap();
        let handles = reg.resolve(&ids[1..2]).unwrap();
        let got = reg.solve(&handles[0], 1, 0, target).unwrap();
        assert_eq!(got.stress, want.stress);
        assert_eq!(got.tangent, want.tangent);
        // The other copies are untouched by that relaxation.
        assert_eq!(reg.export(&ids[2..]).unwrap()[0].state, alone.to_bytes());
    }
}

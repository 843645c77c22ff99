//! Where each Gauss point's assembly lives: pure functions on costs and capacities.
//!
//! Cost of an assembly: its measured solve time (smoothed over iterations) when it has one,
//! else its disc count scaled by the measured seconds per disc (or the disc count alone
//! before any solve).
//! Load of a worker: the sum of its assemblies' costs divided by its cores.

use cosdem_common::GaussPointId;
use std::collections::BTreeMap;

/// What the pool knows about the cost of one assembly.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Cost {
    /// Disc count (from the worker, or the spec's hint before creation).
    pub discs: u64,
    /// Last measured solve time (s), if any.
    pub seconds: Option<f64>,
}

/// One number per assembly, comparable across assemblies.
pub fn effective_costs(costs: &BTreeMap<GaussPointId, Cost>) -> BTreeMap<GaussPointId, f64> {
    let (mut sec, mut discs) = (0.0, 0u64);
    for c in costs.values() {
        if let Some(s) = c.seconds {
            sec += s;
            discs += c.discs.max(1);
        }
    }
    let per_disc = if discs > 0 && sec > 0.0 { sec / discs as f64 } else { 1.0 };
    costs
        .iter()
        .map(|(id, c)| (*id, c.seconds.unwrap_or(c.discs.max(1) as f64 * per_disc)))
        .collect()
}

/// Greedy placement of new assemblies (largest first, onto the least loaded worker).
/// `workers` are (index, cores) of the workers to use; `load` their current load.
pub fn place(
    new: &[(GaussPointId, f64)],
    workers: &[(usize, u32)],
    load: &mut BTreeMap<usize, f64>,
) -> Vec<(GaussPointId, usize)> {
    let mut order: Vec<_> = new.to_vec();
    order.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    let mut out = Vec::with_capacity(order.len());
    for (id, c) in order {
        let &(w, cores) = workers
            .iter()
            .min_by(|a, b| {
                let la = load.get(&a.0).copied().unwrap_or(0.0) + c / a.1.max(1) as f64;
                let lb = load.get(&b.0).copied().unwrap_or(0.0) + c / b.1.max(1) as f64;
                la.total_cmp(&lb).then(a.0.cmp(&b.0))
            })
            .expect("at least one worker");
        *load.entry(w).or_default() += c / cores.max(1) as f64;
        out.push((id, w));
    }
    out
}

/// Moves that bring the most loaded worker down while it helps, when the imbalance
/// (max load / mean load) exceeds `threshold`. Returns (assembly, from, to).
pub fn rebalance(
    owner: &BTreeMap<GaussPointId, usize>,
    cost: &BTreeMap<GaussPointId, f64>,
    workers: &[(usize, u32)],
    threshold: f64,
) -> Vec<(GaussPointId, usize, usize)> {
    if workers.len() < 2 {
        return Vec::new();
    }
    let cores: BTreeMap<usize, f64> = workers.iter().map(|&(w, c)| (w, c.max(1) as f64)).collect();
    let mut load: BTreeMap<usize, f64> = workers.iter().map(|&(w, _)| (w, 0.0)).collect();
    let mut on: BTreeMap<usize, Vec<GaussPointId>> = BTreeMap::new();
    for (id, w) in owner {
        if let Some(l) = load.get_mut(w) {
            *l += cost.get(id).copied().unwrap_or(1.0) / cores[w];
            on.entry(*w).or_default().push(*id);
        }
    }
    let mean = load.values().sum::<f64>() / load.len() as f64;
    let max = load.values().copied().fold(0.0, f64::max);
    if mean <= 0.0 || max / mean <= threshold {
        return Vec::new();
    }
    let mut moves = Vec::new();
    for _ in 0..owner.len() {
        let (&hi, &lh) =
            load.iter().max_by(|a, b| a.1.total_cmp(b.1).then(b.0.cmp(a.0))).expect("workers");
        let (&lo, &ll) =
            load.iter().min_by(|a, b| a.1.total_cmp(b.1).then(a.0.cmp(b.0))).expect("workers");
        // The largest assembly whose move lowers the maximum of the two loads.
        let best = on.get(&hi).and_then(|ids| {
            ids.iter()
                .map(|id| (*id, cost.get(id).copied().unwrap_or(1.0)))
                .filter(|(_, c)| ll + c / cores[&lo] < lh)
                .max_by(|a, b| a.1.total_cmp(&b.1).then(b.0.cmp(&a.0)))
        });
        let Some((id, c)) = best else { break };
        on.get_mut(&hi).expect("hi").retain(|x| *x != id);
        on.entry(lo).or_default().push(id);
        *load.get_mut(&hi).expect("hi") -= c / cores[&hi];
        *load.get_mut(&lo).expect("lo") += c / cores[&lo];
        moves.push((id, hi, lo));
        let mean = load.values().sum::<f64>() / load.len() as f64;
        if load.values().copied().fold(0.0, f64::max) / mean <= threshold {
            break;
        }
    }
    moves
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gp(i: u32) -> GaussPointId {
        GaussPointId::new(i, 0)
    }

    #[test]
    fn place_spreads_by_cost_and_cores() {
        let new: Vec<_> = (0..6).map(|i| (gp(i), 1.0)).collect();
        let mut load = BTreeMap::new();
        let p = place(&new, &[(0, 1), (1, 2)], &mut load);
        let on1 = p.iter().filter(|(_, w)| *w == 1).count();
        assert_eq!(on1, 4, "{p:?}");
    }

    #[test]
    fn rebalance_moves_from_a_crowded_worker_to_a_new_one() {
        let owner: BTreeMap<_, _> = (0..8).map(|i| (gp(i), 0)).collect();
        let cost: BTreeMap<_, _> = (0..8).map(|i| (gp(i), 1.0)).collect();
        let moves = rebalance(&owner, &cost, &[(0, 1), (1, 1)], 1.2);
        assert_eq!(moves.len(), 4, "{moves:?}");
        assert!(moves.iter().all(|m| m.1 == 0 && m.2 == 1));
        // Balanced already: nothing moves.
        let owner: BTreeMap<_, _> = (0..8).map(|i| (gp(i), (i % 2) as usize)).collect();
        assert!(rebalance(&owner, &cost, &[(0, 1), (1, 1)], 1.2).is_empty());
    }
}

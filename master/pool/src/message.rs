//! Message sizes: the calls that carry assembly states (export, a commit that exports, import)
//! are split into messages within the message limit, and a call that still fails for size
//! (one state over the limit) names the limit, its setting and the assemblies' sizes.
//!
//! gRPC refuses a message over the limit on either side (the master's
//! [`PoolConfig::max_message_bytes`](crate::PoolConfig::max_message_bytes), the worker's
//! `--max-message-mib`) with OUT_OF_RANGE and a message naming bytes only: 16 assemblies of
//! 289k discs exported in one reply failed that way, after building them.

use cosdem_common::GaussPointId;
use tonic::{Code, Status};

/// Splits `items` (in order) into groups whose summed `size` stays within `limit`; an item
/// over the limit alone makes a group of its own (its call fails and says why). Never an
/// empty group; no group at all for no items.
pub(crate) fn groups<T>(items: Vec<T>, size: impl Fn(&T) -> u64, limit: u64) -> Vec<Vec<T>> {
    let mut out: Vec<Vec<T>> = Vec::new();
    let mut used = 0u64;
    for item in items {
        let s = size(&item);
        match out.last_mut() {
            Some(g) if used.saturating_add(s) <= limit => {
                g.push(item);
                used = used.saturating_add(s);
            }
            _ => {
                out.push(vec![item]);
                used = s;
            }
        }
    }
    out
}

/// The assemblies of a call and their disc counts, for a message: `16 assemblies of 289000
/// discs`, `3 assemblies of 10 to 300 discs (410 in all)`, or without known counts `2
/// assemblies`.
pub(crate) fn describe(discs: &[(GaussPointId, Option<u64>)]) -> String {
    let n = discs.len();
    let known: Vec<u64> = discs.iter().filter_map(|(_, d)| *d).collect();
    let noun = if n == 1 { "assembly" } else { "assemblies" };
    if known.len() != n || n == 0 {
        return format!("{n} {noun}");
    }
    let (lo, hi) =
        (known.iter().min().copied().unwrap_or(0), known.iter().max().copied().unwrap_or(0));
    let total = known.iter().fold(0u64, |a, d| a.saturating_add(*d));
    if lo == hi {
        format!("{n} {noun} of {lo} discs ({total} in all)")
    } else {
        format!("{n} {noun} of {lo} to {hi} discs ({total} in all)")
    }
}

/// `s` when it is not a failure for size; else the same code with a message naming the
/// call, the assemblies it carried ([`describe`]), both limits and their settings, and what
/// one state of the largest takes ([`cosdem_dem::spec::state_bytes`]).
pub(crate) fn oversized(
    call: &str,
    discs: &[(GaussPointId, Option<u64>)],
    master_limit: usize,
    worker_limit: u64,
    s: Status,
) -> Status {
    if s.code() != Code::OutOfRange {
        return s;
    }
    let largest = discs.iter().filter_map(|(_, d)| *d).max();
    let per_state = largest.map_or(String::new(), |d| {
        format!(
            "; one exported state of {d} discs takes up to {} bytes",
            cosdem_dem::spec::state_bytes(d)
        )
    });
    let worker = if worker_limit > 0 { format!("{worker_limit} bytes") } else { "?".into() };
    Status::out_of_range(format!(
        "{call} of {}: a message over the gRPC message limit ({}). The limit is \
         max_message_bytes = {master_limit} on the master (PoolConfig::max_message_bytes) and \
         {worker} on the worker (cosdem-worker --max-message-mib){per_state}: raise both, or \
         use fewer discs per assembly",
        describe(discs),
        s.message()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_stay_within_the_limit_in_order() {
        let g = groups(vec![3u64, 4, 2, 9, 1, 1, 12], |x| *x, 9);
        assert_eq!(g, vec![vec![3, 4, 2], vec![9], vec![1, 1], vec![12]]);
        assert!(groups(Vec::<u64>::new(), |x| *x, 9).is_empty());
    }

    #[test]
    fn an_oversized_call_names_the_setting_and_the_sizes() {
        let ids: Vec<_> = (0..16).map(|e| (GaussPointId::new(e, 0), Some(289_000u64))).collect();
        let s = Status::out_of_range(
            "Error, decoded message length too large: found 300000000 bytes, the limit is: \
             268435456 bytes",
        );
        let m = oversized("ExportState", &ids, 268_435_456, 268_435_456, s).message().to_string();
        for needle in [
            "16 assemblies of 289000 discs (4624000 in all)",
            "max_message_bytes = 268435456",
            "PoolConfig::max_message_bytes",
            "--max-message-mib",
            "found 300000000 bytes",
        ] {
            assert!(m.contains(needle), "`{needle}` not in {m}");
        }
        let other = oversized("ExportState", &ids, 1, 1, Status::unavailable("gone"));
        assert_eq!(other.message(), "gone");
    }
}

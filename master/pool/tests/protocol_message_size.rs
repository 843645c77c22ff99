//! Messages that carry assembly states stay within the gRPC message limit: the pool sends
//! exports, exporting commits and imports in as many calls as the limit needs (the same
//! states, byte for byte), and a state that cannot fit names the limit, its settings and the
//! assemblies' sizes (16 assemblies of 289k discs failed after 27 s on the 256 MiB limit,
//! naming nothing).

use cosdem_common::micro::{AssemblyRequest, AssemblyState, BoundaryKind};
use cosdem_common::{GaussPointId, MacroDeformation};
use cosdem_dem::AssemblySpec;
use cosdem_dem::spec::state_bytes;
use cosdem_fem::material::{Material, MaterialInput, TrialId};
use cosdem_pool::{Pool, PoolConfig, PoolError};
use cosdem_worker::Dem;
use std::collections::BTreeMap;
use std::time::Duration;

fn config(max_message_bytes: usize) -> PoolConfig {
    PoolConfig {
        connect_timeout: Duration::from_secs(3),
        call_timeout: Duration::from_secs(10),
        solve_timeout: Duration::from_secs(10),
        in_process_threads: 1,
        export_every: 1,
        max_message_bytes,
        ..PoolConfig::default()
    }
}

/// The default hexagonal packing (`{}`: every key at its default): 105 discs, about 18 kB a
/// state.
fn request() -> AssemblyRequest {
    let spec = AssemblySpec::default();
    AssemblyRequest {
        spec_json: b"{}".to_vec(),
        boundary: BoundaryKind::Penalty,
        disc_count_hint: spec.disc_count_hint(),
    }
}

fn ids() -> Vec<GaussPointId> {
    (0..6).map(|e| GaussPointId::new(e, 0)).collect()
}

/// Creates the assemblies, solves and commits one small step (exporting: `export_every` 1),
/// and takes the states a checkpoint takes.
fn run(max_message_bytes: usize) -> Result<BTreeMap<GaussPointId, AssemblyState>, PoolError> {
    let mut pool = Pool::in_process(1, config(max_message_bytes), |_| Dem)?;
    pool.create_assemblies(&ids(), &request())?;
    let target = MacroDeformation::from_gradient([[-1e-4, 0.0], [0.0, -2e-4]], 0.0, [0.0; 2]);
    let inputs: Vec<_> = ids()
        .into_iter()
        .map(|gauss_point| MaterialInput { gauss_point, deformation: target })
        .collect();
    let trial = TrialId { step: 1, iteration: 0 };
    pool.evaluate(trial, &inputs).map_err(|e| PoolError::Unavailable(e.to_string()))?;
    pool.commit(1).map_err(|e| PoolError::Unavailable(e.to_string()))?;
    let states = pool.committed_states().clone();
    let exported = Material::committed_states(&mut pool)
        .map_err(|e| PoolError::Unavailable(e.to_string()))?
        .unwrap();
    assert_eq!(exported.len(), ids().len());
    Ok(states)
}

/// With a limit of 64 KiB, which one state fits and the worker's six do not, the creation's
/// export, the exporting commit and the checkpoint's export are split: the run goes through
/// and its states are those of a run with the default limit, byte for byte. So with a limit
/// of [`state_bytes`] of the disc count: the bound holds for a state in a real reply.
#[test]
fn states_are_sent_in_messages_within_the_limit() {
    let small = run(64 * 1024).unwrap();
    let large = run(cosdem_proto::DEFAULT_MAX_MESSAGE_BYTES).unwrap();
    let bytes: usize = large.values().map(|s| s.state.len()).sum();
    assert!(bytes > 64 * 1024 && state_bytes(105) < 64 * 1024, "{bytes}");
    assert_eq!(small.len(), 6);
    assert_eq!(small, large);
    // `state_bytes` bounds one state as gRPC carries it: a limit of exactly that passes.
    let tight = run(state_bytes(105) as usize).unwrap();
    assert_eq!(tight, large);
    assert!(small.values().all(|s| s.committed_step == 1));
}

/// A state larger than the limit cannot pass: the error names the call, the assembly and its
/// disc count, the limit and its settings on both sides, and what such a state takes.
#[test]
fn a_state_over_the_limit_names_the_setting_and_the_sizes() {
    let e = run(8 * 1024).unwrap_err().to_string();
    for needle in [
        "ExportState of 1 assembly of 105 discs",
        "max_message_bytes = 8192",
        "PoolConfig::max_message_bytes",
        "--max-message-mib",
        &format!("takes up to {} bytes", state_bytes(105)),
    ] {
        assert!(e.contains(needle), "`{needle}` not in {e}");
    }
}

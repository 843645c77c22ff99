//! ImportState with a damaged state names the assembly it was sent for, as well as the part
//! of the state at fault: one request (a migration, a recovery) carries many states, and the
//! decoder alone only knows "header", "checksum", "spec" or "body".

use cosdem_dem::{Assembly, AssemblySpec, PackingSpec};
use cosdem_proto::v1 as pb;
use cosdem_proto::v1::micro_solver_server::MicroSolver;
use cosdem_worker::{Dem, WorkerConfig, WorkerService};
use tonic::{Code, Request};

/// The committed state of a small hexagonal assembly (about 30 discs), as ExportState sends it.
fn state() -> Vec<u8> {
    let spec =
        AssemblySpec { packing: PackingSpec::hexagonal(0.005, 0.04), ..AssemblySpec::default() };
    Assembly::new(&spec).unwrap().to_bytes()
}

fn item(element: u32, point: u32, state: Vec<u8>) -> pb::AssemblyState {
    pb::AssemblyState {
        id: Some(pb::GaussPoint { element, point }),
        committed_step: 0,
        state,
        disc_count: 0,
    }
}

/// The status of importing `states`, which must be refused.
fn refused(states: Vec<pb::AssemblyState>) -> tonic::Status {
    let rt = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
    let svc =
        WorkerService::new(Dem, WorkerConfig { threads: 1, ..WorkerConfig::default() }).unwrap();
    rt.block_on(svc.import_state(Request::new(pb::ImportStateRequest { states })))
        .expect_err("a damaged state must be refused")
}

/// A flipped byte in the middle of a state fails its checksum: INVALID_ARGUMENT naming the
/// assembly (the second of the request, after a good one) and the checksum.
#[test]
fn a_damaged_state_names_its_assembly_and_the_checksum() {
    let good = state();
    let mut bad = good.clone();
    let k = bad.len() / 2;
    bad[k] ^= 0x40;
    let s = refused(vec![item(3, 0, good), item(3, 1, bad)]);
    assert_eq!(s.code(), Code::InvalidArgument, "{}", s.message());
    assert!(
        s.message().starts_with("assembly element 3 gauss point 1: ")
            && s.message().contains("checksum"),
        "{}",
        s.message()
    );
}

/// Bytes that are no state at all fail on the header, and name the assembly too.
#[test]
fn garbage_names_its_assembly_and_the_header() {
    let s = refused(vec![item(7, 2, b"garbage".to_vec())]);
    assert_eq!(s.code(), Code::InvalidArgument, "{}", s.message());
    assert!(
        s.message().starts_with("assembly element 7 gauss point 2: ")
            && s.message().contains("header"),
        "{}",
        s.message()
    );
}

//! Determinism: thread count does not change a bit; serialized state continues bit-exactly,
//! also in a fresh process.

mod common;
use common::*;
use cosdem_common::{MacroDeformation, MicroResponse};
use cosdem_dem::{Assembly, solve_batch};

fn batch() -> (Vec<Assembly>, Vec<MacroDeformation>) {
    let mut v = Vec::new();
    let mut t = Vec::new();
    for k in 0..4 {
        let side = 0.1 + 0.02 * k as f64;
        v.push(Assembly::new(&hex_spec(side, penalty())).unwrap());
        t.push(grad([[-1e-3 * (k + 1) as f64, 2e-4], [0.0, -5e-4]]));
    }
    // Random polydisperse packings under both boundaries (built inside the pool too).
    for (seed, boundary) in [(11, penalty()), (12, cosdem_dem::BoundarySpec::Periodic)] {
        let spec = cosdem_dem::AssemblySpec {
            packing: cosdem_dem::PackingSpec::Random {
                r_min: 0.002,
                r_max: 0.004,
                radii: vec![],
                side: 0.05,
                seed,
                confining_stress: 1e5,
            },
            boundary,
            ..Default::default()
        };
        v.push(Assembly::new(&spec).unwrap());
        t.push(grad([[-1e-3, 5e-4], [0.0, -2e-3]]));
    }
    (v, t)
}

/// Response without the wall time (the only non-deterministic field).
fn strip(r: &MicroResponse) -> MicroResponse {
    let mut r = r.clone();
    r.diagnostics.wall_seconds = 0.0;
    r
}

/// `solve_batch` over four hexagonal and two random assemblies on 1 and on 2 rayon threads:
/// identical responses (compared through their
/// f64 bit patterns, via `PartialEq` on the exact values) and identical serialized states.
#[test]
fn same_bits_with_one_and_two_threads() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let (mut a, t) = batch();
            let r: Vec<MicroResponse> =
                solve_batch(&mut a, &t).into_iter().map(|r| strip(&r.unwrap())).collect();
            a.iter_mut().for_each(|x| x.commit());
            let bytes: Vec<Vec<u8>> = a.iter().map(|x| x.to_bytes()).collect();
            (r, bytes)
        })
    };
    let (r1, b1) = run(1);
    let (r2, b2) = run(2);
    for (x, y) in r1.iter().zip(&r2) {
        let bits = |r: &MicroResponse| r.stress.map(f64::to_bits);
        assert_eq!(bits(x), bits(y));
        assert_eq!(x, y);
    }
    assert_eq!(b1, b2);
}

const CHILD_IN: &str = "COSDEM_ROUNDTRIP_IN";
const CHILD_OUT: &str = "COSDEM_ROUNDTRIP_OUT";

fn second_target() -> MacroDeformation {
    grad([[-1.5e-3, 1e-4], [2e-4, -1.1e-3]])
}

/// Not a test on its own: the child half of `round_trip_in_fresh_process`. Without the
/// environment variable it does nothing.
#[test]
fn roundtrip_child() {
    let (Ok(inp), Ok(out)) = (std::env::var(CHILD_IN), std::env::var(CHILD_OUT)) else {
        return;
    };
    let bytes = std::fs::read(inp).unwrap();
    let mut a = Assembly::from_bytes(&bytes).unwrap();
    let r = a.solve(&second_target()).unwrap();
    a.commit();
    let mut payload = a.to_bytes();
    payload.extend(r.stress.iter().flat_map(|v| v.to_le_bytes()));
    std::fs::write(out, payload).unwrap();
}

/// Solve, commit, serialize; restore in a fresh process (the test binary re-run on
/// `roundtrip_child`), solve again and commit there: the child's bytes and stress equal, bit
/// for bit, those of the same sequence run in this process without ever serializing. Also
/// checks an in-process `from_bytes` and that `rollback` restores the committed state.
#[test]
fn round_trip_in_fresh_process_is_bit_identical() {
    let mut a = Assembly::new(&hex_spec(0.12, penalty())).unwrap();
    a.solve(&grad([[-1e-3, 0.0], [0.0, -1e-3]])).unwrap();
    a.commit();
    let saved = a.to_bytes();
    // Rollback returns to the committed state exactly.
    a.solve(&grad([[-3e-3, 0.0], [0.0, -1e-3]])).unwrap();
    a.rollback();
    assert_eq!(a.to_bytes(), saved);
    // Reference continuation, never serialized.
    let r = a.solve(&second_target()).unwrap();
    a.commit();
    let mut want = a.to_bytes();
    want.extend(r.stress.iter().flat_map(|v| v.to_le_bytes()));
    // In-process restore.
    let mut b = Assembly::from_bytes(&saved).unwrap();
    let rb = b.solve(&second_target()).unwrap();
    b.commit();
    assert_eq!(rb.stress.map(f64::to_bits), r.stress.map(f64::to_bits));
    // Fresh process.
    let dir = std::env::temp_dir();
    let tag = std::process::id();
    let inp = dir.join(format!("cosdem-rt-{tag}.in"));
    let out = dir.join(format!("cosdem-rt-{tag}.out"));
    std::fs::write(&inp, &saved).unwrap();
    let status = std::process::Command::new(std::env::current_exe().unwrap())
        .args(["--exact", "roundtrip_child", "--test-threads", "1"])
        .env(CHILD_IN, &inp)
        .env(CHILD_OUT, &out)
        .status()
        .unwrap();
    assert!(status.success());
    let got = std::fs::read(&out).unwrap();
    let _ = std::fs::remove_file(&inp);
    let _ = std::fs::remove_file(&out);
    assert!(got == want, "fresh-process continuation differs");
}

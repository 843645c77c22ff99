//! The stage clock of `cosdem-worker bench dem` (issue 30): a timed relaxation computes what
//! an untimed one does, bit for bit, and its stages account for the time it took.

use cosdem_common::MacroDeformation;
use cosdem_dem::integrate::StageTimes;
use cosdem_dem::{Assembly, AssemblySpec, PackingSpec};

fn assembly() -> Assembly {
    let spec = AssemblySpec { packing: PackingSpec::hexagonal(0.005, 0.1), ..Default::default() };
    Assembly::new(&spec).unwrap()
}

fn target() -> MacroDeformation {
    MacroDeformation::from_gradient([[2e-4, 0.0], [0.0, -1e-3]], 0.0, [0.0; 2])
}

/// 700 steps towards the same target with and without a clock end in the same trial state
/// (exact: the clock and the equilibrium ratio only read the state), and the four stages sum
/// to no more than the wall time around the call and to most of it (the part outside the
/// relaxation is the affine predictor and the state copies: for 100 discs a few percent; the
/// bound of one half only catches a clock that loses whole stages).
#[test]
fn a_timed_run_is_the_same_run_and_its_stages_add_up() {
    let mut plain = assembly();
    plain.run_steps(&target(), 700).unwrap();
    let mut timed = assembly();
    let mut clock = StageTimes::new();
    let t0 = std::time::Instant::now();
    timed.run_steps_timed(&target(), 700, Some(&mut clock)).unwrap();
    let wall = t0.elapsed().as_secs_f64();
    assert_eq!(plain.trial().unwrap(), timed.trial().unwrap());
    let total: f64 = clock.seconds.iter().sum();
    assert!(clock.seconds.iter().all(|&s| s >= 0.0), "{:?}", clock.seconds);
    assert!(clock.seconds[..3].iter().all(|&s| s > 0.0), "{:?}", clock.seconds);
    assert!(total <= wall && total > 0.5 * wall, "stages {total} s of {wall} s");
}

//! A relaxation that hits its step cap is a failure of its Gauss point: the DEM micro model
//! behind the service turns the assembly's `converged = false` into an error naming the cap
//! (the master then cuts the load step) instead of answering an unrelaxed stress.

use cosdem_common::micro::AssemblyRequest;
use cosdem_common::{GaussPointId, MacroDeformation};
use cosdem_dem::AssemblySpec;
use cosdem_worker::{Dem, MicroModel};

#[test]
fn step_cap_is_a_failure_naming_the_cap() {
    let mut s = AssemblySpec::default();
    s.relaxation.max_steps = 20;
    let req = AssemblyRequest {
        spec_json: serde_json::to_vec(&s).unwrap(),
        boundary: Default::default(),
        disc_count_hint: 105,
    };
    let mut a = Dem.create(GaussPointId::new(0, 0), &req).unwrap();
    // 1e-3 uniaxial strain: far more than 20 steps of relaxation.
    let target = MacroDeformation { f: [[1.0, 0.0], [0.0, 1.0 - 1e-3]], ..Default::default() };
    let e = Dem.solve(&mut a, &target).unwrap_err().to_string();
    assert!(e.contains("step cap") && e.contains("20 steps"), "{e}");
}

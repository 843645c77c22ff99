//! A material can go back to committed states it exported before committing more steps (what
//! the application's stepper does to undo a stage that failed): the pool, holding assemblies,
//! replaces them with the saved ones, and so does the direct material. From there a step is
//! solved bit for bit as by a material that never went further: the same responses and the
//! same exported states, compared through their bytes (`Debug` of the responses writes every
//! `f64` in the form that reads back to its bits).

use cosdem_common::micro::{AssemblyRequest, AssemblyState, BoundaryKind};
use cosdem_common::{GaussPointId, MacroDeformation};
use cosdem_dem::AssemblySpec;
use cosdem_fem::material::{Material, MaterialInput, TrialId};
use cosdem_pool::{DirectDem, Pool, PoolConfig};
use cosdem_worker::Dem;

fn ids() -> Vec<GaussPointId> {
    (0..4).map(|e| GaussPointId::new(e, 0)).collect()
}

/// A biaxial compression `e_yy = -2e-4 k` (`e_xx` half of it) at every point.
fn step(m: &mut dyn Material, step: u64, k: f64) -> String {
    let target =
        MacroDeformation::from_gradient([[-1e-4 * k, 0.0], [0.0, -2e-4 * k]], 0.0, [0.0; 2]);
    let inputs: Vec<_> = ids()
        .into_iter()
        .map(|gauss_point| MaterialInput { gauss_point, deformation: target })
        .collect();
    let answers = m.evaluate(TrialId { step, iteration: 0 }, &inputs).unwrap();
    m.commit(step).unwrap();
    let stress: Vec<_> = answers.iter().map(|a| (a.stress, a.tangent)).collect();
    format!("{stress:?}")
}

fn states(m: &mut dyn Material) -> Vec<AssemblyState> {
    m.committed_states().unwrap().unwrap()
}

/// Step 1, then step 2 with `k = 3`, back to step 1, step 2 with `k = 2`: as step 1 then step
/// 2 with `k = 2`, and the states at step 1 again after going back.
fn goes_back(mut make: impl FnMut() -> Box<dyn Material>) {
    let mut straight = make();
    step(straight.as_mut(), 1, 1.0);
    let expected = step(straight.as_mut(), 2, 2.0);
    let expected_states = states(straight.as_mut());

    let mut m = make();
    step(m.as_mut(), 1, 1.0);
    let saved = states(m.as_mut());
    step(m.as_mut(), 2, 3.0);
    m.restore_states(saved.clone()).unwrap();
    assert_eq!(states(m.as_mut()), saved, "back at step 1");
    assert_eq!(step(m.as_mut(), 2, 2.0), expected);
    assert_eq!(states(m.as_mut()), expected_states);
    assert!(expected_states.iter().all(|s| s.committed_step == 2));
}

#[test]
fn a_pool_goes_back_to_saved_states() {
    let config = PoolConfig { in_process_threads: 1, ..PoolConfig::default() };
    let spec = AssemblySpec::default();
    let request = AssemblyRequest {
        spec_json: b"{}".to_vec(),
        boundary: BoundaryKind::Penalty,
        disc_count_hint: spec.disc_count_hint(),
    };
    goes_back(|| {
        let mut pool = Pool::in_process(2, config.clone(), |_| Dem).unwrap();
        pool.create_assemblies(&ids(), &request).unwrap();
        Box::new(pool)
    });
}

#[test]
fn the_direct_material_goes_back_to_saved_states() {
    goes_back(|| Box::new(DirectDem::new(&AssemblySpec::default(), &ids()).unwrap()));
}

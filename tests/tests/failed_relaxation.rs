//! A relaxation that fails is reported in-band and surfaces as `MaterialError::GaussPoints`
//! naming the Gauss point; the pool stays usable after the rollback (no worker is blamed).

mod common;
use common::*;
use cosdem_common::{GaussPointId, MacroDeformation};
use cosdem_fem::material::{Material, MaterialError, MaterialInput, TrialId};

#[test]
fn failed_relaxation_names_the_gauss_point() {
    let mut pool = standin_pool(2, test_config());
    create(&mut pool, 10, 1);
    let bad = GaussPointId::new(2, 1);
    let inputs = |e_bad: f64| -> Vec<MaterialInput> {
        gauss_points()
            .into_iter()
            .map(|gp| {
                let e = if gp == bad { e_bad } else { 0.001 };
                let d = MacroDeformation::from_strain(&[e, 0.0, 0.0, 0.0, 0.0, 0.0], 0.0);
                MaterialInput { gauss_point: gp, deformation: d }
            })
            .collect()
    };
    // The stand-in's "relaxation" fails beyond an equivalent strain of 0.5.
    let err = pool.evaluate(TrialId { step: 1, iteration: 0 }, &inputs(0.7)).unwrap_err();
    match &err {
        MaterialError::GaussPoints(list) => {
            assert_eq!(list.len(), 1, "{err}");
            assert_eq!(list[0].0, bad);
            assert!(list[0].1.contains("did not converge"), "{err}");
        }
        other => panic!("expected GaussPoints, got {other}"),
    }
    // NaN kinematics are refused before anything is sent, naming the point and the field.
    let mut nan = inputs(0.001);
    nan[0].deformation.w = f64::NAN;
    let err = pool.evaluate(TrialId { step: 1, iteration: 1 }, &nan).unwrap_err().to_string();
    assert!(err.contains("element 0 gauss point 0") && err.contains("`w`"), "{err}");
    pool.rollback().unwrap();
    pool.evaluate(TrialId { step: 1, iteration: 2 }, &inputs(0.001)).unwrap();
    pool.commit(1).unwrap();
    assert_eq!(pool.stats().workers_lost, 0);
}

//! Physics a scene switches off costs nothing and changes nothing else (issue 6, item 3b):
//! `k_r = 0` through the Coulomb rolling model runs the same no-rolling kernel as the `none`
//! model, so the two relaxations are bit-identical (same steps, same stress, same state).

mod common;
use common::*;
use cosdem_dem::{Assembly, RollingModel};

#[test]
fn coulomb_rolling_with_zero_stiffness_is_the_no_rolling_model() {
    let mut zero = hex_spec(0.1, penalty());
    zero.contact.rolling = RollingModel::Coulomb { k_r: 0.0, mu_r: 0.2, c_r: 0.0 };
    let mut none = hex_spec(0.1, penalty());
    none.contact.rolling = RollingModel::None;
    let (mut a, mut b) = (Assembly::new(&zero).unwrap(), Assembly::new(&none).unwrap());
    assert!(!a.law().has_rolling() && !b.law().has_rolling());
    for target in [iso(-1e-3), grad([[-1e-3, 2e-4], [1e-4, -1.5e-3]])] {
        let (ra, rb) = (a.solve(&target).unwrap(), b.solve(&target).unwrap());
        assert_eq!(ra.diagnostics.steps, rb.diagnostics.steps);
        assert_eq!(ra.stress, rb.stress);
        assert_eq!(a.trial().unwrap().dynamics, b.trial().unwrap().dynamics);
        assert!(a.trial().unwrap().pairs.hr.iter().all(|&h| h == 0.0), "no rolling history");
        a.commit();
        b.commit();
    }
}

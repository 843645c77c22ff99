//! Penalty against periodic boundaries, FIRE against Cundall, perturbation against contact
//! tangent.

mod common;
use common::*;
use cosdem_common::voigt::{XX, XY, YX, YY};
use cosdem_dem::{Assembly, BoundarySpec, Driver, TangentKind};

/// Secant stiffness `(ds_xx/de_xx, ds_yy/de_xx, d(s_xy+s_yx)/2 / de_sym)` about an isotropic
/// compression, with the interior-window stress (penalty: contacts with reference midpoint
/// in the central square of half the side, normalized to the bulk contact density) and the
/// strain of the interior affine fit.
fn secant(boundary: BoundarySpec, side: f64) -> [f64; 3] {
    let mut a = Assembly::new(&hex_spec(side, boundary.clone())).unwrap();
    let periodic = matches!(boundary, BoundarySpec::Periodic);
    a.solve(&iso(-1e-3)).unwrap();
    a.commit();
    let half = side / 4.0;
    let measure = |a: &Assembly, st: &cosdem_dem::State| {
        if periodic { a.homogenized(st) } else { a.window(st, half) }
    };
    let h0 = measure(&a, a.committed());
    let norm = 2.0 * 3f64.sqrt() / h0.fabric.density;
    let f0 = a.affine_fit(a.committed());
    let mut out = [0.0; 3];
    a.solve(&grad([[-1.1e-3, 0.0], [0.0, -1e-3]])).unwrap();
    let st = a.trial().unwrap();
    let f = a.affine_fit(st);
    let h = measure(&a, st);
    let de = f[0][0] - f0[0][0];
    out[0] = norm * (h.stress[XX] - h0.stress[XX]) / de;
    out[1] = norm * (h.stress[YY] - h0.stress[YY]) / de;
    a.solve(&grad([[-1e-3, 1e-4], [1e-4, -1e-3]])).unwrap();
    let st = a.trial().unwrap();
    let f = a.affine_fit(st);
    let h = measure(&a, st);
    let de = 0.5 * (f[0][1] - f0[0][1] + f[1][0] - f0[1][0]);
    out[2] = norm * 0.5 * (h.stress[XY] + h.stress[YX] - h0.stress[XY] - h0.stress[YX]) / de;
    out
}

/// A large (about 950 discs, V = 0.09 m^2) hexagonal assembly under penalty and under
/// periodic boundaries gives the same elastic (secant) stiffness within 3%, once the penalty
/// response is measured where the boundary does not reach: interior window, interior strain,
/// bulk contact density (measured: 0.6% on C_xxxx, 1.9% on C_yyxx, 0.2% on the shear).
#[test]
fn penalty_and_periodic_give_the_same_elastic_tangent() {
    let p = secant(penalty(), 0.3);
    let q = secant(BoundarySpec::Periodic, 0.3);
    eprintln!("penalty {p:?}\nperiodic {q:?}");
    for k in 0..3 {
        assert!(rel(p[k], q[k]) < 0.03, "component {k}: penalty {} vs periodic {}", p[k], q[k]);
    }
}

/// FIRE and Cundall damping relax to the same state: the stresses agree within a few times
/// the tolerance-limited accuracy (1e-6 ratio tolerance; 1e-4 relative on the stress).
/// The third run lets FIRE grow its step to a thousand base steps at safety 1: only the cap
/// at `FIRE_CEILING` of the critical step keeps it stable (without it the step would pass
/// the critical one and the stiffest mode would grow until the step cap ends the
/// relaxation unconverged). Measured without the cap: even the default FIRE (1.8 base steps
/// at safety 0.8, 1.44 critical steps) ran into the 400 000-step cap unconverged.
#[test]
fn fire_and_cundall_agree() {
    let target = grad([[-1.3e-3, 1e-4], [0.0, -0.9e-3]]);
    let mut out = Vec::new();
    let mut unbounded = Driver::fire();
    if let Driver::Fire { dt_max, .. } = &mut unbounded {
        *dt_max = 1e3;
    }
    let runs = [(Driver::Cundall { alpha: 0.7 }, 0.8), (Driver::fire(), 0.8), (unbounded, 1.0)];
    for (driver, safety) in runs {
        let mut spec = hex_spec(0.15, penalty());
        spec.relaxation.driver = driver;
        spec.relaxation.safety = safety;
        spec.relaxation.tolerance = 1e-6;
        let mut a = Assembly::new(&spec).unwrap();
        let r = a.solve(&target).unwrap();
        eprintln!("{:?}: {} steps", spec.relaxation.driver, r.diagnostics.steps);
        assert!(r.diagnostics.converged);
        out.push(r.stress);
    }
    let scale = out[0][XX].abs();
    for other in &out[1..] {
        for k in 0..4 {
            assert!(
                (out[0][k] - other[k]).abs() < 1e-4 * scale,
                "{k}: {} vs {}",
                out[0][k],
                other[k]
            );
        }
    }
}

/// The perturbation tangent (central differences of relaxations from the trial state, which
/// is restored) of a periodic hexagonal cell equals the contact tangent on its symmetric
/// part: `C_xxxx`, `C_yyxx`, `C_xyxy + C_xyyx` within 2% (the perturbation also sees the
/// geometric stiffness of the prestress). The trial state after the solve is the one
/// without perturbation.
#[test]
fn perturbation_tangent_matches_contact_tangent() {
    let mut spec = hex_spec(0.1, BoundarySpec::Periodic);
    let mut a = Assembly::new(&spec).unwrap();
    let paper = a.solve(&iso(-1e-3)).unwrap();
    spec.tangent = TangentKind::Perturbation { strain: 1e-6 };
    let mut b = Assembly::new(&spec).unwrap();
    let pert = b.solve(&iso(-1e-3)).unwrap();
    assert_eq!(pert.stress, paper.stress);
    // Same state; only the stored answer's tangent differs.
    let (ta, tb) = (a.trial().unwrap(), b.trial().unwrap());
    assert_eq!((&ta.dynamics, &ta.pairs, ta.target), (&tb.dynamics, &tb.pairs, tb.target));
    let (p, q) = (&paper.tangent, &pert.tangent);
    assert!(rel(q[XX][XX], p[XX][XX]) < 0.02, "{} vs {}", q[XX][XX], p[XX][XX]);
    assert!(rel(q[YY][XX], p[YY][XX]) < 0.02, "{} vs {}", q[YY][XX], p[YY][XX]);
    let sym = |c: &[[f64; 6]; 6]| c[XY][XY] + c[XY][YX];
    assert!(rel(sym(q), sym(p)) < 0.02, "{} vs {}", sym(q), sym(p));
}

/// The kinetic-energy criterion and warm starts reach the same equilibrium as the default
/// (unbalanced force, cold start): stresses within 1e-3 relative (both criteria stop at
/// their own tolerance), and a warm-started second Newton iteration takes fewer steps.
#[test]
fn kinetic_criterion_and_warm_start() {
    let t1 = grad([[-1.2e-3, 0.0], [0.0, -1e-3]]);
    let t2 = grad([[-1.25e-3, 0.0], [0.0, -1e-3]]);
    let mut base = Assembly::new(&hex_spec(0.15, penalty())).unwrap();
    let r_base = base.solve(&t2).unwrap();
    let mut spec = hex_spec(0.15, penalty());
    spec.relaxation.criterion = cosdem_dem::Criterion::KineticEnergy;
    spec.relaxation.tolerance = 1e-8;
    let mut a = Assembly::new(&spec).unwrap();
    let r = a.solve(&t2).unwrap();
    assert!(r.diagnostics.converged);
    assert!(
        rel(r.stress[XX], r_base.stress[XX]) < 1e-3,
        "{} vs {}",
        r.stress[XX],
        r_base.stress[XX]
    );
    let mut spec = hex_spec(0.15, penalty());
    spec.warm_start = true;
    let mut w = Assembly::new(&spec).unwrap();
    w.solve(&t1).unwrap();
    let rw = w.solve(&t2).unwrap();
    assert!(rel(rw.stress[XX], r_base.stress[XX]) < 1e-3);
    assert!(
        rw.diagnostics.steps < r_base.diagnostics.steps,
        "{} vs {}",
        rw.diagnostics.steps,
        r_base.diagnostics.steps
    );
}

/// The adaptive tangent is the paper tangent while the contacts stick and the perturbation
/// tangent once at least `sliding` of them slide, decided on the relaxed state. Checked
/// exactly (same arithmetic, so bit-equal): an isotropic compression slides no contact, so
/// `adaptive` answers the paper tangent with the paper's step count; a threshold of 0 always
/// perturbs; a frictionless cell (mu_s = 0) sheared by 1e-3 slides most of its loaded
/// contacts (as in `extremes.rs`), so a threshold of 0.05 perturbs there.
#[test]
fn adaptive_tangent_switches_where_contacts_slide() {
    let solve = |tangent: TangentKind, mu: f64, target: &cosdem_common::MacroDeformation| {
        let mut spec = hex_spec(0.1, penalty());
        if let cosdem_dem::spec::TangentialModel::Coulomb { mu_s, .. } =
            &mut spec.contact.tangential
        {
            *mu_s = mu;
        }
        spec.tangent = tangent;
        Assembly::new(&spec).unwrap().solve(target).unwrap()
    };
    let adaptive = |sliding| TangentKind::Adaptive { sliding, strain: 1e-6 };
    let pert = TangentKind::Perturbation { strain: 1e-6 };
    let iso = iso(-1e-3);
    let paper = solve(TangentKind::Paper, 0.5, &iso);
    assert_eq!(paper.diagnostics.sliding_fraction, 0.0);
    let sticking = solve(adaptive(0.05), 0.5, &iso);
    assert_eq!(sticking.tangent, paper.tangent);
    assert_eq!(sticking.diagnostics.steps, paper.diagnostics.steps);
    assert_eq!(solve(adaptive(0.0), 0.5, &iso).tangent, solve(pert.clone(), 0.5, &iso).tangent);
    let shear = grad([[0.0, 1e-3], [0.0, 0.0]]);
    let slipping = solve(adaptive(0.05), 0.0, &shear);
    assert!(slipping.diagnostics.sliding_fraction >= 0.05, "{:?}", slipping.diagnostics);
    assert_eq!(slipping.tangent, solve(pert, 0.0, &shear).tangent);
    assert_ne!(slipping.tangent, solve(TangentKind::Paper, 0.0, &shear).tangent);
}

/// The secant tangent is the paper tangent scaled by the assembly's own secant ratio along
/// the step, `s = (dsigma . de) / (de . C de)` from the committed relaxed answer: checked to
/// the bit against that formula evaluated on the public committed state, on a frictionless
/// hexagonal assembly sheared by 1e-3 (its contacts slide, so the relaxed shear stiffness is
/// far below the contact tangent, which keeps k_s on every contact). The relaxation itself is
/// the tangent's business not at all (same stress), a never-relaxed committed state (a
/// hexagonal packing as built) gives the paper tangent, and so does a nil increment.
#[test]
fn secant_tangent_scales_the_paper_tangent_by_the_path_secant() {
    use cosdem_common::voigt::N;
    let make = |tangent: TangentKind| {
        let mut spec = hex_spec(0.1, penalty());
        if let cosdem_dem::spec::TangentialModel::Coulomb { mu_s, .. } =
            &mut spec.contact.tangential
        {
            *mu_s = 0.0;
        }
        spec.tangent = tangent;
        Assembly::new(&spec).unwrap()
    };
    let (mut secant, mut paper) = (make(TangentKind::Secant), make(TangentKind::Paper));
    let t1 = grad([[-1e-3, 1e-3], [0.0, -1e-3]]);
    let (a1, b1) = (secant.solve(&t1).unwrap(), paper.solve(&t1).unwrap());
    assert_eq!(a1.stress, b1.stress);
    assert_eq!(a1.tangent, b1.tangent, "never relaxed before: the paper tangent");
    secant.commit();
    paper.commit();
    let t2 = grad([[-1e-3, 2e-3], [0.0, -1e-3]]);
    let (a2, b2) = (secant.solve(&t2).unwrap(), paper.solve(&t2).unwrap());
    assert_eq!(a2.stress, b2.stress);
    let committed = secant.committed();
    let c = committed.relaxed.as_ref().unwrap();
    let (e1, e0) = (t2.strain(), committed.target.strain());
    let de: [f64; N] = std::array::from_fn(|i| e1[i] - e0[i]);
    let work: f64 = (0..N).map(|i| (a2.stress[i] - c.stress[i]) * de[i]).sum();
    let c2 = &b2.tangent;
    let elastic: f64 = (0..N).map(|i| de[i] * (0..N).map(|j| c2[i][j] * de[j]).sum::<f64>()).sum();
    let s = (work / elastic).clamp(0.05, 1.0);
    eprintln!("secant scale {s:.4} (work {work:.4e}, elastic {elastic:.4e})");
    assert!(s < 0.9, "sliding contacts soften the shear: s = {s}");
    assert_eq!(a2.tangent, b2.tangent.map(|row| row.map(|v| s * v)));
    // A nil increment (the committed target again): the paper tangent.
    let (a3, b3) = (secant.solve(&t1).unwrap(), paper.solve(&t1).unwrap());
    assert_eq!(a3.tangent, b3.tangent);
}

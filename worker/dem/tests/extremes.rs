//! Stability at the extremes (issue 6 item 4): every case gives a finite, converged answer or
//! an error naming the spec field that made it impossible; never NaN, never a hang (each
//! relaxation stops at its step cap and says so).
//!
//! Reference scene, changed one parameter at a time: the paper's contact law and penalty
//! boundary on the hexagonal 105-disc assembly (r = 5 mm, side 0.1 m, V = 0.01 m^2), solved
//! in ONE relaxation from the reference state to a uniaxial compression `e_yy = -1e-3`
//! (`Fbar = diag(1, 1 - 1e-3)`).
//!
//! What a converged case checks, and why (see [`converged`]):
//! - every stress and tangent entry is finite: the contract (never NaN);
//! - the relaxation met its own criterion: `converged` and residual ratio <= `tolerance`;
//! - `s_yy < 0`: a compression gives a compressive stress (tension positive, THEORY.md 0).
//!
//! Run with `--nocapture` to print the table of outcomes (one `|`-separated row per case).

mod common;
use common::*;
use cosdem_common::{MacroDeformation, MicroResponse};
use cosdem_dem::{
    Assembly, AssemblySpec, BoundarySpec, NormalModel, PackingSpec, RollingModel, TangentialModel,
};
use std::time::Instant;

/// Uniaxial compression `e_yy = -e` in one step.
fn uniaxial(e: f64) -> MacroDeformation {
    grad([[0.0, 0.0], [0.0, -e]])
}

/// The reference scene (see the module doc).
fn base() -> AssemblySpec {
    hex_spec(0.1, penalty())
}

/// Builds `spec` and solves `target` once from the reference state: the response and the
/// disc count, or the error message.
fn attempt(
    spec: &AssemblySpec,
    target: &MacroDeformation,
) -> Result<(MicroResponse, usize), String> {
    let mut a = Assembly::new(spec).map_err(|e| e.to_string())?;
    let r = a.solve(target).map_err(|e| e.to_string())?;
    Ok((r, a.disc_count()))
}

/// Asserts the case converged to a finite answer (module doc) and prints its table row.
fn converged(case: &str, spec: &AssemblySpec, target: &MacroDeformation) -> MicroResponse {
    let t0 = Instant::now();
    let (r, n) = attempt(spec, target).unwrap_or_else(|e| panic!("{case}: error {e}"));
    let secs = t0.elapsed().as_secs_f64();
    assert!(r.is_finite(), "{case}: non-finite response {r:?}");
    let d = &r.diagnostics;
    assert!(
        d.converged && d.residual_ratio <= spec.relaxation.tolerance,
        "{case}: not converged: ratio {:e} after {} steps",
        d.residual_ratio,
        d.steps
    );
    eprintln!(
        "| {case} | {n} discs | converged: {} steps, ratio {:.1e}, s_yy = {:.4e} Pa | {secs:.2} s |",
        d.steps, d.residual_ratio, r.stress[1]
    );
    r
}

/// [`converged`] plus the sign check of a compression.
fn compressed(case: &str, spec: &AssemblySpec, target: &MacroDeformation) -> MicroResponse {
    let r = converged(case, spec, target);
    assert!(r.stress[1] < 0.0, "{case}: s_yy = {} is not compressive", r.stress[1]);
    r
}

/// Asserts the case is refused with a message naming `field`; prints its table row.
fn refused(case: &str, spec: &AssemblySpec, target: &MacroDeformation, field: &str) {
    let e = match attempt(spec, target) {
        Ok((r, _)) => panic!("{case}: expected an error naming {field}, got {r:?}"),
        Err(e) => e,
    };
    assert!(e.contains(field), "{case}: error does not name `{field}`: {e}");
    eprintln!("| {case} | - | error: {e} | - |");
}

fn with_stiffness(kn: f64, ks: f64) -> AssemblySpec {
    let mut s = base();
    s.contact.normal = NormalModel::Linear { k_n: kn };
    s.contact.tangential = TangentialModel::Coulomb { k_s: ks, mu_s: 0.5, c_s: 0.0 };
    s
}

/// k_s / k_n from 1e-3 to 10 at the paper's k_n. Besides the common checks: the secant
/// `s_yy / e_yy` is positive and at most 1.05 times the paper tangent's `C_yyyy` (the penalty
/// membrane is in series with the contacts, so it can only soften the response; the measured
/// ratio is 0.85-0.95, and 5% covers the tangent's counting of the edge contacts).
#[test]
fn stiffness_ratio_from_1e_3_to_10() {
    let kn = 6.7e7;
    for ratio in [1e-3, 1e-2, 0.1, 0.5, 1.0, 3.0, 10.0] {
        let case = format!("k_s/k_n = {ratio:e}");
        let r = compressed(&case, &with_stiffness(kn, ratio * kn), &uniaxial(1e-3));
        let secant = r.stress[1] / -1e-3;
        let c = r.tangent[1][1];
        assert!(secant > 0.0 && secant <= 1.05 * c, "{case}: secant {secant:e} vs C_yyyy {c:e}");
    }
}

/// k_n from 1e4 to 1e10 N/m (k_s = k_n / 2, the paper's ratio), everything else the paper's:
/// from a boundary 6.7e4 times stiffer than the contacts to one 15 times softer. Besides the
/// common checks, the secant bound of `stiffness_ratio_from_1e_3_to_10`.
#[test]
fn normal_stiffness_from_1e4_to_1e10() {
    for kn in [1e4, 1e6, 6.7e7, 1e8, 1e10] {
        let case = format!("k_n = {kn:e}");
        let r = compressed(&case, &with_stiffness(kn, 0.5 * kn), &uniaxial(1e-3));
        let secant = r.stress[1] / -1e-3;
        assert!(secant > 0.0 && secant <= 1.05 * r.tangent[1][1], "{case}: secant {secant:e}");
    }
}

/// mu_s = 0 (frictionless) and mu_s = 10, under the uniaxial compression and under a simple
/// shear of 1e-3 (where friction decides whether contacts slide). Frictionless: every
/// loaded contact slides (sliding fraction > 0.5 under shear) and the shear spring, which
/// can carry no force, does not shorten the time step. mu_s = 10: nothing slides.
#[test]
fn sliding_friction_zero_and_ten() {
    let shear = grad([[0.0, 1e-3], [0.0, 0.0]]);
    let mut dts = Vec::new();
    for mu_s in [0.0, 10.0] {
        let mut s = base();
        s.contact.tangential = TangentialModel::Coulomb { k_s: 3.4e7, mu_s, c_s: 0.0 };
        compressed(&format!("mu_s = {mu_s}, uniaxial"), &s, &uniaxial(1e-3));
        let r = converged(&format!("mu_s = {mu_s}, shear 1e-3"), &s, &shear);
        let sliding = r.diagnostics.sliding_fraction;
        if mu_s == 0.0 {
            assert!(sliding > 0.5, "frictionless: sliding fraction {sliding}");
        } else {
            assert!(sliding == 0.0, "mu_s = 10: sliding fraction {sliding}");
        }
        dts.push(Assembly::new(&s).unwrap().time_step());
    }
    let mut none = base();
    none.contact.tangential = TangentialModel::None;
    let dt_none = Assembly::new(&none).unwrap().time_step();
    assert_eq!(dts[0], dt_none, "mu_s = 0 must give the time step of no tangential spring");
    assert!(dts[1] < dt_none);
}

/// mu_r = 0 with a rolling spring up to 1e8 N m/rad (4e6 times the paper's): the spring can
/// carry no moment (its cap is `0 * F_n`), so it must neither break nor slow the relaxation:
/// the time step is exactly that of no rolling model, and the relaxation converges under a
/// curvature (which loads the rolling springs when mu_r > 0).
#[test]
fn rolling_friction_zero_with_stiff_rolling_spring() {
    let mut none = base();
    none.contact.rolling = RollingModel::None;
    let dt_none = Assembly::new(&none).unwrap().time_step();
    let bend = MacroDeformation::from_gradient([[0.0, 0.0], [0.0, -1e-3]], 0.0, [0.05, 0.0]);
    for k_r in [25.0, 1e4, 1e8] {
        let mut s = base();
        s.contact.rolling = RollingModel::Coulomb { k_r, mu_r: 0.0, c_r: 0.0 };
        assert_eq!(Assembly::new(&s).unwrap().time_step(), dt_none, "k_r = {k_r:e}");
        compressed(&format!("mu_r = 0, k_r = {k_r:e}, uniaxial + kappa_x 0.05"), &s, &bend);
    }
}

/// Miehe's penalty eps_f from 1e3 to 1e10 N m (eps_f / V from 1e5 to 1e12 N/m: from 670
/// times softer than k_n to 1.5e4 times stiffer). The stiff end shortens the time step, so
/// the relaxation takes more steps, but it must still converge within the default cap.
#[test]
fn penalty_eps_f_from_1e3_to_1e10() {
    for eps_f in [1e3, 1e5, 6.7e6, 1e8, 1e10] {
        let mut s = base();
        s.boundary = BoundarySpec::Penalty { eps_f, eps_c: 1e3 };
        compressed(&format!("eps_f = {eps_f:e}"), &s, &uniaxial(1e-3));
    }
}

/// One strain increment from 1e-8 to 1e-2 in a single step (uniaxial), and a 1e-2 simple
/// shear: the affine predictor jumps the whole way, the relaxation takes it from there.
#[test]
fn strain_increment_from_1e_8_to_1e_2_in_one_step() {
    let s = base();
    for e in [1e-8, 1e-6, 1e-4, 1e-3, 1e-2] {
        compressed(&format!("uniaxial e_yy = -{e:e}"), &s, &uniaxial(e));
    }
    converged("simple shear 1e-2", &s, &grad([[0.0, 1e-2], [0.0, 0.0]]));
    // A stretch that opens every contact: a loose assembly held by its boundary springs.
    let r = converged("isotropic stretch +1e-2 (all contacts open)", &s, &iso(1e-2));
    assert!(r.diagnostics.contacts == 0, "contacts {}", r.diagnostics.contacts);
}

fn random(r_min: f64, r_max: f64, radii: Vec<f64>, side: f64, b: BoundarySpec) -> AssemblySpec {
    AssemblySpec {
        packing: PackingSpec::Random { r_min, r_max, radii, side, seed: 3, confining_stress: 1e5 },
        boundary: b,
        ..Default::default()
    }
}

/// From the smallest assemblies to 20 000 discs. Seven discs: a random packing of seven
/// given radii (the smallest the packing accepts is four), with either boundary. The
/// smallest hexagonal square (side = 8 r: 14 discs). 2 400 discs under the penalty boundary.
/// 20 000 discs in a periodic cell (the affine predictor is already the equilibrium of a
/// perfect lattice, so this measures building, the broad phase and homogenization at that
/// size in a default-suite budget; the penalty version is `twenty_thousand_discs_penalty`).
#[test]
fn assembly_sizes_from_7_to_20000() {
    let seven = vec![0.005, 0.0045, 0.0055, 0.005, 0.006, 0.004, 0.005];
    for b in [BoundarySpec::Periodic, penalty()] {
        let s = random(0.0, 0.0, seven.clone(), 0.05, b.clone());
        converged(&format!("7 discs, random, {b:?}"), &s, &iso(-1e-3));
    }
    compressed("14 discs, hexagonal side 8 r", &hex_spec(0.04, penalty()), &uniaxial(1e-3));
    compressed("2 400 discs, hexagonal, penalty", &hex_spec(0.45, penalty()), &uniaxial(1e-3));
    let big = hex_spec(1.32, BoundarySpec::Periodic);
    let r = compressed("20 000 discs, hexagonal, periodic", &big, &uniaxial(1e-3));
    assert!(r.diagnostics.contacts > 55_000, "contacts {}", r.diagnostics.contacts);
}

/// The 20 000-disc penalty square: a compression wave has to cross 130 discs, which takes
/// minutes in the debug profile (run with `--ignored`, preferably `--release`).
#[test]
#[ignore = "minutes in the debug profile"]
fn twenty_thousand_discs_penalty() {
    compressed("20 000 discs, hexagonal, penalty", &hex_spec(1.32, penalty()), &uniaxial(1e-4));
}

/// Polydispersity up to r_max / r_min = 10 (random packing at 100 kPa), both boundaries, then
/// a 1e-3 isotropic compression in one step. The smallest disc sets the time step, so the
/// wide distribution costs steps, not stability.
#[test]
fn polydispersity_up_to_10() {
    for (ratio, b) in [(3.0, penalty()), (10.0, BoundarySpec::Periodic), (10.0, penalty())] {
        let r_max = 0.006;
        let s = random(r_max / ratio, r_max, vec![], 0.07, b.clone());
        let r = converged(&format!("r_max/r_min = {ratio}, {b:?}"), &s, &iso(-1e-3));
        assert!(r.stress[0] < 0.0 && r.stress[1] < 0.0, "not compressive: {:?}", r.stress);
    }
}

/// Far beyond the ranges above, where an answer still exists: k_n = 1e300 (scale-free:
/// forces 1e295 N, time step 1e-150 s, all representable). The paper's penalty is then
/// 1e291 times softer than the contacts, so the compressed assembly pushes its boundary out
/// until its contacts carry nothing: finite, converged, a stress of zero to 1e-12 of k_n r.
#[test]
fn far_beyond_the_ranges_still_finite() {
    let r = converged("k_n = 1e300", &with_stiffness(1e300, 5e299), &uniaxial(1e-3));
    assert!(r.stress.iter().all(|s| s.abs() <= 1e-12 * 1e300 * 0.005 / 0.01), "{:?}", r.stress);
}

/// What cannot be done is refused before any work, naming the parameter: a stiffness that
/// overflows the time-step bound, a spring more than 1e12 times stiffer (squared frequency)
/// than the contacts (the relaxation would never end), a density whose discs have no usable
/// mass, a side/radius ratio that asks for more than a million discs, a relaxation cap
/// beyond 1e8 steps, a square smaller than four diameters, a non-finite value.
#[test]
fn impossible_cases_name_the_parameter() {
    let t = uniaxial(1e-3);
    refused("k_n = 1.7e308", &with_stiffness(1.7e308, 1e3), &t, "contact.normal.k_n");
    refused("k_n = inf", &with_stiffness(f64::INFINITY, 1e3), &t, "contact.normal.k_n");
    refused("k_n = 1e-300", &with_stiffness(1e-300, 0.0), &t, "contact.normal.k_n");
    let mut s = base();
    s.contact.rolling = RollingModel::Coulomb { k_r: 1e300, mu_r: 0.2, c_r: 0.0 };
    refused("k_r = 1e300 (mu_r > 0)", &s, &t, "contact.rolling.k_r");
    let mut s = base();
    s.boundary = BoundarySpec::Penalty { eps_f: 1e300, eps_c: 1e3 };
    refused("eps_f = 1e300", &s, &t, "boundary.eps_f");
    let mut s = base();
    s.density = 1e-300;
    refused("density = 1e-300", &s, &t, "density");
    refused("side / r = 1e5", &hex_spec(500.0, penalty()), &t, "packing.side");
    let s = random(1e-6, 1e-5, vec![], 10.0, penalty());
    refused("random side / r = 1e6", &s, &t, "packing.side");
    let mut s = base();
    s.relaxation.max_steps = 1_000_000_000_000;
    refused("max_steps = 1e12", &s, &t, "relaxation.max_steps");
    refused("side < 8 r", &hex_spec(0.039, penalty()), &t, "packing.side");
    let mut s = base();
    s.contact.tangential = TangentialModel::Coulomb { k_s: 3.4e7, mu_s: f64::NAN, c_s: 0.0 };
    refused("mu_s = NaN", &s, &t, "contact.tangential.mu_s");
    refused("target det(F) = 0", &base(), &grad([[-1.0, 0.0], [0.0, 0.0]]), "det(F)");
}

/// A relaxation that cannot converge in its cap stops there and says so: the assembly
/// reports `converged = false` with the steps taken (the service model turns it into a
/// failure message, `worker/service/tests/step_cap.rs`) instead of waiting.
#[test]
fn step_cap_is_reported_not_waited_for() {
    let mut s = base();
    s.relaxation.max_steps = 20;
    let (r, _) = attempt(&s, &uniaxial(1e-3)).unwrap();
    assert!(!r.diagnostics.converged && r.diagnostics.steps == 20, "{:?}", r.diagnostics);
    assert!(r.is_finite());
}

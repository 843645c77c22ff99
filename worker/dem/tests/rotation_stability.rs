//! Stability of the rotational dof of a penalty-held disc under Cundall's damping.
//!
//! A boundary disc of inertia `I` held by the penalty moment spring `k_c = eps_c / V` has
//! `omega^2 >= k_c / I`. Leapfrog's growing mode alternates sign every step, so Cundall's
//! damping, `F (1 - alpha sign(F v))`, multiplies its force by `1 + alpha` on every step:
//! the mode grows when `dt omega sqrt(1 + alpha) > 2`. The relaxation step is `safety` times
//! the undamped Gershgorin step `2 / omega_max`, so at safety 0.8 and `alpha = 0.7`
//! (`0.8 sqrt 1.7 = 1.04`) a dof whose penalty term makes up more than 92 % of `omega_max^2`
//! diverges. The seed-11 random packing (72 discs, 0.047 m square, paper penalty) has its
//! smallest disc (r = 2.0014 mm) on the boundary: `k_c / I = 6.68e12 1/s^2`, 98 % of the
//! bound, `dt omega sqrt 1.7 = 2.07`. Its spin grew by 1.67 per step to NaN within the
//! 1 580 steps of a relaxation that reported convergence (the torques are not in the force
//! ratio and the capped contact moments stay finite), with couple stresses of 1.25 and 1.82 N
//! instead of 0.10 and -0.01 N.

mod common;
use common::*;
use cosdem_dem::boundary::penalty::Penalty;
use cosdem_dem::broadphase::{self, Domain, PairList};
use cosdem_dem::contact::Law;
use cosdem_dem::integrate::{self, Dynamics, System, Work, cundall};
use cosdem_dem::{Assembly, AssemblySpec, Error, PackingSpec, RelaxationSpec};

/// The seed-11 random packing of `tests/determinism.rs` under the paper's penalty boundary.
fn seed11(safety: f64) -> AssemblySpec {
    AssemblySpec {
        packing: PackingSpec::Random {
            r_min: 0.002,
            r_max: 0.004,
            radii: vec![],
            side: 0.05,
            seed: 11,
            confining_stress: 1e5,
        },
        boundary: penalty(),
        relaxation: RelaxationSpec { safety, ..RelaxationSpec::default() },
        ..Default::default()
    }
}

/// The seed-11 packing's loading step of `tests/determinism.rs` at the default safety 0.8:
/// every disc's position, rotation, velocity and spin is finite and its rotation small, and
/// the stress and couple stress match the same step at safety 0.3 (a step 2.7 times smaller,
/// stable without any mass change). Tolerances: the relaxation stops at a force ratio of
/// 1e-4, so two step sizes reach slightly different equilibria; measured, the stresses differ
/// by 1e-5 relative and the couple stresses by 0.003 N (of 0.10 N); the diverged answer was
/// 1.1 and 1.8 N off.
#[test]
fn seed_11_penalty_spin_stays_finite_and_couple_stress_matches_a_smaller_step() {
    let target = grad([[-1e-3, 5e-4], [0.0, -2e-3]]);
    let mut a = Assembly::new(&seed11(0.8)).unwrap();
    let r = a.solve(&target).unwrap();
    assert!(r.diagnostics.converged);
    let d = &a.trial().unwrap().dynamics;
    for k in 0..d.x.len() {
        let all = [d.x[k], d.y[k], d.th[k], d.vx[k], d.vy[k], d.w[k]];
        assert!(all.iter().all(|v| v.is_finite()), "disc {k}: {all:?}");
        assert!(d.th[k].abs() < 0.01, "disc {k} turned by {} rad", d.th[k]);
    }
    let mut small = Assembly::new(&seed11(0.3)).unwrap();
    let s = small.solve(&target).unwrap();
    for c in 0..4 {
        assert!(rel(r.stress[c], s.stress[c]) < 1e-3, "stress {c}: {r:?} vs {s:?}");
    }
    for c in 4..6 {
        let diff = (r.stress[c] - s.stress[c]).abs();
        assert!(diff < 0.01, "couple stress {c}: {} vs {} N", r.stress[c], s.stress[c]);
    }
}

/// The stability condition itself, on one disc spun by its penalty moment spring alone
/// (`omega^2 = k_c / I`) under `cundall::advance`, released from a rotation `th_0`. 5 % below
/// `2 / (omega sqrt(1 + alpha))` the rotation stays within leapfrog's overshoot of its start
/// (`1 / sqrt(1 - (dt omega / 2)^2)` = 3.2 undamped at 0.95 of `2 / omega`; measured 1.12 with
/// `alpha = 0.7`): bound 4. 5 % above it the sign-alternating mode grows by
/// `|lambda| = 1.88` per step (`lambda^2 - (2 - 2.1^2) lambda + 1 = 0`), 1e109 in 400 steps:
/// bound 1e100. Undamped (`alpha = 0`) the limit is the plain `2 / omega`.
#[test]
fn damped_leapfrog_limit_of_a_penalty_held_spin() {
    let (kc, i) = (4.46e5f64, 6.68e-8f64);
    let omega = (kc / i).sqrt();
    let run = |alpha: f64, dt: f64| -> f64 {
        let mut d = Dynamics::at_rest(vec![0.0], vec![0.0]);
        d.th[0] = 1e-6;
        let mut work = Work { fx: vec![0.0], fy: vec![0.0], tq: vec![0.0] };
        let mut peak = 0.0f64;
        for _ in 0..400 {
            work.tq[0] = -kc * d.th[0];
            cundall::advance(&mut d, &work, &[1.0], &[1.0 / i], &[0.0], &[0.0], alpha, dt, 1.0);
            peak = peak.max(d.th[0].abs());
        }
        peak / 1e-6
    };
    for alpha in [0.0f64, 0.7] {
        let limit = 2.0 / (omega * (1.0 + alpha).sqrt());
        let below = run(alpha, 0.95 * limit);
        let above = run(alpha, 1.05 * limit);
        assert!(below < 4.0, "alpha {alpha}: below the limit grew by {below:e}");
        assert!(above > 1e100, "alpha {alpha}: above the limit grew only by {above:e}");
    }
}

/// A disc whose spin is unstable (the seed-11 disc's `k_c / I` at its old step) while its
/// translation relaxes: `integrate::relax` returns `Diverged` (which the assembly redoes at
/// half the step) instead of "converged" with a rotation of 1e170 rad or NaN.
#[test]
fn runaway_spin_is_a_divergence_not_convergence() {
    let (r, m, i) = (0.002, 0.0333, 6.66e-8);
    let (kf, kc) = (2.99e9, 4.46e5);
    let dt = 1.035 * 2.0 / ((kc / i) * 1.7f64).sqrt();
    let law = Law::from_params(&Default::default());
    let pen = Penalty { idx: vec![0], xt: vec![1e-6], yt: vec![0.0], tht: vec![1e-9], kf, kc };
    let (radii, inv_m, inv_i) = ([r], [1.0 / m], [1.0 / i]);
    let sys = System {
        law: &law,
        r: &radii,
        inv_m: &inv_m,
        inv_i: &inv_i,
        penalty: Some(&pen),
        domain: Domain::Open,
        skin: 0.5 * r,
        force_floor: 1e-12 * law.kn * r,
    };
    let mut d = Dynamics::at_rest(vec![0.0], vec![0.0]);
    let mut pairs =
        broadphase::build(&d.x, &d.y, &radii, sys.skin, Domain::Open, &PairList::default());
    let spec = RelaxationSpec::default();
    let got = integrate::relax(&sys, &mut d, &mut pairs, &mut Work::default(), &spec, dt, 1e-4);
    assert!(matches!(got, Err(Error::Diverged { .. })), "{got:?}, rotation {} rad", d.th[0]);
    // The same disc at the step the assembly now gives it relaxes.
    let mut d = Dynamics::at_rest(vec![0.0], vec![0.0]);
    let stable = 0.9 * 2.0 / ((kc / i) * 1.7f64).sqrt();
    let got = integrate::relax(&sys, &mut d, &mut pairs, &mut Work::default(), &spec, stable, 1e-4);
    assert!(got.unwrap().converged && (d.th[0] - 1e-9).abs() < 1e-12, "rotation {}", d.th[0]);
}

/// Runs that were stable keep their masses bit for bit: the paper's hexagonal squares (whose
/// penalty moment spring is 79 % of the bound, `dt omega sqrt 1.7 = 1.86`) and a periodic
/// random packing get `I = m r^2 / 2` on every disc.
#[test]
fn stable_assemblies_keep_their_masses() {
    let periodic = AssemblySpec { boundary: cosdem_dem::BoundarySpec::Periodic, ..seed11(0.8) };
    for spec in [hex_spec(0.1, penalty()), hex_spec(0.28, penalty()), periodic] {
        let a = Assembly::new(&spec).unwrap();
        let refc = a.reference();
        for (k, &r) in refc.r.iter().enumerate() {
            let m = spec.density * std::f64::consts::PI * r * r;
            assert_eq!(refc.inv_m[k].to_bits(), (1.0 / m).to_bits(), "disc {k}");
            assert_eq!(refc.inv_i[k].to_bits(), (2.0 / (m * r * r)).to_bits(), "disc {k}");
        }
    }
}

//! Two discs: the contact law of THEORY.md section 2 (Eqs. 13-23) on one pair, against hand
//! computations.

use cosdem_dem::contact::Law;
use cosdem_dem::contact::pair::interact_dyn;
use cosdem_dem::spec::ContactParams;

fn law() -> Law {
    Law::from_params(&ContactParams::default())
}

/// Normal force is `k_n d` along `n` (q pushed away from p), zero without overlap (no
/// tension). Exact up to one rounding of the overlap (`2r - |l|` in f64): 1e-9 relative.
#[test]
fn normal_force_follows_overlap_without_tension() {
    let law = law();
    let r = 0.005;
    for d in [1e-7, 1e-6, 1e-5, 1e-4] {
        let c = interact_dyn(&law, 1e-6, 2.0 * r - d, 0.0, 0.0, 0.0, 0.0, 0.0, r, r, 0.0, 0.0)
            .expect("overlapping discs interact");
        assert!((c.fnorm - law.kn * d).abs() <= 1e-9 * law.kn * d, "{} vs {}", c.fnorm, law.kn * d);
        assert!((c.fx - c.fnorm).abs() <= 1e-12 * c.fnorm && c.fy == 0.0);
    }
    assert!(
        interact_dyn(&law, 1e-6, 2.0 * r + 1e-9, 0.0, -1.0, 0.0, 0.0, 0.0, r, r, 0.0, 0.0)
            .is_none()
    );
    // Separating fast with a dashpot: the force is clipped at zero, never attractive.
    let mut damped = law;
    damped.cn = 1e6;
    let c = interact_dyn(&damped, 1e-6, 2.0 * r - 1e-7, 0.0, 10.0, 0.0, 0.0, 0.0, r, r, 0.0, 0.0)
        .unwrap();
    assert_eq!(c.fnorm, 0.0);
}

/// Incremental tangential spring: below `mu_s F_n` the force is `-k_s s` for the accumulated
/// slip `s`; the step that would exceed the limit caps the force at exactly `mu_s F_n` and the
/// history follows; further slip keeps it there. Exact (equalities) except for the linear
/// part, which is a sum of increments (1e-12 relative).
#[test]
fn sliding_begins_exactly_at_mu_s_fn() {
    let law = law();
    let (r, d, dt, v) = (0.005, 1e-5, 1e-6, 0.1);
    let fnorm = law.kn * d;
    let cap = law.mu_s * fnorm;
    let (mut hs, mut slip) = (0.0, 0.0);
    let mut started = false;
    for _ in 0..1000 {
        // q moves along +y (= +t for n = +x) relative to p.
        let c = interact_dyn(&law, dt, 2.0 * r - d, 0.0, 0.0, v, 0.0, 0.0, r, r, hs, 0.0).unwrap();
        slip += v * dt;
        let linear = -law.ks * slip;
        if linear.abs() <= cap {
            assert!(!started);
            assert!((c.fs - linear).abs() <= 1e-12 * cap, "{} vs {}", c.fs, linear);
        } else {
            started = true;
            // The cap uses the F_n of this evaluation (overlap rounded once).
            assert_eq!(c.fs, -law.mu_s * c.fnorm);
            assert_eq!(c.hs, c.fs);
            assert!((c.fs + cap).abs() <= 1e-9 * cap);
        }
        hs = c.hs;
    }
    assert!(started, "the test must reach the Coulomb limit");
}

/// Rolling spring saturates at `mu_r r* F_n`, with `r* = 2 r_p r_q / (r_p + r_q)` (unequal
/// discs to exercise `r*`); moment on q is `+M_r`, on p `-M_r` (no tangential force here).
#[test]
fn rolling_saturates_at_mu_r_rstar_fn() {
    let law = law();
    let (rp, rq, d, dt, w) = (0.004, 0.006, 1e-5, 1e-6, 10.0);
    let rstar = 2.0 * rp * rq / (rp + rq);
    let fnorm = law.kn * d;
    let cap = law.mu_r * rstar * fnorm;
    let (mut hr, mut rot) = (0.0, 0.0);
    let mut saturated = false;
    for _ in 0..20_000 {
        // Pure rolling, v_s = 0: w_p a_p + w_q a_q = 0 with the levers a = r - d/2.
        let (ap, aq) = (rp - 0.5 * d, rq - 0.5 * d);
        let (wp, wq) = (-w * aq / (ap + aq), w * ap / (ap + aq));
        let c =
            interact_dyn(&law, dt, rp + rq - d, 0.0, 0.0, 0.0, wp, wq, rp, rq, 0.0, hr).unwrap();
        rot += (wq - wp) * dt;
        let lin = -law.kr * rot;
        if lin.abs() <= cap {
            assert!((c.mr - lin).abs() <= 1e-9 * cap.max(lin.abs()));
        } else {
            saturated = true;
            assert_eq!(c.mr, -law.mu_r * rstar * c.fnorm);
            assert_eq!(c.hr, c.mr);
        }
        assert!(
            c.fs.abs() <= 1e-9 * fnorm,
            "pure rolling must not load the shear spring: {}",
            c.fs
        );
        hr = c.hr;
    }
    assert!(saturated);
}

/// Action and reaction: the pair exerts opposite forces, and the torques balance the couple
/// of the forces (`tau_p + tau_q + l x F_q = 0`) because the levers meet at one contact point
/// (`a_p + a_q = |l|`). Checked for a generic oblique configuration with slip, spin and
/// rolling: 1e-12 relative to the largest term.
#[test]
fn forces_and_moments_balance() {
    let law = law();
    let (rp, rq) = (0.005, 0.004);
    let (dx, dy) = (0.006, 0.005); // |l| = 0.00781 < 0.009
    let c = interact_dyn(&law, 1e-6, dx, dy, 0.3, -0.2, 5.0, -3.0, rp, rq, 120.0, 0.5).unwrap();
    let couple = dx * c.fy - dy * c.fx;
    let scale = c.tp.abs() + c.tq.abs() + couple.abs();
    assert!((c.tp + c.tq + couple).abs() <= 1e-12 * scale, "{} {} {}", c.tp, c.tq, couple);
    assert!(c.fnorm > 0.0 && c.fs.abs() <= law.mu_s * c.fnorm);
}

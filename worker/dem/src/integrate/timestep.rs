use crate::contact::Law;
use crate::error::{Result, invalid};
use crate::spec::{Driver, FIRE_CEILING, RelaxationSpec};

/// Critical step `2 / omega_max` of the disc system, `omega_max` from a Gershgorin bound on
/// the mass-normalized stiffness of the smallest disc (mass `m`, inertia `i`, radius `r`)
/// with six contacts to equally small discs, plus its penalty springs `kf` (N/m) and `kc`
/// (N m/rad). Per contact and in mass-normalized units, the rows are: normal `2 k_n / m`;
/// tangential `(2 + 2 sqrt 2) k_s / m` (self, partner, and the two lever couplings
/// `k_s r / sqrt(m I)`); rotation `(2 k_s r^2 + 2 k_r) / I + 2 sqrt 2 k_s / m`.
///
/// A spring whose friction coefficient is zero carries no force at all (its Coulomb cap is
/// `0 * F_n`, dashpot included), so it does not limit the step: `mu_s = 0` drops `k_s` and
/// `mu_r = 0` drops `k_r` from the bound (a large `k_r` with `mu_r = 0` costs nothing).
pub fn critical_step(law: &Law, m: f64, i: f64, r: f64, kf: f64, kc: f64) -> f64 {
    let w2 = terms(law, m, i, r, kf, kc).iter().map(|(_, w)| w).sum::<f64>();
    2.0 / w2.sqrt()
}

/// The squared-frequency terms of the bound, each named by the spec field that sets it: the
/// largest of the normal, tangential and rolling rows (times six contacts), then the penalty
/// springs.
fn terms(law: &Law, m: f64, i: f64, r: f64, kf: f64, kc: f64) -> [(&'static str, f64); 3] {
    const Z: f64 = 6.0;
    let s2 = std::f64::consts::SQRT_2;
    let ks = if law.mu_s > 0.0 { law.ks } else { 0.0 };
    let kr = if law.mu_r > 0.0 { law.kr } else { 0.0 };
    // The rotation row mixes the shear spring's lever and the rolling spring: it is named
    // after the larger of the two.
    let (rot_s, rot_r) = (2.0 * ks * r * r / i + 2.0 * s2 * ks / m, 2.0 * kr / i);
    let rot_name = if rot_r >= rot_s { "contact.rolling.k_r" } else { "contact.tangential.k_s" };
    let rows = [
        ("contact.normal.k_n", 2.0 * law.kn / m),
        ("contact.tangential.k_s", (2.0 + 2.0 * s2) * ks / m),
        (rot_name, (2.0 * ks * r * r + 2.0 * kr) / i + 2.0 * s2 * ks / m),
    ];
    let (name, top) = largest(&rows);
    [(name, Z * top), ("boundary.eps_f", kf / m), ("boundary.eps_c", kc / i)]
}

/// The entry with the largest value (a NaN counts as largest: it is what broke the step).
fn largest(t: &[(&'static str, f64)]) -> (&'static str, f64) {
    t.iter().copied().fold(t[0], |a, b| if b.1.is_nan() || b.1 > a.1 { b } else { a })
}

/// Largest ratio of the stiffest term of the bound to the contacts' normal term (squared
/// frequencies). Relaxation steps grow with the square root of this ratio (the step follows
/// the stiffest spring, equilibrium the contacts): 1e12 means a million times more steps
/// than the contacts need, which no step cap allows.
pub const MAX_STIFFNESS_RATIO: f64 = 1e12;

/// [`critical_step`], refused with the parameter that makes it unusable:
/// - the density, when the smallest disc's mass or inertia (or a stiffness divided by them)
///   is not a positive finite number;
/// - a stiffness so large that the bound overflows even for a unit mass;
/// - the stiffest term, named with `k_n`, when it is more than [`MAX_STIFFNESS_RATIO`] times
///   the contacts' normal term (e.g. `eps_f = 1e300`, or `k_n = 1e-300` against the paper's
///   penalty): the relaxation would never end.
pub fn checked_step(law: &Law, m: f64, i: f64, r: f64, kf: f64, kc: f64) -> Result<f64> {
    let usable = |v: f64| v.is_finite() && v > 0.0 && (1.0 / v).is_finite();
    let density = |what: String| {
        invalid(
            "density",
            what,
            "the smallest disc's mass (density x relaxation.density_scale x pi r_min^2) and \
             inertia, and the stiffnesses divided by them, must be positive finite numbers",
        )
    };
    if !(usable(m) && usable(i)) {
        return Err(density(format!("{m:e} kg (mass of the smallest disc)")));
    }
    if let Some((field, w2)) = terms(law, 1.0, 1.0, r, kf, kc).iter().find(|t| !t.1.is_finite()) {
        return Err(invalid(
            field,
            format!("{w2:e} (its term of the time-step bound for a unit mass)"),
            "too large to compute with: the time-step bound overflows",
        ));
    }
    let t = terms(law, m, i, r, kf, kc);
    if t.iter().any(|t| !t.1.is_finite()) {
        return Err(density(format!("{m:e} kg (mass of the smallest disc)")));
    }
    let normal = 12.0 * law.kn / m;
    let (field, top) = largest(&t);
    if top > MAX_STIFFNESS_RATIO * normal {
        return Err(invalid(
            field,
            format!("{top:e} 1/s^2 against {normal:e} 1/s^2 of contact.normal.k_n = {:e}", law.kn),
            "stiffness ratio beyond 1e12 (MAX_STIFFNESS_RATIO): the explicit step follows \
             the stiffest spring and the relaxation would need a million times more steps \
             than the contacts",
        ));
    }
    let dt = critical_step(law, m, i, r, kf, kc);
    if dt.is_finite() && dt > 0.0 {
        Ok(dt)
    } else {
        Err(invalid(field, format!("critical step {dt:e} s"), "no usable explicit time step"))
    }
}

/// The largest step a relaxation driver takes with base step `dt`, and the gain its damping
/// applies to a decelerating force: Cundall's local damping multiplies the force by
/// `1 + alpha` while a dof moves away from equilibrium, which is every step of leapfrog's
/// unstable (sign-alternating) mode; FIRE's semi-implicit Euler step has no such gain but
/// grows to [`crate::spec::FIRE_CEILING`] critical steps.
pub fn driver_step(spec: &RelaxationSpec, dt: f64) -> (f64, f64) {
    match spec.driver {
        Driver::Cundall { alpha } => (dt, 1.0 + alpha),
        Driver::Fire { dt_max, .. } => ((dt * dt_max).min(FIRE_CEILING * dt / spec.safety), 1.0),
    }
}

/// Relaxation mass `m` and moment of inertia `i` of a disc of radius `r` held by the penalty
/// springs `kf` (N/m) and `kc` (N m/rad), made stable for the step `h` of a driver with
/// damping gain `gain` (see [`driver_step`]).
///
/// Stability. A dof of mass `M` whose own spring is `k` (no cap: the penalty springs are
/// linear) has `omega_max^2 >= k / M` (Rayleigh quotient of that dof alone), and leapfrog's
/// sign-alternating mode sees the Cundall gain every step, so it grows when
/// `gain h^2 omega_max^2 > 4`, i.e. the relaxation certainly diverges when
/// `h >= 2 / sqrt(gain k / M)`. The Gershgorin step of [`critical_step`] is undamped
/// (`2 / omega_max`): at safety 0.8 and `alpha = 0.7` it exceeds the damped limit by
/// `0.8 sqrt(1.7) = 1.04` wherever one penalty term makes up more than 92 % of the bound,
/// e.g. the moment spring `eps_c / V` on the smallest boundary disc of a small random packing
/// (`I = m r^2 / 2` falls as `r^4`).
///
/// Only such a certainly unstable dof is changed (every other run keeps its bits): its mass
/// is raised until its Gershgorin row (penalty spring plus six contacts to equal discs, the
/// rows of [`critical_step`], the couplings kept at the unscaled partner's mass) reaches
/// `gain h^2 row = 4 safety^2`, the margin the undamped bound gets. The equilibrium a
/// relaxation reaches does not depend on the masses (as with `relaxation.density_scale`).
pub fn stable_penalty_masses(
    law: &Law,
    (m, i, r): (f64, f64, f64),
    (kf, kc): (f64, f64),
    (h, gain, safety): (f64, f64, f64),
) -> (f64, f64) {
    const Z: f64 = 6.0;
    let ks = if law.mu_s > 0.0 { law.ks } else { 0.0 };
    let kr = if law.mu_r > 0.0 { law.kr } else { 0.0 };
    let target = 4.0 * safety * safety / (gain * h * h);
    // Row of a dof of scaled mass M: `diag / M + off / sqrt(M)`; returns the M at `target`.
    let scaled = |k_pen: f64, mass: f64, diag: f64, off: f64| -> f64 {
        if gain * h * h * k_pen < 4.0 * mass {
            return mass;
        }
        let (a, b) = (k_pen + Z * diag, Z * off);
        let u = (-b + b.mul_add(b, 4.0 * a * target).sqrt()) / (2.0 * a);
        let stable = 1.0 / (u * u);
        if stable.is_finite() { stable.max(mass) } else { mass }
    };
    // Translation: normal (self + partner) or tangential (self + partner + two levers).
    let (sm, si) = (m.sqrt(), i.sqrt());
    let m2 = scaled(kf, m, law.kn.max(ks), (law.kn / sm).max(ks / sm + 2.0 * ks * r / si));
    // Rotation: shear lever and rolling spring (self + partner), two levers to translations.
    let kt = ks * r * r + kr;
    let i2 = scaled(kc, i, kt, kt / si + 2.0 * ks * r / sm);
    (m2, i2)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn law(kn: f64, ks: f64, mu_s: f64, kr: f64, mu_r: f64) -> Law {
        Law { kn, cn: 0.0, ks, cs: 0.0, mu_s, kr, cr: 0.0, mu_r }
    }

    /// The usable range passes; an unusable step names the parameter that broke it.
    #[test]
    fn checked_step_names_the_stiffest_term() {
        let (m, i, r) = (0.2, 2.6e-6, 0.005);
        assert!(checked_step(&law(6.7e7, 3.4e7, 0.5, 25.0, 0.2), m, i, r, 6.7e8, 1e5).is_ok());
        let e = |l: Law, kf: f64| checked_step(&l, m, i, r, kf, 0.0).unwrap_err().to_string();
        // Overflow of the stiffness itself.
        assert!(e(law(1.7e308, 1.0, 0.5, 0.0, 0.0), 0.0).contains("contact.normal.k_n"));
        assert!(e(law(1.0, 1e308, 0.5, 0.0, 0.0), 0.0).contains("contact.tangential.k_s"));
        // Ratio to the normal term.
        assert!(e(law(1.0, 1e300, 0.5, 0.0, 0.0), 0.0).contains("contact.tangential.k_s"));
        assert!(e(law(1.0, 1.0, 0.5, 1e300, 0.5), 0.0).contains("contact.rolling.k_r"));
        let msg = e(law(1e-300, 1.0, 0.5, 0.0, 0.0), 1e8);
        assert!(msg.contains("boundary.eps_f") && msg.contains("contact.normal.k_n"), "{msg}");
        // The mass.
        for m in [0.0, 1e-310, 1e-300] {
            let e = checked_step(&law(6.7e7, 1.0, 0.5, 0.0, 0.0), m, m * 1e-5, r, 0.0, 0.0);
            let e = e.unwrap_err().to_string();
            assert!(e.contains("density"), "m = {m}: {e}");
        }
        // Zero friction: the spring carries nothing and does not limit the step.
        let free = law(6.7e7, 0.0, 0.0, 0.0, 0.0);
        assert_eq!(
            critical_step(&law(6.7e7, 1e300, 0.0, 1e300, 0.0), m, i, r, 0.0, 0.0),
            critical_step(&free, m, i, r, 0.0, 0.0)
        );
    }

    /// A certainly unstable penalty dof (`gain h^2 k / M >= 4`) gets the mass that puts its
    /// Gershgorin row at `gain h^2 row = 4 safety^2` (the closed form solves a quadratic in
    /// `1 / sqrt(M)`: checked by re-evaluating the row, to rounding); any other dof keeps its
    /// bits, and FIRE (no damping gain, at most 0.9 critical steps) never changes a mass.
    #[test]
    fn stable_penalty_masses_only_move_unstable_dofs() {
        let l = law(6.7e7, 3.4e7, 0.5, 25.0, 0.2);
        let (r, kf, kc) = (0.002, 2.99e9, 4.46e5);
        let m = 2650.0 * std::f64::consts::PI * r * r;
        let i = 0.5 * m * r * r;
        let dt = 0.8 * critical_step(&l, m, i, r, kf, kc);
        let (m2, i2) = stable_penalty_masses(&l, (m, i, r), (kf, kc), (dt, 1.7, 0.8));
        assert_eq!(m2.to_bits(), m.to_bits(), "the force spring is stable at this step");
        assert!(i2 > i);
        let (ks, kr) = (3.4e7, 25.0);
        let row = (kc + 6.0 * (ks * r * r + kr)) / i2
            + 6.0 * ((ks * r * r + kr) / i.sqrt() + 2.0 * ks * r / m.sqrt()) / i2.sqrt();
        assert!((1.7 * dt * dt * row / (4.0 * 0.64) - 1.0).abs() < 1e-12, "{row:e}");
        // Undamped at the same step, or damped at safety 0.5: unchanged.
        let same =
            |h: f64, gain: f64| stable_penalty_masses(&l, (m, i, r), (kf, kc), (h, gain, 0.8));
        assert_eq!(same(dt, 1.0), (m, i));
        assert_eq!(same(dt * 0.5 / 0.8, 1.7), (m, i));
        let fire = RelaxationSpec { driver: Driver::fire(), ..RelaxationSpec::default() };
        let (h, gain) = driver_step(&fire, dt);
        assert_eq!(same(h, gain), (m, i));
    }
}

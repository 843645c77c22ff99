use super::lanes::Real;

/// Rolling update (Eqs. 20-23): `h_r <- h_r - k_r v_r dt`, `M_r = h_r - c_r v_r`, capped at
/// `mu_r r* F_n` with the history set to the cap. Returns `(M_r, new history)`.
#[inline(always)]
pub fn update<R: Real>(
    hist: R,
    kr: f64,
    cr: f64,
    mu_r: f64,
    rstar: R,
    fnorm: R,
    vr: R,
    dt: f64,
    damped: bool,
) -> (R, R) {
    let h = R::splat(-kr * dt).mul_add(vr, hist);
    let cap = R::splat(mu_r) * rstar * fnorm;
    if damped {
        let trial = R::splat(-cr).mul_add(vr, h);
        let capped = trial.max(-cap).min(cap);
        let h = R::select(trial.abs().gt(cap), capped, h);
        (capped, h)
    } else {
        let capped = h.max(-cap).min(cap);
        (capped, capped)
    }
}

/// Effective rolling radius `r* = 2 r_p r_q / (r_p + r_q)`.
#[inline(always)]
pub fn rstar<R: Real>(rp: R, rq: R) -> R {
    R::splat(2.0) * rp * rq / (rp + rq)
}

/// Elastic energy in the rolling spring.
#[inline]
pub fn energy(kr: f64, hist: f64) -> f64 {
    if kr > 0.0 { 0.5 * hist * hist / kr } else { 0.0 }
}

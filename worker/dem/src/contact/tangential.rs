use super::lanes::Real;

/// Tangential update (Eqs. 16-19): history `f_s <- f_s - k_s v_s dt`, trial
/// `F_s = f_s - c_s v_s`; above `mu_s F_n` the force is capped and the history set to it.
///
/// Returns `(F_s, new history)`. Branch-free (`max`/`min`, never `clamp`, which would panic on
/// a NaN from a diverging run instead of reporting it).
#[inline(always)]
pub fn update<R: Real>(
    hist: R,
    ks: f64,
    cs: f64,
    mu_s: f64,
    fnorm: R,
    vs: R,
    dt: f64,
    damped: bool,
) -> (R, R) {
    let h = R::splat(-ks * dt).mul_add(vs, hist);
    let cap = R::splat(mu_s) * fnorm;
    if damped {
        let trial = R::splat(-cs).mul_add(vs, h);
        let capped = trial.max(-cap).min(cap);
        let h = R::select(trial.abs().gt(cap), capped, h);
        (capped, h)
    } else {
        let capped = h.max(-cap).min(cap);
        (capped, capped)
    }
}

/// Elastic energy in the tangential spring.
#[inline]
pub fn energy(ks: f64, hist: f64) -> f64 {
    if ks > 0.0 { 0.5 * hist * hist / ks } else { 0.0 }
}

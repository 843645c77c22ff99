/// Rolling update (Eqs. 20-23): `h_r <- h_r - k_r v_r dt`, `M_r = h_r - c_r v_r`, capped at
/// `mu_r r* F_n` with the history set to the cap. Returns `(M_r, new history)`.
#[inline(always)]
pub fn update(
    hist: f64,
    kr: f64,
    cr: f64,
    mu_r: f64,
    rstar: f64,
    fnorm: f64,
    vr: f64,
    dt: f64,
    damped: bool,
) -> (f64, f64) {
    let h = (-kr * dt).mul_add(vr, hist);
    let cap = mu_r * rstar * fnorm;
    if damped {
        let trial = (-cr).mul_add(vr, h);
        let capped = trial.max(-cap).min(cap);
        let h = if trial.abs() > cap { capped } else { h };
        (capped, h)
    } else {
        let capped = h.max(-cap).min(cap);
        (capped, capped)
    }
}

/// Effective rolling radius `r* = 2 r_p r_q / (r_p + r_q)`.
#[inline(always)]
pub fn rstar(rp: f64, rq: f64) -> f64 {
    2.0 * rp * rq / (rp + rq)
}

/// Elastic energy in the rolling spring.
#[inline]
pub fn energy(kr: f64, hist: f64) -> f64 {
    if kr > 0.0 { 0.5 * hist * hist / kr } else { 0.0 }
}

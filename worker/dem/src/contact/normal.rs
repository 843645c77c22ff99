/// Normal force `F_n = max(k_n d + c_n d_dot, 0)` (Eqs. 14-15): no tension.
///
/// `d` is the overlap, `d_dot` its rate (`-(v_q - v_p) . n`).
#[inline(always)]
pub fn force(kn: f64, cn: f64, d: f64, d_dot: f64, damped: bool) -> f64 {
    let f = if damped { cn.mul_add(d_dot, kn * d) } else { kn * d };
    f.max(0.0)
}

/// Elastic energy stored in the normal spring.
#[inline]
pub fn energy(kn: f64, d: f64) -> f64 {
    0.5 * kn * d * d
}

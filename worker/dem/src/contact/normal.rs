use super::lanes::Real;

/// Normal force `F_n = max(k_n d + c_n d_dot, 0)` (Eqs. 14-15): no tension.
///
/// `d` is the overlap, `d_dot` its rate (`-(v_q - v_p) . n`).
#[inline(always)]
pub fn force<R: Real>(kn: R, cn: R, d: R, d_dot: R, damped: bool) -> R {
    let f = if damped { cn.mul_add(d_dot, kn * d) } else { kn * d };
    f.max(R::splat(0.0))
}

/// Elastic energy stored in the normal spring.
#[inline]
pub fn energy(kn: f64, d: f64) -> f64 {
    0.5 * kn * d * d
}

use super::{Dynamics, Work};

/// One leapfrog step with Cundall's local non-viscous damping
/// `F_i <- F_i (1 - alpha sign(F_i v_i))` on every translational and rotational dof (the sign
/// taken with `v_{n-1/2}`; `alpha = 0` is plain leapfrog). Returns whether some disc moved
/// farther than `sqrt(lim2)` from its position at the last pair-list build (fused into the
/// position update; a boolean OR so the loop vectorizes, unlike an f64 max).
pub fn advance(
    d: &mut Dynamics,
    work: &Work,
    inv_m: &[f64],
    inv_i: &[f64],
    xb: &[f64],
    yb: &[f64],
    alpha: f64,
    dt: f64,
    lim2: f64,
) -> bool {
    let n = d.x.len();
    let (x, y, th) = (&mut d.x[..n], &mut d.y[..n], &mut d.th[..n]);
    let (vx, vy, w) = (&mut d.vx[..n], &mut d.vy[..n], &mut d.w[..n]);
    let (fx, fy, tq) = (&work.fx[..n], &work.fy[..n], &work.tq[..n]);
    let (inv_m, inv_i, xb, yb) = (&inv_m[..n], &inv_i[..n], &xb[..n], &yb[..n]);
    // Branch-free: sign(F v) in {-1, 0, 1} from two comparisons.
    let damp = |f: f64, v: f64| -> f64 {
        let s = f * v;
        let pos = if s > 0.0 { alpha } else { 0.0 };
        let neg = if s < 0.0 { alpha } else { 0.0 };
        f * (1.0 - pos + neg)
    };
    let mut far = false;
    for k in 0..n {
        let ax = damp(fx[k], vx[k]) * inv_m[k];
        let ay = damp(fy[k], vy[k]) * inv_m[k];
        let aw = damp(tq[k], w[k]) * inv_i[k];
        vx[k] = ax.mul_add(dt, vx[k]);
        vy[k] = ay.mul_add(dt, vy[k]);
        w[k] = aw.mul_add(dt, w[k]);
        x[k] = vx[k].mul_add(dt, x[k]);
        y[k] = vy[k].mul_add(dt, y[k]);
        th[k] = w[k].mul_add(dt, th[k]);
        let dx = x[k] - xb[k];
        let dy = y[k] - yb[k];
        far |= dx.mul_add(dx, dy * dy) > lim2;
    }
    far
}

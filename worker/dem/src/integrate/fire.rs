use super::{Dynamics, Work};
use crate::spec::Driver;

/// FIRE state (Bitzek et al. 2006, with the semi-implicit Euler step of FIRE 2.0): velocities
/// are mixed towards the force direction while the power `P = F.v` stays positive, the step
/// grows after `n_min` downhill steps, and everything stops on an uphill step. Translations
/// and rotations are mixed with their own norms (their units differ); the power is the total.
#[derive(Clone, Debug)]
pub struct Fire {
    dt: f64,
    dt_max: f64,
    alpha: f64,
    alpha_start: f64,
    f_inc: f64,
    f_dec: f64,
    f_alpha: f64,
    n_min: u32,
    downhill: u32,
}

impl Fire {
    /// New FIRE state with base step `dt`, growing to `dt_max` base steps but never above
    /// `ceiling` (s).
    pub fn new(driver: &Driver, dt: f64, ceiling: f64) -> Self {
        let Driver::Fire { alpha_start, f_inc, f_dec, f_alpha, n_min, dt_max } = *driver else {
            unreachable!("Fire::new with a non-FIRE driver")
        };
        Self {
            dt,
            dt_max: (dt * dt_max).min(ceiling),
            alpha: alpha_start,
            alpha_start,
            f_inc,
            f_dec,
            f_alpha,
            n_min,
            downhill: 0,
        }
    }

    /// One FIRE step; returns whether a disc moved farther than `sqrt(lim2)` since the last
    /// build, and the step used (the histories must advance by it).
    pub fn advance(
        &mut self,
        d: &mut Dynamics,
        work: &Work,
        inv_m: &[f64],
        inv_i: &[f64],
        xb: &[f64],
        yb: &[f64],
        lim2: f64,
    ) -> (bool, f64) {
        let n = d.x.len();
        let dt = self.dt;
        let (fx, fy, tq) = (&work.fx[..n], &work.fy[..n], &work.tq[..n]);
        // Euler velocity update, then power and norms.
        let (mut p, mut v2, mut f2, mut w2, mut t2) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for k in 0..n {
            d.vx[k] = (fx[k] * inv_m[k]).mul_add(dt, d.vx[k]);
            d.vy[k] = (fy[k] * inv_m[k]).mul_add(dt, d.vy[k]);
            d.w[k] = (tq[k] * inv_i[k]).mul_add(dt, d.w[k]);
            p += fx[k].mul_add(d.vx[k], fy[k] * d.vy[k]) + tq[k] * d.w[k];
            v2 += d.vx[k].mul_add(d.vx[k], d.vy[k] * d.vy[k]);
            f2 += fx[k].mul_add(fx[k], fy[k] * fy[k]);
            w2 += d.w[k] * d.w[k];
            t2 += tq[k] * tq[k];
        }
        if p > 0.0 {
            let a = self.alpha;
            let sv = if f2 > 0.0 { a * (v2 / f2).sqrt() } else { 0.0 };
            let sw = if t2 > 0.0 { a * (w2 / t2).sqrt() } else { 0.0 };
            for k in 0..n {
                d.vx[k] = (1.0 - a).mul_add(d.vx[k], sv * fx[k]);
                d.vy[k] = (1.0 - a).mul_add(d.vy[k], sv * fy[k]);
                d.w[k] = (1.0 - a).mul_add(d.w[k], sw * tq[k]);
            }
            self.downhill += 1;
            if self.downhill > self.n_min {
                self.dt = (self.dt * self.f_inc).min(self.dt_max);
                self.alpha *= self.f_alpha;
            }
        } else {
            d.vx.fill(0.0);
            d.vy.fill(0.0);
            d.w.fill(0.0);
            self.downhill = 0;
            self.dt *= self.f_dec;
            self.alpha = self.alpha_start;
        }
        let h = self.dt;
        let mut far = false;
        for k in 0..n {
            d.x[k] = d.vx[k].mul_add(h, d.x[k]);
            d.y[k] = d.vy[k].mul_add(h, d.y[k]);
            d.th[k] = d.w[k].mul_add(h, d.th[k]);
            let dx = d.x[k] - xb[k];
            let dy = d.y[k] - yb[k];
            far |= dx.mul_add(dx, dy * dy) > lim2;
        }
        (far, h)
    }
}

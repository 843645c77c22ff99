//! Eq. 24 as THEORY.md reads it: on the boundary particles (reference centre within one
//! largest diameter of the reference square's edges)
//! `f_q = -(eps_f/V)(x_q - xhat_q)`, `xhat_q = X_c + Fbar (X_q - X_c)`,
//! `m_q = -(eps_c/V)(th_q - thhat_q)`, `thhat_q = wbar + kbar . (X_q - X_c)`.

use cosdem_common::MacroDeformation;
use serde::{Deserialize, Serialize};

/// Penalty springs of the boundary layer for one target deformation.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Penalty {
    /// Boundary particles.
    pub idx: Vec<u32>,
    /// Target x of each boundary particle.
    pub xt: Vec<f64>,
    /// Target y.
    pub yt: Vec<f64>,
    /// Target rotation.
    pub tht: Vec<f64>,
    /// Force spring `eps_f / V` (N/m).
    pub kf: f64,
    /// Moment spring `eps_c / V` (N m/rad).
    pub kc: f64,
}

/// Indices of the boundary layer: discs whose reference centre is closer than one largest
/// diameter to an edge of `[0, lx] x [0, ly]` (strictly closer, with a 1e-9 relative margin,
/// so a hexagonal packing gets exactly its outer ring).
pub fn boundary_layer(x0: &[f64], y0: &[f64], lx: f64, ly: f64, dmax: f64) -> Vec<u32> {
    let lim = dmax * (1.0 - 1e-9);
    (0..x0.len())
        .filter(|&k| x0[k].min(lx - x0[k]).min(y0[k]).min(ly - y0[k]) < lim)
        .map(|k| k as u32)
        .collect()
}

impl Penalty {
    /// Targets for `target`: `x0`, `y0` are the reference centres (possibly shifted so the
    /// prestressed reference state is in equilibrium, see `packing::random`), `th0` the rest
    /// rotations, `xc` the reference centre.
    pub fn new(
        idx: &[u32],
        x0: &[f64],
        y0: &[f64],
        th0: &[f64],
        xc: [f64; 2],
        kf: f64,
        kc: f64,
        target: &MacroDeformation,
    ) -> Self {
        let f = &target.f;
        let mut xt = Vec::with_capacity(idx.len());
        let mut yt = Vec::with_capacity(idx.len());
        let mut tht = Vec::with_capacity(idx.len());
        for &q in idx {
            let q = q as usize;
            let (dx, dy) = (x0[q] - xc[0], y0[q] - xc[1]);
            xt.push(xc[0] + f[0][0].mul_add(dx, f[0][1] * dy));
            yt.push(xc[1] + f[1][0].mul_add(dx, f[1][1] * dy));
            tht.push(th0[q] + target.w + target.kappa[0].mul_add(dx, target.kappa[1] * dy));
        }
        Self { idx: idx.to_vec(), xt, yt, tht, kf, kc }
    }

    /// Adds the penalty forces and moments.
    pub fn apply(
        &self,
        x: &[f64],
        y: &[f64],
        th: &[f64],
        fx: &mut [f64],
        fy: &mut [f64],
        tq: &mut [f64],
    ) {
        for (k, &q) in self.idx.iter().enumerate() {
            let q = q as usize;
            fx[q] -= self.kf * (x[q] - self.xt[k]);
            fy[q] -= self.kf * (y[q] - self.yt[k]);
            tq[q] -= self.kc * (th[q] - self.tht[k]);
        }
    }

    /// Stored energy of the penalty springs.
    pub fn energy(&self, x: &[f64], y: &[f64], th: &[f64]) -> f64 {
        let mut e = 0.0;
        for (k, &q) in self.idx.iter().enumerate() {
            let q = q as usize;
            let (dx, dy, dt) = (x[q] - self.xt[k], y[q] - self.yt[k], th[q] - self.tht[k]);
            e += 0.5 * self.kf * dx.mul_add(dx, dy * dy) + 0.5 * self.kc * dt * dt;
        }
        e
    }

    /// Boundary-average stress `(1/A) sum_q (x_q - x_c)_i f_q,j` (Voigt, force part only).
    pub fn boundary_stress(&self, x: &[f64], y: &[f64], xc: [f64; 2], area: f64) -> [f64; 4] {
        let mut s = [0.0; 4];
        for (k, &q) in self.idx.iter().enumerate() {
            let q = q as usize;
            let fxq = -self.kf * (x[q] - self.xt[k]);
            let fyq = -self.kf * (y[q] - self.yt[k]);
            let (lx, ly) = (x[q] - xc[0], y[q] - xc[1]);
            s[0] += lx * fxq;
            s[1] += ly * fyq;
            s[2] += lx * fyq;
            s[3] += ly * fxq;
        }
        s.map(|v| v / area)
    }
}

//! The force kernel: one pass over the pair list, accumulating forces and torques.

use super::{Law, pair::interact};
use crate::broadphase::PairList;

/// Read-only disc kinematics (structure of arrays).
#[derive(Clone, Copy, Debug)]
pub struct Bodies<'a> {
    /// Centre x (m).
    pub x: &'a [f64],
    /// Centre y (m).
    pub y: &'a [f64],
    /// Velocity x (m/s).
    pub vx: &'a [f64],
    /// Velocity y (m/s).
    pub vy: &'a [f64],
    /// Spin (rad/s).
    pub w: &'a [f64],
    /// Radius (m).
    pub r: &'a [f64],
}

/// Force accumulators (structure of arrays).
#[derive(Debug)]
pub struct Accum<'a> {
    /// Force x (N).
    pub fx: &'a mut [f64],
    /// Force y (N).
    pub fy: &'a mut [f64],
    /// Torque (N m).
    pub tq: &'a mut [f64],
}

/// Sums over the active contacts, returned by the kernel for the equilibrium criterion.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactSums {
    /// Sum of normal force magnitudes (N).
    pub fn_sum: f64,
    /// Number of active contacts.
    pub active: u32,
}

/// Adds the contact forces of every pair to `acc` and advances the histories by `v dt`.
/// Dispatches to the monomorphization matching the law and domain.
pub fn accumulate(
    law: &Law,
    dt: f64,
    b: Bodies<'_>,
    pl: &mut PairList,
    acc: &mut Accum<'_>,
) -> ContactSums {
    let per = !pl.ox.is_empty();
    match (law.has_rolling(), law.has_damping(), per) {
        (true, true, true) => run::<true, true, true>(law, dt, b, pl, acc),
        (true, true, false) => run::<true, true, false>(law, dt, b, pl, acc),
        (true, false, true) => run::<true, false, true>(law, dt, b, pl, acc),
        (true, false, false) => run::<true, false, false>(law, dt, b, pl, acc),
        (false, true, true) => run::<false, true, true>(law, dt, b, pl, acc),
        (false, true, false) => run::<false, true, false>(law, dt, b, pl, acc),
        (false, false, true) => run::<false, false, true>(law, dt, b, pl, acc),
        (false, false, false) => run::<false, false, false>(law, dt, b, pl, acc),
    }
}

#[inline(never)]
fn run<const ROLL: bool, const DAMP: bool, const PER: bool>(
    law: &Law,
    dt: f64,
    b: Bodies<'_>,
    pl: &mut PairList,
    acc: &mut Accum<'_>,
) -> ContactSums {
    let n = b.x.len();
    let (x, y, vx, vy, w, r) = (&b.x[..n], &b.y[..n], &b.vx[..n], &b.vy[..n], &b.w[..n], &b.r[..n]);
    let fx = &mut acc.fx[..n];
    let fy = &mut acc.fy[..n];
    let tq = &mut acc.tq[..n];
    let m = pl.i.len();
    let pi = &pl.i[..m];
    let pj = &pl.j[..m];
    let fs = &mut pl.fs[..m];
    let hr = &mut pl.hr[..m];
    let (ox, oy) = if PER { (&pl.ox[..m], &pl.oy[..m]) } else { (&[][..], &[][..]) };
    let mut sums = ContactSums::default();
    for k in 0..m {
        let i = pi[k] as usize;
        let j = pj[k] as usize;
        let (mut dx, mut dy) = (x[j] - x[i], y[j] - y[i]);
        if PER {
            dx += ox[k];
            dy += oy[k];
        }
        let hist_r = if ROLL { hr[k] } else { 0.0 };
        match interact::<ROLL, DAMP>(
            law,
            dt,
            dx,
            dy,
            vx[j] - vx[i],
            vy[j] - vy[i],
            w[i],
            w[j],
            r[i],
            r[j],
            fs[k],
            hist_r,
        ) {
            None => {
                fs[k] = 0.0;
                if ROLL {
                    hr[k] = 0.0;
                }
            }
            Some(c) => {
                fs[k] = c.hs;
                if ROLL {
                    hr[k] = c.hr;
                }
                fx[j] += c.fx;
                fy[j] += c.fy;
                fx[i] -= c.fx;
                fy[i] -= c.fy;
                tq[j] += c.tq;
                tq[i] += c.tp;
                sums.fn_sum += c.fnorm;
                sums.active += 1;
            }
        }
    }
    sums
}

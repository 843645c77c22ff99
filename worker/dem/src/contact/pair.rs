//! The interaction of one pair of discs: the single implementation of Eqs. 13-23 that the
//! kernel inlines.
//!
//! Branch vectors. THEORY.md writes the slip rate as `v_s = (v_q - v_p).t - (w_p r_p + w_q r_q)`.
//! Under a rigid rotation `omega` of two overlapping discs, `v_q - v_p = omega |l| t` with
//! `|l| = r_p + r_q - d`, so that formula gives `v_s = -omega d`: a spurious slip that breaks
//! objectivity by `k_s d omega dt` per step (about 5% of `F_n` for a 0.1 rad rotation at 0.1%
//! overlap). We measure the levers to the middle of the overlap, `a_p = r_p - d/2`,
//! `a_q = r_q - d/2` (`a_p + a_q = |l|`), in both the slip rate and the torques, which keeps
//! the contact work-conjugate (energy is conserved) and makes a rigid rotation slip-free.
//! The difference from the printed formula is O(d/r).

use super::{Law, normal, rolling, tangential};

/// What one contact does to its two discs (force on `q`; `p` gets the opposite).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairForce {
    /// Force on `q`, x component (N).
    pub fx: f64,
    /// Force on `q`, y component (N).
    pub fy: f64,
    /// Torque on `p` (N m).
    pub tp: f64,
    /// Torque on `q` (N m).
    pub tq: f64,
    /// Normal force magnitude `F_n >= 0`.
    pub fnorm: f64,
    /// Tangential force `F_s` along `t = (-n_y, n_x)`.
    pub fs: f64,
    /// Rolling moment `M_r` on `q`.
    pub mr: f64,
    /// New tangential history.
    pub hs: f64,
    /// New rolling history.
    pub hr: f64,
}

/// Interaction of discs `p` and `q` with branch `(dx, dy) = x_q - x_p`, relative velocity
/// `(dvx, dvy) = v_q - v_p`, spins `wp`, `wq`, radii, histories `hs`, `hr` and step `dt`
/// (the histories advance by `v dt`). `None` when the discs do not overlap (the caller resets
/// the histories).
#[inline(always)]
pub fn interact<const ROLL: bool, const DAMP: bool>(
    law: &Law,
    dt: f64,
    dx: f64,
    dy: f64,
    dvx: f64,
    dvy: f64,
    wp: f64,
    wq: f64,
    rp: f64,
    rq: f64,
    hs: f64,
    hr: f64,
) -> Option<PairForce> {
    let rs = rp + rq;
    let d2 = dx.mul_add(dx, dy * dy);
    if d2 >= rs * rs {
        return None;
    }
    let dist = d2.sqrt();
    let inv = 1.0 / dist;
    let nx = dx * inv;
    let ny = dy * inv;
    let ov = rs - dist;
    let ap = (-0.5f64).mul_add(ov, rp);
    let aq = (-0.5f64).mul_add(ov, rq);
    // t = (-n_y, n_x)
    let vt = dvy.mul_add(nx, -(dvx * ny));
    let vs = vt - wp.mul_add(ap, wq * aq);
    let d_dot = if DAMP { -dvx.mul_add(nx, dvy * ny) } else { 0.0 };
    let fnorm = normal::force(law.kn, law.cn, ov, d_dot, DAMP);
    let (fs, hs) = tangential::update(hs, law.ks, law.cs, law.mu_s, fnorm, vs, dt, DAMP);
    let (mr, hr) = if ROLL {
        let rstar = rolling::rstar(rp, rq);
        rolling::update(hr, law.kr, law.cr, law.mu_r, rstar, fnorm, wq - wp, dt, DAMP)
    } else {
        (0.0, 0.0)
    };
    let fx = fnorm.mul_add(nx, -(fs * ny));
    let fy = fnorm.mul_add(ny, fs * nx);
    let tq = (-aq).mul_add(fs, mr);
    let tp = (-ap).mul_add(fs, -mr);
    Some(PairForce { fx, fy, tp, tq, fnorm, fs, mr, hs, hr })
}

/// Convenience wrapper choosing the monomorphization from the law (tests, tools).
pub fn interact_dyn(
    law: &Law,
    dt: f64,
    dx: f64,
    dy: f64,
    dvx: f64,
    dvy: f64,
    wp: f64,
    wq: f64,
    rp: f64,
    rq: f64,
    hs: f64,
    hr: f64,
) -> Option<PairForce> {
    match (law.has_rolling(), law.has_damping()) {
        (true, true) => interact::<true, true>(law, dt, dx, dy, dvx, dvy, wp, wq, rp, rq, hs, hr),
        (true, false) => interact::<true, false>(law, dt, dx, dy, dvx, dvy, wp, wq, rp, rq, hs, hr),
        (false, true) => interact::<false, true>(law, dt, dx, dy, dvx, dvy, wp, wq, rp, rq, hs, hr),
        (false, false) => {
            interact::<false, false>(law, dt, dx, dy, dvx, dvy, wp, wq, rp, rq, hs, hr)
        }
    }
}

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

use super::lanes::Real;
use super::{Law, normal, rolling, tangential};

/// What one contact does to its two discs (force on `q`; `p` gets the opposite), for one pair
/// (`f64`) or four ([`super::lanes::F4`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairForce<R = f64> {
    /// Force on `q`, x component (N).
    pub fx: R,
    /// Force on `q`, y component (N).
    pub fy: R,
    /// Torque on `p` (N m).
    pub tp: R,
    /// Torque on `q` (N m).
    pub tq: R,
    /// Normal force magnitude `F_n >= 0`.
    pub fnorm: R,
    /// Tangential force `F_s` along `t = (-n_y, n_x)`.
    pub fs: R,
    /// Rolling moment `M_r` on `q`.
    pub mr: R,
    /// New tangential history.
    pub hs: R,
    /// New rolling history.
    pub hr: R,
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
    let g = geometry::<f64, ROLL>(dx, dy, rp, rq, d2);
    Some(respond::<f64, ROLL, DAMP>(law, dt, &g, Motion { dvx, dvy, wp, wq }, hs, hr))
}

/// The contact geometry of an overlapping pair, for one pair (`f64`) or four
/// ([`super::lanes::F4`]).
#[derive(Clone, Copy, Debug)]
pub struct Geometry<R> {
    /// Unit normal from `p` to `q`, x.
    pub nx: R,
    /// Unit normal, y.
    pub ny: R,
    /// Overlap `r_p + r_q - d` (m).
    pub ov: R,
    /// Lever of `p`, `r_p - ov/2` (m).
    pub ap: R,
    /// Lever of `q` (m).
    pub aq: R,
    /// Rolling radius `r*` (zero without rolling).
    pub rstar: R,
}

/// The geometry of a pair with branch `(dx, dy)`, radii `rp`, `rq` and `d2 = dx^2 + dy^2`
/// (as `dx.mul_add(dx, dy * dy)`) below `(rp + rq)^2`: the law's square root and divisions.
#[inline(always)]
pub fn geometry<R: Real, const ROLL: bool>(dx: R, dy: R, rp: R, rq: R, d2: R) -> Geometry<R> {
    let rs = rp + rq;
    let dist = d2.sqrt();
    let inv = R::splat(1.0) / dist;
    let ov = rs - dist;
    let half = R::splat(-0.5);
    let rstar = if ROLL { rolling::rstar(rp, rq) } else { R::splat(0.0) };
    Geometry {
        nx: dx * inv,
        ny: dy * inv,
        ov,
        ap: half.mul_add(ov, rp),
        aq: half.mul_add(ov, rq),
        rstar,
    }
}

/// The relative motion of a pair: `v_q - v_p` and the two spins.
#[derive(Clone, Copy, Debug)]
pub struct Motion<R> {
    /// Relative velocity `v_q - v_p`, x (m/s).
    pub dvx: R,
    /// Relative velocity, y (m/s).
    pub dvy: R,
    /// Spin of `p` (rad/s).
    pub wp: R,
    /// Spin of `q` (rad/s).
    pub wq: R,
}

/// The law of an overlapping pair (Eqs. 13-23 with the levers of the module documentation)
/// from its [`geometry`], its motion and its histories. The scalar [`interact`] and the
/// four-lane kernel both call [`geometry`] then this, so a pair gets the same bits in either.
#[inline(always)]
pub fn respond<R: Real, const ROLL: bool, const DAMP: bool>(
    law: &Law,
    dt: f64,
    g: &Geometry<R>,
    m: Motion<R>,
    hs: R,
    hr: R,
) -> PairForce<R> {
    let Geometry { nx, ny, ov, ap, aq, rstar } = *g;
    let Motion { dvx, dvy, wp, wq } = m;
    // t = (-n_y, n_x)
    let vt = dvy.mul_add(nx, -(dvx * ny));
    let vs = vt - wp.mul_add(ap, wq * aq);
    let d_dot = if DAMP { -dvx.mul_add(nx, dvy * ny) } else { R::splat(0.0) };
    let fnorm = normal::force(R::splat(law.kn), R::splat(law.cn), ov, d_dot, DAMP);
    let (fs, hs) = tangential::update(hs, law.ks, law.cs, law.mu_s, fnorm, vs, dt, DAMP);
    let (mr, hr) = if ROLL {
        rolling::update(hr, law.kr, law.cr, law.mu_r, rstar, fnorm, wq - wp, dt, DAMP)
    } else {
        (R::splat(0.0), R::splat(0.0))
    };
    let fx = fnorm.mul_add(nx, -(fs * ny));
    let fy = fnorm.mul_add(ny, fs * nx);
    let tq = (-aq).mul_add(fs, mr);
    let tp = (-ap).mul_add(fs, -mr);
    PairForce { fx, fy, tp, tq, fnorm, fs, mr, hs, hr }
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

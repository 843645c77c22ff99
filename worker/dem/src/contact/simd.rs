//! The force kernel four pairs at a time on AVX2 (the x86-64-v3 baseline), through `pulp`'s
//! safe token for the two operations plain array code does not vectorize: no `unsafe` here.
//!
//! The arithmetic is the law's own ([`super::pair::geometry`] and [`super::pair::respond`])
//! in four [`F4`] lanes, so each pair gets the scalar law's bits. Two things are written
//! with the token, because LLVM turned their array forms into a branch per lane (measured:
//! slower than the scalar loop):
//!
//! - the contact test `!(d2 >= (r_p + r_q)^2)`, the scalar law's own, NaN included, as one
//!   vector comparison giving all bits set where the discs touch;
//! - keeping a result only where the discs touch, as a bitwise AND with that mask, which
//!   leaves +0.0 (all bits clear) elsewhere.
//!
//! The forces are then added pair by pair in the order of the list, each component as the
//! scalar loop adds it. A pair out of contact adds +0.0, which changes no sum: a sum of terms
//! starting at +0.0, as the forces do, is never -0.0. The kernel therefore gives the scalar
//! loop's result bit for bit (`four_lanes_give_the_scalar_bits` checks it).
//!
//! It is 1.27x faster than one pair at a time on its own (`cosdem-worker bench dem`, "force
//! kernel alone"), not more: the square root and the two divisions do not speed up in lanes
//! (the divider serves a 256-bit operation at half the rate of two 128-bit ones), and the
//! twelve reads of two discs and the six additions into them stay one value at a time. What
//! was tried besides, and measured, is in `docs/notes/2026-12-06-simd-kernel.md`.

use super::kernel::{Accum, ContactSums, Pass};
use super::lanes::{F4, Real};
use super::pair::{Motion, geometry, respond};
use crate::broadphase::PairList;
use pulp::x86::V3;
use std::arch::x86_64::{__m256d, _CMP_NGE_UQ};

/// The four-lane kernel when the processor has AVX2 and FMA (always on the x86-64-v3
/// baseline the workspace builds for); `None` sends the caller to the scalar loop.
pub fn token() -> Option<V3> {
    V3::try_new()
}

/// Adds the forces of the first `whole` pairs (a multiple of four) to `acc`, as the scalar
/// loop would, and returns their sums.
#[inline(always)]
pub(super) fn run<const ROLL: bool, const DAMP: bool, const PER: bool>(
    simd: V3,
    Pass { law, dt, b }: Pass<'_>,
    pl: &mut PairList,
    acc: &mut Accum<'_>,
    whole: usize,
) -> ContactSums {
    let n = b.x.len();
    let (x, y, vx, vy, w, r) = (&b.x[..n], &b.y[..n], &b.vx[..n], &b.vy[..n], &b.w[..n], &b.r[..n]);
    let (fx, fy, tq) = (&mut acc.fx[..n], &mut acc.fy[..n], &mut acc.tq[..n]);
    let (pi, pj) = (&pl.i[..whole], &pl.j[..whole]);
    let (fs, hr) = (&mut pl.fs[..whole], &mut pl.hr[..whole]);
    let (ox, oy) = if PER { (&pl.ox[..whole], &pl.oy[..whole]) } else { (&[][..], &[][..]) };
    let avx = simd.avx;
    let v = |a: [f64; 4]| -> __m256d { pulp::cast(a) };
    let f4 = |a: __m256d| F4(pulp::cast(a));
    let zero = F4::splat(0.0);
    let mut sums = ContactSums::default();
    // The sums of the disc `p` of the pairs in hand, held in registers while consecutive pairs
    // share it (a run: the list is built disc by disc) and written back when the run ends. No
    // pair of a run adds to them as its `q` (a pair list has `q > p`), so the order of the
    // additions is the scalar loop's; what it saves is each addition's wait for the store of
    // the one before.
    let mut run = usize::MAX;
    let (mut rx, mut ry, mut rt) = (0.0, 0.0, 0.0);
    for k in (0..whole).step_by(4) {
        let ii: [usize; 4] = std::array::from_fn(|l| pi[k + l] as usize);
        let jj: [usize; 4] = std::array::from_fn(|l| pj[k + l] as usize);
        let at = |a: &[f64], ix: &[usize; 4]| F4([a[ix[0]], a[ix[1]], a[ix[2]], a[ix[3]]]);
        let here = |a: &[f64]| F4([a[k], a[k + 1], a[k + 2], a[k + 3]]);
        let (mut dx, mut dy) = (at(x, &jj) - at(x, &ii), at(y, &jj) - at(y, &ii));
        if PER {
            dx = dx + here(ox);
            dy = dy + here(oy);
        }
        let (rp, rq) = (at(r, &ii), at(r, &jj));
        let rs = rp + rq;
        let d2 = dx.mul_add(dx, dy * dy);
        let rs2 = rs * rs;
        // `!(d2 >= rs2)`, the scalar law's test, NaN included: all bits set where the discs touch.
        let touch = avx._mm256_cmp_pd::<_CMP_NGE_UQ>(v(d2.0), v(rs2.0));
        let g = geometry::<F4, ROLL>(dx, dy, rp, rq, d2);
        let motion = Motion {
            dvx: at(vx, &jj) - at(vx, &ii),
            dvy: at(vy, &jj) - at(vy, &ii),
            wp: at(w, &ii),
            wq: at(w, &jj),
        };
        let hist_r = if ROLL { here(hr) } else { zero };
        let c = respond::<F4, ROLL, DAMP>(law, dt, &g, motion, here(fs), hist_r);
        // +0.0 (all bits clear) where they do not.
        let keep = |x: F4| f4(avx._mm256_and_pd(v(x.0), touch)).0;
        let (cfx, cfy, ctp, ctq, cfn) =
            (keep(c.fx), keep(c.fy), keep(c.tp), keep(c.tq), keep(c.fnorm));
        fs[k..k + 4].copy_from_slice(&keep(c.hs));
        if ROLL {
            hr[k..k + 4].copy_from_slice(&keep(c.hr));
        }
        for l in 0..4 {
            let (i, j) = (ii[l], jj[l]);
            debug_assert!(j > i, "pair ({i}, {j}): a pair list has j > i");
            if i != run {
                if run != usize::MAX {
                    [fx[run], fy[run], tq[run]] = [rx, ry, rt];
                }
                run = i;
                [rx, ry, rt] = [fx[i], fy[i], tq[i]];
            }
            fx[j] += cfx[l];
            fy[j] += cfy[l];
            rx -= cfx[l];
            ry -= cfy[l];
            tq[j] += ctq[l];
            rt += ctp[l];
            sums.fn_sum += cfn[l];
        }
        sums.active += avx._mm256_movemask_pd(touch).count_ones();
    }
    if run != usize::MAX {
        [fx[run], fy[run], tq[run]] = [rx, ry, rt];
    }
    sums
}

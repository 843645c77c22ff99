//! The force kernel: one pass over the pair list, accumulating forces and torques. On x86-64
//! with AVX2 (the workspace's baseline) the pairs go four at a time through
//! [`super::simd`], the last one to three one at a time; elsewhere all one at a time. Both give
//! the same bits.

use super::Law;
use super::pair::interact;
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

/// What one pass over a pair list reads besides the pairs: the law, the step and the discs.
#[derive(Clone, Copy, Debug)]
pub(super) struct Pass<'a> {
    pub(super) law: &'a Law,
    pub(super) dt: f64,
    pub(super) b: Bodies<'a>,
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
    accumulate_with(true, law, dt, b, pl, acc)
}

/// [`accumulate`], four pairs at a time when `lanes` (and the processor has AVX2), else one
/// pair at a time: the same result bit for bit either way (`lanes = false` is the benchmark's
/// yardstick for what the lanes gain).
pub fn accumulate_with(
    lanes: bool,
    law: &Law,
    dt: f64,
    b: Bodies<'_>,
    pl: &mut PairList,
    acc: &mut Accum<'_>,
) -> ContactSums {
    let per = !pl.ox.is_empty();
    let s = Pass { law, dt, b };
    match (law.has_rolling(), law.has_damping(), per) {
        (true, true, true) => run::<true, true, true>(lanes, s, pl, acc),
        (true, true, false) => run::<true, true, false>(lanes, s, pl, acc),
        (true, false, true) => run::<true, false, true>(lanes, s, pl, acc),
        (true, false, false) => run::<true, false, false>(lanes, s, pl, acc),
        (false, true, true) => run::<false, true, true>(lanes, s, pl, acc),
        (false, true, false) => run::<false, true, false>(lanes, s, pl, acc),
        (false, false, true) => run::<false, false, true>(lanes, s, pl, acc),
        (false, false, false) => run::<false, false, false>(lanes, s, pl, acc),
    }
}

/// One monomorphization: with `lanes` (and AVX2), the four-lane kernel over the whole fours,
/// then the rest one pair at a time.
#[inline(never)]
fn run<const ROLL: bool, const DAMP: bool, const PER: bool>(
    lanes: bool,
    s: Pass<'_>,
    pl: &mut PairList,
    acc: &mut Accum<'_>,
) -> ContactSums {
    #[cfg(target_arch = "x86_64")]
    if let (true, Some(simd)) = (lanes, super::simd::token()) {
        let whole = pl.i.len() - pl.i.len() % 4;
        let head = super::simd::run::<ROLL, DAMP, PER>(simd, s, pl, acc, whole);
        return scalar::<ROLL, DAMP, PER>(s, pl, acc, whole, head);
    }
    let _ = lanes;
    scalar::<ROLL, DAMP, PER>(s, pl, acc, 0, ContactSums::default())
}

/// The pairs from `start` on, one at a time, continuing `sums`: the reference the four-lane
/// kernel reproduces.
fn scalar<const ROLL: bool, const DAMP: bool, const PER: bool>(
    Pass { law, dt, b }: Pass<'_>,
    pl: &mut PairList,
    acc: &mut Accum<'_>,
    start: usize,
    mut sums: ContactSums,
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
    for k in start..m {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::pair::interact_dyn;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The pair-by-pair loop the kernel must reproduce: [`interact_dyn`] on each pair in
    /// list order, forces added as it goes.
    fn reference(
        law: &Law,
        dt: f64,
        b: Bodies<'_>,
        pl: &mut PairList,
        f: &mut [Vec<f64>; 3],
    ) -> ContactSums {
        let mut sums = ContactSums::default();
        for k in 0..pl.len() {
            let (i, j) = (pl.i[k] as usize, pl.j[k] as usize);
            let (mut dx, mut dy) = (b.x[j] - b.x[i], b.y[j] - b.y[i]);
            if !pl.ox.is_empty() {
                dx += pl.ox[k];
                dy += pl.oy[k];
            }
            let (vx, vy) = (b.vx[j] - b.vx[i], b.vy[j] - b.vy[i]);
            let hr = if law.has_rolling() { pl.hr[k] } else { 0.0 };
            match interact_dyn(
                law, dt, dx, dy, vx, vy, b.w[i], b.w[j], b.r[i], b.r[j], pl.fs[k], hr,
            ) {
                None => {
                    pl.fs[k] = 0.0;
                    if law.has_rolling() {
                        pl.hr[k] = 0.0;
                    }
                }
                Some(c) => {
                    pl.fs[k] = c.hs;
                    if law.has_rolling() {
                        pl.hr[k] = c.hr;
                    }
                    f[0][j] += c.fx;
                    f[1][j] += c.fy;
                    f[0][i] -= c.fx;
                    f[1][i] -= c.fy;
                    f[2][j] += c.tq;
                    f[2][i] += c.tp;
                    sums.fn_sum += c.fnorm;
                    sums.active += 1;
                }
            }
        }
        sums
    }

    /// The four-lane kernel gives the scalar law's bits (issue 30, item 2: SIMD without a
    /// change of result). Random discs, pairs in and out of contact, some sliding and rolling
    /// at their caps, with and without periodic offsets, dashpots and rolling, and pair counts
    /// that are not multiples of four (the scalar tail). Compared bit for bit, so no tolerance.
    #[test]
    fn four_lanes_give_the_scalar_bits() {
        let mut rng = ChaCha8Rng::seed_from_u64(30);
        for case in 0..64 {
            let n = 20 + case;
            let r: Vec<f64> = (0..n).map(|_| rng.random_range(1e-3..1.5e-3)).collect();
            let x: Vec<f64> = (0..n).map(|_| rng.random_range(0.0..0.02)).collect();
            let y: Vec<f64> = (0..n).map(|_| rng.random_range(0.0..0.02)).collect();
            let v = |rng: &mut ChaCha8Rng| -> Vec<f64> {
                (0..n).map(|_| rng.random_range(-0.1..0.1)).collect()
            };
            let (vx, vy, w) = (v(&mut rng), v(&mut rng), v(&mut rng));
            let per = case % 2 == 0;
            let mut pl = PairList::default();
            for i in 0..n {
                for j in i + 1..n {
                    let (ox, oy) =
                        if per { (rng.random_range(-1e-4..1e-4), 0.0) } else { (0.0, 0.0) };
                    let d = (x[j] - x[i] + ox).hypot(y[j] - y[i] + oy);
                    if d < r[i] + r[j] + 1e-3 {
                        pl.i.push(i as u32);
                        pl.j.push(j as u32);
                        if per {
                            pl.ox.push(ox);
                            pl.oy.push(oy);
                        }
                        // Large histories put some pairs past their caps.
                        pl.fs.push(rng.random_range(-50.0..50.0));
                        pl.hr.push(rng.random_range(-0.05..0.05));
                    }
                }
            }
            let law = Law {
                kn: 1e6,
                cn: if case % 4 < 2 { 0.0 } else { 3.0 },
                ks: 5e5,
                cs: if case % 4 < 2 { 0.0 } else { 1.0 },
                mu_s: 0.5,
                kr: if case % 8 < 4 { 0.0 } else { 2.0 },
                cr: 0.0,
                mu_r: 0.1,
            };
            let b = Bodies { x: &x, y: &y, vx: &vx, vy: &vy, w: &w, r: &r };
            let mut expected = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
            let mut pl_ref = pl.clone();
            let want = reference(&law, 1e-6, b, &mut pl_ref, &mut expected);
            let (mut fx, mut fy, mut tq) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
            let mut acc = Accum { fx: &mut fx, fy: &mut fy, tq: &mut tq };
            let got = accumulate(&law, 1e-6, b, &mut pl, &mut acc);
            assert!(want.active > 4 && (want.active as usize) < pl.len(), "case {case}: {want:?}");
            assert_eq!(got.active, want.active, "case {case}");
            assert_eq!(got.fn_sum.to_bits(), want.fn_sum.to_bits(), "case {case}");
            let bits = |v: &[f64]| v.iter().map(|a| a.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&fx), bits(&expected[0]), "case {case}: fx");
            assert_eq!(bits(&fy), bits(&expected[1]), "case {case}: fy");
            assert_eq!(bits(&tq), bits(&expected[2]), "case {case}: torque");
            assert_eq!(bits(&pl.fs), bits(&pl_ref.fs), "case {case}: tangential history");
            assert_eq!(bits(&pl.hr), bits(&pl_ref.hr), "case {case}: rolling history");
        }
    }
}

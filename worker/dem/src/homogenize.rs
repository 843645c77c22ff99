//! Homogenization (THEORY.md, Eqs. 26-29 in our conventions): for each active contact
//! between `p` and `q`, `l = x_q - x_p`, `f` = force `p` receives from `q`, `M` = rolling
//! moment `p` receives, `A = det(Fbar) V`:
//! `s_ij = (1/A) sum l_i f_j`, `m_i = (1/A) sum l_i M`,
//! `C_ijkl = (1/A) sum l_i K_jl l_k` with `K = k_n n n + k_s' t t`, `D_ij = (1/A) sum k_r' l_i l_j`.
//! Forces are evaluated from the state (spring parts only: dashpots vanish at rest).
//! A contact is active when the discs overlap or touch within 1e-9 of their radii sum
//! (THEORY.md: `d >= -tol` for the tangent of a just-touching packing).

use crate::broadphase::PairList;
use crate::contact::{Law, rolling};
use cosdem_common::voigt::{KX, N, index};
use cosdem_common::{StressVector, Tangent};

/// Fabric of the active contacts.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Fabric {
    /// Active contacts.
    pub contacts: u32,
    /// Coordination number `2 N_c / N`.
    pub coordination: f64,
    /// Fraction of contacts at the sliding limit.
    pub sliding_fraction: f64,
    /// Fraction of contacts with saturated rolling moment.
    pub rolling_fraction: f64,
    /// `sum |l|^2 / A`: the contact density factor (`2 sqrt 3` in a perfect hexagonal bulk).
    pub density: f64,
}

/// Homogenized stress, contact-stiffness tangents and fabric.
#[derive(Clone, Debug, PartialEq)]
pub struct Homogenized {
    /// `[s_xx, s_yy, s_xy, s_yx, m_x, m_y]`.
    pub stress: StressVector,
    /// Paper tangent (`k_s`, `k_r` on every active contact).
    pub paper: Tangent,
    /// Sliding-aware tangent.
    pub sliding_aware: Tangent,
    /// Fabric.
    pub fabric: Fabric,
}

/// One active contact evaluated from the state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactEval {
    /// Pair index in the list.
    pub k: usize,
    /// Branch `l = x_q - x_p`, x.
    pub lx: f64,
    /// Branch, y.
    pub ly: f64,
    /// Normal force on q (>= 0).
    pub fnorm: f64,
    /// Tangential force on q along t.
    pub fs: f64,
    /// Rolling moment on q.
    pub mr: f64,
    /// Whether the tangential force is at its Coulomb limit.
    pub sliding: bool,
    /// Whether the rolling moment is at its limit.
    pub rolling_saturated: bool,
}

/// Visits every active contact in pair-list order (fixed summation order).
pub fn for_each_contact(
    law: &Law,
    x: &[f64],
    y: &[f64],
    r: &[f64],
    pairs: &PairList,
    mut f: impl FnMut(ContactEval),
) {
    let per = !pairs.ox.is_empty();
    for k in 0..pairs.len() {
        let (i, j) = (pairs.i[k] as usize, pairs.j[k] as usize);
        let mut lx = x[j] - x[i];
        let mut ly = y[j] - y[i];
        if per {
            lx += pairs.ox[k];
            ly += pairs.oy[k];
        }
        let rs = r[i] + r[j];
        let d2 = lx.mul_add(lx, ly * ly);
        // Just-touching contacts (gap below 1e-9 of the radii sum, e.g. a hexagonal packing
        // at Fbar = I whose overlaps are +-rounding) count, with zero force, so the tangent of
        // the reference state does not depend on the sign of a rounding error.
        let touch = rs * (1.0 + 1e-9);
        if d2 >= touch * touch {
            continue;
        }
        let ov = rs - d2.sqrt();
        let fnorm = (law.kn * ov).max(0.0);
        let (fs, mr) = if ov > 0.0 { (pairs.fs[k], pairs.hr[k]) } else { (0.0, 0.0) };
        let lim = 1.0 - 1e-9;
        let sliding = law.ks > 0.0 && fnorm > 0.0 && fs.abs() >= law.mu_s * fnorm * lim;
        let rolling_saturated = law.kr > 0.0
            && fnorm > 0.0
            && mr.abs() >= law.mu_r * rolling::rstar(r[i], r[j]) * fnorm * lim;
        f(ContactEval { k, lx, ly, fnorm, fs, mr, sliding, rolling_saturated });
    }
}

/// Stress, tangents and fabric of the current state; `area` is the current area `A`.
pub fn homogenize(
    law: &Law,
    x: &[f64],
    y: &[f64],
    r: &[f64],
    pairs: &PairList,
    area: f64,
) -> Homogenized {
    homogenize_subset(law, x, y, r, pairs, area, |_| true)
}

/// As [`homogenize`] over the contacts whose pair index passes `keep` (e.g. a window of the
/// interior), divided by `area` (the area that subset represents).
pub fn homogenize_subset(
    law: &Law,
    x: &[f64],
    y: &[f64],
    r: &[f64],
    pairs: &PairList,
    area: f64,
    keep: impl Fn(usize) -> bool,
) -> Homogenized {
    let mut s = [0.0; N];
    let mut c_paper = [[0.0; N]; N];
    let mut c_slide = [[0.0; N]; N];
    let mut fab = Fabric::default();
    let (mut nslide, mut nroll) = (0u32, 0u32);
    for_each_contact(law, x, y, r, pairs, |c| {
        if !keep(c.k) {
            return;
        }
        let len = c.lx.hypot(c.ly);
        let (nx, ny) = (c.lx / len, c.ly / len);
        let (tx, ty) = (-ny, nx);
        let l = [c.lx, c.ly];
        let n = [nx, ny];
        let t = [tx, ty];
        // force p receives from q
        let f = [-(c.fnorm * nx + c.fs * tx), -(c.fnorm * ny + c.fs * ty)];
        for i in 0..2 {
            for j in 0..2 {
                s[index(i, j)] += l[i] * f[j];
            }
            s[KX + i] += l[i] * (-c.mr);
        }
        let ks_eff = if c.sliding { 0.0 } else { law.ks };
        let kr_eff = if c.rolling_saturated { 0.0 } else { law.kr };
        for i in 0..2 {
            for j in 0..2 {
                for k in 0..2 {
                    for m in 0..2 {
                        let kn_part = law.kn * n[j] * n[m];
                        let lk = l[i] * l[k];
                        c_paper[index(i, j)][index(k, m)] += lk * (kn_part + law.ks * t[j] * t[m]);
                        c_slide[index(i, j)][index(k, m)] += lk * (kn_part + ks_eff * t[j] * t[m]);
                    }
                }
                c_paper[KX + i][KX + j] += law.kr * l[i] * l[j];
                c_slide[KX + i][KX + j] += kr_eff * l[i] * l[j];
            }
        }
        fab.contacts += 1;
        fab.density += len * len;
        nslide += c.sliding as u32;
        nroll += c.rolling_saturated as u32;
    });
    let inv = 1.0 / area;
    s.iter_mut().for_each(|v| *v *= inv);
    c_paper.iter_mut().flatten().for_each(|v| *v *= inv);
    c_slide.iter_mut().flatten().for_each(|v| *v *= inv);
    fab.density *= inv;
    fab.coordination = 2.0 * fab.contacts as f64 / x.len().max(1) as f64;
    if fab.contacts > 0 {
        fab.sliding_fraction = nslide as f64 / fab.contacts as f64;
        fab.rolling_fraction = nroll as f64 / fab.contacts as f64;
    }
    Homogenized { stress: s, paper: c_paper, sliding_aware: c_slide, fabric: fab }
}

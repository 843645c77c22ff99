//! The bookkeeping of the current frame, checked on closed forms (no assembly).

use super::*;

/// A non-symmetric stress with couple stresses, of the size of a consolidated packing.
const S: StressVector = [-1.1e5, -0.9e5, 2.3e4, 1.7e4, 31.0, -12.0];

/// A full, non-symmetric tangent of the size of a contact tangent (1e7 Pa, 1 N in the
/// couple-stress rows).
fn tangent() -> Tangent {
    std::array::from_fn(|r| {
        std::array::from_fn(|k| {
            let v = 1.0 + ((7 * r + 3 * k) % 11) as f64 / 5.0 - 0.3 * (r == k) as u8 as f64;
            if r >= KX || k >= KX { v } else { 1e7 * v }
        })
    })
}

fn f0() -> MacroDeformation {
    MacroDeformation { f: [[1.03, 0.12], [-0.05, 0.96]], w: 0.07, kappa: [0.4, -0.3] }
}

/// `G s G^T / det G` and `G m / det G` in Voigt order: the finite transport of the shortcut.
fn pushed(g: &[[f64; 2]; 2], s: &StressVector) -> StressVector {
    let inc = Increment { rotation: rot(0.0), stretch: *g, strain: [0.0; N] };
    extrapolate_current(s, &[[0.0; N]; N], &inc).0
}

/// The transport of a perturbation column is the derivative of the shortcut's finite transport
/// `G s G^T / det G` along `G = I + h E`: the two halves of the current frame speak of the
/// same rate. Central differences with h = 1e-4 are exact here up to rounding (the transport
/// is a ratio of quadratics in h, its h^2 term is of order |s| h^2 = 1e-3 Pa) and the
/// rounding of 1e5 Pa over 2h (1e-7 Pa): tolerance 1e-2 Pa, 1e-7 of |s|.
#[test]
fn the_transport_is_the_derivative_of_the_finite_push_forward() {
    let h = 1e-4;
    for col in [XX, YY, XY, YX] {
        let (a, b) = unit(col).unwrap();
        let mut g = [[1.0, 0.0], [0.0, 1.0]];
        g[a][b] += h;
        let plus = pushed(&g, &S);
        g[a][b] -= 2.0 * h;
        let minus = pushed(&g, &S);
        let t = transport(col, &S);
        for r in 0..N {
            let d = (plus[r] - minus[r]) / (2.0 * h);
            assert!((d - t[r]).abs() <= 1e-2, "column {col} row {r}: {d} vs {}", t[r]);
        }
    }
    assert_eq!(transport(KX, &S), [0.0; N]);
    assert_eq!(transport(KY, &S), [0.0; N]);
    // One entry by hand: column e_xy has E[1][0] = 1, so (E s)_ij = delta_iy s_xj and
    // (s E^T)_ij = delta_jy s_iy... with b = x: (s E^T)_ij = s_ik E_jk = delta_jy s_ix, tr E = 0;
    // at (y, y): s_xy + s_yx.
    assert_eq!(transport(XY, &S)[YY], S[XY] + S[YX]);
}

/// At `F = I` the multiplicative perturbation is the additive one, bit for bit (so the two
/// frames relax the same perturbed states there); elsewhere it is `(I + h E) F` and `K + h F^T
/// e_i`, so the current curvature `F'^-T K'` moves by exactly `h e_i` (to rounding).
#[test]
fn the_perturbation_is_multiplicative_and_equals_the_additive_one_at_the_identity() {
    let id = MacroDeformation { kappa: [0.3, -0.2], w: 0.1, ..MacroDeformation::IDENTITY };
    for col in 0..N {
        for h in [1e-5, -1e-5] {
            let a = perturbed(&id, col, h, TangentFrame::Reference);
            let b = perturbed(&id, col, h, TangentFrame::Current);
            assert_eq!(a, b, "column {col}");
        }
    }
    let base = f0();
    let h = 1e-3;
    for col in [XX, YY, XY, YX] {
        let (a, b) = unit(col).unwrap();
        let mut e = [[0.0; 2]; 2];
        e[a][b] = h;
        let left = [[1.0 + e[0][0], e[0][1]], [e[1][0], 1.0 + e[1][1]]];
        let want = mat_mul(&left, &base.f);
        let got = perturbed(&base, col, h, TangentFrame::Current);
        assert_eq!((got.w, got.kappa), (base.w, base.kappa));
        for i in 0..2 {
            for j in 0..2 {
                assert!((got.f[i][j] - want[i][j]).abs() <= 2.0 * f64::EPSILON, "{col}");
            }
        }
    }
    let current = |m: &MacroDeformation| {
        let fi = mat_inv(&m.f);
        [0, 1].map(|i| fi[0][i] * m.kappa[0] + fi[1][i] * m.kappa[1])
    };
    let k0 = current(&base);
    for (col, i) in [(KX, 0), (KY, 1)] {
        let p = perturbed(&base, col, h, TangentFrame::Current);
        assert_eq!(p.f, base.f);
        let k = current(&p);
        for j in 0..2 {
            let want = k0[j] + if i == j { h } else { 0.0 };
            assert!((k[j] - want).abs() <= 1e-15, "column {col}: k_{j} {} vs {want}", k[j]);
        }
    }
}

/// An isotropic (non-symmetric) tensor `l d_ij d_kl + m d_ik d_jl + n d_il d_jk` and an
/// isotropic curvature block are unchanged by any rotation, a rotation and its inverse cancel,
/// and a rank-one tangent `s (x) e` turns into `(Q s Q^T) (x) (Q e Q^T)`: the Voigt index
/// bookkeeping of `rotate_tangent` is that of the stress. Tolerance: 1e-14 of the largest entry
/// (sums of 16 products, each rounded at 1.1e-16).
#[test]
fn rotating_a_tangent_turns_each_index() {
    let d = |i: usize, j: usize| if i == j { 1.0 } else { 0.0 };
    let mut iso = [[0.0; N]; N];
    for i in 0..2 {
        for j in 0..2 {
            for k in 0..2 {
                for l in 0..2 {
                    iso[index(i, j)][index(k, l)] = 3e7 * d(i, j) * d(k, l)
                        + 2e7 * d(i, k) * d(j, l)
                        + 0.5e7 * d(i, l) * d(j, k);
                }
            }
        }
    }
    iso[KX][KX] = 25.0;
    iso[KY][KY] = 25.0;
    let q = rot(0.7);
    let c = tangent();
    let back = rotate_tangent(&rotate_tangent(&c, &q), &transpose(&q));
    let turned = rotate_tangent(&iso, &q);
    for r in 0..N {
        for k in 0..N {
            let d = (turned[r][k] - iso[r][k]).abs();
            assert!(d <= 1e-14 * 5.5e7, "iso {r} {k}: {} vs {}", turned[r][k], iso[r][k]);
            assert!((back[r][k] - c[r][k]).abs() <= 1e-14 * 3.2e7, "back {r} {k}");
        }
    }
    let e: [f64; N] = [0.3, -0.1, 0.7, 0.2, 1.5, -0.4];
    let one: Tangent = std::array::from_fn(|r| std::array::from_fn(|k| S[r] * e[k]));
    let turn = |v: &[f64; N]| {
        let inc = Increment { rotation: q, stretch: rot(0.0), strain: [0.0; N] };
        extrapolate_current(v, &[[0.0; N]; N], &inc).0
    };
    let (sq, eq) = (turn(&S), turn(&e));
    let got = rotate_tangent(&one, &q);
    for r in 0..N {
        for k in 0..N {
            let want = sq[r] * eq[k];
            assert!((got[r][k] - want).abs() <= 1e-9 * want.abs().max(1.0), "{r} {k}");
        }
    }
}

/// The shortcut's answer. A rigid rotation (F -> Q F, w -> w + q, K unchanged) answers `Q s_0
/// Q^T` and `Q m_0`, for both boundaries, up to the rounding of `dF` (entries of order 1, a
/// few 1e-16, times C = 2e7: a few 1e-8 Pa on 1e5). A rotation superposed on any target turns
/// the answer and its tangent (objectivity; same rounding). For a small increment the answer
/// moves by the convected rate `transport + C de` (central differences at h = 1e-6: the
/// h^2 term is |C| h^2 ~ 1e-4 Pa, rounding 1e-16 1e5 / 1e-6 ~ 1e-5 Pa: tolerance 1e-3 Pa).
#[test]
fn the_shortcut_rotates_rigidly_is_objective_and_follows_the_rate() {
    let (old, c) = (f0(), tangent());
    for periodic in [false, true] {
        for qa in [std::f64::consts::FRAC_PI_2, 0.3, -2.5] {
            let q = rot(qa);
            let rigid = MacroDeformation { f: mat_mul(&q, &old.f), w: old.w + qa, ..old };
            let (s, t, bound) = extrapolate_current(&S, &c, &increment(&old, &rigid, periodic));
            let inc = Increment { rotation: q, stretch: rot(0.0), strain: [0.0; N] };
            let want = extrapolate_current(&S, &c, &inc).0;
            let tw = rotate_tangent(&c, &q);
            assert!(bound <= 1e-7, "{periodic} {qa}: {bound}");
            for r in 0..N {
                assert!((s[r] - want[r]).abs() <= 1e-7, "{periodic} {qa} row {r}");
                for k in 0..N {
                    assert!((t[r][k] - tw[r][k]).abs() <= 1e-8 * tw[r][k].abs().max(1.0));
                }
            }
            let new =
                MacroDeformation { f: [[1.01, 0.14], [-0.03, 0.95]], w: 0.09, kappa: [0.5, -0.3] };
            let base = extrapolate_current(&S, &c, &increment(&old, &new, periodic));
            let sup = MacroDeformation { f: mat_mul(&q, &new.f), w: new.w + qa, ..new };
            let turned = extrapolate_current(&S, &c, &increment(&old, &sup, periodic));
            let want = extrapolate_current(&base.0, &[[0.0; N]; N], &inc).0;
            for r in 0..N {
                assert!((turned.0[r] - want[r]).abs() <= 1e-6, "objective: {periodic} {qa} {r}");
            }
        }
    }
    // Penalty: a column of the convected rate, dF = I + h E at fixed w (or dK = h F^T e_i).
    // The answer is linear in h but for the transport's O(|s| h^2) = 1e-7 Pa; the rounding of
    // dF - I (1e-16) times |C| (3e7) over 2h is 1e-2 Pa per column: tolerance 1e-8 of the row's
    // largest entry (0.3 Pa on the stress rows, 3e-8 N on the couple-stress rows).
    let h = 1e-6;
    for col in 0..N {
        let plus = perturbed(&old, col, h, TangentFrame::Current);
        let minus = perturbed(&old, col, -h, TangentFrame::Current);
        let sp = extrapolate_current(&S, &c, &increment(&old, &plus, false)).0;
        let sm = extrapolate_current(&S, &c, &increment(&old, &minus, false)).0;
        let t = transport(col, &S);
        for r in 0..N {
            let (d, want) = ((sp[r] - sm[r]) / (2.0 * h), t[r] + c[r][col]);
            let scale = c[r].iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert!((d - want).abs() <= 1e-8 * scale, "col {col} row {r}: {d} vs {want}");
        }
    }
}

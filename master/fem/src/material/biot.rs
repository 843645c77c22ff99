//! Objective elastic Cosserat law for the updated-Lagrangian option: St Venant-Kirchhoff on the
//! first Cosserat stretch `U = R(w)^T F` (design note 2026-12-05, Sections 2.4-2.5).
//!
//! Index conventions (THEORY.md): `s_ij` has the face normal as first index and is
//! work-conjugate to `u_j,i`; a stress matrix `S` goes to Voigt as `s[index(i, j)] = S[i][j]`,
//! a strain-like matrix `A` as `e[index(i, j)] = A[j][i]` (so Voigt `XY` is `A[1][0]`, first
//! order `u_y,x - w`). The energy per reference area is
//! `W = (1/2) e^L . C0 e^L + G lc^2 K . K` with `e^L` the Voigt vector of `E = U - I`;
//! `s = (1/det F) F tau R(w)^T` and `m = (1/det F) F M` are its push-forward.

use super::{ElasticCosserat, Material, MaterialError, MaterialInput, TrialId};
use cosdem_common::voigt::{KX, KY, index};
use cosdem_common::{
    KinematicsError, MacroDeformation, MicroDiagnostics, MicroResponse, StressVector, Tangent,
};

type M2 = [[f64; 2]; 2];

/// The four force-stress entries `(i, j)`, in Voigt order `XX, YY, XY, YX`.
const PAIRS: [(usize, usize); 4] = [(0, 0), (1, 1), (0, 1), (1, 0)];

fn mul(a: &M2, b: &M2) -> M2 {
    std::array::from_fn(|i| std::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j]))
}

fn transpose(a: &M2) -> M2 {
    [[a[0][0], a[1][0]], [a[0][1], a[1][1]]]
}

/// `R(a) = [[cos a, -sin a], [sin a, cos a]]`.
fn rotation(a: f64) -> M2 {
    let (s, c) = a.sin_cos();
    [[c, -s], [s, c]]
}

/// The objective Cosserat law of Section 2.5 of the design, on the constants of Eq. 8.
///
/// Input per Gauss point: the total `F`, the total micro-rotation `w` and the reference
/// curvature `K = grad_X w`. Output: the Cauchy stress and couple stress of the deformed
/// configuration, and the tangent in the convected sense of Section 2.4:
/// `ds = g s - tr(g) s + s g^T + C[de]`, `dm = g m - tr(g) m + D grad_x(dw)` for a variation
/// `g = grad_x du`, `dw`, with `de` the Voigt vector of `h = g - dw Z`. The strain-stress block
/// is `C[de] = (1/det F) F C0[R(w)^T h F] R(w)^T - s h^T`, the curvature block
/// `D = (2 G lc^2 / det F) F F^T`, the cross blocks zero. The strain-stress block is not
/// symmetric in general (hence `is_symmetric() = false`). At small strain it reduces to [`ElasticCosserat`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BiotCosserat {
    /// The constants (`lam`, `G`, `Gc`, `lc`) of the small-strain law it reduces to.
    pub elastic: ElasticCosserat,
}

impl BiotCosserat {
    /// `C0[A]`: Eq. 8 on the Voigt strain of the matrix `A` (`e_ij = A_ji`), as a stress matrix
    /// (`tau[i][j] = t[index(i, j)]`).
    fn c0(&self, a: &M2) -> M2 {
        let c = self.elastic.tangent();
        let e: [f64; 4] = std::array::from_fn(|k| {
            let (i, j) = PAIRS[k];
            a[j][i]
        });
        std::array::from_fn(|i| {
            std::array::from_fn(|j| (0..4).map(|l| c[index(i, j)][l] * e[l]).sum())
        })
    }

    /// Stress `[s_xx, s_yy, s_xy, s_yx, m_x, m_y]` and convected tangent at one point.
    ///
    /// # Errors
    /// [`KinematicsError`] when a component is not finite or `det F <= 0`.
    pub fn response(
        &self,
        d: &MacroDeformation,
    ) -> Result<(StressVector, Tangent), KinematicsError> {
        d.validate()?;
        let (f, j) = (d.f, d.det());
        let r = rotation(d.w);
        let rt = transpose(&r);
        let mut u = mul(&rt, &f);
        u[0][0] -= 1.0;
        u[1][1] -= 1.0;
        let tau = self.c0(&u);
        // s = (1/J) F tau R^T
        let s = mul(&mul(&f, &tau), &rt).map(|row| row.map(|v| v / j));
        let b = 2.0 * self.elastic.shear * self.elastic.length * self.elastic.length;
        let big_m = [b * d.kappa[0], b * d.kappa[1]];
        let m: [f64; 2] = std::array::from_fn(|i| (f[i][0] * big_m[0] + f[i][1] * big_m[1]) / j);
        let mut stress = [0.0; 6];
        for (p, q) in PAIRS {
            stress[index(p, q)] = s[p][q];
        }
        (stress[KX], stress[KY]) = (m[0], m[1]);

        let mut tangent = [[0.0; 6]; 6];
        // Column index(k, l) of the strain is de_kl = h_lk: the unit matrix with h[l][k] = 1.
        for (k, l) in PAIRS {
            let mut h = [[0.0; 2]; 2];
            h[l][k] = 1.0;
            let dtau = self.c0(&mul(&mul(&rt, &h), &f));
            let push = mul(&mul(&f, &dtau), &rt);
            let sht = mul(&s, &transpose(&h));
            for (p, q) in PAIRS {
                tangent[index(p, q)][index(k, l)] = push[p][q] / j - sht[p][q];
            }
        }
        let fft = mul(&f, &transpose(&f));
        for p in 0..2 {
            for q in 0..2 {
                tangent[KX + p][KX + q] = b * fft[p][q] / j;
            }
        }
        Ok((stress, tangent))
    }
}

impl Material for BiotCosserat {
    fn evaluate(
        &mut self,
        _trial: TrialId,
        inputs: &[MaterialInput],
    ) -> Result<Vec<MicroResponse>, MaterialError> {
        let mut out = Vec::with_capacity(inputs.len());
        let mut failed = Vec::new();
        for i in inputs {
            match self.response(&i.deformation) {
                Ok((stress, tangent)) => out.push(MicroResponse {
                    stress,
                    tangent,
                    diagnostics: MicroDiagnostics { converged: true, ..Default::default() },
                }),
                Err(e) => failed.push((i.gauss_point, e.to_string())),
            }
        }
        if failed.is_empty() { Ok(out) } else { Err(MaterialError::GaussPoints(failed)) }
    }

    fn commit(&mut self, _step: u64) -> Result<(), MaterialError> {
        Ok(())
    }

    fn rollback(&mut self) -> Result<(), MaterialError> {
        Ok(())
    }

    fn is_symmetric(&self) -> bool {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cosdem_common::GaussPointId;
    use cosdem_common::voigt::{XX, XY, YX, YY};
    use proptest::prelude::*;

    const G: f64 = 2e7;

    fn law() -> BiotCosserat {
        BiotCosserat { elastic: ElasticCosserat::new(G, 0.25, 0.3 * G, 0.05) }
    }

    fn at(f: M2, w: f64, kappa: [f64; 2]) -> MacroDeformation {
        MacroDeformation { f, w, kappa }
    }

    /// The stress matrix `S[i][j] = s[index(i, j)]` and the couple stress of a vector.
    fn split(s: &StressVector) -> (M2, [f64; 2]) {
        (std::array::from_fn(|i| std::array::from_fn(|j| s[index(i, j)])), [s[KX], s[KY]])
    }

    fn max_abs<const K: usize>(v: impl IntoIterator<Item = [f64; K]>) -> f64 {
        v.into_iter().flatten().map(f64::abs).fold(0.0, f64::max)
    }

    #[test]
    fn rigid_rotation_is_stress_free() {
        // F = R(a), w = a, K = 0: U = R(a)^T R(a) = I up to round-off (~1e-16), so |s| is C0
        // times that, a few 1e-16 G; 1e-12 G leaves room without hiding a missing R^T (which
        // gives s ~ G (1 - cos a), 0.3 G at the smallest angle tried).
        for a in [0.8, -1.3, 2.0, 3.0, std::f64::consts::PI, -std::f64::consts::PI] {
            let (s, _) = law().response(&at(rotation(a), a, [0.0; 2])).unwrap();
            assert!(s.iter().all(|v| v.abs() <= 1e-12 * G), "a = {a}: {s:?}");
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        #[test]
        fn superposed_rotation_turns_the_stress(
            h in prop::array::uniform4(-0.5f64..0.5), w in -0.7f64..0.7,
            kappa in prop::array::uniform2(-20.0f64..20.0), b in -3.1f64..3.1,
        ) {
            // (Q F, w + b, K) with Q = R(b): U and K unchanged, so s -> Q s Q^T, m -> Q m.
            // A few roundings of products of entries of size <= 2: 1e-12 of the largest.
            let f = [[1.0 + h[0], h[1]], [h[2], 1.0 + h[3]]];
            prop_assume!(f[0][0] * f[1][1] - f[0][1] * f[1][0] > 0.2);
            let q = rotation(b);
            let (s0, _) = law().response(&at(f, w, kappa)).unwrap();
            let (s1, _) = law().response(&at(mul(&q, &f), w + b, kappa)).unwrap();
            let ((a0, m0), (a1, m1)) = (split(&s0), split(&s1));
            let want = mul(&mul(&q, &a0), &transpose(&q));
            let scale = max_abs([s0]);
            for i in 0..2 {
                let qm = q[i][0] * m0[0] + q[i][1] * m0[1];
                prop_assert!((m1[i] - qm).abs() <= 1e-12 * scale);
                for j in 0..2 {
                    prop_assert!((a1[i][j] - want[i][j]).abs() <= 1e-12 * scale);
                }
            }
        }

        #[test]
        fn tangent_is_the_convected_derivative(
            h in prop::array::uniform4(-0.5f64..0.5), w in -0.7f64..0.7,
            kappa in prop::array::uniform2(-20.0f64..20.0),
        ) {
            // Central differences, eps = 1e-6: truncation eps^2 |third derivative| ~ 1e-12 C,
            // cancellation 1e-16 |s| / eps ~ 1e-10 C (measured: between 1e-10 and 1e-9 of the
            // largest entry). A wrong index or sign in any term moves
            // an entry by O(|s|) or O(|F - I| C), 1e-2 C or more here: 1e-6 of the largest
            // entry sits four orders of magnitude from both.
            let f = [[1.0 + h[0], h[1]], [h[2], 1.0 + h[3]]];
            prop_assume!(f[0][0] * f[1][1] - f[0][1] * f[1][0] > 0.2);
            let law = law();
            let (s, c) = law.response(&at(f, w, kappa)).unwrap();
            let (s_mat, m) = split(&s);
            let eps = 1e-6;
            let tol = 1e-6 * max_abs(c);
            let fd = |d: MacroDeformation, e: MacroDeformation| -> StressVector {
                let (a, b) = (law.response(&d).unwrap().0, law.response(&e).unwrap().0);
                std::array::from_fn(|k| (a[k] - b[k]) / (2.0 * eps))
            };
            // Strain columns: F' = (I + eps E) F at fixed w and K (so grad_x(dw) = 0), minus
            // the transport E s - tr(E) s + s E^T (and E m - tr(E) m for the couple stress).
            for (k, l) in PAIRS {
                let col = index(k, l);
                let mut e = [[0.0; 2]; 2];
                e[l][k] = 1.0;
                let ef = mul(&e, &f);
                let pert = |t: f64| {
                    let g = std::array::from_fn(|i| std::array::from_fn(|j| f[i][j] + t * ef[i][j]));
                    at(g, w, kappa)
                };
                let ds = fd(pert(eps), pert(-eps));
                let tr = e[0][0] + e[1][1];
                let (es, se) = (mul(&e, &s_mat), mul(&s_mat, &transpose(&e)));
                for (p, q) in PAIRS {
                    let conv = ds[index(p, q)] - (es[p][q] - tr * s_mat[p][q] + se[p][q]);
                    let err = (conv - c[index(p, q)][col]).abs();
                    prop_assert!(err <= tol, "C[{}][{col}]: {err}", index(p, q));
                }
                for p in 0..2 {
                    let em = e[p][0] * m[0] + e[p][1] * m[1];
                    let conv = ds[KX + p] - (em - tr * m[p]);
                    prop_assert!((conv - c[KX + p][col]).abs() <= tol, "m row {p}, col {col}");
                }
            }
            // Curvature columns: dK = F^T d is grad_x(dw) = d at fixed F: dm = D d, ds = 0.
            for q in 0..2 {
                let pert = |t: f64| at(f, w, std::array::from_fn(|i| kappa[i] + t * f[q][i]));
                let ds = fd(pert(eps), pert(-eps));
                for p in 0..6 {
                    prop_assert!((ds[p] - c[p][KX + q]).abs() <= tol, "C[{p}][{}]", KX + q);
                }
            }
            // w alone: g = 0, h = -dw Z, so de[XY] = -dw, de[YX] = +dw and no transport.
            let ds = fd(at(f, w + eps, kappa), at(f, w - eps, kappa));
            for p in 0..6 {
                let want = c[p][YX] - c[p][XY];
                prop_assert!((ds[p] - want).abs() <= tol, "w column, row {p}");
            }
        }
    }

    #[test]
    fn simple_shear_matches_the_closed_form() {
        // F = [[1, gamma], [0, 1]], w = -atan(gamma / 2), K = 0: s = lam (r - 2) V + 2 G (B - V)
        // (design Section 2.5). Both sides are a few dozen roundings of numbers of size <= 3:
        // 1e-12 relative. The design's printed digits: to half a unit of their last place.
        let law = law();
        let lam = law.elastic.lambda;
        let cases = [
            (1.0, [1.633437, 0.422291, 1.211146], 1e-6),
            (0.1, [0.0150156, 0.0049906, 0.1002495], 1e-7),
        ];
        for (gamma, printed, unit) in cases {
            let d = at([[1.0, gamma], [0.0, 1.0]], -(gamma / 2.0_f64).atan(), [0.0; 2]);
            let (s, _) = law.response(&d).unwrap();
            let r = (4.0_f64 + gamma * gamma).sqrt();
            let v = [[(2.0 + gamma * gamma) / r, gamma / r], [gamma / r, 2.0 / r]];
            let b = [[1.0 + gamma * gamma, gamma], [gamma, 1.0]];
            let (mat, m) = split(&s);
            for (i, j) in PAIRS {
                let want = lam * (r - 2.0) * v[i][j] + 2.0 * G * (b[i][j] - v[i][j]);
                let err = (mat[i][j] - want).abs();
                assert!(err <= 1e-12 * want.abs(), "gamma {gamma} ({i}, {j}): {err}");
            }
            assert_eq!(m, [0.0, 0.0]);
            for (k, p) in [(XX, printed[0]), (YY, printed[1]), (XY, printed[2]), (YX, printed[2])] {
                let got = s[k] / G;
                assert!((got - p).abs() <= 0.5 * unit, "gamma {gamma}, component {k}: {got}");
            }
        }
    }

    #[test]
    fn pure_stretch_nominal_stress_is_eq_8() {
        // F = diag(a, b), w = 0: U = F, so det(F) F^-1 s = tau = C0 (F - I) and
        // det(F) F^-1 m = 2 G lc^2 K, Eq. 8 on strain(), exactly but for a few roundings:
        // 1e-12 relative to the largest component.
        let law = law();
        for (a, b) in [(0.7, 1.2), (1.3, 0.9), (0.5, 0.5)] {
            let d = at([[a, 0.0], [0.0, b]], 0.0, [3.0, -5.0]);
            let (s, _) = law.response(&d).unwrap();
            let want = law.elastic.stress(&d.strain());
            // Row i of det(F) F^-1 is scaled by det(F) / F_ii.
            let row = [b, a, b, a, b, a];
            let scale = max_abs([want]);
            for k in 0..6 {
                let err = (row[k] * s[k] - want[k]).abs();
                assert!(err <= 1e-12 * scale, "({a}, {b}) component {k}: {err}");
            }
        }
    }

    #[test]
    fn small_strain_reduces_to_eq_8() {
        // |F - I|, w ~ 1e-6: the law differs from Eq. 8 by relative terms of order |F - I|,
        // 1e-6, so 1e-5 relative passes, while a wrong index in C0 or a transposed
        // push-forward gives O(1) differences.
        let law = law();
        let g = [[1e-6, -2e-6], [1.5e-6, -0.5e-6]];
        let d = MacroDeformation::from_gradient(g, 0.7e-6, [2e-4, -1e-4]);
        let (s, c) = law.response(&d).unwrap();
        let want = law.elastic.stress(&d.strain());
        let c0 = law.elastic.tangent();
        for k in 0..6 {
            let err = (s[k] - want[k]).abs();
            assert!(err <= 1e-5 * max_abs([want]), "stress {k}: {s:?} against {want:?}");
            for l in 0..6 {
                assert!((c[k][l] - c0[k][l]).abs() <= 1e-5 * max_abs(c0), "tangent [{k}][{l}]");
            }
        }
    }

    #[test]
    fn bad_points_are_named_with_det_f() {
        // Every failing point is reported by its id with det F (or the non-finite field);
        // the good point in the same batch does not hide them.
        let inputs = [
            (GaussPointId::new(3, 1), at([[1.0, 0.0], [0.0, -0.5]], 0.0, [0.0; 2])),
            (GaussPointId::new(0, 0), MacroDeformation::IDENTITY),
            (GaussPointId::new(4, 2), at([[f64::NAN, 0.0], [0.0, 1.0]], 0.0, [0.0; 2])),
        ]
        .map(|(gauss_point, deformation)| MaterialInput { gauss_point, deformation });
        let mut law = law();
        assert!(!law.is_symmetric());
        let trial = TrialId { step: 1, iteration: 0 };
        let err = law.evaluate(trial, &inputs).unwrap_err();
        let MaterialError::GaussPoints(points) = &err else { panic!("{err}") };
        assert_eq!(points.len(), 2, "{err}");
        let msg = err.to_string();
        let inverted = "element 3 gauss point 1: macro deformation gradient is not invertible: \
                        det(F) = -0.5";
        assert!(msg.contains(inverted), "{msg}");
        assert!(msg.contains("element 4 gauss point 2") && msg.contains("F_xx"), "{msg}");
        let ok = law.evaluate(trial, &inputs[1..2]).unwrap();
        assert_eq!(ok[0].stress, [0.0; 6]);
        assert_eq!(ok[0].tangent, law.elastic.tangent());
    }
}

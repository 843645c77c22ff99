//! Objectivity: a rigid rotation superposed on Fbar (with the micro-rotation turned by the
//! same angle) rotates the stress and changes nothing else.

mod common;
use common::*;
use cosdem_common::MacroDeformation;
use cosdem_common::voigt::{KX, KY, XX, XY, YX, YY};
use cosdem_dem::{Assembly, BoundarySpec};

fn rotate(m: &MacroDeformation, th: f64) -> MacroDeformation {
    let (c, s) = (th.cos(), th.sin());
    let r = [[c, -s], [s, c]];
    let mut f = [[0.0; 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            f[i][j] = r[i][0] * m.f[0][j] + r[i][1] * m.f[1][j];
        }
    }
    // Eq. 24 uses kbar . (X_q - X_c): kbar is the gradient of w over the reference
    // coordinates, which a superposed rigid rotation (w -> w + th) leaves unchanged.
    MacroDeformation { f, w: m.w + th, kappa: m.kappa }
}

/// Stress `s_ij` rotates as `R s R^T`, couple stress as `R m`; contact count, sliding
/// fraction and every contact's normal and tangential force are unchanged. The affine
/// predictor maps the committed state rigidly (slip from the exact rotation of each branch
/// vector, levers to the contact point), so the rotated state is already in equilibrium:
/// differences are rounding, checked at 1e-9 of the stress scale (and of the largest contact
/// force). Both boundaries, a 0.3 rad rotation, a prestate with shear forces and curvature.
#[test]
fn rigid_rotation_rotates_stress_and_changes_nothing_else() {
    for boundary in [penalty(), BoundarySpec::Periodic] {
        let periodic = matches!(boundary, BoundarySpec::Periodic);
        let mut a = Assembly::new(&hex_spec(0.1, boundary)).unwrap();
        let mut f0 = grad([[-1.2e-3, 3e-4], [1e-4, -0.8e-3]]);
        if !periodic {
            f0.kappa = [0.02, -0.01];
        }
        let r0 = a.solve(&f0).unwrap();
        a.commit();
        let snap0 = a.snapshot();
        let th = 0.3;
        let r1 = a.solve(&rotate(&f0, th)).unwrap();
        let snap1 = a.snapshot();
        let (c, s) = (th.cos(), th.sin());
        let rm = [[c, -s], [s, c]];
        let t0 = [[r0.stress[XX], r0.stress[XY]], [r0.stress[YX], r0.stress[YY]]];
        let scale = t0[0][0].abs().max(t0[1][1].abs());
        for i in 0..2 {
            for j in 0..2 {
                let mut want = 0.0;
                for k in 0..2 {
                    for l in 0..2 {
                        want += rm[i][k] * rm[j][l] * t0[k][l];
                    }
                }
                let got = r1.stress[cosdem_common::voigt::index(i, j)];
                assert!((got - want).abs() <= 1e-9 * scale, "s_{i}{j}: {got} vs {want}");
            }
        }
        let m0 = [r0.stress[KX], r0.stress[KY]];
        let mscale = m0[0].abs().max(m0[1].abs()).max(1e-300);
        for i in 0..2 {
            let want = rm[i][0] * m0[0] + rm[i][1] * m0[1];
            assert!((r1.stress[KX + i] - want).abs() <= 1e-6 * mscale + 1e-9, "m_{i}");
        }
        assert_eq!(r0.diagnostics.contacts, r1.diagnostics.contacts);
        assert_eq!(r0.diagnostics.sliding_fraction, r1.diagnostics.sliding_fraction);
        assert_eq!(snap0.contacts.len(), snap1.contacts.len());
        let fmax = snap0.contacts.iter().map(|c| c.fn_).fold(0.0, f64::max);
        for (c0, c1) in snap0.contacts.iter().zip(&snap1.contacts) {
            assert_eq!((c0.p, c0.q), (c1.p, c1.q));
            assert!((c0.fn_ - c1.fn_).abs() <= 1e-9 * fmax);
            assert!((c0.fs - c1.fs).abs() <= 1e-9 * fmax);
        }
    }
}

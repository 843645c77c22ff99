//! Hexagonal packings against the closed forms of THEORY.md (section 2): the contact tangent,
//! the secant response, and the equality of contact- and boundary-average stress.

mod common;
use common::*;
use cosdem_common::voigt::{KX, KY, XX, XY, YX, YY};
use cosdem_dem::{Assembly, BoundarySpec, TangentialModel};

const KN: f64 = 6.7e7;
const KS: f64 = 3.4e7;
const KR: f64 = 25.0;

/// About 105 discs in V = 0.01 m^2 with r = 5 mm (the paper's smallest assembly).
#[test]
fn hexagonal_count_in_paper_range() {
    let a = Assembly::new(&hex_spec(0.1, penalty())).unwrap();
    assert!((90..=110).contains(&a.disc_count()), "{}", a.disc_count());
    assert!((a.area() - 0.01).abs() < 1e-15);
}

/// Paper tangent of a compressed (all contacts closed) 429-disc penalty assembly against the
/// closed forms scaled by the counted contact density `sum |l|^2 / A` (the assembly has fewer
/// contacts per area near its edge). 2%: what remains is the orientation imbalance of a
/// hexagonal lattice cut to a square (measured: at most 1.3%, on D_xx). The periodic cell
/// (every disc six contacts) matches to 1e-9.
#[test]
fn paper_tangent_matches_closed_form_with_counted_density() {
    for (boundary, tol) in [(penalty(), 0.02), (BoundarySpec::Periodic, 1e-9)] {
        let mut a = Assembly::new(&hex_spec(0.2, boundary)).unwrap();
        let r = a.solve(&iso(-1e-3)).unwrap();
        assert!(r.diagnostics.converged);
        let h = a.homogenized(a.trial().unwrap());
        let cf = closed_form(KN, KS, KR, h.fabric.density);
        let c = r.tangent;
        let checks = [
            ("C_xxxx", c[XX][XX], cf[0]),
            ("C_yyyy", c[YY][YY], cf[0]),
            ("C_xxyy", c[XX][YY], cf[1]),
            ("C_xyxy", c[XY][XY], cf[2]),
            ("C_yxyx", c[YX][YX], cf[2]),
            ("C_xyyx", c[XY][YX], cf[3]),
            ("D_xx", c[KX][KX], cf[4]),
            ("D_yy", c[KY][KY], cf[4]),
        ];
        for (name, got, want) in checks {
            assert!(rel(got, want) < tol, "{name}: {got} vs {want} ({:?})", a.spec().boundary);
        }
        assert_eq!(c[XX][KX], 0.0, "cross blocks are zero");
    }
}

/// Secant response of a periodic hexagonal cell (every disc six contacts, so "interior only"
/// is the whole cell) to a small uniaxial strain and a small symmetric shear on top of an
/// isotropic compression, against the closed forms at the counted density. 2%: the secant
/// also contains the geometric (initial-stress) stiffness of the prestress (measured 1.1% on
/// C_xxyy, under 0.2% elsewhere). The symmetric shear checks `C_xyxy + C_xyyx`; the
/// antisymmetric part is the subject of `antisymmetric_shear_relaxes_interior_rotations`.
#[test]
fn periodic_secant_matches_closed_form() {
    let mut a = Assembly::new(&hex_spec(0.2, BoundarySpec::Periodic)).unwrap();
    let r0 = a.solve(&iso(-1e-3)).unwrap();
    a.commit();
    let h = a.homogenized(a.committed());
    let cf = closed_form(KN, KS, KR, h.fabric.density);
    let e = 1e-4;
    let r = a.solve(&grad([[-1e-3 - e, 0.0], [0.0, -1e-3]])).unwrap();
    let de = -e / (1.0 - 1e-3); // strain increment relative to the compressed state
    assert!(rel((r.stress[XX] - r0.stress[XX]) / de, cf[0]) < 0.02);
    assert!(rel((r.stress[YY] - r0.stress[YY]) / de, cf[1]) < 0.02);
    let r = a.solve(&grad([[-1e-3, e], [e, -1e-3]])).unwrap();
    let ds = 0.5 * (r.stress[XY] + r.stress[YX] - r0.stress[XY] - r0.stress[YX]);
    let de = e / (1.0 - 1e-3);
    assert!(rel(ds / de, cf[2] + cf[3]) < 0.02, "{} vs {}", ds / de, cf[2] + cf[3]);
}

/// Secant response of a 429-disc penalty assembly, with the strain measured by the best
/// affine fit of the interior discs (the boundary discs lag their targets: the measured
/// strain is about 0.89 of the imposed one), against the contact tangent of the same
/// assembly (counted contacts). Uniaxial: `s_xx` and `s_yy` within 2% (measured 1.2% and
/// 0.6%). Curvature with `k_s = 0` (then the affine rotation field is the exact equilibrium,
/// the tangential springs would otherwise turn a rotation gradient into shear): `m_x` within
/// 2% of `D_xx` (measured 0.1%).
#[test]
fn penalty_secant_matches_tangent_at_measured_strain() {
    let mut a = Assembly::new(&hex_spec(0.2, penalty())).unwrap();
    let r0 = a.solve(&iso(-1e-3)).unwrap();
    a.commit();
    let f0 = a.affine_fit(a.committed());
    let c = r0.tangent;
    let r = a.solve(&grad([[-1.1e-3, 0.0], [0.0, -1e-3]])).unwrap();
    assert!(r.diagnostics.converged);
    let f = a.affine_fit(a.trial().unwrap());
    let de = [f[0][0] - f0[0][0], f[1][1] - f0[1][1], f[1][0] - f0[1][0], f[0][1] - f0[0][1]];
    let lag = de[0] / -1e-4;
    assert!(lag > 0.8 && lag < 1.0, "interior strain / imposed = {lag}");
    for row in [XX, YY] {
        let pred: f64 = (0..4).map(|k| c[row][k] * de[k]).sum();
        let got = r.stress[row] - r0.stress[row];
        assert!(rel(got, pred) < 0.02, "row {row}: {got} vs {pred}");
    }
    let mut spec = hex_spec(0.2, penalty());
    spec.contact.tangential = TangentialModel::None;
    let mut a = Assembly::new(&spec).unwrap();
    let r0 = a.solve(&iso(-1e-3)).unwrap();
    a.commit();
    let mut t = iso(-1e-3);
    t.kappa = [0.01, 0.0];
    let r = a.solve(&t).unwrap();
    let d = (r.stress[KX] - r0.stress[KX]) / 0.01;
    assert!(rel(d, r0.tangent[KX][KX]) < 0.02, "{d} vs {}", r0.tangent[KX][KX]);
    let cf = closed_form(KN, 0.0, KR, a.homogenized(a.committed()).fabric.density);
    assert!(rel(d, cf[4]) < 0.02, "{d} vs closed form {}", cf[4]);
}

/// The contact-average stress equals the boundary-average stress of the penalty forces at
/// equilibrium. Their difference is `(1/A) sum_q x_q f_net,q` over all discs, bounded by
/// `N (L/2) mean|f_net| / A` while the stress is about `N_c 2r mean F_n / A`, so relative to
/// the stress it is at most about `ratio * L / (2r)` (ratio = unbalanced-force ratio reached);
/// checked at the default tolerance and at a 100 times tighter one.
#[test]
fn contact_and_boundary_average_stress_agree() {
    for tol in [1e-4, 1e-6] {
        let mut spec = hex_spec(0.2, penalty());
        spec.relaxation.tolerance = tol;
        let mut a = Assembly::new(&spec).unwrap();
        let r = a.solve(&grad([[-1.2e-3, 2e-4], [1e-4, -0.8e-3]])).unwrap();
        assert!(r.diagnostics.converged);
        let b = a.boundary_stress(a.trial().unwrap()).unwrap();
        let scale = r.stress[XX].abs().max(r.stress[YY].abs());
        let bound = r.diagnostics.residual_ratio * 0.2 / 0.01;
        for k in 0..4 {
            let diff = (r.stress[k] - b[k]).abs() / scale;
            assert!(diff <= bound, "component {k}: {diff} > {bound} (tol {tol})");
        }
    }
}

/// Antisymmetric shear (`wbar` turned with Fbar fixed) is resisted only by the boundary
/// layer: Eq. 24 pins the rotations of the boundary discs, the interior discs rotate freely
/// and relax the couple, so the measured `d(s_xy - s_yx)` is a few percent of the affine
/// closed form `C_xyxy - C_xyyx = sqrt(3) k_s / 2` (which assumes every disc turns with
/// `wbar`). Pinned here as a documented property, not a defect.
#[test]
fn antisymmetric_shear_relaxes_interior_rotations() {
    let mut a = Assembly::new(&hex_spec(0.2, penalty())).unwrap();
    let r0 = a.solve(&iso(-1e-3)).unwrap();
    a.commit();
    let mut t = iso(-1e-3);
    t.w = 1e-4; // e_xy = -w, e_yx = +w
    let r = a.solve(&t).unwrap();
    let skew = (r.stress[XY] - r0.stress[XY]) - (r.stress[YX] - r0.stress[YX]);
    let affine = (r0.tangent[XY][XY] - r0.tangent[XY][YX]) * (-2e-4);
    assert!((skew / affine).abs() < 0.05, "measured {skew} vs affine {affine}");
}

/// At Fbar = I the hexagonal discs just touch (overlaps are +-rounding): every touching pair
/// counts as a contact (THEORY.md's `d >= -tol`), so the reference tangent is the closed
/// form at the counted density (2%, as for the compressed state) and the stress is zero.
#[test]
fn just_touching_reference_has_the_full_tangent() {
    let mut a = Assembly::new(&hex_spec(0.2, penalty())).unwrap();
    let r = a.solve(&cosdem_common::MacroDeformation::IDENTITY).unwrap();
    let h = a.homogenized(a.trial().unwrap());
    let n = a.disc_count() as u32;
    assert!(
        r.diagnostics.contacts > 3 * n - 4 * 22,
        "{} contacts for {n} discs",
        r.diagnostics.contacts
    );
    assert!(r.stress.iter().all(|s| s.abs() < 1e-6));
    let cf = closed_form(KN, KS, KR, h.fabric.density);
    assert!(rel(r.tangent[XX][XX], cf[0]) < 0.02);
    assert!(rel(r.tangent[XY][XY], cf[2]) < 0.02);
    assert!(rel(r.tangent[KX][KX], cf[4]) < 0.02);
}

/// Fluctuation field (Eq. 35, `u_R = u - (Fbar - I)(X - X_c)`): zero to rounding for a
/// periodic hexagonal cell (the affine field is the equilibrium), and for a penalty assembly
/// the boundary-layer lag shows up as fluctuations that are a small fraction of the affine
/// displacement at the edge (measured about 10%: the membrane effect).
#[test]
fn fluctuation_field() {
    let g = grad([[-1.2e-3, 3e-4], [1e-4, -0.8e-3]]);
    let mut a = Assembly::new(&hex_spec(0.2, BoundarySpec::Periodic)).unwrap();
    a.solve(&g).unwrap();
    let s = a.snapshot();
    let worst = s.fluctuation.iter().map(|u| u[0].hypot(u[1])).fold(0.0, f64::max);
    assert!(worst < 1e-12, "{worst}");
    let mut a = Assembly::new(&hex_spec(0.2, penalty())).unwrap();
    a.solve(&g).unwrap();
    let s = a.snapshot();
    let worst = s.fluctuation.iter().map(|u| u[0].hypot(u[1])).fold(0.0, f64::max);
    let edge = 0.1 * 1.3e-3;
    assert!(worst > 0.0 && worst < 0.3 * edge, "{worst} vs affine edge displacement {edge}");
    assert_eq!(s.x.len(), a.disc_count());
    assert_eq!(s.boundary.len(), a.reference().boundary.len());
}

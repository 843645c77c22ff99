//! The hexagonal lattice's orientation and initial overlap against closed forms: the turned
//! lattice carries a vertical load on its columns at zero lateral stress, and an overlapping
//! lattice starts prestressed in equilibrium.

mod common;
use common::*;
use cosdem_common::MacroDeformation;
use cosdem_common::voigt::{XX, XY, YX, YY};
use cosdem_dem::spec::LatticeOrientation;
use cosdem_dem::{Assembly, AssemblySpec, BoundarySpec, PackingSpec};

const KN: f64 = 6.7e7;
const R: f64 = 0.005;

fn lattice(orientation: LatticeOrientation, overlap: f64, boundary: BoundarySpec) -> AssemblySpec {
    AssemblySpec {
        packing: PackingSpec::Hexagonal { radius: R, side: 0.1, orientation, overlap },
        boundary,
        ..Default::default()
    }
}

/// The periodic lattice turned so that its columns lie along y, shortened by `e_yy` and
/// widened just enough that the 30- and 150-degree contacts stay touching without force
/// (their length back to `2 r`, plus 1e-9): only the columns carry load, so the lateral
/// stress is zero (to round-off: the other families' forces are exactly zero, their Coulomb
/// limit too) and the axial stress is the columns' closed form `-k_n s |e_yy| l / A`, with
/// `l = s (1 + e_yy)` the column contact's branch length and `A = (sqrt 3 / 2) s^2 (1 + e_xx)
/// (1 + e_yy)` the current area per disc (relative 1e-9: the relaxation's equilibrium is the
/// affine state itself, every disc alike in the periodic cell). The lattice with rows along
/// x under the same deformation carries it on its 60-degree contacts: a lateral stress of
/// the order of the axial, which is why it cannot stand unconfined.
#[test]
fn turned_lattice_carries_a_vertical_load_at_zero_lateral_stress() {
    let e_yy: f64 = -1e-3;
    let fx = ((1.0 - 0.25 * (1.0 + e_yy) * (1.0 + e_yy)) / 0.75).sqrt() * (1.0 + 1e-9);
    let f = MacroDeformation::from_gradient([[fx - 1.0, 0.0], [0.0, e_yy]], 0.0, [0.0; 2]);
    let mut a =
        Assembly::new(&lattice(LatticeOrientation::Columns, 0.0, BoundarySpec::Periodic)).unwrap();
    let r = a.solve(&f).unwrap();
    assert!(r.diagnostics.converged);
    let s = 2.0 * R;
    let l = s * (1.0 + e_yy);
    let area = 3f64.sqrt() / 2.0 * s * s * fx * (1.0 + e_yy);
    let want = -KN * s * e_yy.abs() * l / area;
    assert!(rel(r.stress[YY], want) < 1e-9, "s_yy {} vs {want}", r.stress[YY]);
    assert!(r.stress[XX].abs() < 1e-9 * want.abs(), "s_xx {} (s_yy {want})", r.stress[XX]);
    assert!(r.stress[XY].abs() + r.stress[YX].abs() < 1e-9 * want.abs());

    let mut rows =
        Assembly::new(&lattice(LatticeOrientation::Rows, 0.0, BoundarySpec::Periodic)).unwrap();
    let r = rows.solve(&f).unwrap();
    let bound = (1.0 - 3f64.sqrt() * 0.5) / (3.0 + 3f64.sqrt() * 0.5);
    assert!(
        r.stress[XX] / r.stress[YY] > bound,
        "rows: s_xx {} s_yy {} (bound {bound})",
        r.stress[XX],
        r.stress[YY]
    );
}

/// A periodic lattice with neighbours overlapping by `d` of the diameter is at rest in
/// equilibrium under the isotropic stress of its six contacts per disc: `-sqrt 3 f / s` with
/// `f = k_n 2 r d` and `s = 2 r (1 - d)` (three contacts per disc, the three families'
/// `n n` summing to 3/2 I, area per disc `(sqrt 3 / 2) s^2`); 1e-9 relative, the affine
/// state being the equilibrium. Both orientations alike.
#[test]
fn an_overlapping_periodic_lattice_is_prestressed_isotropically() {
    let d = 0.01;
    let s = 2.0 * R * (1.0 - d);
    let want = -(3f64.sqrt()) * KN * 2.0 * R * d / s;
    for o in [LatticeOrientation::Rows, LatticeOrientation::Columns] {
        let mut a = Assembly::new(&lattice(o, d, BoundarySpec::Periodic)).unwrap();
        let r = a.solve(&MacroDeformation::IDENTITY).unwrap();
        assert!(r.diagnostics.converged, "{o:?}");
        for k in [XX, YY] {
            assert!(rel(r.stress[k], want) < 1e-9, "{o:?} {k}: {} vs {want}", r.stress[k]);
        }
    }
}

/// Cut to a square with a penalty boundary, an overlapping lattice (the boundary springs'
/// rest points placed against its prestress) relaxes at rest to an isotropic compression of
/// the closed form of its own contacts, `(s_xx + s_yy) / 2 = -(f / 2 s) rho` with
/// `rho = sum |l|^2 / A` the counted contact density (`2 sqrt 3` in the bulk, fewer contacts
/// per area near the edges). 3 %: measured 2.1 % below, both orientations, because the edge
/// discs do not stay as laid (they move up to 1e-2 r in 140 DEM steps, unexplained as yet:
/// docs/notes/2026-12-06-hexagonal-lattice.md); isotropic within 2 % (measured 1.1 %).
#[test]
fn an_overlapping_penalty_lattice_relaxes_to_its_prestress() {
    let d = 0.01;
    let (f, s) = (KN * 2.0 * R * d, 2.0 * R * (1.0 - d));
    for o in [LatticeOrientation::Rows, LatticeOrientation::Columns] {
        let mut a = Assembly::new(&lattice(o, d, penalty())).unwrap();
        let r = a.solve(&MacroDeformation::IDENTITY).unwrap();
        assert!(r.diagnostics.converged, "{o:?}");
        let rho = a.homogenized(a.trial().unwrap()).fabric.density;
        let want = -f / (2.0 * s) * rho;
        let mean = 0.5 * (r.stress[XX] + r.stress[YY]);
        assert!(rel(mean, want) < 0.03, "{o:?}: {mean} vs {want} (rho {rho})");
        assert!(rel(r.stress[XX], r.stress[YY]) < 0.02, "{o:?}: {:?}", r.stress);
    }
}

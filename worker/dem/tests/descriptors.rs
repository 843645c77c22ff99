//! Micro descriptors of whole assemblies: the dense hexagonal packing against its closed
//! forms, a contact pushed past the Coulomb limit, the answers of the solve (relaxed and
//! shortcut) and the growth of the fabric anisotropy under biaxial compression.

mod common;
use common::*;
use cosdem_common::{MacroDeformation, MicroDescriptors};
use cosdem_dem::broadphase::{self, Domain, PairList};
use cosdem_dem::contact::{Law, tangential};
use cosdem_dem::descriptors::of_state;
use cosdem_dem::{Assembly, AssemblySpec, BoundarySpec, PackingSpec};
use std::f64::consts::PI;

/// The periodic hexagonal packing at `Fbar = I` (every disc touches six neighbours at 60
/// degrees, `N_c = 3 N`). Closed forms: coordination 6 with and without rattlers (there are
/// none), fabric `I/2` (the six directions are isotropic: `sum cos^2 = 3`), anisotropy 0,
/// porosity `1 - pi / (2 sqrt 3)`. The periodic cell of `n_c` columns by an even number `n_r`
/// of rows is `2 r n_c` by `sqrt(3) r n_r` and holds `n_c n_r` discs, so its solid fraction is
/// exactly the infinite lattice's: no finite-size correction. (The penalty square of the
/// same lattice is not tiled by it: its porosity differs by O(r / side) and its boundary
/// discs have fewer contacts.) Tolerances: rounding of the trigonometric sums over ~100
/// contacts and of `1 - x`, 1e-12.
#[test]
fn periodic_hexagonal_packing_matches_closed_forms() {
    let mut a = Assembly::new(&hex_spec(0.1, BoundarySpec::Periodic)).unwrap();
    let resp = a.solve(&MacroDeformation::IDENTITY).unwrap();
    let d = resp.diagnostics.descriptors.expect("a DEM answer carries descriptors");
    assert_eq!(resp.diagnostics.contacts as usize, 3 * a.disc_count());
    assert_eq!(d.coordination, 6.0);
    assert_eq!(d.mechanical_coordination, 6.0);
    assert!((d.fabric_xx - 0.5).abs() < 1e-12, "F_xx = {}", d.fabric_xx);
    assert!((d.fabric_yy - 0.5).abs() < 1e-12, "F_yy = {}", d.fabric_yy);
    assert!(d.fabric_xy.abs() < 1e-12, "F_xy = {}", d.fabric_xy);
    assert!(d.anisotropy < 1e-12, "a = {}", d.anisotropy);
    let solid = PI / (2.0 * 3f64.sqrt());
    assert!((d.porosity - (1.0 - solid)).abs() < 1e-12, "n = {}", d.porosity);
    assert!((d.void_ratio - (1.0 / solid - 1.0)).abs() < 1e-12, "e = {}", d.void_ratio);
    // Nothing turns at the reference; no contact carries a tangential force.
    assert_eq!((d.mean_rotation, d.sliding_fraction), (0.0, 0.0));
}

/// An isotropic stretch of the periodic packing by `lam` scales the cell area by `lam^2`, so
/// the solid fraction divides by `lam^2` exactly as the closed form says (the discs keep their
/// radii): `n = 1 - pi / (2 sqrt 3 lam^2)`. Contacts open, so the contact descriptors drop to
/// zero. 1e-12 as above.
#[test]
fn porosity_follows_the_cell_area() {
    let mut a = Assembly::new(&hex_spec(0.1, BoundarySpec::Periodic)).unwrap();
    let lam = 1.01;
    let d = a.solve(&iso(lam - 1.0)).unwrap().diagnostics.descriptors.unwrap();
    let solid = PI / (2.0 * 3f64.sqrt() * lam * lam);
    assert!((d.porosity - (1.0 - solid)).abs() < 1e-12, "n = {}", d.porosity);
    assert_eq!((d.coordination, d.anisotropy, d.fabric_xx), (0.0, 0.0, 0.0));
}

/// Two overlapping discs along x and two along y; the tangential spring of the first pair is
/// pushed by the contact law's own update ([`tangential::update`]) with a slip ten times the
/// one that reaches `mu_s F_n`, so it is capped at the Coulomb limit; the second gets a slip
/// of half that one and sticks. Sliding fraction 1/2, counted exactly.
#[test]
fn contact_pushed_past_coulomb_slides() {
    let law = Law { kn: 1e6, cn: 0.0, ks: 5e5, cs: 0.0, mu_s: 0.5, kr: 0.0, cr: 0.0, mu_r: 0.0 };
    let r = [1.0; 4];
    let (x, y) = ([0.0, 1.99, 10.0, 10.0], [0.0, 0.0, 0.0, 1.99]);
    let mut pairs = broadphase::build(&x, &y, &r, 0.1, Domain::Open, &PairList::default());
    assert_eq!(pairs.len(), 2, "two pairs within the skin");
    let fnorm = law.kn * 0.01;
    let slip_to_cap = law.mu_s * fnorm / law.ks;
    for (k, slip) in [(0, 10.0 * slip_to_cap), (1, 0.5 * slip_to_cap)] {
        let (_, hist) = tangential::update(0.0, law.ks, 0.0, law.mu_s, fnorm, slip, 1.0, false);
        pairs.fs[k] = hist;
    }
    assert_eq!(pairs.fs[0].abs(), law.mu_s * fnorm, "the first spring is capped");
    let d = of_state(&law, &x, &y, &r, &[0.0; 4], &pairs, 100.0);
    assert_eq!(d.sliding_fraction, 0.5);
    assert_eq!(d.coordination, 1.0);
    // One normal along x, one along y: isotropic.
    assert!((d.fabric_xx - 0.5).abs() < 1e-15 && d.anisotropy < 1e-12);
}

/// The descriptors of an answer are those of the state it answered from: the relaxed trial
/// state, or for a shortcut answer (`skip_below`) the committed, last relaxed state. Their
/// sliding fraction is the diagnostics' own and their coordination `2 contacts / N`: one
/// definition of a contact everywhere. Exact comparisons: the same sums in the same order.
#[test]
fn answers_carry_the_descriptors_of_their_state() {
    let mut spec = hex_spec(0.06, penalty());
    spec.relaxation.skip_below = 1e-4;
    let mut a = Assembly::new(&spec).unwrap();
    let target = grad([[-2e-3, 1e-3], [0.0, -3e-3]]);
    let r = a.solve(&target).unwrap();
    let d = r.diagnostics.descriptors.unwrap();
    assert_eq!(d, a.descriptors(a.trial().unwrap()));
    assert_eq!(d.sliding_fraction, r.diagnostics.sliding_fraction);
    assert_eq!(d.coordination, 2.0 * r.diagnostics.contacts as f64 / a.disc_count() as f64);
    a.commit();
    let small = grad([[-2e-3 - 1e-5, 1e-3], [0.0, -3e-3]]);
    let s = a.solve(&small).unwrap();
    assert_eq!(s.diagnostics.answer, cosdem_common::Answer::Skipped);
    assert_eq!(s.diagnostics.descriptors, Some(d));
}

fn random_periodic() -> AssemblySpec {
    AssemblySpec {
        packing: PackingSpec::Random {
            r_min: 0.002,
            r_max: 0.004,
            radii: vec![],
            side: 0.06,
            seed: 11,
            confining_stress: 1e5,
        },
        boundary: BoundarySpec::Periodic,
        ..Default::default()
    }
}

/// `F_yy - F_xx`: positive when the contact normals lean to y.
fn lean_to_y(d: &MicroDescriptors) -> f64 {
    d.fabric_yy - d.fabric_xx
}

/// Biaxial compression of a random periodic packing (~100 discs at 100 kPa): `e_yy` down to
/// -2 % in four committed steps with `e_xx = +1 %` (roughly isochoric). Contacts normal to the
/// compression gain force and lateral ones open, so the contact normals turn to the loading
/// direction: `F_yy - F_xx` grows at every step and ends positive with the major fabric
/// direction within 30 degrees of y, and the anisotropy exceeds the reference's. A sign and
/// direction check (the amount depends on the packing, no closed form): 30 degrees leaves
/// room for the random packing's initial fabric.
#[test]
fn biaxial_compression_turns_the_fabric_to_the_loading_direction() {
    let mut a = Assembly::new(&random_periodic()).unwrap();
    let d0 = a.solve(&MacroDeformation::IDENTITY).unwrap().diagnostics.descriptors.unwrap();
    a.commit();
    let mut last = lean_to_y(&d0);
    let mut d = d0;
    for step in 1..=4 {
        let e = 0.005 * step as f64;
        let r = a.solve(&grad([[0.5 * e, 0.0], [0.0, -e]])).unwrap();
        assert!(r.diagnostics.converged, "step {step}");
        a.commit();
        d = r.diagnostics.descriptors.unwrap();
        eprintln!(
            "step {step}: F = ({:.4}, {:.4}, {:.4}), a = {:.4}, theta = {:.3}, Z = {:.3}, \
             Zm = {:.3}, n = {:.4}, sliding {:.3}, rotation {:.2e}",
            d.fabric_xx,
            d.fabric_yy,
            d.fabric_xy,
            d.anisotropy,
            d.fabric_direction,
            d.coordination,
            d.mechanical_coordination,
            d.porosity,
            d.sliding_fraction,
            d.mean_rotation
        );
        assert!(lean_to_y(&d) > last, "step {step}: F_yy - F_xx did not grow");
        last = lean_to_y(&d);
    }
    assert!(lean_to_y(&d) > 0.0);
    assert!(d.fabric_direction.abs() > PI / 3.0, "theta = {}", d.fabric_direction);
    assert!(d.anisotropy > d0.anisotropy, "a {} -> {}", d0.anisotropy, d.anisotropy);
    assert!(d.mechanical_coordination >= d.coordination);
}

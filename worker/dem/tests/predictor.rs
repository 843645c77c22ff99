//! The extrapolated predictor (`relaxation.predictor = "extrapolated"`): the same equilibrium
//! as the affine jump, from a start nearer to it, and a state that travels bit for bit.

mod common;
use common::*;
use cosdem_common::MacroDeformation;
use cosdem_common::voigt::{XX, YY};
use cosdem_dem::spec::Predictor;
use cosdem_dem::{Assembly, AssemblySpec, BoundarySpec, PackingSpec};

/// A random periodic specimen (radii 2-3 mm, side 6 cm, about 90 discs, 100 kPa).
fn spec(predictor: Predictor) -> AssemblySpec {
    let mut s = AssemblySpec {
        packing: PackingSpec::Random {
            r_min: 0.002,
            r_max: 0.003,
            radii: vec![],
            side: 0.06,
            seed: 7,
            confining_stress: 1e5,
        },
        boundary: BoundarySpec::Periodic,
        ..Default::default()
    };
    s.relaxation.predictor = predictor;
    s
}

/// Biaxial compression to `k` increments of (`exx`, `eyy`).
fn at(k: f64, exx: f64, eyy: f64) -> MacroDeformation {
    MacroDeformation::from_gradient([[exx * k, 0.0], [0.0, eyy * k]], 0.0, [0.0; 2])
}

/// Solves and commits `steps` increments; returns each step's DEM steps and stress.
fn path(a: &mut Assembly, steps: usize, exx: f64, eyy: f64) -> Vec<(u64, [f64; 6])> {
    (1..=steps)
        .map(|k| {
            let r = a.solve(&at(k as f64, exx, eyy)).unwrap();
            assert!(r.diagnostics.converged, "step {k}");
            a.commit();
            (r.diagnostics.steps, r.stress)
        })
        .collect()
}

/// In the elastic range the non-affine response is linear in the increment, so the last
/// step's fluctuation increment is the next one's: with increments of 1e-5 (contacts stick;
/// the stress moves by about 0.5 % of the 100 kPa confinement a step) the extrapolated start
/// already meets the criterion at its first check, and every later step needs at most half
/// the steps of the affine jump (measured: 10 against 50). The first step has nothing to
/// extrapolate from and is the affine predictor's bit for bit. Both end at the same
/// equilibrium: the stresses agree to 1e-5 of the confinement (1 Pa; measured 0.4 Pa), the
/// scale at which two relaxations that stop at an unbalance of 1e-4 of the mean contact force
/// from different starts can differ.
#[test]
fn the_elastic_path_is_extrapolated_exactly() {
    let mut affine = Assembly::new(&spec(Predictor::Affine)).unwrap();
    let mut extra = Assembly::new(&spec(Predictor::Extrapolated)).unwrap();
    let (pa, pe) = (path(&mut affine, 4, 4e-6, -1e-5), path(&mut extra, 4, 4e-6, -1e-5));
    assert_eq!(pa[0].0, pe[0].0);
    assert_eq!(pa[0].1.map(f64::to_bits), pe[0].1.map(f64::to_bits));
    for k in 1..4 {
        assert!(2 * pe[k].0 <= pa[k].0, "step {}: {:?} against {:?}", k + 1, pe, pa);
        for c in [XX, YY] {
            assert!((pe[k].1[c] - pa[k].1[c]).abs() < 1e-5 * 1e5, "{:?} {:?}", pe[k], pa[k]);
        }
    }
}

/// Past the elastic range (increments of 1e-4, contacts sliding) the start is only nearer:
/// the extrapolated path ends at the affine path's deviator to within 1 % (measured 0.59 %:
/// the contact histories are path dependent, and the two relaxations slide differently), and
/// takes fewer DEM steps over the path (measured 1 650 against 2 170). Both checks bite: a
/// shift three times too large ended 118 % off, the reversed shift within 1 % but in more
/// steps than the affine jump (both tried on this test).
#[test]
fn a_sliding_path_reaches_the_same_stresses_in_fewer_steps() {
    let mut affine = Assembly::new(&spec(Predictor::Affine)).unwrap();
    let mut extra = Assembly::new(&spec(Predictor::Extrapolated)).unwrap();
    let (pa, pe) = (path(&mut affine, 10, 4e-4, -1e-3), path(&mut extra, 10, 4e-4, -1e-3));
    let q = |s: &[f64; 6]| s[XX] - s[YY];
    let sum = |p: &[(u64, [f64; 6])]| p.iter().map(|s| s.0).sum::<u64>();
    let (qa, qe) = (q(&pa[9].1), q(&pe[9].1));
    assert!(rel(qe, qa) < 0.01, "deviator {qe} against {qa}");
    assert!(sum(&pe) < sum(&pa), "{} against {}", sum(&pe), sum(&pa));
}

/// The increment belongs to the committed state: an assembly restored from its bytes after a
/// commit takes the next step bit for bit as the original does, and a rollback keeps it. A
/// reversal (unloading) projects below zero, so it gets no shift: from the same committed
/// state (one step, which nothing is extrapolated into) it is the affine predictor's answer
/// bit for bit. An affine assembly keeps no increment, and its bytes carry none (the
/// extrapolated one's are longer by at least the three arrays of 8-byte numbers).
#[test]
fn the_increment_travels_with_the_state() {
    let mut a = Assembly::new(&spec(Predictor::Extrapolated)).unwrap();
    path(&mut a, 2, 4e-4, -1e-3);
    let step = a.last_step().expect("an increment after two commits").clone();
    assert_eq!(step.to, a.committed().target);
    let mut b = Assembly::from_bytes(&a.to_bytes()).unwrap();
    assert_eq!(b.last_step(), Some(&step));
    let next = at(3.0, 4e-4, -1e-3);
    let (ra, rb) = (a.solve(&next).unwrap(), b.solve(&next).unwrap());
    assert_eq!(ra.stress.map(f64::to_bits), rb.stress.map(f64::to_bits));
    assert_eq!(ra.diagnostics.steps, rb.diagnostics.steps);
    a.rollback();
    assert_eq!(a.last_step(), Some(&step));

    let mut e = Assembly::new(&spec(Predictor::Extrapolated)).unwrap();
    let mut f = Assembly::new(&spec(Predictor::Affine)).unwrap();
    path(&mut e, 1, 4e-4, -1e-3);
    path(&mut f, 1, 4e-4, -1e-3);
    assert!(e.last_step().is_some() && f.last_step().is_none());
    let n = e.disc_count();
    assert!(e.to_bytes().len() >= f.to_bytes().len() + 24 * n);
    let back = at(0.5, 4e-4, -1e-3);
    let (re, rf) = (e.solve(&back).unwrap(), f.solve(&back).unwrap());
    assert_eq!(re.diagnostics.steps, rf.diagnostics.steps);
    assert_eq!(re.stress.map(f64::to_bits), rf.stress.map(f64::to_bits));
}

/// A damaged increment is refused by name: the bytes of an extrapolated assembly cut short
/// inside the increment (checksum recomputed, so only the decoding can object).
#[test]
fn a_truncated_increment_is_refused_by_name() {
    let mut a = Assembly::new(&spec(Predictor::Extrapolated)).unwrap();
    path(&mut a, 1, 4e-4, -1e-3);
    let bytes = a.to_bytes();
    let mut cut = bytes[..bytes.len() - 4 - 100].to_vec();
    let crc = crc32fast::hash(&cut);
    cut.extend_from_slice(&crc.to_le_bytes());
    let e = Assembly::from_bytes(&cut).unwrap_err().to_string();
    assert!(e.contains("last step"), "{e}");
}

//! Explicit disc lists (what a packing file becomes on the master): the assembly built from a
//! hexagonal packing written out and read back is the hexagonal assembly, and a bad list is
//! refused naming the key, the disc and the value.

mod common;

use common::{grad, hex_spec, penalty};
use cosdem_dem::packing::Packing;
use cosdem_dem::packing::formats::{PackingFormat, ReadOptions, read, write_lammps, write_yade};
use cosdem_dem::{Assembly, AssemblySpec, BoundarySpec, PackingSpec};

/// The spec of `p` as an explicit disc list, the rest as `base`.
fn explicit(base: &AssemblySpec, p: &Packing) -> AssemblySpec {
    AssemblySpec {
        packing: PackingSpec::Explicit {
            x: p.x.clone(),
            y: p.y.clone(),
            radii: p.r.clone(),
            lx: p.lx,
            ly: p.ly,
        },
        ..base.clone()
    }
}

/// A hexagonal assembly (penalty and periodic) written as YADE text and as a LAMMPS data file
/// from its committed state, read back and built, is the same assembly: same reference
/// region, same discs, and the same stress and tangent, bit for bit, after a compression with
/// shear (the relaxation is deterministic, so any difference in the reference would show).
#[test]
fn a_written_hexagonal_packing_builds_the_same_assembly() {
    for boundary in [penalty(), BoundarySpec::Periodic] {
        let periodic = matches!(boundary, BoundarySpec::Periodic);
        let spec = hex_spec(0.06, boundary);
        let mut a = Assembly::new(&spec).unwrap();
        let p = Packing::committed(&a);
        let opt = ReadOptions { density: spec.density, periodic };
        for (text, format) in [
            (write_yade(&p), PackingFormat::Yade),
            (write_lammps(&p, spec.density), PackingFormat::Lammps),
        ] {
            let q = read(&text, format, "hex", &opt).unwrap();
            let mut b = Assembly::new(&explicit(&spec, &q)).unwrap();
            assert_eq!(a.disc_count(), b.disc_count());
            assert_eq!(a.area().to_bits(), b.area().to_bits(), "{format:?} periodic {periodic}");
            assert_eq!(a.reference().x0, b.reference().x0);
            assert_eq!(a.reference().boundary, b.reference().boundary);
            let target = grad([[-1e-3, 4e-4], [0.0, -5e-4]]);
            let (ra, rb) = (a.solve(&target).unwrap(), b.solve(&target).unwrap());
            assert_eq!(ra.stress.map(f64::to_bits), rb.stress.map(f64::to_bits));
            assert_eq!(ra.tangent, rb.tangent);
            a.rollback();
        }
    }
}

/// The same list builds the same assembly twice (bit for bit): no seed, no relaxation before
/// the first load.
#[test]
fn an_explicit_packing_is_deterministic() {
    let spec = hex_spec(0.05, penalty());
    let p = Packing::committed(&Assembly::new(&spec).unwrap());
    let s = explicit(&spec, &p);
    assert_eq!(Assembly::new(&s).unwrap().to_bytes(), Assembly::new(&s).unwrap().to_bytes());
}

/// A bad explicit list is refused naming the key, the disc and the value.
#[test]
fn bad_explicit_lists_are_refused() {
    let spec = hex_spec(0.05, penalty());
    let p = Packing::committed(&Assembly::new(&spec).unwrap());
    let err = |edit: &dyn Fn(&mut Packing)| {
        let mut q = p.clone();
        edit(&mut q);
        explicit(&spec, &q).validate().unwrap_err().to_string()
    };
    let e = err(&|q| q.r[3] = -0.001);
    assert!(e.contains("packing.radii") && e.contains("radii[3] = -0.001"), "{e}");
    let e = err(&|q| q.x[7] = f64::NAN);
    assert!(e.contains("packing.x") && e.contains("x[7] = NaN"), "{e}");
    let e = err(&|q| q.y[2] = q.ly + 0.02);
    assert!(e.contains("packing.y") && e.contains("y[2]"), "{e}");
    let e = err(&|q| q.y.pop().map(drop).unwrap_or(()));
    assert!(e.contains("packing.y") && e.contains("centres for"), "{e}");
    let e = err(&|q| q.x[1] = q.x[0] + 0.5 * q.r[0]);
    assert!(e.contains("packing.radii") && e.contains("discs 0 and 1 overlapping"), "{e}");
    let e = err(&|q| {
        q.x.truncate(3);
        q.y.truncate(3);
        q.r.truncate(3);
    });
    assert!(e.contains("packing.radii") && e.contains("= 3:"), "{e}");
    let e = err(&|q| q.lx = 0.02);
    assert!(e.contains("packing"), "{e}");
    let big = PackingSpec::Explicit {
        x: vec![0.5; 1_000_001],
        y: vec![0.5; 1_000_001],
        radii: vec![1e-4; 1_000_001],
        lx: 1.0,
        ly: 1.0,
    };
    let e = AssemblySpec { packing: big, ..spec.clone() }.validate().unwrap_err().to_string();
    assert!(e.contains("1000001 radii") && e.contains("MAX_DISCS"), "{e}");
    let file = PackingSpec::File { file: "dense.txt".into(), format: PackingFormat::Yade };
    let e = AssemblySpec { packing: file, ..spec }.validate().unwrap_err().to_string();
    assert!(e.contains("packing.file") && e.contains("dense.txt"), "{e}");
}

/// Discs that overlap only through the periodic cell pass as a penalty square and are
/// refused when the assembly is built periodic.
#[test]
fn overlaps_through_the_cell_are_refused_when_periodic() {
    let spec = hex_spec(0.05, BoundarySpec::Periodic);
    let mut p = Packing::committed(&Assembly::new(&spec).unwrap());
    p.lx -= 0.2 * p.r[0];
    let s = explicit(&spec, &p);
    let e = Assembly::new(&s).unwrap_err().to_string();
    assert!(e.contains("across the cell"), "{e}");
}

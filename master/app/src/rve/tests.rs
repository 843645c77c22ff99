//! The RVE driver on a tiny hexagonal assembly (5 mm discs in a 5 cm square, about 30 discs):
//! stress control reaches its target, the table path reproduces the isotropic path bit for
//! bit, and the output files have one row per state.

use super::report::{RVE_COLUMNS, RveSummary, RveWriter};
use super::*;
use cosdem_dem::{AssemblySpec, PackingSpec};

fn tiny() -> Assembly {
    let spec =
        AssemblySpec { packing: PackingSpec::hexagonal(0.005, 0.05), ..AssemblySpec::default() };
    Assembly::new(&spec).unwrap()
}

fn run(settings: &RveSettings) -> Vec<RveRow> {
    let mut a = tiny();
    let mut rows = Vec::new();
    drive(&mut a, settings, &mut |r| {
        rows.push(r.clone());
        Ok(())
    })
    .unwrap();
    rows
}

/// Biaxial: every state holds s_xx = -p within the tolerance (checked on the returned
/// stress, relative 1e-3 as set), and the axial stress grows in compression over the first
/// steps (elastic range, 1e-4 strain per step).
#[test]
fn biaxial_holds_the_confining_pressure() {
    let s = RveSettings { steps: 4, increment: 1e-4, pressure: 1e5, ..RveSettings::default() };
    let rows = run(&s);
    assert_eq!(rows.len(), 5);
    for r in &rows {
        assert!((r.stress[XX] + 1e5).abs() <= 1e-3 * 1e5, "step {}: {:?}", r.step, r.stress);
        assert!(r.control_residual <= 1e-3);
    }
    for w in rows.windows(2) {
        assert!(w[1].stress[YY] < w[0].stress[YY], "{:?} -> {:?}", w[0].stress, w[1].stress);
        assert!((w[0].deformation.f[1][1] - w[1].deformation.f[1][1] - 1e-4).abs() < 1e-15);
    }
}

/// The same deformations given as a table give bit-identical stresses: the drive is a
/// deterministic function of (assembly, sequence of targets).
#[test]
fn table_reproduces_the_isotropic_path() {
    let iso = RveSettings {
        path: RvePath::Isotropic,
        steps: 3,
        increment: 2e-4,
        ..RveSettings::default()
    };
    let a = run(&iso);
    let table: Vec<_> = a[1..].iter().map(|r| r.deformation).collect();
    let b = run(&RveSettings { path: RvePath::Table(table), ..iso });
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x.stress, y.stress);
        assert_eq!(x.tangent, y.tangent);
    }
    // Isotropic compression of a hexagonal packing: compressive and nearly isotropic stress.
    let s = a.last().unwrap().stress;
    assert!(s[XX] < 0.0 && s[YY] < 0.0);
    assert!((s[XX] - s[YY]).abs() < 0.2 * s[XX].abs(), "{s:?}");
}

/// Simple shear at constant vertical stress, then the files: one row per state, 24 and 37
/// columns, and a summary with a finite peak friction angle.
/// The simple-shear run's peak friction angle, measured.
const PEAK_FRICTION_ANGLE: f64 = 16.688_807_263_394_672;

#[test]
fn simple_shear_writes_the_files() {
    let s = RveSettings {
        path: RvePath::SimpleShear,
        steps: 3,
        increment: 2e-4,
        pressure: 5e4,
        ..RveSettings::default()
    };
    let dir = std::env::temp_dir().join(format!("cosdem-rve-{}", std::process::id()));
    let mut a = tiny();
    let summary = RveSummary { path: "simple-shear".into(), ..Default::default() };
    let mut w = RveWriter::create(&dir, summary, s.tolerance).unwrap();
    drive(&mut a, &s, &mut |r| {
        assert!((r.stress[YY] + 5e4).abs() <= 1e-3 * 5e4, "{:?}", r.stress);
        w.write(r).map_err(|e| Error::Observer(e.to_string()))
    })
    .unwrap();
    w.finish(0.0).unwrap();
    let csv = std::fs::read_to_string(dir.join("rve.csv")).unwrap();
    assert_eq!(csv.lines().count(), 5);
    assert_eq!(csv.lines().next().unwrap().split(',').count(), RVE_COLUMNS.len());
    let t = std::fs::read_to_string(dir.join("tangent.csv")).unwrap();
    assert_eq!(t.lines().nth(1).unwrap().split(',').count(), 37);
    // The peak mobilised friction angle (degrees), measured: a deterministic relaxation, so
    // 1e-9 relative covers only a change of summation order.
    let phi = w.summary().peak_friction_angle;
    assert!((phi - PEAK_FRICTION_ANGLE).abs() <= 1e-9 * PEAK_FRICTION_ANGLE, "{phi} degrees");
    let json = std::fs::read_to_string(dir.join("rve.json")).unwrap();
    assert!(json.contains("peak_friction_angle"));
    std::fs::remove_dir_all(&dir).unwrap();
}

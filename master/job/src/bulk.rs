//! The bulk density of a DEM material, from its assembly: what gravity weighs when neither the
//! region (`bulk_density`) nor the stage (`[stage.gravity] density`) gives one.
//!
//! A dry granular continuum weighs its solid density times its solid fraction,
//! `rho_bulk = rho_s * sum(pi r^2) / V`, with `V` the assembly's area. The solid fraction is
//! that of the assembly as built: exact for a hexagonal lattice or an explicit disc list, and
//! for a random packing that of the specimen generated and consolidated at its confining
//! stress. So the master builds one assembly per DEM material whose density it needs (for a
//! random packing, one packing generation: the cost a worker pays per specimen), once per
//! process: the answer is kept by the spec (its `Debug` text: every number to the bit), since the job's stages are expanded more
//! than once.

use cosdem_dem::packing::Packing;
use cosdem_dem::{Assembly, AssemblySpec};
use std::collections::BTreeMap;
use std::sync::{Mutex, OnceLock};

/// Bulk densities already computed, by their spec's `Debug` text.
fn memo() -> &'static Mutex<BTreeMap<String, f64>> {
    static MEMO: OnceLock<Mutex<BTreeMap<String, f64>>> = OnceLock::new();
    MEMO.get_or_init(Mutex::default)
}

/// `density * solid fraction` of the assembly `spec` builds (kg/m^3 of the continuum).
pub fn assembly_bulk_density(spec: &AssemblySpec) -> cosdem_dem::Result<f64> {
    let key = format!("{spec:?}");
    if let Some(&rho) = memo().lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
        return Ok(rho);
    }
    let a = Assembly::new(spec)?;
    let solid: f64 = Packing::committed(&a).r.iter().map(|r| std::f64::consts::PI * r * r).sum();
    let rho = spec.density * solid / a.area();
    memo().lock().unwrap_or_else(|e| e.into_inner()).insert(key, rho);
    Ok(rho)
}

#[cfg(test)]
mod tests {
    use super::assembly_bulk_density;
    use cosdem_dem::{AssemblySpec, PackingSpec};

    /// The default assembly, 105 discs of radius 5 mm in the penalty square of side 0.1 m (the
    /// lattice's whole rows and columns: 0.825 full, where the infinite lattice would be
    /// 0.907), weighs `2650 * 105 pi 0.005^2 / 0.1^2`; an explicit 5 x 5 lattice of discs of
    /// radius 0.999 m in a 10 x 10 m periodic cell `2000 * 25 pi 0.999^2 / 100`. Both to
    /// rounding (1e-12): the sum of 105 equal terms and one division.
    #[test]
    fn bulk_density_is_solid_density_times_solid_fraction() {
        let hex = AssemblySpec::default();
        let rho = assembly_bulk_density(&hex).unwrap();
        let expected = 2650.0 * 105.0 * std::f64::consts::PI * 0.005 * 0.005 / (0.1 * 0.1);
        assert!((rho / expected - 1.0).abs() < 1e-12, "{rho} vs {expected}");
        // The memo answers the same bits.
        assert_eq!(assembly_bulk_density(&hex).unwrap().to_bits(), rho.to_bits());

        let mut explicit = AssemblySpec {
            boundary: cosdem_dem::BoundarySpec::Periodic,
            density: 2000.0,
            ..AssemblySpec::default()
        };
        let side = 10.0;
        let n = 5;
        let (mut x, mut y) = (Vec::new(), Vec::new());
        for k in 0..n * n {
            x.push(1.0 + 2.0 * (k % n) as f64);
            y.push(1.0 + 2.0 * (k / n) as f64);
        }
        explicit.packing =
            PackingSpec::Explicit { x, y, radii: vec![0.999; 25], lx: side, ly: side };
        let rho = assembly_bulk_density(&explicit).unwrap();
        let expected = 2000.0 * 25.0 * std::f64::consts::PI * 0.999 * 0.999 / (side * side);
        assert!((rho / expected - 1.0).abs() < 1e-12, "{rho} vs {expected}");
    }
}

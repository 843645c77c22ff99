//! Benchmark workloads: particle-steps per second of hexagonal assemblies under slow
//! compression, and the wall time of one full relaxation.

use crate::assembly::Assembly;
use crate::error::Result;
use crate::spec::{AssemblySpec, ContactParams, PackingSpec};
use cosdem_common::MacroDeformation;
use std::time::Instant;

/// One benchmark line.
#[derive(Clone, Debug, PartialEq)]
pub struct Rate {
    /// Discs in the assembly.
    pub discs: usize,
    /// Steps run.
    pub steps: u64,
    /// Particle-steps per second.
    pub rate: f64,
}

/// Hexagonal assembly of radius 5 mm with about `n` discs, default contact law.
pub fn hexagonal(n: usize) -> Result<Assembly> {
    hexagonal_with(n, ContactParams::default())
}

/// Hexagonal assembly of radius 5 mm with about `n` discs and the given contact law.
pub fn hexagonal_with(n: usize, contact: ContactParams) -> Result<Assembly> {
    let r = 0.005;
    let side = (n as f64 * 2.0 * 3f64.sqrt() * r * r).sqrt() + 2.0 * r;
    let spec = AssemblySpec {
        packing: PackingSpec::Hexagonal { radius: r, side },
        contact,
        ..Default::default()
    };
    Assembly::new(&spec)
}

/// Slow uniaxial compression: the vertical strain grows by `5e-6` every 500 steps (each
/// chunk: affine jump of the boundary targets, 100 damped steps, commit), `steps` steps in
/// all, full contact law, one core. Returns the rate in particle-steps per second.
pub fn rate(n: usize, steps: u64) -> Result<Rate> {
    rate_with(n, steps, ContactParams::default())
}

/// As [`rate`] with the given contact law (what switching a sub-model off saves).
pub fn rate_with(n: usize, steps: u64, contact: ContactParams) -> Result<Rate> {
    let mut a = hexagonal_with(n, contact)?;
    let chunk = 500u64;
    let mut e = 0.0;
    let mut run = |a: &mut Assembly, count: u64| -> Result<u64> {
        let mut done = 0;
        while done < count {
            e -= 5e-6;
            let target = MacroDeformation::from_gradient([[0.0, 0.0], [0.0, e]], 0.0, [0.0; 2]);
            done += a.run_steps(&target, chunk)?;
            a.commit();
        }
        Ok(done)
    };
    run(&mut a, 10 * chunk)?; // warm caches, close the contacts
    let t0 = Instant::now();
    let s = run(&mut a, steps)?;
    let dt = t0.elapsed().as_secs_f64();
    Ok(Rate { discs: a.disc_count(), steps: s, rate: (a.disc_count() as f64 * s as f64) / dt })
}

/// Full relaxation of the 0.0784 m^2 assembly (r = 5 mm) after a `1e-3` compressive strain
/// increment: returns (discs, steps, converged, wall seconds).
pub fn relaxation() -> Result<(usize, u64, bool, f64)> {
    let spec = AssemblySpec {
        packing: PackingSpec::Hexagonal { radius: 0.005, side: 0.28 },
        ..Default::default()
    };
    let mut a = Assembly::new(&spec)?;
    let target = MacroDeformation::from_gradient([[0.0, 0.0], [0.0, -1e-3]], 0.0, [0.0; 2]);
    let t0 = Instant::now();
    let r = a.solve(&target)?;
    Ok((a.disc_count(), r.diagnostics.steps, r.diagnostics.converged, t0.elapsed().as_secs_f64()))
}

/// Builds a random polydisperse packing (r in [4, 6] mm, 100 kPa, seed 1) of side `side`
/// with the given boundary: returns (discs, wall seconds).
pub fn random_build(side: f64, boundary: crate::spec::BoundarySpec) -> Result<(usize, f64)> {
    let spec = AssemblySpec {
        packing: PackingSpec::Random {
            r_min: 0.004,
            r_max: 0.006,
            radii: vec![],
            side,
            seed: 1,
            confining_stress: 1e5,
        },
        boundary,
        ..Default::default()
    };
    let t0 = Instant::now();
    let a = Assembly::new(&spec)?;
    Ok((a.disc_count(), t0.elapsed().as_secs_f64()))
}

//! Benchmark workloads: particle-steps per second of hexagonal assemblies under slow
//! compression, and the wall time of one full relaxation.

use crate::assembly::Assembly;
use crate::error::Result;
use crate::integrate::StageTimes;
use crate::spec::{AssemblySpec, ContactParams, Driver, PackingSpec, Predictor, RelaxationSpec};
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
    let spec =
        AssemblySpec { packing: PackingSpec::hexagonal(r, side), contact, ..Default::default() };
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
    let mut strain = 0.0;
    compress(&mut a, &mut strain, 10 * CHUNK, None)?; // warm caches, close the contacts
    let t0 = Instant::now();
    let s = compress(&mut a, &mut strain, steps, None)?;
    let dt = t0.elapsed().as_secs_f64();
    Ok(Rate { discs: a.disc_count(), steps: s, rate: (a.disc_count() as f64 * s as f64) / dt })
}

/// Steps per chunk of the compression workload.
const CHUNK: u64 = 500;

/// The workload of [`rate`]: `steps` steps in chunks of [`CHUNK`], each an affine jump of
/// `-5e-6` vertical strain (from `strain`, which it advances) then the chunk's steps, then a
/// commit. With a clock the equilibrium ratio is also computed, at the spec's `check_every`.
fn compress(
    a: &mut Assembly,
    strain: &mut f64,
    steps: u64,
    mut clock: Option<&mut StageTimes>,
) -> Result<u64> {
    let mut done = 0;
    while done < steps {
        *strain -= 5e-6;
        let target = MacroDeformation::from_gradient([[0.0, 0.0], [0.0, *strain]], 0.0, [0.0; 2]);
        done += a.run_steps_timed(&target, CHUNK, clock.as_deref_mut())?;
        a.commit();
    }
    Ok(done)
}

/// Where a step's time goes: seconds per [`crate::integrate::Stage`] over `steps` steps of
/// [`rate`]'s workload at about `n` discs, the equilibrium ratio computed every
/// `check_every` steps as in a solve. The clock reads the time four times a step, which the
/// stages' figures include (tens of nanoseconds a step).
#[derive(Clone, Debug, PartialEq)]
pub struct Split {
    /// Discs in the assembly.
    pub discs: usize,
    /// Steps run.
    pub steps: u64,
    /// Seconds per stage, in the order of [`crate::integrate::Stage`]: integration, broad
    /// phase, forces, criterion.
    pub seconds: [f64; 4],
}

/// Measures a [`Split`]: the compression of [`rate`] after the same warm-up, timed by stage.
pub fn split(n: usize, steps: u64) -> Result<Split> {
    let mut a = hexagonal(n)?;
    let mut strain = 0.0;
    compress(&mut a, &mut strain, 10 * CHUNK, None)?;
    let mut clock = StageTimes::new();
    let s = compress(&mut a, &mut strain, steps, Some(&mut clock))?;
    Ok(Split { discs: a.disc_count(), steps: s, seconds: clock.seconds })
}

/// The force kernel alone: the hexagonal assembly of about `n` discs after [`rate`]'s warm-up
/// (every neighbour pair in contact), its forces computed `passes` times from the same state
/// (the histories advance, nothing moves), by the kernel of every solve or, with `one_at_a_time`,
/// one pair at a time ([`crate::contact::kernel::accumulate_with`]). Returns (pairs, seconds per pair).
pub fn pair_cost(n: usize, passes: usize, one_at_a_time: bool) -> Result<(usize, f64)> {
    use crate::contact::kernel::{Accum, Bodies, accumulate_with};
    let mut a = hexagonal(n)?;
    let mut strain = 0.0;
    compress(&mut a, &mut strain, 10 * CHUNK, None)?;
    let (law, state) = (*a.law(), a.committed().clone());
    let d = &state.dynamics;
    let b = Bodies { x: &d.x, y: &d.y, vx: &d.vx, vy: &d.vy, w: &d.w, r: &a.reference().r };
    let mut pairs = state.pairs.clone();
    let m = a.disc_count();
    let (mut fx, mut fy, mut tq) = (vec![0.0; m], vec![0.0; m], vec![0.0; m]);
    let t0 = Instant::now();
    for _ in 0..passes {
        for f in [&mut fx, &mut fy, &mut tq] {
            f.fill(0.0);
        }
        let mut acc = Accum { fx: &mut fx, fy: &mut fy, tq: &mut tq };
        let sums = accumulate_with(!one_at_a_time, &law, a.time_step(), b, &mut pairs, &mut acc);
        std::hint::black_box(sums);
    }
    let per = t0.elapsed().as_secs_f64() / (passes.max(1) * pairs.len().max(1)) as f64;
    Ok((pairs.len(), per))
}

/// Full relaxation of the 0.0784 m^2 assembly (r = 5 mm) after a `1e-3` compressive strain
/// increment: returns (discs, steps, converged, wall seconds).
pub fn relaxation() -> Result<(usize, u64, bool, f64)> {
    let spec = AssemblySpec { packing: PackingSpec::hexagonal(0.005, 0.28), ..Default::default() };
    let mut a = Assembly::new(&spec)?;
    let target = MacroDeformation::from_gradient([[0.0, 0.0], [0.0, -1e-3]], 0.0, [0.0; 2]);
    let t0 = Instant::now();
    let r = a.solve(&target)?;
    Ok((a.disc_count(), r.diagnostics.steps, r.diagnostics.converged, t0.elapsed().as_secs_f64()))
}

/// The relaxations of one size in [`relaxation_scaling`].
#[derive(Clone, Debug, PartialEq)]
pub struct Relaxation {
    /// Discs in the assembly.
    pub discs: usize,
    /// Relaxations (load steps).
    pub count: usize,
    /// Relaxation steps of all of them (all sub-steps).
    pub steps: u64,
    /// How many reached the tolerance.
    pub converged: usize,
    /// Wall seconds of all the solves.
    pub seconds: f64,
}

/// Load steps of [`relaxation_scaling`].
pub const SCALING_STEPS: usize = 10;

/// A way of relaxing the yardstick's load steps (issue 30, item 1's candidates): the
/// relaxation settings, whether each trial starts from the last trial (`warm_start`), and
/// the trial solves per load step (`iterates`).
#[derive(Clone, Debug, PartialEq)]
pub struct Candidate {
    /// The name the benchmark prints.
    pub name: &'static str,
    /// Driver, criterion and tolerance.
    pub relaxation: RelaxationSpec,
    /// Each trial from the last one (the job's `warm_start`) instead of the committed state.
    pub warm_start: bool,
    /// Trial solves per load step, as a Newton iteration asks them: at the fractions
    /// `1 - 10^-j` of the step's increment (j = 1 .. iterates - 1), then at the step's end,
    /// which is committed. 1: one solve per step.
    pub iterates: usize,
}

impl Candidate {
    /// The default relaxation, one solve per step: the yardstick's own path.
    pub fn reference() -> Self {
        Self {
            name: "default (Cundall 0.7), one solve per step",
            relaxation: RelaxationSpec::default(),
            warm_start: false,
            iterates: 1,
        }
    }

    /// The candidates the benchmark compares, each at the default criterion and tolerance:
    /// the drivers (Cundall's damping at 0.7 and 0.9, FIRE) on one solve per step, and the
    /// initial guess (from the committed state or, warm, from the last trial) on three
    /// Newton-like trials per step.
    pub fn all() -> Vec<Self> {
        let cundall = |alpha| RelaxationSpec {
            driver: Driver::Cundall { alpha },
            ..RelaxationSpec::default()
        };
        let extrapolated =
            RelaxationSpec { predictor: Predictor::Extrapolated, ..RelaxationSpec::default() };
        let three = |name, warm_start| Self {
            name,
            relaxation: RelaxationSpec::default(),
            warm_start,
            iterates: 3,
        };
        vec![
            Self::reference(),
            Self {
                name: "Cundall 0.9, one solve per step",
                relaxation: cundall(0.9),
                ..Self::reference()
            },
            Self {
                name: "FIRE, one solve per step",
                relaxation: RelaxationSpec { driver: Driver::fire(), ..RelaxationSpec::default() },
                ..Self::reference()
            },
            three("default, 3 trials per step, each from the committed state", false),
            three("warm start, 3 trials per step, each from the last trial", true),
            Self {
                name: "extrapolated predictor, one solve per step",
                relaxation: extrapolated.clone(),
                ..Self::reference()
            },
            Self {
                name: "extrapolated + warm start, 3 trials per step",
                relaxation: extrapolated,
                ..three("", true)
            },
        ]
    }
}

/// The cost of a relaxation against the assembly's size: the biaxial example's specimen
/// (random discs of radii 2-3 mm, seed 7, brought to 100 kPa, periodic cell, the default
/// relaxation) at each side in `sides`, taken through [`SCALING_STEPS`] load steps as a Gauss
/// point of that example sees them before its peak (each `e_xx = +4e-4`, `e_yy = -1e-3`,
/// solved from the last committed state, then committed: to 1 % axial strain). Issue 30's
/// measure of "DEM steps per answer" against N.
pub fn relaxation_scaling(sides: &[f64]) -> Result<Vec<Relaxation>> {
    relaxation_scaling_with(sides, &Candidate::reference())
}

/// [`relaxation_scaling`] relaxed by `candidate` (a random specimen is generated with the
/// default relaxation whatever the job's, so every candidate starts from the same packing).
/// `count` is the number of solves, `SCALING_STEPS * iterates`.
pub fn relaxation_scaling_with(sides: &[f64], candidate: &Candidate) -> Result<Vec<Relaxation>> {
    let iterates = candidate.iterates.max(1);
    let mut out = Vec::with_capacity(sides.len());
    for &side in sides {
        let spec = AssemblySpec {
            packing: PackingSpec::Random {
                r_min: 0.002,
                r_max: 0.003,
                radii: vec![],
                side,
                seed: 7,
                confining_stress: 1e5,
            },
            boundary: crate::spec::BoundarySpec::Periodic,
            relaxation: candidate.relaxation.clone(),
            warm_start: candidate.warm_start,
            ..Default::default()
        };
        let mut a = Assembly::new(&spec)?;
        let mut run = Relaxation {
            discs: a.disc_count(),
            count: SCALING_STEPS * iterates,
            steps: 0,
            converged: 0,
            seconds: 0.0,
        };
        let at = |e: f64| {
            MacroDeformation::from_gradient([[4e-4 * e, 0.0], [0.0, -1e-3 * e]], 0.0, [0.0; 2])
        };
        for k in 1..=SCALING_STEPS {
            for j in 1..=iterates {
                // 0.9, 0.99, ... of the step's increment, then its end.
                let short = if j == iterates { 0.0 } else { 10f64.powi(-(j as i32)) };
                let target = at(k as f64 - short);
                let t0 = Instant::now();
                let r = a.solve(&target)?;
                run.seconds += t0.elapsed().as_secs_f64();
                run.steps += r.diagnostics.steps;
                run.converged += usize::from(r.diagnostics.converged);
            }
            a.commit();
        }
        out.push(run);
    }
    Ok(out)
}

/// The least-squares exponent `b` of `y ~ x^b` through the points (at least two distinct
/// `x`, all positive).
pub fn power_law_exponent(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (lx, ly): (Vec<f64>, Vec<f64>) = points.iter().map(|(x, y)| (x.ln(), y.ln())).unzip();
    let (mx, my) = (lx.iter().sum::<f64>() / n, ly.iter().sum::<f64>() / n);
    let sxy: f64 = lx.iter().zip(&ly).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = lx.iter().map(|x| (x - mx) * (x - mx)).sum();
    sxy / sxx
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The exponent of exact power laws comes back to round-off (1e-12), whatever the
    /// prefactor and the spacing of the points.
    #[test]
    fn power_law_exponent_recovers_exact_laws() {
        for b in [0.5, 1.0, 1.38, 2.0] {
            let pts: Vec<(f64, f64)> = [105.0, 418.0, 1613.0, 6407.0]
                .iter()
                .map(|&x| (x, 3e-5 * f64::powf(x, b)))
                .collect();
            assert!((power_law_exponent(&pts) - b).abs() < 1e-12, "{b}");
        }
    }

    /// The candidates on the smallest specimen (106 discs): each starts from the same packing
    /// and every relaxation converges; the reference candidate is the yardstick's path; and a
    /// warm start saves steps on the Newton-like trials (the later trials are 1 % and 0 % of
    /// the increment away from the last one, so a start from it is far closer to equilibrium
    /// than the committed state: at least a third fewer steps, a bound it passes by a wide
    /// margin and that a warm start ignored by the solve would fail).
    #[test]
    fn candidates_start_alike_converge_and_warm_trials_save_steps() {
        let runs: Vec<Relaxation> = Candidate::all()
            .iter()
            .map(|c| relaxation_scaling_with(&[0.05], c).unwrap().remove(0))
            .collect();
        for (c, r) in Candidate::all().iter().zip(&runs) {
            assert_eq!(r.discs, runs[0].discs, "{}", c.name);
            assert_eq!(r.count, SCALING_STEPS * c.iterates, "{}", c.name);
            assert_eq!(r.converged, r.count, "{}", c.name);
        }
        assert_eq!(relaxation_scaling(&[0.05]).unwrap()[0].steps, runs[0].steps);
        let by = |name: &str| {
            let i = Candidate::all().iter().position(|c| c.name.starts_with(name)).unwrap();
            runs[i].steps as f64
        };
        assert!(by("warm start") < by("default, 3 trials") * 2.0 / 3.0, "{runs:?}");
    }
}

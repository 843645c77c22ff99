//! Seeded random polydisperse packing.
//!
//! 1. Radii: the explicit list, or `N = round(0.84 L^2 / (pi E[r^2]))` draws uniform in
//!    `[r_min, r_max]` (0.84: about the jamming fraction of a polydisperse disc packing, so
//!    the final cell is close to the requested side).
//! 2. Random sequential addition, largest discs first, in a periodic square at area fraction
//!    0.35 (no overlaps), then sorted by cell for locality.
//! 3. (In `assembly`) frictionless periodic compression by `Fbar = lambda I` in 1% steps with
//!    FIRE relaxation (at most 4000 steps per stage: near jamming a frictionless packing
//!    relaxes slowly and only the final state matters), then bisection on `lambda` until the mean stress is within 2% of the
//!    confining stress; the compressed cell becomes the reference (side reported by
//!    `Assembly::area`). For a penalty boundary the configuration is cut to the square and
//!    the boundary springs' rest points are placed so the cut packing is in equilibrium,
//!    then an isotropic re-compression restores the confining stress lost with the cut
//!    contacts and becomes the reference. The final relaxation at the reference uses the full
//!    contact law. Every relaxation of the generation uses the default relaxation settings,
//!    whatever the job's (the specimen is the material: a speed knob must not change it);
//!    the assembly then relaxes its loading with the job's. 827 discs (0.0784 m^2): about
//!    0.5 s.
//!
//! ChaCha8 with the given seed: same seed, same bits, on every host.

use super::Packing;
use crate::error::{Error, Result};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Loose non-overlapping periodic arrangement (area fraction 0.35) of the requested radii.
pub fn loose(r_min: f64, r_max: f64, radii: &[f64], side: f64, seed: u64) -> Result<Packing> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut r: Vec<f64> = if radii.is_empty() {
        let er2 = (r_min * r_min + r_min * r_max + r_max * r_max) / 3.0;
        let n = (0.84 * side * side / (std::f64::consts::PI * er2)).round().max(4.0) as usize;
        (0..n).map(|_| r_min + (r_max - r_min) * rng.random::<f64>()).collect()
    } else {
        radii.to_vec()
    };
    let solid: f64 = r.iter().map(|&a| std::f64::consts::PI * a * a).sum();
    let l0 = (solid / 0.35).sqrt();
    r.sort_by(|a, b| b.total_cmp(a));
    let rmax = r[0];
    let nc = ((l0 / (2.0 * rmax)).floor() as usize).max(1);
    let cs = l0 / nc as f64;
    let mut grid: Vec<Vec<u32>> = vec![Vec::new(); nc * nc];
    let (mut x, mut y): (Vec<f64>, Vec<f64>) =
        (Vec::with_capacity(r.len()), Vec::with_capacity(r.len()));
    for k in 0..r.len() {
        let mut placed = false;
        for _ in 0..10_000 {
            let px = l0 * rng.random::<f64>();
            let py = l0 * rng.random::<f64>();
            let cx = ((px / cs) as usize).min(nc - 1) as isize;
            let cy = ((py / cs) as usize).min(nc - 1) as isize;
            let mut ok = true;
            'outer: for dy in -1..=1isize {
                for dx in -1..=1isize {
                    let c = (cy + dy).rem_euclid(nc as isize) as usize * nc
                        + (cx + dx).rem_euclid(nc as isize) as usize;
                    for &o in &grid[c] {
                        let o = o as usize;
                        let mut ddx = x[o] - px;
                        let mut ddy = y[o] - py;
                        ddx -= (ddx / l0).round() * l0;
                        ddy -= (ddy / l0).round() * l0;
                        let s = r[o] + r[k];
                        if ddx * ddx + ddy * ddy < s * s {
                            ok = false;
                            break 'outer;
                        }
                    }
                }
            }
            if ok {
                grid[cy as usize * nc + cx as usize].push(k as u32);
                x.push(px);
                y.push(py);
                placed = true;
                break;
            }
        }
        if !placed {
            return Err(Error::Packing(format!("could not place disc {k} of {}", r.len())));
        }
    }
    let mut p = Packing { x, y, r, lx: l0, ly: l0 };
    p.sort_by_cell(2.0 * rmax);
    Ok(p)
}

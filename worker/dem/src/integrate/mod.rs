//! Explicit integration (leapfrog) and the quasi-static relaxation drivers.
//!
//! Leapfrog: forces at `x_n` (histories advanced by the displacement `v_{n-1/2} dt`), then
//! `v_{n+1/2} = v_{n-1/2} + dt F_n / m`, `x_{n+1} = x_n + dt v_{n+1/2}`. The history increments
//! are exactly the incremental displacements, so below the Coulomb limits the contact springs
//! are conservative and the scheme is symplectic.

/// Cundall's local non-viscous damping.
pub mod cundall;
/// FIRE (fast inertial relaxation engine).
pub mod fire;
/// Critical time step from the stiffest oscillator.
pub mod timestep;

use crate::boundary::penalty::Penalty;
use crate::broadphase::{self, Domain, PairList};
use crate::contact::kernel::{self, Accum, Bodies, ContactSums};
use crate::contact::{Law, rolling};
use crate::error::{Error, Result};
use crate::spec::{Criterion, Driver, RelaxationSpec};
use serde::{Deserialize, Serialize};

/// Disc kinematic state (structure of arrays).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Dynamics {
    /// Centre x (m).
    pub x: Vec<f64>,
    /// Centre y (m).
    pub y: Vec<f64>,
    /// Rotation since the reference state (rad).
    pub th: Vec<f64>,
    /// Velocity x (m/s).
    pub vx: Vec<f64>,
    /// Velocity y (m/s).
    pub vy: Vec<f64>,
    /// Spin (rad/s).
    pub w: Vec<f64>,
}

impl Dynamics {
    /// Discs at rest at the given centres.
    pub fn at_rest(x: Vec<f64>, y: Vec<f64>) -> Self {
        let n = x.len();
        Self { x, y, th: vec![0.0; n], vx: vec![0.0; n], vy: vec![0.0; n], w: vec![0.0; n] }
    }

    /// Sets every velocity and spin to zero.
    pub fn stop(&mut self) {
        self.vx.fill(0.0);
        self.vy.fill(0.0);
        self.w.fill(0.0);
    }

    /// True when every entry is finite.
    pub fn is_finite(&self) -> bool {
        [&self.x, &self.y, &self.th, &self.vx, &self.vy, &self.w]
            .iter()
            .all(|v| v.iter().all(|a| a.is_finite()))
    }
}

/// The fixed part of a system: what one relaxation needs besides the state.
#[derive(Clone, Copy, Debug)]
pub struct System<'a> {
    /// Contact law.
    pub law: &'a Law,
    /// Radii.
    pub r: &'a [f64],
    /// Inverse masses (with density scaling).
    pub inv_m: &'a [f64],
    /// Inverse moments of inertia (with density scaling).
    pub inv_i: &'a [f64],
    /// Penalty springs (None for periodic).
    pub penalty: Option<&'a Penalty>,
    /// Domain for the broad phase.
    pub domain: Domain,
    /// Verlet skin (m).
    pub skin: f64,
    /// Force scale below which a mean net force counts as zero (N).
    pub force_floor: f64,
}

/// Scratch force arrays.
#[derive(Clone, Debug, Default)]
pub struct Work {
    /// Force x.
    pub fx: Vec<f64>,
    /// Force y.
    pub fy: Vec<f64>,
    /// Torque.
    pub tq: Vec<f64>,
}

/// How a relaxation ended.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RelaxReport {
    /// Steps taken.
    pub steps: u64,
    /// Final equilibrium ratio.
    pub ratio: f64,
    /// Whether the ratio went below the tolerance.
    pub converged: bool,
}

/// Computes all forces at the current state, advancing histories by `v dt`.
pub fn forces(
    sys: &System<'_>,
    d: &Dynamics,
    pairs: &mut PairList,
    work: &mut Work,
    dt: f64,
) -> ContactSums {
    let n = d.x.len();
    work.fx.clear();
    work.fx.resize(n, 0.0);
    work.fy.clear();
    work.fy.resize(n, 0.0);
    work.tq.clear();
    work.tq.resize(n, 0.0);
    let b = Bodies { x: &d.x, y: &d.y, vx: &d.vx, vy: &d.vy, w: &d.w, r: sys.r };
    let mut acc = Accum { fx: &mut work.fx, fy: &mut work.fy, tq: &mut work.tq };
    let sums = kernel::accumulate(sys.law, dt, b, pairs, &mut acc);
    if let Some(p) = sys.penalty {
        p.apply(&d.x, &d.y, &d.th, &mut work.fx, &mut work.fy, &mut work.tq);
    }
    sums
}

/// Unbalanced-force ratio: mean |net force| over mean contact normal force. With no active
/// contact the mean penalty force is the reference; a mean net force below `floor` is zero.
pub fn unbalanced_ratio(sys: &System<'_>, d: &Dynamics, work: &Work, sums: ContactSums) -> f64 {
    let n = work.fx.len().max(1);
    let mut net = 0.0;
    for k in 0..work.fx.len() {
        net += work.fx[k].hypot(work.fy[k]);
    }
    let net = net / n as f64;
    if net <= sys.force_floor {
        return 0.0;
    }
    let mut reference = if sums.active > 0 { sums.fn_sum / sums.active as f64 } else { 0.0 };
    if reference <= 0.0
        && let Some(p) = sys.penalty
    {
        let mut s = 0.0;
        for (k, &q) in p.idx.iter().enumerate() {
            let q = q as usize;
            s += (p.kf * (d.x[q] - p.xt[k])).hypot(p.kf * (d.y[q] - p.yt[k]));
        }
        reference = s / p.idx.len().max(1) as f64;
    }
    if reference > 0.0 { net / reference } else { f64::INFINITY }
}

/// Kinetic energy (translation + rotation) with the relaxation masses.
pub fn kinetic_energy(sys: &System<'_>, d: &Dynamics) -> f64 {
    let mut e = 0.0;
    for k in 0..d.x.len() {
        let v2 = d.vx[k].mul_add(d.vx[k], d.vy[k] * d.vy[k]);
        e += 0.5 * v2 / sys.inv_m[k] + 0.5 * d.w[k] * d.w[k] / sys.inv_i[k];
    }
    e
}

/// Elastic energy stored in contacts (normal, tangential, rolling) and penalty springs.
pub fn elastic_energy(sys: &System<'_>, d: &Dynamics, pairs: &PairList) -> f64 {
    let law = sys.law;
    let mut e = 0.0;
    for k in 0..pairs.len() {
        let (i, j) = (pairs.i[k] as usize, pairs.j[k] as usize);
        let mut dx = d.x[j] - d.x[i];
        let mut dy = d.y[j] - d.y[i];
        if !pairs.ox.is_empty() {
            dx += pairs.ox[k];
            dy += pairs.oy[k];
        }
        let ov = sys.r[i] + sys.r[j] - dx.hypot(dy);
        if ov > 0.0 {
            e += crate::contact::normal::energy(law.kn, ov)
                + crate::contact::tangential::energy(law.ks, pairs.fs[k])
                + rolling::energy(law.kr, pairs.hr[k]);
        }
    }
    if let Some(p) = sys.penalty {
        e += p.energy(&d.x, &d.y, &d.th);
    }
    e
}

/// Largest turn of one disc in one base step (rad) a relaxation accepts. A stable step obeys
/// `omega dt < 2`, so a disc turning by `|w| dt` oscillates with an amplitude of at least
/// `|w| dt / 2` rad: one radian per step is a half-radian rotation ringing at the stiffest
/// frequency, which no quasi-static relaxation has: a 2 mm disc (the smallest of the random
/// examples) holding all of 1 J as spin turns by 3e-3 rad per step at its 6e-7 s step.
pub const MAX_TURN_PER_STEP: f64 = 1.0;

/// True when a relaxation has blown up: a NaN or an infinity in the positions, rotations,
/// velocities, spins, forces or torques, or a disc turning faster than
/// [`MAX_TURN_PER_STEP`] per base step `dt`. The spin is checked because the equilibrium
/// ratios never see it: the torques are not in the unbalanced-force ratio, and the contact
/// moments a runaway spin loads stay capped (`mu_s F_n`, `mu_r r* F_n`), so an unstable
/// rotation (the penalty moment spring, see [`timestep::stable_penalty_masses`]) grows to
/// 1e170 rad and then NaN while the force balance reports convergence.
pub fn blown_up(d: &Dynamics, work: &Work, dt: f64) -> bool {
    let finite = |v: &[f64]| v.iter().all(|a| a.is_finite());
    let spin = d.w.iter().fold(0.0f64, |a, w| a.max(w.abs()));
    let all_finite = d.is_finite() && finite(&work.fx) && finite(&work.fy) && finite(&work.tq);
    !all_finite || spin * dt > MAX_TURN_PER_STEP
}

/// Squared rebuild distance: half the skin.
pub fn rebuild_limit2(sys: &System<'_>) -> f64 {
    0.25 * sys.skin * sys.skin
}

/// Rebuilds the pair list when `far` (some disc moved more than half the skin since the last
/// build).
pub fn maybe_rebuild(sys: &System<'_>, d: &Dynamics, pairs: &mut PairList, far: bool) {
    if far {
        *pairs = broadphase::build(&d.x, &d.y, sys.r, sys.skin, sys.domain, pairs);
    }
}

/// Relaxes `d` to equilibrium with the driver of `spec`, starting with the forces already in
/// `work` (computed at `d`, with `sums`). Base step `dt`; `tol` overrides the tolerance.
pub fn relax(
    sys: &System<'_>,
    d: &mut Dynamics,
    pairs: &mut PairList,
    work: &mut Work,
    spec: &RelaxationSpec,
    dt: f64,
    tol: f64,
) -> Result<RelaxReport> {
    relax_timed(sys, d, pairs, work, spec, dt, tol, &mut NoClock)
}

/// [`relax`] with `clock` told when each stage of a step ends: the same arithmetic (a clock
/// only reads the time), so the same result bit for bit.
#[allow(clippy::too_many_arguments)]
pub fn relax_timed(
    sys: &System<'_>,
    d: &mut Dynamics,
    pairs: &mut PairList,
    work: &mut Work,
    spec: &RelaxationSpec,
    dt: f64,
    tol: f64,
    clock: &mut impl StageClock,
) -> Result<RelaxReport> {
    clock.start();
    let mut sums = forces(sys, d, pairs, work, dt);
    clock.lap(Stage::Forces);
    let ratio_of = |d: &Dynamics, pairs: &PairList, work: &Work, sums: ContactSums| -> f64 {
        match spec.criterion {
            Criterion::UnbalancedForce => unbalanced_ratio(sys, d, work, sums),
            Criterion::KineticEnergy => {
                let ke = kinetic_energy(sys, d);
                let el = elastic_energy(sys, d, pairs);
                if ke == 0.0 {
                    // At rest: fall back on the force balance so a fresh start is not "done".
                    unbalanced_ratio(sys, d, work, sums)
                } else if el > 0.0 {
                    ke / el
                } else {
                    f64::INFINITY
                }
            }
        }
    };
    let mut fire = match spec.driver {
        // `dt` is `safety` critical steps (a divergence retry halves it, and the ceiling).
        Driver::Fire { .. } => {
            Some(fire::Fire::new(&spec.driver, dt, crate::spec::FIRE_CEILING * dt / spec.safety))
        }
        Driver::Cundall { .. } => None,
    };
    let alpha = match spec.driver {
        Driver::Cundall { alpha } => alpha,
        Driver::Fire { .. } => 0.0,
    };
    let check = spec.check_every as u64;
    let mut step = 0u64;
    loop {
        if step.is_multiple_of(check) || step >= spec.max_steps {
            let ratio = ratio_of(d, pairs, work, sums);
            // A ratio may be infinite at a finite state (no contact and no penalty force to
            // compare with); a blow-up is judged on the state and forces themselves.
            if ratio.is_nan() || blown_up(d, work, dt) {
                return Err(Error::Diverged { steps: step });
            }
            if ratio <= tol {
                return Ok(RelaxReport { steps: step, ratio, converged: true });
            }
            if step >= spec.max_steps {
                return Ok(RelaxReport { steps: step, ratio, converged: false });
            }
            clock.lap(Stage::Criterion);
        }
        let lim2 = rebuild_limit2(sys);
        let (disp2, h) = match fire.as_mut() {
            None => {
                let (xb, yb) = (&pairs.xb, &pairs.yb);
                (cundall::advance(d, work, sys.inv_m, sys.inv_i, xb, yb, alpha, dt, lim2), dt)
            }
            Some(f) => f.advance(d, work, sys.inv_m, sys.inv_i, &pairs.xb, &pairs.yb, lim2),
        };
        clock.lap(Stage::Integration);
        maybe_rebuild(sys, d, pairs, disp2);
        clock.lap(Stage::BroadPhase);
        sums = forces(sys, d, pairs, work, h);
        clock.lap(Stage::Forces);
        step += 1;
    }
}

/// The stages of a relaxation step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// The velocity and position update of the driver (Cundall or FIRE).
    Integration = 0,
    /// The check for a pair-list rebuild, and the rebuild when some disc moved more than half
    /// the skin.
    BroadPhase = 1,
    /// The contact law over the pair list, and the penalty springs.
    Forces = 2,
    /// The equilibrium ratio, every `check_every` steps.
    Criterion = 3,
}

/// Told by [`relax_timed`] when it starts and each time a stage ends.
pub trait StageClock {
    /// A relaxation starts: what came before is no stage's.
    fn start(&mut self);
    /// `stage` has just ended.
    fn lap(&mut self, stage: Stage);
}

/// The clock of every solve: does nothing, and compiles to nothing.
pub struct NoClock;

impl StageClock for NoClock {
    #[inline(always)]
    fn start(&mut self) {}
    #[inline(always)]
    fn lap(&mut self, _: Stage) {}
}

/// Wall time spent in each [`Stage`], indexed by the stage: each lap adds the time since the
/// previous lap (or since the relaxation started) to the stage that ended.
#[derive(Clone, Copy, Debug)]
pub struct StageTimes {
    last: std::time::Instant,
    /// Seconds per stage, in the order of [`Stage`].
    pub seconds: [f64; 4],
}

impl StageTimes {
    /// A clock starting now with nothing counted.
    pub fn new() -> Self {
        Self { last: std::time::Instant::now(), seconds: [0.0; 4] }
    }
}

impl Default for StageTimes {
    fn default() -> Self {
        Self::new()
    }
}

impl StageClock for StageTimes {
    fn start(&mut self) {
        self.last = std::time::Instant::now();
    }

    fn lap(&mut self, stage: Stage) {
        let now = std::time::Instant::now();
        self.seconds[stage as usize] += (now - self.last).as_secs_f64();
        self.last = now;
    }
}

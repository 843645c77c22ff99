//! Benchmarks of the two-scale coupling (issue 4): what the worker pool costs on top of the
//! DEM solves, how a 64-Gauss-point step scales from one worker to two, and what the FE side
//! costs next to the DEM side. Run through `cosdem bench ...` (release build); every figure is
//! printed, nothing here is a test.
//!
//! # 0. Coupling floor ([`rpc_floor`])
//! The same evaluate + commit cycle on stand-in assemblies that do no work: the time per
//! iteration against the batch size, fitted by `a + b n` (fixed cost per iteration, cost per
//! Gauss point). Divided by the DEM solve time it bounds the overhead from below.
//!
//! # Workload
//! Every measurement drives the same deterministic sequence: `points` hexagonal assemblies
//! (disc radius 5 mm, about `discs` discs each, default contact law and relaxation; see
//! [`hexagonal_spec`]), and `iterations` Newton-like iterations; iteration `k` (1-based) is
//! load step `k`: every assembly is relaxed to the uniaxial compressive increment
//! `e_yy = -1e-4 k` ([`target`]) and the result is committed. Building the assemblies (and
//! connecting the pool) is not timed. The sum of the relaxation steps and of the stresses of
//! all solves is recorded for every run: identical figures across modes prove the DEM work
//! was identical (the solves are deterministic), so time differences are the coupling's.
//!
//! # 1. RPC overhead ([`overhead`])
//! Three ways, interleaved in each repetition (in an order rotated from one repetition to the
//! next) so that machine noise hits all of them alike:
//! - **direct**: [`Assembly::solve`] + [`Assembly::commit`] in a plain loop on this thread
//!   (the baseline, no RPC, no serialization);
//! - **in-process**: [`Pool::in_process`] with one worker, one relaxation thread
//!   (`PoolConfig::in_process_threads = 1`), its service called directly (no transport); per iteration one `Material::evaluate`
//!   of all points (one `SolveBatch`) and one `Material::commit` (carried on the next
//!   `SolveBatch`, or a call of its own every `export_every` commits, when it also ships the
//!   committed states back to the master);
//! - **tcp**: [`Pool::connect`] to one `cosdem-worker listen --threads 1` process spawned on
//!   a free loopback port (a separate process: real sockets, real HTTP/2 framing).
//!
//! Time per Gauss point per iteration = wall time / (points x iterations).
//!
//! **Overhead (the figure: RPC overhead per Gauss point per iteration against the DEM
//! solve time)** = (wall time of the run - sum of its solves' own wall times / parallelism) /
//! (sum of the solves' own wall times / parallelism), both from the same run
//! ([`Run::in_run_overhead`]; parallelism = 1 here: one worker, one relaxation thread, so the
//! solves run one after the other). The solves' own wall times are measured inside
//! `Assembly::solve`, wherever it ran, so the numerator is everything the coupling adds and
//! does not hide behind a solve: RPC round trips, (de)serialization, thread hand-offs,
//! scheduling, the commit (and, every `export_every` commits, the states shipped back). For
//! the direct loop the same figure is the floor (the loop and `commit`). Being measured
//! within one run it is insensitive to load changes between runs; it is not insensitive to
//! the load during the run: on an oversubscribed machine every thread hand-off waits for a
//! time slice, which inflates it (see [`rpc_floor`] for the coupling's cost on its own).
//! The difference of two runs, (pool time - direct time) / direct time, per repetition, is
//! printed too, but load changes between the runs make it much noisier than the overhead
//! itself.
//!
//! # 2. Scaling ([`scaling`])
//! The step time of a job of `points` Gauss points (default 64): one iteration = one
//! evaluate of all points + commit, averaged over `iterations`, with 1 worker x 1 thread and
//! 2 workers x 1 thread, in-process and over TCP (worker processes with `--threads 1`).
//! Speedup = time(1 worker) / time(2 workers), per repetition. The same solves on 1 and 2
//! plain threads without any coupling ([`run_direct_threads`]) give the machine's own
//! ceiling: two virtual cores need not run two relaxations at twice the speed of one.
//!
//! # 3. FE versus DEM ([`fe_versus_dem`])
//! The FE cost of one Newton iteration (material evaluation with the elastic Cosserat law,
//! assembly of residual and tangent, numeric Cholesky factorization and solve: the same
//! measurement as `master/benches/newton_iteration.rs`) on the `n x n` Q8 panel with 2x2 Gauss
//! points (the paper's scene: 10 x 10 elements, 400 Gauss points), against the DEM cost of
//! one iteration of that scene: 400 x the direct time per Gauss point of `~105`-disc
//! assemblies (single core, no parallelism credited). Ratio = FE / DEM.

/// Figure 3: FE versus DEM cost per Newton iteration.
mod fe;
/// Figure 0: the coupling floor.
mod floor;
/// Figure 1: RPC overhead.
mod overhead;
/// Figure 2: scaling from one worker to two.
mod scaling;
/// The worker processes of the TCP runs.
mod workers;

pub use fe::{fe_iteration, fe_panel, fe_versus_dem};
pub use floor::rpc_floor;
pub use overhead::overhead;
pub use scaling::scaling;
pub use workers::{WorkerProcesses, worker_binary};

use cosdem_common::micro::{AssemblyRequest, BoundaryKind};
use cosdem_common::{GaussPointId, MacroDeformation, MicroResponse};
use cosdem_dem::{Assembly, AssemblySpec, PackingSpec};
use cosdem_fem::material::{Material, MaterialInput, TrialId};
use cosdem_pool::{Pool, PoolConfig};
use cosdem_worker::Dem;
use std::path::PathBuf;
use std::time::Instant;

/// Errors of the benchmarks (anything: they only report).
pub type BenchResult<T> = std::result::Result<T, Box<dyn std::error::Error + Send + Sync>>;

/// Hexagonal packing of 5 mm discs with about `discs` discs (the side is chosen from the
/// packing density; [`Assembly::disc_count`] gives the exact count), default everything else.
pub fn hexagonal_spec(discs: usize) -> AssemblySpec {
    let r = 0.005;
    let side = (discs as f64 * 2.0 * 3f64.sqrt() * r * r).sqrt() + 2.0 * r;
    AssemblySpec { packing: PackingSpec::hexagonal(r, side), ..Default::default() }
}

/// The trial deformation of iteration `k` (1-based): `e_yy = -1e-4 k`.
pub fn target(k: u64) -> MacroDeformation {
    MacroDeformation::from_gradient([[0.0, 0.0], [0.0, -1e-4 * k as f64]], 0.0, [0.0; 2])
}

/// One timed run of the workload.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Run {
    /// Wall time of all iterations (s), set-up excluded.
    pub seconds: f64,
    /// Solves done (points x iterations).
    pub solves: u64,
    /// Relaxation steps of all solves (identical across modes when the work is).
    pub relax_steps: u64,
    /// Sum of all stress components of all solves (likewise).
    pub stress_sum: f64,
    /// Sum of the solves' own wall times (`MicroDiagnostics::wall_seconds`, measured inside
    /// `Assembly::solve`, wherever it ran) (s).
    pub dem_seconds: f64,
    /// Largest number of assemblies held by one worker (pool runs; 0 for direct runs).
    pub busiest_worker: usize,
}

impl Run {
    /// Wall time per Gauss point per iteration (s).
    pub fn per_solve(&self) -> f64 {
        self.seconds / self.solves.max(1) as f64
    }

    fn record(&mut self, r: &MicroResponse) {
        self.solves += 1;
        self.relax_steps += r.diagnostics.steps;
        self.stress_sum += r.stress.iter().sum::<f64>();
        self.dem_seconds += r.diagnostics.wall_seconds;
    }

    /// Everything but the relaxations, relative to them, within this run: (wall time - sum of
    /// the solves' own wall times) / sum of the solves' own wall times. Insensitive to load
    /// changes between runs (both terms are measured in the same run).
    pub fn in_run_overhead(&self) -> f64 {
        (self.seconds - self.dem_seconds) / self.dem_seconds
    }

    fn same_work(&self, other: &Run) -> bool {
        self.relax_steps == other.relax_steps
            && self.solves == other.solves
            && (self.stress_sum - other.stress_sum).abs()
                <= 1e-9 * self.stress_sum.abs().max(other.stress_sum.abs())
    }
}

/// Minimum, median and maximum of a sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spread {
    /// Smallest value.
    pub min: f64,
    /// Median.
    pub median: f64,
    /// Largest value.
    pub max: f64,
}

impl Spread {
    /// Of a non-empty sample (NaN for an empty one).
    pub fn of(values: &[f64]) -> Spread {
        let mut v = values.to_vec();
        v.sort_by(f64::total_cmp);
        if v.is_empty() {
            return Spread { min: f64::NAN, median: f64::NAN, max: f64::NAN };
        }
        let n = v.len();
        let median = if n % 2 == 1 { v[n / 2] } else { 0.5 * (v[n / 2 - 1] + v[n / 2]) };
        Spread { min: v[0], median, max: v[n - 1] }
    }

    /// `median [min, max]` scaled by `scale`, `digits` decimals.
    pub fn show(&self, scale: f64, digits: usize) -> String {
        format!(
            "{:.d$} [{:.d$} .. {:.d$}]",
            self.median * scale,
            self.min * scale,
            self.max * scale,
            d = digits
        )
    }
}

/// The workload with direct [`Assembly::solve`] calls on this thread. Returns the run and
/// the disc count of one assembly.
pub fn run_direct(
    spec: &AssemblySpec,
    points: usize,
    iterations: u64,
) -> BenchResult<(Run, usize)> {
    let mut assemblies = (0..points).map(|_| Assembly::new(spec)).collect::<Result<Vec<_>, _>>()?;
    let discs = assemblies.first().map_or(0, Assembly::disc_count);
    let mut run = Run::default();
    let t0 = Instant::now();
    for k in 1..=iterations {
        let t = target(k);
        for a in &mut assemblies {
            let r = a.solve(&t)?;
            if !r.diagnostics.converged {
                return Err(format!("direct solve at iteration {k} did not converge").into());
            }
            run.record(&r);
            a.commit();
        }
    }
    run.seconds = t0.elapsed().as_secs_f64();
    Ok((run, discs))
}

/// The workload with direct [`Assembly::solve`] calls spread over `threads` threads (one
/// assembly per task, as a worker's relaxation pool does): what the machine itself gives
/// when two relaxations run at once, the ceiling of [`scaling`].
pub fn run_direct_threads(
    spec: &AssemblySpec,
    points: usize,
    iterations: u64,
    threads: usize,
) -> BenchResult<Run> {
    use rayon::prelude::*;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
    let mut assemblies = (0..points).map(|_| Assembly::new(spec)).collect::<Result<Vec<_>, _>>()?;
    let mut run = Run::default();
    let t0 = Instant::now();
    for k in 1..=iterations {
        let t = target(k);
        let responses = pool.install(|| {
            assemblies
                .par_iter_mut()
                .map(|a| {
                    let r = a.solve(&t)?;
                    a.commit();
                    Ok(r)
                })
                .collect::<Result<Vec<_>, cosdem_dem::Error>>()
        })?;
        for r in &responses {
            run.record(r);
        }
    }
    run.seconds = t0.elapsed().as_secs_f64();
    Ok(run)
}

/// The workload through `pool` (assemblies created first, untimed; released afterwards).
pub fn run_pool(
    pool: &mut Pool,
    spec: &AssemblySpec,
    points: usize,
    iterations: u64,
) -> BenchResult<Run> {
    let ids: Vec<GaussPointId> = (0..points as u32).map(|e| GaussPointId::new(e, 0)).collect();
    let request = AssemblyRequest {
        spec_json: serde_json::to_vec(spec)?,
        boundary: BoundaryKind::Unspecified,
        disc_count_hint: 0,
    };
    pool.create_assemblies(&ids, &request)?;
    let mut held = std::collections::BTreeMap::<String, usize>::new();
    for w in pool.assignment().into_values() {
        *held.entry(w).or_default() += 1;
    }
    let mut run = Run { busiest_worker: held.into_values().max().unwrap_or(0), ..Run::default() };
    let t0 = Instant::now();
    for k in 1..=iterations {
        let deformation = target(k);
        let inputs: Vec<MaterialInput> =
            ids.iter().map(|&gauss_point| MaterialInput { gauss_point, deformation }).collect();
        let responses = pool.evaluate(TrialId { step: k, iteration: 0 }, &inputs)?;
        for r in &responses {
            run.record(r);
        }
        pool.commit(k)?;
    }
    run.seconds = t0.elapsed().as_secs_f64();
    pool.release();
    Ok(run)
}

fn single_thread_config() -> PoolConfig {
    PoolConfig { in_process_threads: 1, ..PoolConfig::default() }
}

/// One relaxation thread per worker; no rebalancing: the assemblies are identical, so the
/// placement by disc count is already even, and timing noise on a loaded machine must not
/// migrate assemblies in the middle of a measurement.
fn bench_config(w: &Workload) -> PoolConfig {
    PoolConfig {
        export_every: w.export_every,
        defer_commits: w.defer_commits,
        rebalance_threshold: f64::INFINITY,
        ..single_thread_config()
    }
}

fn in_process_pool(workers: usize, w: &Workload) -> BenchResult<Pool> {
    Ok(Pool::in_process(workers, bench_config(w), |_| Dem)?)
}

fn tcp_pool(procs: &WorkerProcesses, w: &Workload) -> BenchResult<Pool> {
    Ok(Pool::connect(&procs.addresses, bench_config(w))?)
}

fn check_same(label: &str, a: &Run, b: &Run) -> BenchResult<()> {
    if a.same_work(b) {
        Ok(())
    } else {
        Err(format!(
            "{label}: DEM work differs ({} vs {} relaxation steps, stress sums {:e} vs {:e})",
            a.relax_steps, b.relax_steps, a.stress_sum, b.stress_sum
        )
        .into())
    }
}

/// Parameters of [`overhead`] and [`scaling`].
#[derive(Clone, Debug)]
pub struct Workload {
    /// About this many discs per assembly.
    pub discs: usize,
    /// Gauss points (assemblies).
    pub points: usize,
    /// Iterations (load steps) per run.
    pub iterations: u64,
    /// Repetitions of every measurement.
    pub repeats: usize,
    /// The `cosdem-worker` binary for the TCP runs; `None` skips them.
    pub worker_bin: Option<PathBuf>,
    /// [`PoolConfig::export_every`] of the pools (1: every commit ships every state back).
    pub export_every: u64,
    /// [`PoolConfig::defer_commits`] of the pools (false: every commit is a call of its own).
    pub defer_commits: bool,
}

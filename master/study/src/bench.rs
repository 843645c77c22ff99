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
//! **Overhead (the issue's figure: RPC overhead per Gauss point per iteration against the DEM
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

use cosdem_common::micro::{AssemblyRequest, BoundaryKind};
use cosdem_common::{GaussPointId, MacroDeformation, MicroResponse};
use cosdem_dem::{Assembly, AssemblySpec, PackingSpec};
use cosdem_fem::assembly::{Component, Field};
use cosdem_fem::element::{ElementKind, QuadratureRule};
use cosdem_fem::material::{ElasticCosserat, Material, MaterialInput, TrialId};
use cosdem_fem::mesh::Mesh;
use cosdem_fem::solve::{Dirichlet, IterationTiming, Loading, Model, Solver, SolverSettings};
use cosdem_pool::{Pool, PoolConfig};
use cosdem_worker::Dem;
use std::io::Write;
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// Errors of the benchmarks (anything: they only report).
pub type BenchResult<T> = std::result::Result<T, Box<dyn std::error::Error + Send + Sync>>;

/// Hexagonal packing of 5 mm discs with about `discs` discs (the side is chosen from the
/// packing density; [`Assembly::disc_count`] gives the exact count), default everything else.
pub fn hexagonal_spec(discs: usize) -> AssemblySpec {
    let r = 0.005;
    let side = (discs as f64 * 2.0 * 3f64.sqrt() * r * r).sqrt() + 2.0 * r;
    AssemblySpec { packing: PackingSpec::Hexagonal { radius: r, side }, ..Default::default() }
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

/// `cosdem-worker listen` processes on free loopback ports, killed (by their own handles)
/// when dropped.
pub struct WorkerProcesses {
    children: Vec<Child>,
    /// Their `127.0.0.1:port` addresses.
    pub addresses: Vec<String>,
}

impl WorkerProcesses {
    /// Starts `n` workers from the binary `bin`, each with `threads` relaxation threads, and
    /// waits until each accepts connections.
    pub fn spawn(bin: &Path, n: usize, threads: usize) -> BenchResult<WorkerProcesses> {
        let mut me = WorkerProcesses { children: Vec::new(), addresses: Vec::new() };
        for _ in 0..n {
            // A port free now; the worker binds it right away.
            let port = TcpListener::bind("127.0.0.1:0")?.local_addr()?.port();
            let addr = format!("127.0.0.1:{port}");
            let child = Command::new(bin)
                .args(["listen", "--listen", &addr, "--threads", &threads.to_string()])
                .env("RUST_LOG", "warn")
                .stdin(Stdio::null())
                .stdout(Stdio::null())
                .spawn()
                .map_err(|e| format!("starting {}: {e}", bin.display()))?;
            me.children.push(child);
            me.addresses.push(addr);
        }
        let deadline = Instant::now() + Duration::from_secs(30);
        for (i, addr) in me.addresses.iter().enumerate() {
            loop {
                if TcpStream::connect(addr).is_ok() {
                    break;
                }
                if let Some(status) = me.children[i].try_wait()? {
                    return Err(format!("worker {addr} exited: {status}").into());
                }
                if Instant::now() > deadline {
                    return Err(format!("worker {addr} did not start listening").into());
                }
                std::thread::sleep(Duration::from_millis(50));
            }
        }
        Ok(me)
    }
}

impl Drop for WorkerProcesses {
    fn drop(&mut self) {
        for c in &mut self.children {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

/// The `cosdem-worker` binary next to the running executable (both are built by
/// `cargo build --release`), unless given.
pub fn worker_binary(given: Option<&Path>) -> BenchResult<PathBuf> {
    let path = match given {
        Some(p) => p.to_path_buf(),
        None => std::env::current_exe()?
            .parent()
            .ok_or("executable without a directory")?
            .join(format!("cosdem-worker{}", std::env::consts::EXE_SUFFIX)),
    };
    if !path.is_file() {
        return Err(format!(
            "worker binary {} not found: build it (cargo build --release) or pass --worker-bin",
            path.display()
        )
        .into());
    }
    Ok(path)
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

/// Figure 1: direct versus in-process pool versus TCP pool, one worker with one thread.
/// Prints as it goes to `out`.
pub fn overhead(w: &Workload, out: &mut dyn Write) -> BenchResult<()> {
    let spec = hexagonal_spec(w.discs);
    let procs = match &w.worker_bin {
        Some(bin) => Some(WorkerProcesses::spawn(bin, 1, 1)?),
        None => None,
    };
    let (mut direct, mut inproc, mut tcp) = (Vec::new(), Vec::new(), Vec::new());
    let (mut over_in, mut over_tcp) = (Vec::new(), Vec::new());
    let mut in_run: [Vec<f64>; 3] = Default::default();
    let mut discs = 0;
    let mut steps_per_solve = 0.0;
    for rep in 0..w.repeats {
        // Rotate the order of the modes from one repetition to the next, so that no mode
        // always runs first (cold caches, frequency ramps, neighbours' load).
        let modes = if procs.is_some() { 3 } else { 2 };
        let mut runs = [None; 3];
        for j in 0..modes {
            let mode = (j + rep) % modes;
            runs[mode] = Some(match mode {
                0 => {
                    let (d, n) = run_direct(&spec, w.points, w.iterations)?;
                    discs = n;
                    d
                }
                1 => run_pool(&mut in_process_pool(1, w)?, &spec, w.points, w.iterations)?,
                _ => {
                    let p = procs.as_ref().ok_or("no worker process")?;
                    run_pool(&mut tcp_pool(p, w)?, &spec, w.points, w.iterations)?
                }
            });
        }
        for (m, r) in runs.iter().enumerate() {
            if let Some(r) = r {
                in_run[m].push(r.in_run_overhead());
            }
        }
        let d = runs[0].ok_or("direct run missing")?;
        let i = runs[1].ok_or("in-process run missing")?;
        steps_per_solve = d.relax_steps as f64 / d.solves.max(1) as f64;
        check_same("in-process", &d, &i)?;
        let mut line = format!(
            "  rep {}: direct {:.3} ms, in-process {:.3} ms ({:+.2}%)",
            rep + 1,
            d.per_solve() * 1e3,
            i.per_solve() * 1e3,
            100.0 * (i.seconds - d.seconds) / d.seconds
        );
        direct.push(d.per_solve());
        inproc.push(i.per_solve());
        over_in.push((i.seconds - d.seconds) / d.seconds);
        if let Some(t) = runs[2] {
            check_same("tcp", &d, &t)?;
            line += &format!(
                ", tcp {:.3} ms ({:+.2}%)",
                t.per_solve() * 1e3,
                100.0 * (t.seconds - d.seconds) / d.seconds
            );
            tcp.push(t.per_solve());
            over_tcp.push((t.seconds - d.seconds) / d.seconds);
        }
        writeln!(out, "{line}")?;
    }
    writeln!(
        out,
        "RPC overhead: {} Gauss points x {} iterations of {discs}-disc hexagonal assemblies \
         ({steps_per_solve:.0} relaxation steps per solve), 1 worker x 1 thread, states exported \
         every {} commits, commits {}, {} repetitions; per Gauss point per iteration, median \
         [min .. max]:",
        w.points,
        w.iterations,
        w.export_every,
        if w.defer_commits { "carried on the next SolveBatch" } else { "sent as calls" },
        w.repeats
    )?;
    writeln!(out, "  direct Assembly::solve : {} ms", Spread::of(&direct).show(1e3, 3))?;
    writeln!(
        out,
        "  in-process pool       : {} ms, overhead vs direct {} %",
        Spread::of(&inproc).show(1e3, 3),
        Spread::of(&over_in).show(100.0, 2)
    )?;
    if procs.is_some() {
        writeln!(
            out,
            "  loopback TCP pool     : {} ms, overhead vs direct {} %",
            Spread::of(&tcp).show(1e3, 3),
            Spread::of(&over_tcp).show(100.0, 2)
        )?;
    }
    writeln!(
        out,
        "  in-run: (wall - sum of the solves' own wall times) / the latter, same run: \
         direct {} %, in-process {} %{}",
        Spread::of(&in_run[0]).show(100.0, 2),
        Spread::of(&in_run[1]).show(100.0, 2),
        if procs.is_some() {
            format!(", tcp {} %", Spread::of(&in_run[2]).show(100.0, 2))
        } else {
            String::new()
        }
    )?;
    Ok(())
}

/// Figure 2: step time with 1 and 2 workers of one thread each, in-process and over TCP.
/// Prints as it goes to `out`.
pub fn scaling(w: &Workload, out: &mut dyn Write) -> BenchResult<()> {
    let spec = hexagonal_spec(w.discs);
    let discs = Assembly::new(&spec)?.disc_count();
    let mut transports: Vec<(&str, Option<[WorkerProcesses; 2]>)> =
        vec![("direct", None), ("in-process", None)];
    if let Some(bin) = &w.worker_bin {
        transports.push((
            "tcp",
            Some([WorkerProcesses::spawn(bin, 1, 1)?, WorkerProcesses::spawn(bin, 2, 1)?]),
        ));
    }
    let mut summary = Vec::new();
    for (name, procs) in &transports {
        let (mut one, mut two, mut speedup) = (Vec::new(), Vec::new(), Vec::new());
        for rep in 0..w.repeats {
            let mut step = [0.0; 2];
            let mut busiest = [0; 2];
            let mut runs = Vec::new();
            for (k, n) in [1usize, 2].into_iter().enumerate() {
                if *name == "direct" {
                    let r = run_direct_threads(&spec, w.points, w.iterations, n)?;
                    step[k] = r.seconds / w.iterations as f64;
                    busiest[k] = w.points.div_ceil(n);
                    runs.push(r);
                    continue;
                }
                let mut pool = match procs {
                    None => in_process_pool(n, w)?,
                    Some(p) => tcp_pool(&p[k], w)?,
                };
                if pool.live_workers() != n {
                    return Err(format!(
                        "{name}: {} workers live, {n} wanted",
                        pool.live_workers()
                    )
                    .into());
                }
                let r = run_pool(&mut pool, &spec, w.points, w.iterations)?;
                drop(pool);
                step[k] = r.seconds / w.iterations as f64;
                busiest[k] = r.busiest_worker;
                runs.push(r);
            }
            check_same(name, &runs[0], &runs[1])?;
            writeln!(
                out,
                "  {name} rep {}: 1 worker {:.3} s, 2 workers {:.3} s per iteration, speedup \
                 {:.2}x (busiest of 2 workers holds {} of {} assemblies)",
                rep + 1,
                step[0],
                step[1],
                step[0] / step[1],
                busiest[1],
                w.points
            )?;
            one.push(step[0]);
            two.push(step[1]);
            speedup.push(step[0] / step[1]);
        }
        summary.push(format!(
            "  {name:<10}: 1 worker {} s, 2 workers {} s, speedup {} x",
            Spread::of(&one).show(1.0, 3),
            Spread::of(&two).show(1.0, 3),
            Spread::of(&speedup).show(1.0, 2)
        ));
    }
    writeln!(
        out,
        "Scaling: step time (one evaluate of {} Gauss points + commit) of {discs}-disc \
         assemblies, workers of 1 thread each, states exported every {} commits, {} iterations x \
         {} repetitions, median [min .. max]; {} cores available; `direct` = the same solves \
         on 1 and 2 plain threads, no coupling (what this machine gives two relaxations at \
         once: the ceiling of the others):",
        w.points,
        w.export_every,
        w.iterations,
        w.repeats,
        std::thread::available_parallelism().map_or(1, |c| c.get())
    )?;
    for line in summary {
        writeln!(out, "{line}")?;
    }
    Ok(())
}

/// A loopback TCP worker serving the stand-in model inside this process (its own 2-thread
/// runtime, like a worker process's), for [`rpc_floor`].
struct LoopbackStandIn {
    _rt: tokio::runtime::Runtime,
    addr: String,
}

impl LoopbackStandIn {
    fn start() -> BenchResult<LoopbackStandIn> {
        use cosdem_worker::{StandIn, WorkerConfig, bind, serve_listener};
        let rt =
            tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build()?;
        let config =
            WorkerConfig { listen: "127.0.0.1:0".parse()?, threads: 1, ..WorkerConfig::default() };
        let listener = rt.block_on(bind(&config))?;
        let addr = listener.local_addr()?.to_string();
        rt.spawn(serve_listener(listener, config, StandIn::new(), std::future::pending()));
        Ok(LoopbackStandIn { _rt: rt, addr })
    }
}

/// One run of the workload of [`run_pool`] on stand-in assemblies that do no work: what the
/// coupling alone costs per iteration (evaluate + commit) for `points` Gauss points.
fn run_floor(pool: &mut Pool, points: usize, iterations: u64) -> BenchResult<f64> {
    let ids: Vec<GaussPointId> = (0..points as u32).map(|e| GaussPointId::new(e, 0)).collect();
    let request = AssemblyRequest {
        spec_json: br#"{"discs": 400, "work_per_disc": 0}"#.to_vec(),
        boundary: BoundaryKind::Unspecified,
        disc_count_hint: 0,
    };
    pool.create_assemblies(&ids, &request)?;
    let t0 = Instant::now();
    for k in 1..=iterations {
        let deformation = target(k);
        let inputs: Vec<MaterialInput> =
            ids.iter().map(|&gauss_point| MaterialInput { gauss_point, deformation }).collect();
        pool.evaluate(TrialId { step: k, iteration: 0 }, &inputs)?;
        pool.commit(k)?;
    }
    let per_iteration = t0.elapsed().as_secs_f64() / iterations as f64;
    pool.release();
    Ok(per_iteration)
}

/// Least-squares line `y = a + b x`.
fn fit_line(x: &[f64], y: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
    let b = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    (my - b * mx, b)
}

/// Figure 0: the coupling's own cost, without DEM work. One worker x one thread holds
/// `points` stand-in assemblies whose solve does no work (microseconds); per iteration one
/// evaluate (one SolveBatch) and one commit, as in [`overhead`]. The time per iteration
/// against the batch size, fitted by `a + b n`, splits it into the fixed cost per iteration
/// (`a`: the SolveBatch and Commit round trips, thread hand-offs) and the cost per Gauss
/// point (`b`: (de)serialization, one streamed message, one relaxation task). In-process
/// (the service called directly; and over the in-memory HTTP/2 duplex transport), and over
/// loopback TCP to a worker served by this process; commits carried on the next SolveBatch
/// (the default) and, for comparison, sent as calls of their own.
pub fn rpc_floor(
    sizes: &[usize],
    iterations: u64,
    repeats: usize,
    out: &mut dyn Write,
) -> BenchResult<()> {
    let tcp = LoopbackStandIn::start()?;
    writeln!(
        out,
        "Coupling floor: stand-in assemblies with no work, 1 worker x 1 thread, evaluate + \
         commit per iteration, {iterations} iterations x {repeats} repetitions, median [min .. max]; \
         commits carried on the next SolveBatch (the default) and sent as calls of their own:"
    )?;
    for (transport, defer_commits) in [
        ("in-process", true),
        ("in-process", false),
        ("duplex", true),
        ("tcp", true),
        ("tcp", false),
    ] {
        let config = PoolConfig {
            rebalance_threshold: f64::INFINITY,
            defer_commits,
            in_process_duplex: transport == "duplex",
            ..single_thread_config()
        };
        let label = format!("{transport}{}", if defer_commits { "" } else { " (commit calls)" });
        let mut medians = Vec::new();
        for &n in sizes {
            let mut v = Vec::new();
            for _ in 0..repeats {
                let mut pool = match transport {
                    "tcp" => Pool::connect(std::slice::from_ref(&tcp.addr), config.clone())?,
                    _ => Pool::in_process(1, config.clone(), |_| cosdem_worker::StandIn::new())?,
                };
                v.push(run_floor(&mut pool, n, iterations)?);
            }
            let s = Spread::of(&v);
            writeln!(
                out,
                "  {label:<26} {n:>4} points: {} ms per iteration, {:.1} us per point",
                s.show(1e3, 3),
                s.median / n as f64 * 1e6
            )?;
            medians.push(s.median);
        }
        let x: Vec<f64> = sizes.iter().map(|&n| n as f64).collect();
        let (a, b) = fit_line(&x, &medians);
        writeln!(
            out,
            "  {label:<26} fit: {:.3} ms fixed per iteration + {:.1} us per Gauss point",
            a * 1e3,
            b * 1e6
        )?;
    }
    Ok(())
}

/// The FE benchmark scene: the unit panel meshed `n x n` with Q8 and 2x2 Gauss points, rough
/// platens, top moved down by 1 cm, and its elastic Cosserat material (G = 1e7 Pa, nu = 0.3,
/// Gc = 5e6 Pa, lc = 0.01 m). Shared by `fe_iteration` and `benches/newton_iteration.rs`.
pub fn fe_panel(n: usize) -> cosdem_fem::Result<(Solver, ElasticCosserat)> {
    let mesh = Mesh::rectangle(ElementKind::Q8, 1.0, 1.0, n, n, [0.0, 0.0])?;
    let loading = Loading {
        dirichlet: vec![
            Dirichlet::new("bottom", Component::Ux, 0.0),
            Dirichlet::new("bottom", Component::Uy, 0.0),
            Dirichlet::new("top", Component::Ux, 0.0),
            Dirichlet::new("top", Component::Uy, -0.01),
        ],
        ..Default::default()
    };
    let model = Model { mesh, field: Field::Cosserat, rule: QuadratureRule::Gauss2x2, loading };
    let solver = Solver::new(model, SolverSettings::default())?;
    Ok((solver, ElasticCosserat::new(1e7, 0.3, 5e6, 0.01)))
}

/// The FE cost of one Newton iteration on the `n x n` Q8 panel (2x2 Gauss points, elastic
/// Cosserat material), averaged over `reps` iterations after a first one that includes the
/// symbolic analysis. Returns (free dofs, Gauss points, seconds per iteration).
pub fn fe_iteration(n: usize, reps: usize) -> BenchResult<(usize, usize, f64)> {
    let (mut solver, mut mat) = fe_panel(n)?;
    solver.iteration_work(&mut mat)?; // symbolic analysis
    let mut sum = IterationTiming::default();
    let reps = reps.max(1);
    for _ in 0..reps {
        let t = std::hint::black_box(solver.iteration_work(&mut mat)?);
        sum.material_s += t.material_s;
        sum.assembly_s += t.assembly_s;
        sum.solve_s += t.solve_s;
    }
    let per = (sum.material_s + sum.assembly_s + sum.solve_s) / reps as f64;
    let gauss = solver.gauss().per_element * solver.model().mesh.n_elements();
    Ok((solver.dofs().n_free, gauss, per))
}

/// Figure 3: FE cost of one Newton iteration of the `elements x elements` scene against the
/// DEM cost of the same iteration (Gauss points x direct time per `discs`-disc assembly).
pub fn fe_versus_dem(
    elements: usize,
    discs: usize,
    iterations: u64,
    repeats: usize,
    out: &mut dyn Write,
) -> BenchResult<()> {
    let spec = hexagonal_spec(discs);
    let (mut fe, mut dem, mut ratio) = (Vec::new(), Vec::new(), Vec::new());
    let (mut dofs, mut gauss, mut n_discs) = (0, 0, 0);
    for rep in 0..repeats {
        let (d, g, f) = fe_iteration(elements, 20)?;
        (dofs, gauss) = (d, g);
        let (run, n) = run_direct(&spec, 8, iterations)?;
        n_discs = n;
        let dem_iteration = g as f64 * run.per_solve();
        writeln!(
            out,
            "  rep {}: FE {:.3} ms, DEM {:.3} ms per point x {g} = {:.1} ms, FE/DEM {:.3}%",
            rep + 1,
            f * 1e3,
            run.per_solve() * 1e3,
            dem_iteration * 1e3,
            100.0 * f / dem_iteration
        )?;
        fe.push(f);
        dem.push(dem_iteration);
        ratio.push(f / dem_iteration);
    }
    writeln!(
        out,
        "FE versus DEM per Newton iteration, Q8 {elements}x{elements} ({dofs} free dofs, {gauss} \
         Gauss points of {n_discs} discs, DEM on one core), median [min .. max]:"
    )?;
    writeln!(
        out,
        "  FE (material + assembly + factorization + solve): {} ms",
        Spread::of(&fe).show(1e3, 3)
    )?;
    writeln!(
        out,
        "  DEM ({gauss} x direct solve)                      : {} ms",
        Spread::of(&dem).show(1e3, 1)
    )?;
    writeln!(
        out,
        "  FE / DEM                                         : {} %",
        Spread::of(&ratio).show(100.0, 3)
    )?;
    Ok(())
}

//! Shared helpers: stand-in specs, a small two-scale-like loading program driven through the
//! `Material` trait, in-process TCP workers on port 0, worker processes, and the quick example
//! job run through the run driver on in-process DEM workers.
#![allow(dead_code, missing_docs)]

use cosdem_app::output::run_dir::RunWriter;
use cosdem_app::run::{Ending, Run, RunObserver, RunOutcome, WorkerChoice};
use cosdem_common::micro::{AssemblyRequest, BoundaryKind};
use cosdem_common::{Answer, GaussPointId, MacroDeformation, MicroResponse};
use cosdem_fem::material::{Material, MaterialInput, TrialId};
use cosdem_fem::solve::{SolutionView, StepReport};
use cosdem_job::Job;
use cosdem_pool::{Pool, PoolConfig};
use cosdem_proto::v1::micro_solver_client::MicroSolverClient;
use cosdem_worker::{StandIn, WorkerConfig, bind, serve_listener};
use std::io::{BufRead, BufReader};
use std::net::SocketAddr;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::Duration;
use tonic::transport::Channel;

/// The Gauss points of the program: 4 elements x 4 points... kept small.
pub fn gauss_points() -> Vec<GaussPointId> {
    (0..4).flat_map(|e| (0..3).map(move |p| GaussPointId::new(e, p))).collect()
}

/// A stand-in spec with `discs` pretend discs and `work` fake work per disc.
pub fn spec(discs: u64, work: u64) -> AssemblyRequest {
    AssemblyRequest {
        spec_json: format!(r#"{{"discs": {discs}, "work_per_disc": {work}}}"#).into_bytes(),
        boundary: BoundaryKind::Penalty,
        disc_count_hint: discs,
    }
}

/// Disc counts vary by Gauss point so that balancing has something to do.
pub fn create(pool: &mut Pool, discs: u64, work: u64) {
    for (k, gp) in gauss_points().into_iter().enumerate() {
        pool.create_assemblies(&[gp], &spec(discs * (1 + (k as u64 % 3)), work)).unwrap();
    }
}

/// Trial kinematics of Gauss point `k` at load `lambda` and Newton iteration `it`: loading,
/// then unloading (the damage history makes the answer path-dependent).
fn target(k: usize, lambda: f64, it: u32) -> MacroDeformation {
    let a = 1.0 + 0.1 * k as f64;
    let wobble = 1e-5 / (1.0 + it as f64);
    let e = [
        0.002 * lambda * a + wobble,
        -0.001 * lambda,
        0.0005 * lambda * a,
        0.0003 * lambda,
        0.01 * lambda,
        -0.02 * lambda * a,
    ];
    MacroDeformation::from_strain(&e, 0.001 * lambda)
}

fn inputs(lambda: f64, it: u32) -> Vec<MaterialInput> {
    gauss_points()
        .into_iter()
        .enumerate()
        .map(|(k, gp)| MaterialInput { gauss_point: gp, deformation: target(k, lambda, it) })
        .collect()
}

/// Everything a run produced, with the non-deterministic wall time zeroed.
pub type Trace = Vec<(TrialId, Vec<MicroResponse>)>;

/// Called after each evaluation with (step, iteration): tests kill workers there.
pub type Hook<'a> = &'a mut dyn FnMut(u64, u32);

/// A two-scale-like program: 6 load steps, 3 Newton iterations each, a step cut (rollback)
/// in step 3, unloading in steps 5-6; commit after each step.
pub fn run_program(pool: &mut dyn Material, hook: Hook<'_>) -> Trace {
    let loads = [1.0, 2.0, 3.5, 4.0, 2.5, 1.0];
    let mut trace = Trace::new();
    let mut lambda_prev = 0.0;
    for (s, &lambda) in loads.iter().enumerate() {
        let step = s as u64 + 1;
        let mut iteration = 0;
        let mut lambda = lambda;
        if step == 3 {
            // A failed attempt: two iterations, then the solver cuts the step.
            for _ in 0..2 {
                let trial = TrialId { step, iteration };
                let r = pool.evaluate(trial, &inputs(lambda, iteration)).unwrap();
                trace.push((trial, r));
                hook(step, iteration);
                iteration += 1;
            }
            pool.rollback().unwrap();
            lambda = 0.5 * (lambda + lambda_prev);
        }
        for _ in 0..3 {
            let trial = TrialId { step, iteration };
            let r = pool.evaluate(trial, &inputs(lambda, iteration)).unwrap();
            trace.push((trial, r));
            hook(step, iteration);
            iteration += 1;
        }
        pool.commit(step).unwrap();
        lambda_prev = lambda;
    }
    for (_, rs) in trace.iter_mut() {
        for r in rs {
            r.diagnostics.wall_seconds = 0.0;
        }
    }
    trace
}

/// Asserts two traces are bit-identical (f64 compared by bits).
pub fn assert_identical(a: &Trace, b: &Trace) {
    assert_eq!(a.len(), b.len());
    for ((ta, ra), (tb, rb)) in a.iter().zip(b) {
        assert_eq!(ta, tb);
        for (x, y) in ra.iter().zip(rb) {
            let bits = |r: &MicroResponse| -> Vec<u64> {
                r.stress.iter().chain(r.tangent.iter().flatten()).map(|v| v.to_bits()).collect()
            };
            assert_eq!(bits(x), bits(y), "trial {ta:?}");
            assert_eq!(x.diagnostics, y.diagnostics, "trial {ta:?}");
        }
    }
}

/// Pool configuration for tests: short deadlines.
pub fn test_config() -> PoolConfig {
    PoolConfig {
        connect_timeout: Duration::from_secs(3),
        call_timeout: Duration::from_secs(10),
        solve_timeout: Duration::from_secs(10),
        in_process_threads: 1,
        ..PoolConfig::default()
    }
}

/// A pool of `n` in-process stand-in workers built with `config`.
pub fn standin_pool(n: usize, config: PoolConfig) -> Pool {
    Pool::in_process(n, config, |_| StandIn::new()).unwrap()
}

/// `n` worker processes (the test-worker binary, default arguments) and a pool connected to
/// them, in that order, with `config`. The processes live as long as the returned vector.
pub fn process_pool(n: usize, config: PoolConfig) -> (Vec<WorkerProcess>, Pool) {
    let procs: Vec<_> = (0..n).map(|_| WorkerProcess::start(&[], &[])).collect();
    let addrs: Vec<String> = procs.iter().map(|p| p.addr.to_string()).collect();
    let pool = Pool::connect(&addrs, config).unwrap();
    (procs, pool)
}

/// The reference run: one in-process worker.
pub fn reference(discs: u64, work: u64) -> Trace {
    let mut pool = standin_pool(1, test_config());
    create(&mut pool, discs, work);
    run_program(&mut pool, &mut |_, _| {})
}

/// A worker served by this test's tokio runtime on 127.0.0.1:0; returns its address.
pub async fn start_worker(config: WorkerConfig, model: StandIn) -> SocketAddr {
    let listener = bind(&config).await.unwrap();
    let addr = listener.local_addr().unwrap();
    tokio::spawn(serve_listener(listener, config, model, std::future::pending()));
    addr
}

/// A raw client (no token).
pub async fn client(addr: SocketAddr) -> MicroSolverClient<Channel> {
    MicroSolverClient::connect(format!("http://{addr}")).await.unwrap()
}

/// A worker process (the test-worker binary); killed on drop.
pub struct WorkerProcess {
    pub child: Child,
    pub addr: SocketAddr,
}

impl WorkerProcess {
    /// Starts `test-worker` with extra arguments and environment, on 127.0.0.1:0 unless
    /// `--listen` is among the arguments.
    pub fn start(args: &[&str], env: &[(&str, &str)]) -> WorkerProcess {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_test-worker"));
        if !args.contains(&"--listen") {
            cmd.args(["--listen", "127.0.0.1:0"]);
        }
        cmd.args(["--threads", "1"]).args(args).env_remove("COSDEM_TOKEN");
        for (k, v) in env {
            cmd.env(k, v);
        }
        let mut child = cmd.stdout(Stdio::piped()).stderr(Stdio::inherit()).spawn().unwrap();
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap()).read_line(&mut line).unwrap();
        let addr = line
            .trim()
            .strip_prefix("LISTENING ")
            .unwrap_or_else(|| panic!("worker said {line:?}"))
            .parse()
            .unwrap();
        WorkerProcess { child, addr }
    }

    /// SIGKILL.
    pub fn kill(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Drop for WorkerProcess {
    fn drop(&mut self) {
        self.kill();
    }
}

/// `examples/quick.toml` (a confined 2 x 2 panel, 16 DEM assemblies of 105 discs, 2 mm steps)
/// compressed by `displacement` (m) only, so that it takes `displacement / 2 mm` steps.
pub fn quick(displacement: f64) -> Job {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/quick.toml");
    let mut job = Job::load(&path).unwrap();
    job.loading.compression.as_mut().expect("quick compresses its panel").displacement =
        displacement;
    job
}

/// Runs `job` through the run driver without a run directory, its DEM assemblies on `workers`
/// in-process workers of `threads` relaxation threads each (0: the pool's default), telling
/// `observer` about every step. Panics unless every step converges.
pub fn run_in_process(
    job: &Job,
    workers: usize,
    threads: usize,
    observer: &mut dyn RunObserver,
) -> RunOutcome {
    let mut job = job.clone();
    job.workers.in_process = workers;
    let choice = WorkerChoice {
        addresses: Vec::new(),
        config: PoolConfig { in_process_threads: threads, ..PoolConfig::default() },
    };
    let outcome = Run::without_dir(&job).workers(choice).observer(observer).execute().unwrap();
    assert!(matches!(outcome.ending, Ending::Finished), "{:?}", outcome.ending);
    outcome
}

/// What every step of a run computed, to the bit: the reactions and the Gauss-point stresses
/// (as `f64::to_bits`), the answer kind of every Gauss point and the DEM steps its answer
/// took, in step order. For comparing runs exactly (determinism is the contract).
#[derive(Default, PartialEq, Debug)]
pub struct StepBits {
    /// The reactions of every step.
    pub reactions: Vec<u64>,
    /// The stresses of every Gauss point of every step.
    pub stresses: Vec<u64>,
    /// How every Gauss point of every step was answered.
    pub answers: Vec<Answer>,
    /// The DEM steps of all the answers.
    pub steps: u64,
}

impl RunObserver for StepBits {
    fn on_step(
        &mut self,
        r: &StepReport,
        s: &SolutionView<'_>,
        _: Option<&RunWriter>,
    ) -> cosdem_fem::Result<()> {
        for v in r.reactions.values() {
            self.reactions.extend(v.iter().map(|x| x.to_bits()));
        }
        for g in s.gauss_points {
            self.stresses.extend(g.stress.iter().map(|x| x.to_bits()));
            self.answers.push(g.diagnostics.answer);
            self.steps += g.diagnostics.steps;
        }
        Ok(())
    }
}

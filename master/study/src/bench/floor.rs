//! Figure 0: the coupling's own cost on stand-in assemblies that do no work.

use super::{BenchResult, Spread, single_thread_config, target};
use cosdem_common::GaussPointId;
use cosdem_common::micro::{AssemblyRequest, BoundaryKind};
use cosdem_fem::material::{Material, MaterialInput, TrialId};
use cosdem_pool::{Pool, PoolConfig};
use std::io::Write;
use std::time::Instant;

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
/// evaluate (one SolveBatch) and one commit, as in [`super::overhead`]. The time per iteration
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

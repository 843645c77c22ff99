//! Figure 2: the step time of a 64-Gauss-point job with one and two workers.

use super::{
    BenchResult, Spread, WorkerProcesses, Workload, check_same, hexagonal_spec, in_process_pool,
    run_direct_threads, run_pool, tcp_pool,
};
use cosdem_dem::Assembly;
use std::io::Write;

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

//! Figure 1: the RPC overhead per Gauss point per iteration (direct, in-process pool, TCP).

use super::{
    BenchResult, Spread, WorkerProcesses, Workload, check_same, hexagonal_spec, in_process_pool,
    run_direct, run_pool, tcp_pool,
};
use std::io::Write;

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

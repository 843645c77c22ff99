//! The fault-injection suite's machinery: the job, worker processes with faults, runs through
//! the run driver into run directories, their outputs compared to the undisturbed run's, and
//! the printed table of cases and outcomes.
#![allow(dead_code, missing_docs)]

use crate::common::{WorkerProcess, quick};
use cosdem_app::run::{Ending, Run, RunError, RunOutcome, WorkerChoice};
use cosdem_job::Job;
use cosdem_pool::PoolConfig;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, OnceLock};
use std::time::{Duration, Instant};

/// The quick example shortened to 4 load steps of 2 mm, a checkpoint after every step.
pub fn job() -> Job {
    let mut job = quick(0.008);
    job.output.checkpoint_every = 1;
    job
}

/// Short deadlines, so that a stopped worker is found lost in seconds; admission of lost
/// workers waited for briefly (a stopped one never answers).
pub fn config(defer_commits: bool) -> PoolConfig {
    PoolConfig {
        connect_timeout: Duration::from_secs(2),
        call_timeout: Duration::from_secs(2),
        solve_timeout: Duration::from_secs(4),
        admit_wait: Duration::from_millis(100),
        defer_commits,
        ..PoolConfig::default()
    }
}

/// What a run leaves that must not depend on faults.
#[derive(Clone, Debug, PartialEq)]
pub struct Outputs {
    pub curve: Vec<u8>,
    /// `summary.json` without `wall_seconds`, `workers` and the specimens' generation time.
    pub summary: serde_json::Value,
    pub checkpoint: Vec<u8>,
}

impl Outputs {
    pub fn read(dir: &Path) -> Outputs {
        let read = |f: &str| {
            std::fs::read(dir.join(f)).unwrap_or_else(|e| panic!("{}/{f}: {e}", dir.display()))
        };
        let mut summary: serde_json::Value = serde_json::from_slice(&read("summary.json")).unwrap();
        if let Some(m) = summary.as_object_mut() {
            m.remove("wall_seconds");
            m.remove("workers");
            if let Some(s) = m.get_mut("specimens").and_then(|s| s.as_object_mut()) {
                s.remove("seconds");
            }
        }
        Outputs { curve: read("curve.csv"), summary, checkpoint: read("checkpoint.bin") }
    }

    /// What differs from `reference`, if anything.
    pub fn differences(&self, reference: &Outputs) -> Vec<&'static str> {
        let mut d = Vec::new();
        if self.curve != reference.curve {
            d.push("curve.csv");
        }
        if self.summary != reference.summary {
            d.push("summary.json");
        }
        if self.checkpoint != reference.checkpoint {
            d.push("checkpoint.bin");
        }
        d
    }
}

/// One case: a fault (`PHASE:N:ACTION`) on worker 1 of 3, and maybe another on worker 2.
pub struct Case {
    pub fault: String,
    pub second: Option<String>,
    pub defer_commits: bool,
    /// The pool's `rebalance_threshold` (default 1.25; near 1 migrates at every step).
    pub rebalance_threshold: Option<f64>,
}

impl Case {
    pub fn one(phase: &str, n: u32, action: &str, defer_commits: bool) -> Case {
        Case {
            fault: format!("{phase}:{n}:{action}"),
            second: None,
            defer_commits,
            rebalance_threshold: None,
        }
    }

    /// Rebalances (migrates assemblies) whenever the loads differ by more than `threshold`.
    pub fn rebalancing(mut self, threshold: f64) -> Case {
        self.rebalance_threshold = Some(threshold);
        self
    }

    /// The pool's settings for the case.
    pub fn config(&self) -> PoolConfig {
        let base = config(self.defer_commits);
        PoolConfig {
            rebalance_threshold: self.rebalance_threshold.unwrap_or(base.rebalance_threshold),
            ..base
        }
    }

    /// A second fault, on worker 2.
    pub fn and(mut self, phase: &str, n: u32, action: &str) -> Case {
        self.second = Some(format!("{phase}:{n}:{action}"));
        self
    }

    pub fn name(&self) -> String {
        let mut calls = if self.defer_commits { String::new() } else { " (commit calls)".into() };
        if let Some(t) = self.rebalance_threshold {
            calls.push_str(&format!(" (rebalance threshold {t})"));
        }
        match &self.second {
            Some(f) => format!("{} then {f}{calls}", self.fault),
            None => format!("{}{calls}", self.fault),
        }
    }
}

/// Three `test-worker --model dem` processes, `faults[i]` on worker `i`, each logging to
/// `log` when it fires.
pub fn workers(faults: [Option<&str>; 3], log: &Path) -> Vec<WorkerProcess> {
    let log = log.to_string_lossy().into_owned();
    faults
        .iter()
        .map(|fault| {
            let mut args = vec!["--model", "dem", "--grace-period", "2"];
            if let Some(f) = fault {
                args.extend(["--fault", f, "--fault-log", &log]);
            }
            WorkerProcess::start(&args, &[])
        })
        .collect()
}

/// Runs `job()` into `dir` on `procs` (a resume of `dir` when `resume`).
pub fn run(
    dir: &Path,
    procs: &[WorkerProcess],
    config: PoolConfig,
    resume: bool,
) -> Result<RunOutcome, RunError> {
    let job = job();
    let choice =
        WorkerChoice { addresses: procs.iter().map(|p| p.addr.to_string()).collect(), config };
    let run = Run::new(&job, dir).workers(choice).checkpoints(true);
    if resume { run.resume(false) } else { run }.execute()
}

/// What became of a worker process: exited (how), stopped, or running.
pub fn fate(w: &mut WorkerProcess, wait: Duration) -> String {
    let t = Instant::now();
    loop {
        if let Some(status) = w.child.try_wait().unwrap() {
            use std::os::unix::process::ExitStatusExt;
            return match status.signal() {
                Some(s) => format!("killed by signal {s}"),
                None => format!("exited {}", status.code().unwrap_or(-1)),
            };
        }
        let stat = std::fs::read_to_string(format!("/proc/{}/stat", w.child.id()));
        // The state follows the command name in parentheses.
        let state = stat
            .ok()
            .and_then(|s| s.rsplit(')').next()?.split_whitespace().next().map(String::from));
        if state.as_deref() == Some("T") {
            return "stopped".into();
        }
        if t.elapsed() >= wait {
            return "running".into();
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Serializes the suite's tests (each runs three worker processes and deadlines of seconds:
/// in parallel on a small machine they would starve each other) and holds the undisturbed
/// run's outputs.
static LOCK: Mutex<()> = Mutex::new(());
static REFERENCE: OnceLock<Outputs> = OnceLock::new();

/// Where the suite's run directories go.
pub fn base() -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join("faults_workers")
}

/// A fresh run directory and fault log for `name`.
pub fn fresh(name: &str) -> (PathBuf, PathBuf) {
    let safe: String =
        name.chars().map(|c| if c.is_ascii_alphanumeric() { c } else { '-' }).collect();
    let dir = base().join(&safe);
    let log = base().join(format!("{safe}.faults"));
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_file(&log);
    std::fs::create_dir_all(base()).unwrap();
    (dir, log)
}

/// The undisturbed run on three workers (computed once).
pub fn reference() -> &'static Outputs {
    REFERENCE.get_or_init(|| {
        let (dir, log) = fresh("reference");
        let procs = workers([None; 3], &log);
        let outcome = run(&dir, &procs, config(true), false).expect("the reference run");
        assert!(matches!(outcome.ending, Ending::Finished), "reference: {:?}", outcome.ending);
        assert_eq!(outcome.steps, 4, "the reference run must reach its end");
        Outputs::read(&dir)
    })
}

/// A table of cases and outcomes; failures are collected and asserted at the end.
pub struct Suite {
    name: &'static str,
    rows: Vec<(String, String)>,
    failures: Vec<String>,
    _serial: MutexGuard<'static, ()>,
}

impl Suite {
    pub fn new(name: &'static str) -> Suite {
        let serial = LOCK.lock().unwrap_or_else(|e| e.into_inner());
        reference();
        Suite { name, rows: Vec::new(), failures: Vec::new(), _serial: serial }
    }

    fn row(&mut self, case: String, outcome: String, ok: bool) {
        if !ok {
            self.failures.push(format!("{case}: {outcome}"));
        }
        self.rows.push((case, outcome));
    }

    /// Runs `case` and checks that it finishes byte-identical to the reference.
    pub fn survives(&mut self, case: &Case) {
        let name = case.name();
        let (dir, log) = fresh(&name);
        let mut procs = workers([None, Some(&case.fault), case.second.as_deref()], &log);
        let t = Instant::now();
        let outcome = run(&dir, &procs, case.config(), false);
        let took = t.elapsed();
        let fired = std::fs::read_to_string(&log).unwrap_or_default();
        let fate = fate(&mut procs[1], Duration::from_secs(3));
        let (outcome, ok) = match outcome {
            Err(e) => (format!("setup failed: {e}"), false),
            Ok(o) if !matches!(o.ending, Ending::Finished) => {
                (format!("ended {} at step {}", o.ending.status(), o.steps), false)
            }
            Ok(_) if fired.lines().count() < 1 + usize::from(case.second.is_some()) => {
                (format!("finished, but a fault never fired (fired: {fired:?})"), false)
            }
            Ok(_) => {
                let d = Outputs::read(&dir).differences(reference());
                if d.is_empty() {
                    (format!("finished byte-identical in {took:.1?}; victim {fate}"), true)
                } else {
                    (format!("finished, {} differ; victim {fate}", d.join(", ")), false)
                }
            }
        };
        self.row(name, outcome, ok);
    }

    /// Every worker hit by `phase:n:action`: the run must fail naming the loss, its directory
    /// keep the committed steps, and a resume on new workers finish byte-identical.
    pub fn all_lost_then_resume(&mut self, phase: &str, n: u32, action: &str) {
        let fault = format!("{phase}:{n}:{action}");
        let name = format!("{fault} on every worker");
        let (dir, log) = fresh(&name);
        let procs = workers([Some(fault.as_str()); 3], &log);
        let outcome = run(&dir, &procs, config(true), false);
        drop(procs);
        let (failed, ok) = match &outcome {
            Ok(o) => match &o.ending {
                Ending::Failed(e) if e.to_string().contains("lost") => {
                    (format!("failed after {} committed steps: {e}", o.steps), true)
                }
                e => (format!("ended {} (not a failure naming the loss)", e.status()), false),
            },
            Err(e) if e.to_string().contains("lost") => (format!("setup failed: {e}"), true),
            Err(e) => (format!("setup failed, not naming the loss: {e}"), false),
        };
        self.row(name.clone(), failed, ok);
        if !ok {
            return;
        }
        let committed = std::fs::read_to_string(dir.join("summary.json")).unwrap_or_default();
        let resume = "  then resumed on 3 new workers".to_string();
        if !dir.join("checkpoint.bin").exists() {
            self.row(resume, format!("no checkpoint to resume from ({committed})"), false);
            return;
        }
        let procs = workers([None; 3], &log);
        let outcome = run(&dir, &procs, config(true), true);
        let (outcome, ok) = match outcome {
            Err(e) => (format!("resume refused: {e}"), false),
            Ok(o) if !matches!(o.ending, Ending::Finished) => {
                (format!("ended {} at step {}", o.ending.status(), o.steps), false)
            }
            Ok(_) => {
                let d = Outputs::read(&dir).differences(reference());
                if d.is_empty() {
                    ("finished byte-identical".into(), true)
                } else {
                    (format!("finished, {} differ", d.join(", ")), false)
                }
            }
        };
        self.row(resume, outcome, ok);
    }

    /// Prints the table, then fails if any case did.
    pub fn print(&self) {
        let width = self.rows.iter().map(|(c, _)| c.len()).max().unwrap_or(0);
        println!("\nfault-injection suite, workers ({}): case -> outcome", self.name);
        for (case, outcome) in &self.rows {
            println!("  {case:width$}  {outcome}");
        }
        assert!(self.failures.is_empty(), "failed cases:\n{}", self.failures.join("\n"));
    }
}

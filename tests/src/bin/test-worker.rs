//! Test-only worker binary for the multi-process tests: the stand-in model (default) or the
//! real DEM (`--model dem`), the real binary's `listen` arguments, and faults to inject.
//! Prints `LISTENING <addr>` on stdout once bound. (The real binary is `cosdem-worker`.)
//!
//! `--fault PHASE:N:ACTION` (repeatable) fires when the worker receives its `N`-th call of
//! `PHASE` (create, solve, commit, export, import, rollback: CreateAssemblies, SolveBatch,
//! Commit, ExportState, ImportState, Rollback), before serving it: `kill` (SIGKILL itself),
//! `term` (SIGTERM itself: the call in flight finishes, new ones are refused, it exits within
//! `--grace-period`), `stop` (SIGSTOP itself: silent until its caller's deadline) or
//! `garbage` (serves the call and answers bytes that are not a gRPC message).

use clap::Parser;
use cosdem_worker::{
    CallHook, CallVerdict, Dem, ServeOptions, StandIn, StandInOptions, WorkerConfig, bind,
    serve_listener_with, shutdown_signal,
};
use cosdem_worker_cli::ListenArgs;
use std::io::Write;
use std::str::FromStr;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

/// The phases a fault can fire in, by the gRPC method that carries them.
const PHASES: [(&str, &str); 6] = [
    ("create", "CreateAssemblies"),
    ("solve", "SolveBatch"),
    ("commit", "Commit"),
    ("export", "ExportState"),
    ("import", "ImportState"),
    ("rollback", "Rollback"),
];

/// What a fault does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Action {
    Kill,
    Term,
    Stop,
    Garbage,
}

/// `PHASE:N:ACTION`.
#[derive(Clone, Debug)]
struct Fault {
    /// Index into [`PHASES`].
    phase: usize,
    /// Which call of that phase (from 1).
    n: u64,
    action: Action,
}

impl FromStr for Fault {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let parts: Vec<&str> = s.split(':').collect();
        let [phase, n, action] = parts[..] else {
            return Err(format!("--fault {s:?}: expected PHASE:N:ACTION"));
        };
        let phase = PHASES.iter().position(|(p, _)| *p == phase).ok_or_else(|| {
            let names: Vec<_> = PHASES.iter().map(|(p, _)| *p).collect();
            format!("--fault {s:?}: phase {phase:?} is not one of {names:?}")
        })?;
        let n = n
            .parse::<u64>()
            .ok()
            .filter(|n| *n >= 1)
            .ok_or_else(|| format!("--fault {s:?}: N = {n:?} must be a call number from 1"))?;
        let action = match action {
            "kill" => Action::Kill,
            "term" => Action::Term,
            "stop" => Action::Stop,
            "garbage" => Action::Garbage,
            _ => {
                return Err(format!(
                    "--fault {s:?}: action {action:?} is not one of kill, term, stop, garbage"
                ));
            }
        };
        Ok(Fault { phase, n, action })
    }
}

/// The model to serve.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum Model {
    /// The stand-in (cheap, with `--hang-after`).
    Standin,
    /// The real DEM assemblies.
    Dem,
}

/// Test worker.
#[derive(Parser)]
struct Args {
    #[command(flatten)]
    listen: ListenArgs,
    /// The model served.
    #[arg(long, value_enum, default_value = "standin")]
    model: Model,
    /// After this many solves, every further solve hangs for `--hang-secs` (stand-in only).
    #[arg(long)]
    hang_after: Option<u64>,
    /// How long a hanging solve sleeps.
    #[arg(long, default_value_t = 60)]
    hang_secs: u64,
    /// PHASE:N:ACTION: a fault at the N-th call of PHASE (see the file's note). Repeatable.
    #[arg(long)]
    fault: Vec<Fault>,
    /// File a line `PHASE:N:ACTION` is appended to when a fault fires (before it acts).
    #[arg(long)]
    fault_log: Option<std::path::PathBuf>,
}

/// Sends `signal` to this process (through kill(1): the test crate has no libc).
fn signal_self(signal: &str) {
    let pid = std::process::id().to_string();
    if let Err(e) = std::process::Command::new("kill").args([signal, &pid]).status() {
        eprintln!("test-worker: kill {signal} {pid}: {e}");
    }
}

/// The hook that counts the calls of each phase and fires the faults.
fn hook(faults: Vec<Fault>, log: Option<std::path::PathBuf>) -> CallHook {
    let counts: Arc<[AtomicU64; PHASES.len()]> = Arc::new(Default::default());
    Arc::new(move |path: &str| {
        let method = path.rsplit('/').next().unwrap_or("");
        let Some(phase) = PHASES.iter().position(|(_, m)| *m == method) else {
            return CallVerdict::Serve;
        };
        let n = counts[phase].fetch_add(1, Ordering::SeqCst) + 1;
        let mut verdict = CallVerdict::Serve;
        for f in faults.iter().filter(|f| f.phase == phase && f.n == n) {
            let line = format!("{}:{n}:{:?}", PHASES[phase].0, f.action).to_lowercase();
            eprintln!("test-worker {}: fault {line}", std::process::id());
            if let Some(log) = &log {
                let appended = std::fs::OpenOptions::new()
                    .create(true)
                    .append(true)
                    .open(log)
                    .and_then(|mut file| writeln!(file, "{line}"));
                if let Err(e) = appended {
                    eprintln!("test-worker: fault log {}: {e}", log.display());
                }
            }
            match f.action {
                Action::Kill => {
                    signal_self("-KILL");
                    loop {
                        std::thread::sleep(Duration::from_secs(1));
                    }
                }
                Action::Term => signal_self("-TERM"),
                Action::Stop => signal_self("-STOP"),
                Action::Garbage => verdict = CallVerdict::Garbage,
            }
        }
        verdict
    })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args = Args::parse();
    let mut options: ServeOptions = args.listen.serve_options()?;
    if !args.fault.is_empty() {
        options.hook = Some(hook(args.fault.clone(), args.fault_log.clone()));
    }
    let config: WorkerConfig = args.listen.try_into()?;
    let runtime =
        tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build()?;
    let served = runtime.block_on(async {
        // Handlers first: the test may send SIGTERM as soon as it reads the address.
        let shutdown = shutdown_signal();
        let listener = bind(&config).await?;
        println!("LISTENING {}", listener.local_addr()?);
        std::io::stdout().flush()?;
        match args.model {
            Model::Standin => {
                let model = StandIn::with_options(StandInOptions {
                    hang_after_solves: args.hang_after,
                    hang_for: Duration::from_secs(args.hang_secs),
                });
                serve_listener_with(listener, config, model, shutdown, options).await?;
            }
            Model::Dem => serve_listener_with(listener, config, Dem, shutdown, options).await?,
        }
        Ok::<_, Box<dyn std::error::Error>>(())
    });
    // Past the grace period, calls may still run: exit without waiting for them.
    runtime.shutdown_background();
    served
}

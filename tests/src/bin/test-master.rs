//! Test-only master: `cosdem run` through the run driver (in-process workers, checkpoints,
//! snapshots) that SIGKILLs itself, or pauses, at a chosen phase of a chosen step, for the
//! fault-injection suite (`tests/tests/faults_master.rs`). The real binary is `cosdem`.
//!
//! ```text
//! test-master JOB OUT [--resume | --overwrite] [--fault PHASE:STEP:K:ACTION]
//! ```
//! PHASE: `setup` (building the material), `solve` (the K-th evaluation of step STEP, from 1),
//! `commit` (the commit of step STEP), `recorded` (step STEP's outputs written, its checkpoint
//! not yet). ACTION: `kill` (SIGKILL itself) or `pause` (sleep 60 s, holding the directory).

use cosdem_app::output::run_dir::RunWriter;
use cosdem_app::run::{Ending, Run, RunObserver, WorkerChoice, material_for};
use cosdem_common::micro::{AssemblyState, MicroSnapshot};
use cosdem_common::{GaussPointId, MicroResponse};
use cosdem_fem::material::{Material, MaterialError, MaterialInput, TrialId};
use cosdem_fem::solve::{SolutionView, StepReport};
use cosdem_job::Job;
use std::path::PathBuf;

/// Where the fault strikes.
#[derive(Clone, Copy, PartialEq)]
enum Phase {
    Setup,
    Solve,
    Commit,
    Recorded,
}

#[derive(Clone, Copy)]
struct Fault {
    phase: Phase,
    step: u64,
    k: u64,
    pause: bool,
}

impl Fault {
    fn parse(s: &str) -> Fault {
        let p: Vec<&str> = s.split(':').collect();
        assert_eq!(p.len(), 4, "--fault PHASE:STEP:K:ACTION, got {s:?}");
        let phase = match p[0] {
            "setup" => Phase::Setup,
            "solve" => Phase::Solve,
            "commit" => Phase::Commit,
            "recorded" => Phase::Recorded,
            other => panic!("unknown phase {other:?}"),
        };
        let pause = match p[3] {
            "kill" => false,
            "pause" => true,
            other => panic!("unknown action {other:?}"),
        };
        Fault { phase, step: p[1].parse().unwrap(), k: p[2].parse().unwrap(), pause }
    }

    /// Strikes: SIGKILL (no destructor, no flush: as `kill -9`) or a pause.
    fn strike(&self) {
        eprintln!("FAULT");
        if self.pause {
            std::thread::sleep(std::time::Duration::from_secs(60));
            return;
        }
        let pid = std::process::id().to_string();
        let _ = std::process::Command::new("kill").args(["-KILL", &pid]).status();
        std::thread::sleep(std::time::Duration::from_secs(60));
        unreachable!("SIGKILL did not arrive");
    }
}

/// The job's material with the fault's solve and commit phases.
struct Faulty {
    inner: Box<dyn Material>,
    fault: Option<Fault>,
    /// The step being solved (the last committed one + 1) and its evaluations so far.
    step: u64,
    evaluations: u64,
}

impl Material for Faulty {
    fn evaluate(
        &mut self,
        trial: TrialId,
        inputs: &[MaterialInput],
    ) -> Result<Vec<MicroResponse>, MaterialError> {
        self.evaluations += 1;
        if let Some(f) = self.fault.filter(|f| f.phase == Phase::Solve)
            && (f.step, f.k) == (self.step, self.evaluations)
        {
            f.strike();
        }
        self.inner.evaluate(trial, inputs)
    }

    fn commit(&mut self, step: u64) -> Result<(), MaterialError> {
        if let Some(f) = self.fault.filter(|f| f.phase == Phase::Commit && f.step == step) {
            f.strike();
        }
        self.inner.commit(step)?;
        self.step = step + 1;
        self.evaluations = 0;
        Ok(())
    }

    fn rollback(&mut self) -> Result<(), MaterialError> {
        self.inner.rollback()
    }

    fn is_symmetric(&self) -> bool {
        self.inner.is_symmetric()
    }

    fn committed_states(&mut self) -> Result<Option<Vec<AssemblyState>>, MaterialError> {
        self.inner.committed_states()
    }

    /// The inner material was built from these very states (as `cosdem run --resume` builds
    /// its pool from the checkpoint): only the step is taken.
    fn restore_states(&mut self, states: Vec<AssemblyState>) -> Result<(), MaterialError> {
        self.step = states.first().map_or(0, |s| s.committed_step) + 1;
        Ok(())
    }

    fn snapshot(&mut self, id: GaussPointId) -> Result<Option<MicroSnapshot>, MaterialError> {
        self.inner.snapshot(id)
    }
}

/// Strikes once step STEP is recorded (curve row, VTK, snapshots, summary written), before
/// its checkpoint.
struct Recorded(Option<Fault>);

impl RunObserver for Recorded {
    fn on_step(
        &mut self,
        r: &StepReport,
        _: &SolutionView<'_>,
        _: Option<&RunWriter>,
    ) -> cosdem_fem::Result<()> {
        if let Some(f) = self.0.filter(|f| f.phase == Phase::Recorded && f.step == r.step) {
            f.strike();
        }
        Ok(())
    }
}

fn main() {
    let mut args = std::env::args().skip(1);
    let job = Job::load(&PathBuf::from(args.next().expect("JOB"))).unwrap();
    let out = PathBuf::from(args.next().expect("OUT"));
    let (mut resume, mut overwrite, mut fault) = (false, false, None);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--resume" => resume = true,
            "--overwrite" => overwrite = true,
            "--fault" => fault = Some(Fault::parse(&args.next().expect("--fault value"))),
            other => panic!("unknown argument {other:?}"),
        }
    }
    let mut observer = Recorded(fault);
    let job_ref = &job;
    let saved = resume.then(|| {
        let path = out.join(cosdem_app::checkpoint::FILE);
        cosdem_app::checkpoint::Checkpoint::read(&path).map(|c| c.assembly_states())
    });
    let saved = match saved.transpose() {
        Ok(s) => s,
        Err(e) => {
            eprintln!("ERROR {e}");
            std::process::exit(2);
        }
    };
    let mut run = Run::new(&job, &out)
        .checkpoints(true)
        .snapshots(true)
        .material(move |ids| {
            if let Some(f) = fault.filter(|f| f.phase == Phase::Setup) {
                f.strike();
            }
            let mesh = job_ref.build_mesh()?;
            let inner =
                material_for(job_ref, &WorkerChoice::default(), &mesh, ids, saved)?.material;
            Ok(Box::new(Faulty { inner, fault, step: 1, evaluations: 0 }))
        })
        .overwrite(overwrite)
        .observer(&mut observer);
    if resume {
        run = run.resume(false);
    }
    match run.execute() {
        Ok(o) if matches!(o.ending, Ending::Finished) => println!("FINISHED {}", o.steps),
        Ok(o) => {
            eprintln!("ENDED {:?}", o.ending);
            std::process::exit(1);
        }
        Err(e) => {
            eprintln!("ERROR {e}");
            std::process::exit(2);
        }
    }
}

//! Test-only worker binary serving the stand-in model, for the multi-process tests.
//! Prints `LISTENING <addr>` on stdout once bound. (The real binary is `cosdem-worker`.)

use clap::Parser;
use cosdem_worker::{StandIn, StandInOptions, WorkerConfig, bind, serve_listener, shutdown_signal};
use cosdem_worker_cli::ListenArgs;
use std::io::Write;
use std::time::Duration;

/// Stand-in worker for tests.
#[derive(Parser)]
struct Args {
    #[command(flatten)]
    listen: ListenArgs,
    /// After this many solves, every further solve hangs for `--hang-secs`.
    #[arg(long)]
    hang_after: Option<u64>,
    /// How long a hanging solve sleeps.
    #[arg(long, default_value_t = 60)]
    hang_secs: u64,
}

#[tokio::main(flavor = "multi_thread", worker_threads = 2)]
async fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args = Args::parse();
    let config: WorkerConfig = args.listen.try_into()?;
    let model = StandIn::with_options(StandInOptions {
        hang_after_solves: args.hang_after,
        hang_for: Duration::from_secs(args.hang_secs),
    });
    // Handlers first: the test may send SIGTERM as soon as it reads the address.
    let shutdown = shutdown_signal();
    let listener = bind(&config).await?;
    println!("LISTENING {}", listener.local_addr()?);
    std::io::stdout().flush()?;
    serve_listener(listener, config, model, shutdown).await?;
    Ok(())
}

//! The TCP runs' worker processes: `cosdem-worker listen` on free loopback ports.

use super::BenchResult;
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

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

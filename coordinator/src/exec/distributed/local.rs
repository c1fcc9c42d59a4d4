//! Worker processes on this machine (`--local-workers N`): the same binary run as
//! `yat worker` on a free loopback port. They are killed when dropped, and since each watches
//! its stdin (a pipe from us) they also exit when the coordinator dies without dropping them.

use std::io::{BufRead, BufReader};
use std::process::{Child, ChildStdin, ChildStdout, Command, ExitStatus, Stdio};
use std::sync::{mpsc, Arc, Mutex};
use std::time::Duration;

use anyhow::{bail, Context};

/// How long a starting worker may take to print its address.
const STARTUP_TIMEOUT: Duration = Duration::from_secs(30);

/// The local workers of a configuration: started by its first render and kept for every render
/// after it (the frames of a sequence), so their caches of the scene's files stay warm; stopped
/// when the configuration is dropped.
#[derive(Default)]
pub struct LocalWorkers {
    count: usize,
    started: Mutex<Vec<Arc<LocalWorker>>>,
}

impl LocalWorkers {
    pub fn new(count: usize) -> Self {
        Self {
            count,
            started: Mutex::default(),
        }
    }

    pub fn count(&self) -> usize {
        self.count
    }

    /// The workers, started on the first call.
    pub fn get(&self) -> anyhow::Result<Vec<Arc<LocalWorker>>> {
        let mut started = self
            .started
            .lock()
            .expect("no panic while starting workers");
        if started.is_empty() && self.count > 0 {
            let cores = crate::cpus::threads_or_usable_cpus(None, "local workers");
            *started = LocalWorker::spawn_all(self.count, cores)?
                .into_iter()
                .map(Arc::new)
                .collect();
        }
        Ok(started.clone())
    }
}

pub struct LocalWorker {
    pub address: String,
    pub token: String,
    child: Mutex<Child>,
    /// Held open: closing it tells the worker to exit; the worker writes nothing after its
    /// first line, so the unread pipe never fills.
    _stdin: ChildStdin,
    _stdout: BufReader<ChildStdout>,
}

impl LocalWorker {
    /// Starts `count` workers sharing `cores` cores between them.
    pub fn spawn_all(count: usize, cores: usize) -> anyhow::Result<Vec<LocalWorker>> {
        let exe = std::env::current_exe().context("cannot find the yat executable")?;
        let threads = (cores / count).max(1);
        // Loopback ports are open to every local user: each render's workers get a fresh token.
        let token = random_token()?;
        (0..count)
            .map(|i| {
                let mut child = Command::new(&exe)
                    .args(["worker", "--listen", "127.0.0.1:0", "--exit-with-stdin"])
                    .args(["--threads", &threads.to_string()])
                    .env("YAT_TOKEN", &token)
                    .stdin(Stdio::piped())
                    .stdout(Stdio::piped())
                    .stderr(Stdio::inherit())
                    .spawn()
                    .with_context(|| format!("cannot start local worker {i}"))?;
                let stdin = child.stdin.take().expect("piped");
                let stdout = child.stdout.take().expect("piped");
                let mut worker = LocalWorker {
                    address: String::new(),
                    token: token.clone(),
                    child: Mutex::new(child),
                    _stdin: stdin,
                    _stdout: BufReader::new(stdout),
                };
                worker.address = worker.read_address()?;
                Ok(worker)
            })
            .collect()
    }

    /// Reads the `listening on ADDR` line, without waiting forever on a worker that hangs.
    fn read_address(&mut self) -> anyhow::Result<String> {
        let (tx, rx) = mpsc::channel();
        let stdout = &mut self._stdout;
        let line = std::thread::scope(|scope| {
            scope.spawn(move || {
                let mut line = String::new();
                let _ = tx.send(stdout.read_line(&mut line).map(|_| line));
            });
            let line = rx.recv_timeout(STARTUP_TIMEOUT);
            if line.is_err() {
                // Unblocks the reader thread so the scope can end.
                let _ = self.child.lock().unwrap().kill();
            }
            line
        });
        let line = match line {
            Ok(Ok(line)) => line,
            Ok(Err(e)) => bail!("cannot read a local worker's address: {e}"),
            Err(_) => bail!("a local worker did not start within {STARTUP_TIMEOUT:?}"),
        };
        match line.trim().strip_prefix("listening on ") {
            Some(address) => Ok(address.to_string()),
            None => bail!(
                "a local worker did not start ({})",
                self.exit_status()
                    .map_or_else(|| format!("it printed {line:?}"), |s| s.to_string())
            ),
        }
    }

    /// The exit status, once the process has ended.
    pub fn exit_status(&self) -> Option<ExitStatus> {
        self.child.lock().unwrap().try_wait().ok().flatten()
    }
}

impl Drop for LocalWorker {
    fn drop(&mut self) {
        let mut child = self.child.lock().unwrap();
        let _ = child.kill();
        let _ = child.wait();
    }
}

/// 128 bits from the operating system's random source, as hex: a secret no other local user
/// can guess.
fn random_token() -> anyhow::Result<String> {
    let mut bytes = [0u8; 16];
    getrandom::fill(&mut bytes)
        .map_err(|e| anyhow::anyhow!("cannot draw a token from the system's random source: {e}"))?;
    Ok(bytes.iter().map(|b| format!("{b:02x}")).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_are_fresh_hex_secrets() {
        let tokens: std::collections::HashSet<String> =
            (0..64).map(|_| random_token().unwrap()).collect();
        assert_eq!(tokens.len(), 64);
        assert!(tokens
            .iter()
            .all(|t| t.len() == 32 && t.bytes().all(|b| b.is_ascii_hexdigit())));
    }
}

//! A worker against a stranger on loopback, as processes: `yat worker` under a descriptor
//! limit of 256 with its standard error on a pipe nobody reads (a supervisor's full log pipe),
//! a stranger on 127.0.0.2-9 holding as many connections as it can and reconnecting as they
//! close, and a coordinator rendering through that worker meanwhile: the image is the
//! in-process bytes, the render takes a stated time at most, and after the attack a token
//! holder is served at once.

use std::io::Read;
use std::net::SocketAddr;
use std::os::fd::AsRawFd;
use std::os::unix::process::CommandExt;
use std::process::{ChildStderr, Stdio};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use tokio::io::AsyncReadExt;

use crate::util::*;

const TOKEN: &str = "correct horse";
/// The worker's descriptor limit, soft and hard.
const DESCRIPTORS: u64 = 256;
/// Connections the stranger tries to hold at once.
const HOLDERS: usize = 600;
/// How much longer than an unattacked render the attacked one may take. The stranger's
/// reconnect loop shares the machine's cores with the worker and the coordinator, so part of
/// the cost is the test's own.
const SLOWDOWN: f64 = 3.0;
const SLOWDOWN_GRACE: Duration = Duration::from_secs(10);

/// A `yat worker` with the token, limited to [`DESCRIPTORS`] descriptors, logging everything
/// (debug) to a pipe.
fn limited_worker() -> Worker {
    let mut command = Worker::command("127.0.0.1:0", &["--token", TOKEN]);
    command.stderr(Stdio::piped()).env("YAT_LOG", "debug");
    // SAFETY: only setrlimit runs between fork and exec, on a struct on the stack.
    unsafe {
        command.pre_exec(|| {
            let limit = libc::rlimit {
                rlim_cur: DESCRIPTORS,
                rlim_max: DESCRIPTORS,
            };
            if libc::setrlimit(libc::RLIMIT_NOFILE, &limit) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    Worker::spawn(command)
}

/// Bytes waiting in the pipe.
fn pipe_bytes(pipe: &ChildStderr) -> usize {
    let mut waiting: libc::c_int = 0;
    // SAFETY: FIONREAD writes one int, given here, for the pipe's open descriptor.
    let status = unsafe { libc::ioctl(pipe.as_raw_fd(), libc::FIONREAD, &mut waiting) };
    assert_eq!(status, 0, "{}", std::io::Error::last_os_error());
    waiting as usize
}

/// The stranger: [`HOLDERS`] tasks, each connecting from one of 127.0.0.2-9, holding the
/// connection until the worker closes it, and connecting again at once.
struct Stranger {
    stop: tokio::sync::watch::Sender<bool>,
    thread: std::thread::JoinHandle<()>,
    connections: Arc<AtomicU64>,
    held: Arc<AtomicU64>,
    most_held: Arc<AtomicU64>,
}

impl Stranger {
    fn attack(address: SocketAddr) -> Self {
        let (stop, stopped) = tokio::sync::watch::channel(false);
        let connections = Arc::new(AtomicU64::new(0));
        let held = Arc::new(AtomicU64::new(0));
        let most_held = Arc::new(AtomicU64::new(0));
        let counters = (connections.clone(), held.clone(), most_held.clone());
        let thread = std::thread::spawn(move || {
            let runtime = tokio::runtime::Builder::new_current_thread()
                .enable_all()
                .build()
                .unwrap();
            runtime.block_on(async move {
                let tasks: Vec<_> = (0..HOLDERS)
                    .map(|i| {
                        let source: SocketAddr =
                            format!("127.0.0.{}:0", 2 + i % 8).parse().unwrap();
                        let mut stopped = stopped.clone();
                        let (connections, held, most_held) = counters.clone();
                        tokio::spawn(async move {
                            while !*stopped.borrow() {
                                let socket = tokio::net::TcpSocket::new_v4().unwrap();
                                socket.bind(source).unwrap();
                                let Ok(mut stream) = socket.connect(address).await else {
                                    tokio::time::sleep(Duration::from_millis(10)).await;
                                    continue;
                                };
                                connections.fetch_add(1, Ordering::Relaxed);
                                let now = held.fetch_add(1, Ordering::Relaxed) + 1;
                                most_held.fetch_max(now, Ordering::Relaxed);
                                let mut sink = [0u8; 1024];
                                loop {
                                    tokio::select! {
                                        read = stream.read(&mut sink) => match read {
                                            Ok(0) | Err(_) => break,
                                            Ok(_) => {}
                                        },
                                        _ = stopped.changed() => break,
                                    }
                                }
                                held.fetch_sub(1, Ordering::Relaxed);
                            }
                        })
                    })
                    .collect();
                for task in tasks {
                    task.await.unwrap();
                }
            });
        });
        Self {
            stop,
            thread,
            connections,
            held,
            most_held,
        }
    }

    /// Stops; the connections made in all and the most held at once.
    fn stop(self) -> (u64, u64) {
        self.stop.send(true).unwrap();
        self.thread.join().unwrap();
        assert_eq!(self.held.load(Ordering::Relaxed), 0);
        (
            self.connections.load(Ordering::Relaxed),
            self.most_held.load(Ordering::Relaxed),
        )
    }
}

#[test]
fn a_stranger_holding_connections_costs_a_token_holder_little_and_a_full_log_pipe_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path());
    let reference = dir.path().join("in-process.png");
    assert_success(&render(&scene, &reference, &["--quiet"]));
    let expected = image_bytes(&reference);
    let through = |worker: &Worker, name: &str| {
        let out = dir.path().join(name);
        let started = Instant::now();
        let output = render(
            &scene,
            &out,
            // Without a result for 30 s the render fails instead of waiting for good.
            &[
                "--workers",
                &worker.address,
                "--token",
                TOKEN,
                "--quiet",
                "--timeout",
                "30",
            ],
        );
        let took = started.elapsed();
        assert_success(&output);
        assert!(image_bytes(&out) == expected, "{name}: other bytes");
        took
    };

    let calm = limited_worker();
    let unattacked = through(&calm, "unattacked.png");
    drop(calm);

    let mut worker = limited_worker();
    let stderr = worker.take_stderr().unwrap();
    let address: SocketAddr = worker.address.parse().unwrap();
    let stranger = Stranger::attack(address);
    // The worker's debug lines about the stranger's connections fill its log pipe (asserted
    // after the render).
    let filling = Instant::now();
    while pipe_bytes(&stderr) < 60_000 && filling.elapsed() < Duration::from_secs(10) {
        std::thread::sleep(Duration::from_millis(20));
    }
    let attacked = through(&worker, "attacked.png");
    let (connections, most_held) = stranger.stop();
    let in_pipe = pipe_bytes(&stderr);

    let released = Instant::now();
    let stats = worker.stats(Some(TOKEN));
    let served = released.elapsed();
    assert_eq!(stats.units_done, 32, "the attacked render's units");
    worker.kill();
    let mut log = String::new();
    let mut stderr = stderr;
    stderr.read_to_string(&mut log).unwrap();
    // "serving N connections at most, not 256: the descriptor limit is 256 with ..."
    let start = log
        .lines()
        .find(|l| l.contains("connections at most, not 256"))
        .unwrap_or_else(|| panic!("no start line in {} bytes of log", log.len()));
    let cap: u64 = start
        .split("serving ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{start}"));
    eprintln!(
        "hostile peer: unattacked {unattacked:?}, attacked {attacked:?}; the stranger made \
         {connections} connections, held {most_held} at most; a token holder served {served:?} \
         after; log pipe {} bytes; {start}",
        log.len()
    );
    assert!(
        (1..=DESCRIPTORS - 64).contains(&cap),
        "the cap leaves room under the descriptor limit: {start}"
    );
    assert!(
        in_pipe >= 60_000,
        "the log pipe held {in_pipe} bytes, not full"
    );
    let allowed = unattacked.mul_f64(SLOWDOWN) + SLOWDOWN_GRACE;
    assert!(attacked < allowed, "{attacked:?} against {unattacked:?}");
    assert!(served < Duration::from_secs(5), "{served:?}");
}

//! The accept loop when the process runs out of file descriptors: it backs off, says
//! NOT_SERVING, logs one line for the whole episode instead of one per attempt, and serves
//! again once descriptors are free. A test binary of its own: it lowers its own process's
//! descriptor limit.

use std::fs::File;
use std::io::Write;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use tokio::time::Instant;
use tonic_health::pb::health_check_response::ServingStatus;
use tonic_health::pb::{health_client::HealthClient, HealthCheckRequest};
use yat_proto::auth::AttachToken;
use yat_proto::{pb, RenderNodeClient};
use yat_worker::WorkerConfig;

mod support;
use support::*;

const TOKEN: &str = "honest";

/// Log lines, kept for the test to read.
#[derive(Clone, Default)]
struct Captured(Arc<Mutex<Vec<u8>>>);

impl Write for Captured {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        self.0.lock().unwrap().extend_from_slice(bytes);
        Ok(bytes.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

impl Captured {
    fn lines_with(&self, text: &str) -> Vec<String> {
        String::from_utf8_lossy(&self.0.lock().unwrap())
            .lines()
            .filter(|line| line.contains(text))
            .map(str::to_string)
            .collect()
    }
}

/// The soft and hard limits on open descriptors.
fn descriptor_limit() -> libc::rlimit {
    let mut limit = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: getrlimit writes the struct it is given.
    assert_eq!(
        unsafe { libc::getrlimit(libc::RLIMIT_NOFILE, &mut limit) },
        0
    );
    limit
}

fn set_descriptor_limit(limit: &libc::rlimit) {
    // SAFETY: setrlimit reads the struct it is given.
    assert_eq!(unsafe { libc::setrlimit(libc::RLIMIT_NOFILE, limit) }, 0);
}

/// Takes every descriptor the process may still open: lowers the soft limit to a few above
/// those open, then opens files until the system says EMFILE. Returns the files.
fn exhaust_descriptors() -> Vec<File> {
    let open = std::fs::read_dir("/proc/self/fd").unwrap().count() as u64;
    set_descriptor_limit(&libc::rlimit {
        rlim_cur: open + 16,
        ..descriptor_limit()
    });
    let mut files = Vec::new();
    loop {
        match File::open("/dev/null") {
            Ok(file) => files.push(file),
            Err(e) => {
                assert_eq!(e.raw_os_error(), Some(libc::EMFILE), "{e}");
                return files;
            }
        }
    }
}

async fn health_status(health: &mut HealthClient<tonic::transport::Channel>) -> ServingStatus {
    let request = HealthCheckRequest {
        service: "yat.render.v1.RenderNode".into(),
    };
    health.check(request).await.unwrap().into_inner().status()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn out_of_descriptors_the_worker_says_not_serving_logs_once_and_serves_again() {
    let log = Captured::default();
    let writer = log.clone();
    tracing_subscriber::fmt()
        .with_writer(move || writer.clone())
        .with_env_filter("yat_worker=warn")
        .init();
    let worker = Served::start(WorkerConfig {
        token: Some(TOKEN.into()),
        ..WorkerConfig::default()
    })
    .await;
    // One connection, authenticated, that carries the health checks while no new one can be
    // accepted.
    let channel = worker.channel();
    let mut client =
        RenderNodeClient::with_interceptor(channel.clone(), AttachToken::new(Some(TOKEN)).unwrap());
    client.stats(pb::StatsRequest {}).await.unwrap();
    let mut health = HealthClient::new(channel);
    assert_eq!(health_status(&mut health).await, ServingStatus::Serving);

    // A socket made while descriptors were free, connected once they are not: its connection
    // waits in the listen backlog, and every accept of it fails with EMFILE.
    let waiting = tokio::net::TcpSocket::new_v4().unwrap();
    let limit = descriptor_limit();
    let files = exhaust_descriptors();
    let _waiting = waiting.connect(worker.address).await.unwrap();
    let exhausted = Instant::now();
    let mut not_serving = None;
    while exhausted.elapsed() < Duration::from_secs(3) {
        if not_serving.is_none() && health_status(&mut health).await == ServingStatus::NotServing {
            not_serving = Some(exhausted.elapsed());
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    let not_serving = not_serving.expect("NOT_SERVING while out of descriptors");

    drop(files);
    set_descriptor_limit(&limit);
    let released = Instant::now();
    let mut fresh = worker.client(Some(TOKEN));
    tokio::time::timeout(Duration::from_secs(5), fresh.stats(pb::StatsRequest {}))
        .await
        .expect("a new client is served")
        .unwrap();
    let served = released.elapsed();
    assert_eq!(health_status(&mut health).await, ServingStatus::Serving);
    let lines = log.lines_with("cannot accept a connection");
    eprintln!(
        "out of descriptors: NOT_SERVING after {not_serving:?}; a new client served {served:?} \
         after the release; accept failures logged: {lines:?}"
    );
    // The back-off tops out at 1 s, so the loop retries within it.
    assert!(served < Duration::from_secs(2), "{served:?}");
    // Some ten failed accepts in the 3 s (10, 20, 40 ... 1000 ms apart): one line.
    assert_eq!(lines.len(), 1, "{lines:?}");
    assert!(lines[0].contains("Too many open files"), "{lines:?}");
}

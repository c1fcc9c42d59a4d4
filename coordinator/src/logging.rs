//! Where log lines go: standard error, written by a thread of their own through a bounded
//! queue. A standard error nobody drains (a supervisor's or a container runtime's full log
//! pipe, a parent that never reads it) then costs lines, never a stalled accept loop or render:
//! when the queue is full, new lines are dropped.

use std::io::IsTerminal;
use std::sync::Mutex;

use tracing_appender::non_blocking::{NonBlockingBuilder, WorkerGuard};
use tracing_subscriber::EnvFilter;

/// Lines waiting for standard error at most (a few MiB).
const QUEUED_LINES: usize = 10_000;

/// Flushes the queue when taken and dropped.
static WRITER: Mutex<Option<WorkerGuard>> = Mutex::new(None);

/// Installs the log: the `YAT_LOG` filter, else `default_filter`.
pub fn init(default_filter: &str) {
    let (writer, guard) = NonBlockingBuilder::default()
        .lossy(true)
        .buffered_lines_limit(QUEUED_LINES)
        .finish(std::io::stderr());
    tracing_subscriber::fmt()
        .with_env_filter(
            EnvFilter::try_from_env("YAT_LOG").unwrap_or_else(|_| EnvFilter::new(default_filter)),
        )
        .with_writer(writer)
        // Colours for a person at a terminal, plain text for a log file or a collector.
        .with_ansi(std::io::stderr().is_terminal())
        .init();
    *WRITER.lock().unwrap_or_else(|e| e.into_inner()) = Some(guard);
}

/// Writes what is queued (waiting a second at most for a blocked standard error).
pub fn flush() {
    drop(WRITER.lock().unwrap_or_else(|e| e.into_inner()).take());
}

/// Ends the process with `code` once the queued lines are written.
pub fn exit(code: i32) -> ! {
    flush();
    std::process::exit(code)
}

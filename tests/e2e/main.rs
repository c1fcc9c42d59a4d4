//! End-to-end tests: the real `yat` binary, real workers, real sockets. One test binary; each
//! module is a part of the command line, and `architecture` checks the workspace's import graph.

mod adaptive;
mod architecture;
mod check;
mod discovery;
mod distributed;
mod drain;
mod files;
mod frames;
mod halts;
#[path = "../fixtures/hostile.rs"]
mod hostile;
mod hostile_peer;
mod hostile_worker;
mod http;
mod isa;
#[path = "../fixtures/lit_sphere.rs"]
mod lit_sphere;
mod luxconsole;
mod memory;
mod outputs;
mod progress_log;
mod resume;
mod status;
mod util;
mod worker_metrics;
#[path = "../fixtures/workspace.rs"]
mod workspace;

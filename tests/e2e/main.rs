//! End-to-end tests: the real `yat` binary, real workers, real sockets. One test binary; each
//! module is a part of the command line.

mod check;
mod distributed;
mod resume;
mod util;

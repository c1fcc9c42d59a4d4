//! Who renders a job: the in-process executor and the distributed one, siblings that share
//! progress reporting and never import each other.

pub mod distributed;
pub mod in_process;
pub mod progress;
pub mod progress_log;
